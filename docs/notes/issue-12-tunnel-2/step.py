"""Per-step wall time of a plain Gate.step on models/tunnel (tunnel.py's command schedule).

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-2/step.py [rounds]   -> median us per step
(over rounds x 100 steps, each round's mean), verdict counts.
"""
import collections
import hashlib
import sys
import time

import mujoco
import numpy as np

from monitor.gate import Gate

m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)


def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    vs = collections.Counter()
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
        vs[str(r.verdict)] += 1
    return (time.perf_counter() - t) / n, vs, d.qpos.tobytes()


run(20)
rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
res = [run(100) for _ in range(rounds)]
print(f"{np.median([r[0] for r in res]) * 1e6:.0f}", dict(res[0][1]), hashlib.md5(res[0][2]).hexdigest()[:12])
