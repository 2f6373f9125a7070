import time, statistics, mujoco, numpy as np
from monitor import Plan, Scene, certify
XML = """<mujoco><option timestep="0.01"/><worldbody><body name="wall" pos="0.1 0 0"><geom name="wall" type="box" size="0.005 0.2 0.2"/></body>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.01"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
T = np.linspace(0, 0.05, 6); Q = np.linspace(-0.05, -0.03, 6)[:, None]
plans = [Plan(T, Q + 1e-6 * k, m) for k in range(3000)]
for p in plans[:200]: certify(sc, p, 0.001)
ts = []
for blk in range(10):
    t0 = time.process_time()
    for p in plans[200 + blk * 280: 200 + (blk + 1) * 280]:
        certify(sc, p, 0.001)
    ts.append((time.process_time() - t0) / 280 * 1e6)
print("certify per fresh plan us: median %.1f" % statistics.median(ts), "verdict", certify(sc, plans[-1], 0.001).verdict, certify(sc, plans[-1], 0.001).stats["checker_mix"])
