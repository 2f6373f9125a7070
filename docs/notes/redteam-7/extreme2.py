import mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
from monitor import Plan, Scene, certify, BodyMotion
from monitor.errors import MonitorError
XML = """
<mujoco>
  <worldbody>
    <geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
    <body name="ball"><joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="0.02"/></body>
  </worldbody>
</mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
def run(name, t, q, meths=("auto", "toleranced", "extrusion")):
    out = []
    try:
        p = Plan(t, q, m)
    except MonitorError as e:
        print(f"{name:40s} Plan typed {type(e).__name__}: {str(e)[:60]}"); return
    for meth in meths:
        try:
            c = certify(sc, p, margin=0.0, method=meth, budget={"seconds": 5.0})
            out.append(f"{meth}:{c.verdict.value if hasattr(c.verdict,'value') else c.verdict}({c.clearance:.2g})")
        except MonitorError as e:
            out.append(f"{meth}:typed({type(e).__name__})")
    print(f"{name:40s}", " ".join(out))
# all pass through the wall at x=0.3 (ball must be violation or uncertain)
for dt in (1e-300, 1e-307, 2.3e-308, 2.2250738585072014e-308, 2.225e-308, 1e-308, 1e-320, 5e-324):
    run(f"dq=2 dt={dt:.3g}", [0, dt], [[-1.0], [1.0]])
for dq, dt in ((1e10, 1e-298), (1e10, 1e-300), (1e100, 1e-210), (1e100, 1e-200), (1e300, 1e-8), (1e300, 1.0), (1e308, 1.0)):
    run(f"dq={dq:.3g} dt={dt:.3g}", [0, dt], [[-dq / 2], [dq / 2]])
for a in (1e307, 8e307, 8.9e307, 9e307, 1.7e308):
    run(f"through +-{a:.3g} dt=1", [0, 1], [[-a], [a]])
# time offsets: window far from zero
for T in (1e15, 1e16, 1e17, 1e300):
    run(f"window at T={T:.3g}", [T, np.nextafter(T, np.inf)], [[-1.0], [1.0]])
