import mujoco, numpy as np, time, statistics
from monitor import Plan, Scene, certify
import monitor.motion._kinematics as KK
import monitor.motion.plan as PP
real = KK.finite_velocities
acc = []
def spy(t, p):
    t0 = time.perf_counter(); r = real(t, p); acc.append(time.perf_counter() - t0); return r
KK.finite_velocities = spy
orig_ts = PP.Plan.translation_segments
acc2 = []
def ts(self, b):
    t0 = time.perf_counter(); r = orig_ts(self, b); acc2.append(time.perf_counter() - t0); return r
PP.Plan.translation_segments = ts
XML = """<mujoco><option timestep="0.01"/><worldbody><body name="wall" pos="0.1 0 0"><geom name="wall" type="box" size="0.005 0.2 0.2"/></body>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.01"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
T = np.linspace(0, 0.05, 6); Q = np.linspace(-0.05, -0.03, 6)[:, None]
for k in range(2000):
    certify(sc, Plan(T, Q + 1e-6 * k, m), 0.001)
print("finite_velocities in situ median %.2f us, p90 %.2f" % (statistics.median(acc[200:]) * 1e6, np.percentile(acc[200:], 90) * 1e6))
print("translation_segments in situ median %.2f us" % (statistics.median(acc2[200:]) * 1e6))
