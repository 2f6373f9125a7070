import os
import sys; sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "tests"))
import test_redteam_6 as T, mujoco, numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "tests")); from test_gate_static_reuse import _key
from monitor.gate import Gate
def run(general):
    m = mujoco.MjModel.from_xml_string(T._XML); m.body_pos[m.body("wall").id, 0] = 0.06
    d = mujoco.MjData(m)
    g = Gate(m, pairs="all", margin=1e-3, allowed=None, ongoing="violation")
    if general: own = g._certify; g._certify = lambda p: own(p)
    pos = [0.0, -0.0] + [-0.0001 * k for k in range(1, 70)]
    out, false = [], 0
    for rep in range(2):
        for i, p in enumerate(pos):
          for j in range(2):
            d.qpos[0] = p; d.qvel[0] = 0.0
            if i % 7 == 0: d.time += 1.0  # same rows, other times
            r = g.step(d, np.array([6.0])); mujoco.mj_forward(m, d)
            dist = T._sphere_box_distance(m, d, 0, 1)
            false += r.applied_verdict == "certified" and dist <= 1e-3
            out.append(_key(r))
    return out, false, g.stats["static_reused"], len(g._static_keys[1]) if g._static_keys else None
a = run(False); b = run(True)
print("same", sum(x == y for x, y in zip(a[0], b[0])), "/", len(a[0]), "false", a[1], b[1], "static hits", a[2], "memo size", a[3])
