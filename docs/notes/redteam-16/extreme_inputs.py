"""Red team 16, ideas (1)/(4): extreme times (overflowing midpoints, 1e15 s, subnormal spans, -0.0) and
coordinates (1e308, 9e8, the 1e9 edge, hinge 1e300 / 1e-300), 2000 waypoints; auto and toleranced.
Run in both trees and diff."""
import mujoco, numpy as np, monitor, warnings
warnings.simplefilter("ignore")
XML = '''<mujoco><worldbody><geom name="w" type="box" size=".1 .1 .1" pos="0.5 0 0"/>
<body name="a" pos="0 0 0"><joint name="ja" type="slide" axis="1 0 0"/><geom name="ga" type="sphere" size=".1"/></body>
<body name="b" pos="0 0.5 0"><joint name="jb" type="hinge" axis="0 0 1"/><geom name="gb" type="capsule" size=".05 .1" pos="0.2 0 0"/></body>
</worldbody></mujoco>'''
m = mujoco.MjModel.from_xml_string(XML)
sc = monitor.Scene.from_model(m, pairs="all")
cases = {
 "t huge overflow mid": ([1e308, 1.7e308], [[0, 0], [0.35, 1.0]]),
 "t symmetric max": ([-1.7e308, 1.7e308], [[0, 0], [0.35, 1.0]]),
 "t 1e15": ([1e15, 1e15 + 1], [[0, 0], [0.35, 1.0]]),
 "t subnormal span": ([0.0, 5e-324], [[0, 0], [0.35, 1.0]]),
 "t subnormal span 2": ([5e-324, 1e-323], [[0, 0], [0.35, 1.0]]),
 "t -0.0": ([-0.0, 1.0], [[0, 0], [0.35, 1.0]]),
 "q huge slide": ([0, 1], [[0, 0], [1e308, 0]]),
 "q huge slide neg": ([0, 1], [[-1.7e308, 0], [1.7e308, 0]]),
 "q big 9e8": ([0, 1], [[9e8, 0], [9e8 + 1, 0]]),
 "q 1e9 edge": ([0, 1], [[1e9 - 0.5, 0], [1e9 - 0.25, 0]]),
 "q hinge 1e300": ([0, 1], [[0, 1e300], [0.35, 1e300]]),
 "q hinge tiny": ([0, 1], [[0, 0], [0.35, 1e-300]]),
 "q hinge huge diff": ([0, 1], [[0, -1e300], [0.35, 1e300]]),
 "many waypoints": (list(np.arange(2000) * 1e-3), np.c_[np.linspace(0, 0.35, 2000), np.zeros(2000)]),
}
for name, (t, q) in cases.items():
    out = []
    for meth in ("auto", "toleranced"):
        try:
            p = monitor.Plan(np.array(t, float), np.array(q, float), model=m)
            c = monitor.certify(sc, p, margin=0.01, method=meth)
            out.append((c.verdict.value, c.witness and c.witness.time, c.earliest_time))
        except Exception as e:
            out.append(type(e).__module__ + "." + type(e).__name__ + ": " + str(e)[:70])
    print(name, out)
