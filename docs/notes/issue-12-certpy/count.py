import collections
import os

import mujoco
import numpy as np

from monitor.certify import engine

cnt = collections.Counter()
for name in ("_window_kernel", "_extrusion_decided", "_find_witness", "_all_culled", "_certify_fast"):
    f = getattr(engine, name)
    def w(*a, _f=f, _n=name, **k):
        cnt[_n] += 1
        return _f(*a, **k)
    setattr(engine, name, w)
from monitor.gate import Gate

tree = os.environ["PYTHONPATH"]
m = mujoco.MjModel.from_xml_path(os.path.join(tree, "models/tunnel/scene.xml"))
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, 0)
N = 600
for k in range(N):
    target = 0.3 if (k // 100) % 2 == 0 else -0.3
    gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
print({k: round(v / N, 3) for k, v in cnt.items()})
