"""Every certificate of N bench tunnel_gate steps (to_dict without wall_seconds) and the final state, hashed.

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-3/dump.py [steps] [out.txt]
Run in the base tree and in this one: the files must be identical (old-vs-new, separate processes).
Also prints the per-step median wall time of the run (one process: a rough figure only).
"""
import hashlib
import sys
import time

import mujoco
import numpy as np

from monitor.gate import Gate

steps = int(sys.argv[1]) if len(sys.argv) > 1 else 600
out = sys.argv[2] if len(sys.argv) > 2 else None
m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, 0)
lines, dt = [], []
for k in range(steps):
    target = 0.3 if (k // 100) % 2 == 0 else -0.3
    ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
    t = time.perf_counter()
    r = gate.step(d, ctrl, nstep=1)
    dt.append(time.perf_counter() - t)
    c = r.certificate.to_dict()
    c["stats"].pop("wall_seconds")
    lines.append(f"{k} {r.verdict} {repr(c)}")
lines.append("qpos " + d.qpos.tobytes().hex() + " qvel " + d.qvel.tobytes().hex())
text = "\n".join(lines) + "\n"
if out:
    open(out, "w").write(text)
print(hashlib.md5(text.encode()).hexdigest(), f"median step {np.median(dt) * 1e6:.0f} us")
