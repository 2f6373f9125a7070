import mujoco, numpy as np
from monitor.scene import Scene
from monitor.errors import MonitorError
XML = """
<mujoco>
  <worldbody>
    <geom name="wg" type="box" size="0.05 0.02 0.03" pos="0.3 0.2 0.1" euler="10 20 30"/>
    <body name="m" mocap="true" pos="0.5 0 0" euler="0 30 40">
      <geom name="mg" type="box" size="0.05 0.02 0.03" pos="0.1 0.2 0.0" euler="5 0 0"/>
    </body>
    <body name="s" pos="-0.5 0 0.2" euler="20 0 10">
      <geom name="sg" type="box" size="0.05 0.02 0.03" pos="0.1 -0.2 0.0"/>
    </body>
    <body name="h" pos="0 0.5 0" euler="0 20 0">
      <joint type="hinge" axis="0 1 1"/>
      <geom name="hg" type="box" size="0.05 0.02 0.03" pos="0.1 0 0.2"/>
    </body>
  </worldbody>
</mujoco>"""
m0 = mujoco.MjModel.from_xml_string(XML)
print("compiled body_sameframe", m0.body_sameframe, "geom_sameframe", m0.geom_sameframe, "world ipos", m0.body_ipos[0], m0.body_iquat[0])
bad = 0; n = 0; refused = 0
for gname in ["wg", "mg", "sg", "hg"]:
    for bsf in (0, 1, 3):
        for gsf in range(5):
            m = mujoco.MjModel.from_xml_string(XML)
            g = m.geom(gname).id; b = m.geom_bodyid[g]
            m.body_ipos[b] = [0.03, -0.07, 0.11]
            m.body_iquat[b] = np.array([0.9, 0.1, 0.3, -0.2]) / np.linalg.norm([0.9, 0.1, 0.3, -0.2])
            m.body_sameframe[b] = bsf
            m.geom_sameframe[g] = gsf
            d = mujoco.MjData(m); d.qpos[:] = 0.4; mujoco.mj_forward(m, d)
            try:
                sc = Scene.from_model(m, pairs="all")
            except MonitorError:
                refused += 1; continue
            gi = sc.geom(gname)
            P = gi.shape.points  # body frame
            W = P @ d.xmat[b].reshape(3, 3).T + d.xpos[b]
            # MuJoCo's box vertices
            R = d.geom_xmat[g].reshape(3, 3); s = m.geom_size[g]
            V = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * s
            Wm = V @ R.T + d.geom_xpos[g]
            err = max(np.min(np.linalg.norm(W[:, None] - Wm[None], axis=2), axis=1).max(), 0)
            n += 1
            if err > 1e-9:
                bad += 1; print(gname, "b", b, "bsf", bsf, "gsf", gsf, "err", round(err, 4))
print("cases", n, "bad", bad, "refused", refused)
