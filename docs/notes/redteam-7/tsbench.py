import timeit, mujoco, numpy as np, statistics
from monitor import Plan
XML = """<mujoco><option timestep="0.01"/><worldbody><geom name="wall" type="box" size="0.005 0.2 0.2" pos="0.1 0 0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.01"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
p = Plan(np.linspace(0, 0.05, 6), np.linspace(0, 0.03, 6)[:, None], m)
p.translation_segments(1)
ts = [min(timeit.repeat(lambda: p.translation_segments(1), number=2000, repeat=5)) / 2000 * 1e6 for _ in range(3)]
print("translation_segments(moving body) us: %.2f" % statistics.median(ts))
