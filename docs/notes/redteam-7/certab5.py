"""In-process A/B of the velocity check in extrusion_swept.decide_pair: the module's finite_velocities
swapped with an always-True stub in alternating blocks (fresh Plan per certify call, tunnel-like window)."""
import time, statistics, mujoco, numpy as np
from monitor import Plan, Scene, certify
import monitor.certify.extrusion_swept as XS
real = XS.finite_velocities
XML = """<mujoco><option timestep="0.01"/><worldbody><body name="wall" pos="0.1 0 0"><geom name="wall" type="box" size="0.005 0.2 0.2"/></body>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.01"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
T = np.linspace(0, 0.05, 6); Q = np.linspace(-0.05, -0.03, 6)[:, None]
plans = [Plan(T, Q + 1e-6 * k, m) for k in range(6000)]
for p in plans[:200]: certify(sc, p, 0.001)
res = {"check": [], "none": []}
i = 200
for blk in range(20):
    mode = "check" if blk % 2 == 0 else "none"
    XS.finite_velocities = real if mode == "check" else (lambda t, p: True)
    t0 = time.process_time()
    for p in plans[i:i + 280]:
        certify(sc, p, 0.001)
    i += 280
    res[mode].append((time.process_time() - t0) / 280 * 1e6)
print(" ".join("%s median %.1f us" % (k, statistics.median(v)) for k, v in res.items()), certify(sc, plans[-1], 0.001).stats["checker_mix"])
