import mujoco, numpy as np, math, tracemalloc
from monitor._paths import scene_path
from monitor.gate import Gate
import monitor.gate as G
from monitor.errors import InvalidInputError
from monitor.certify.types import Verdict
m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
res = []
for dt, hz in [(0.01, 1e9), (1e-300, 0.25), (5e-324, 0.25), (0.01, 1000.0), (0.01, 1000.0000001), (0.01, 999.9999), (float('nan'), .25), (-0.01, .25), (0.0, .25), (float('inf'), .25)]:
    m.opt.timestep = dt
    g = Gate(m, margin=0.001, brake_horizon=hz)
    d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0)
    try:
        n = g.brake_steps; out = ("ok", n)
    except InvalidInputError as e:
        out = ("err", str(e)[:60])
    except Exception as e:
        out = ("UNTYPED", repr(e)[:80])
    res.append((dt, hz, out))
m.opt.timestep = 0.01
for r in res: print(r)
# decide path with a huge horizon: typed error, bounded memory
g = Gate(m, margin=0.001, brake_horizon=1e7)
d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0); d.qpos[0] = -0.3
tracemalloc.start()
try:
    g.step(d, np.array([0.0])); print("no error?!")
except InvalidInputError as e: print("decide typed:", str(e)[:70])
print("peak MB", tracemalloc.get_traced_memory()[1]/1e6)
# brake_verdict types over a tunnel run
g = Gate(m, margin=0.001); d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0)
types = {}
for k in range(200):
    r = g.step(d, np.clip([12.0 * ((0.3 if (k//25)%2==0 else -0.3) - d.qpos[0])], -6, 6))
    types[(type(r.brake_verdict).__name__, str(r.brake_verdict))] = types.get((type(r.brake_verdict).__name__, str(r.brake_verdict)),0)+1
print(types)
