import mujoco, numpy as np, itertools
xml = """<mujoco><worldbody><body name="b" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2">
<joint type="hinge" axis="0 1 0"/><inertial pos="0.05 -0.02 0.01" quat="0.8 0.2 -0.1 0.3" mass="1" diaginertia="1 2 3"/>
<geom type="box" size=".1 .1 .1" pos="-.03 .04 .02" quat="0.7 0.1 0.5 -0.2"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(xml); d = mujoco.MjData(m); d.qpos[0] = 0.4
def q2m(q): R = np.zeros(9); mujoco.mju_quat2Mat(R, np.asarray(q, float) / np.linalg.norm(q)); return R.reshape(3, 3)
def inertial(b):
    bs = int(m.body_sameframe[b])
    if bs == 1: return np.eye(3), np.zeros(3)
    if bs == 3: return np.eye(3), m.body_ipos[b].copy()
    return q2m(m.body_iquat[b]), m.body_ipos[b].copy()
def frame(g):
    sf = int(m.geom_sameframe[g]); b = m.geom_bodyid[g]
    if sf == 1: return np.eye(3), np.zeros(3)
    if sf == 2: return inertial(b)
    if sf == 3: return np.eye(3), m.geom_pos[g].copy()
    if sf == 4: return inertial(b)[0], m.geom_pos[g].copy()
    return q2m(m.geom_quat[g]), m.geom_pos[g].copy()
from monitor.scene import geom_frame
bad = {"new": 0, "cur": 0}; n = 0
for bs, gs in itertools.product(range(4), range(5)):   # body_sameframe 2 (INERTIA) is never compiled; tried too
    m.body_sameframe[1] = bs; m.geom_sameframe[0] = gs
    mujoco.mj_kinematics(m, d)
    Rb = d.xmat[1].reshape(3, 3); pb = d.xpos[1]
    for fn, tag in ((frame, "new"), (geom_frame, "cur")):
        R, p = fn(m, 0) if fn is geom_frame else fn(0)
        ok = np.allclose(Rb @ R, d.geom_xmat[0].reshape(3, 3), atol=1e-12) and np.allclose(pb + Rb @ p, d.geom_xpos[0], atol=1e-12)
        if not ok:
            bad[tag] += 1
            print(tag, "body_sameframe", bs, "geom_sameframe", gs)
    n += 1
print("combos", n, "mismatch proposed", bad["new"], "mismatch current geom_frame", bad["cur"])
