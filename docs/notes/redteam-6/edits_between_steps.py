"""Probe: edits / settings between steps; static shortcut vs general path vs closed-form oracle."""
import os
import mujoco, numpy as np, math, sys
from monitor._paths import scene_path
from monitor.gate import Gate
from monitor.tolerances import DEFAULT
import dataclasses
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "tests"))
from test_gate_static_reuse import _key

def box_sphere(m, d, gbox, gs):
    R = d.geom_xmat[gbox].reshape(3, 3); c = R.T @ (d.geom_xpos[gs] - d.geom_xpos[gbox])
    h = m.geom_size[gbox]; q = np.clip(c, -h, h)
    out = np.linalg.norm(c - q)
    if out > 0: return out - m.geom_size[gs, 0]
    return -(np.min(h - np.abs(c))) - m.geom_size[gs, 0]

def quat_z(a): return np.array([math.cos(a/2), 0, 0, math.sin(a/2)])
EDITS = {
 "wall_body_pos": lambda m, g: m.body_pos.__setitem__((m.body("wall").id, 0), -0.04),
 "wall_body_quat": lambda m, g: m.body_quat.__setitem__(m.body("wall").id, quat_z(math.pi/2)),
 "wall_geom_pos": lambda m, g: (m.geom_sameframe.__setitem__(0, 0), m.geom_pos.__setitem__((0, 0), -0.04)),
 "wall_geom_quat": lambda m, g: (m.geom_sameframe.__setitem__(0, 0), m.geom_quat.__setitem__(0, quat_z(math.pi/2))),
 "ball_jnt_axis": lambda m, g: m.jnt_axis.__setitem__(0, [0, 1, 0]),
 "ball_qpos0": lambda m, g: m.qpos0.__setitem__(0, -0.045),
 "wall_ipos_sameframe2": lambda m, g: (m.geom_sameframe.__setitem__(0, 2), m.body_ipos.__setitem__((m.body("wall").id, 0), -0.04)),
 "wall_iquat_sameframe4": lambda m, g: (m.geom_sameframe.__setitem__(0, 4), m.body_iquat.__setitem__(m.body("wall").id, quat_z(math.pi/2))),
 "wall_geom_size": lambda m, g: m.geom_size.__setitem__((0, 0), 0.04),
 "timestep": lambda m, g: setattr(m.opt, "timestep", 0.005),
 "margin": lambda m, g: setattr(g, "margin", 0.05),
 "epsilon": lambda m, g: setattr(g, "epsilon", 0.5),
 "tolerances": lambda m, g: setattr(g, "tolerances", dataclasses.replace(DEFAULT)),
 "ongoing": lambda m, g: setattr(g, "ongoing", "deepen"),
 "penetration_tol": lambda m, g: (setattr(g, "ongoing", "deepen"), setattr(g, "penetration_tol", 1e-6)),
 "reuse_off": lambda m, g: setattr(g, "reuse", False),
 "reuse_off_on": lambda m, g: (setattr(g, "reuse", False), setattr(g, "reuse", True)),
 "ball_neg_zero": None,
}
def run(edit, general, steps=8, at=4):
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    m.geom_contype[0] = 0; m.geom_conaffinity[0] = 0
    d = mujoco.MjData(m); d.qpos[0] = -0.05; mujoco.mj_forward(m, d)
    g = Gate(m, pairs="all", margin=0.001, allowed=None, ongoing="violation")
    if general:
        orig = g._certify; g._certify = lambda p: orig(p)
    out = []; bad = 0
    for k in range(steps):
        if k == at:
            if edit == "ball_neg_zero":
                pass
            else:
                EDITS[edit](m, g)
        r = g.step(d, np.array([6.0]))
        mujoco.mj_forward(m, d)
        dist = box_sphere(m, d, 0, 1)
        if r.applied_verdict == "certified" and not dist > g.margin: bad += 1
        out.append(_key(r))
    return out, bad, g.stats["static_reused"]
tot = 0
for e in EDITS:
    s, bs, n = run(e, False); gg, bg, _ = run(e, True)
    same = sum(a == b for a, b in zip(s, gg)); tot += len(s)
    print(f"{e:24s} same {same}/{len(s)} bad static {bs} general {bg} static_hits {n}")
print("steps", tot)
