"""The log's Foxglove scene draws each geom where MuJoCo's kinematics put it (red team 4 follow-up).

Base b036d4c drew every geom at ``geom_pos`` / ``geom_quat`` in its body frame; MuJoCo places a geom
the compiler marked ``geom_sameframe`` at its body's (or inertial) frame instead, so after a
centre-of-mass edit (``body_ipos``) or a ``geom_pos`` edit of such a geom the drawing showed it
elsewhere than the simulation (and the certificate's Scene) had it. Oracle: MuJoCo's own
``geom_xpos`` / ``geom_xmat`` after ``mj_kinematics``, the drawn pose composed with MuJoCo's body
pose, quaternions read with scipy's (x, y, z, w) convention (independent of the module's).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

_XML = """<mujoco><worldbody>
<geom name="origin" type="sphere" size="0.05"/>
<body name="b" pos="0 -0.5 0"><freejoint/>
  <geom name="cap" type="capsule" size="0.05 0.02" pos="0.3 0 0" euler="0 90 0"/></body>
<body name="c" pos="1 0 0" euler="0 0 20"><freejoint/>
  <geom name="box" type="box" size=".1 .05 .02" pos="0.1 0.2 0"/>
  <geom name="cyl" type="cylinder" size=".03 .05" pos="-0.1 0 0.1" euler="30 0 0"/></body>
</worldbody></mujoco>"""


def _edited_model():
    m = mujoco.MjModel.from_xml_string(_XML)
    S = mujoco.mjtSameFrame
    frames = {n: int(m.geom_sameframe[m.geom(n).id]) for n in ("origin", "cap", "box", "cyl")}
    assert frames == {"origin": S.mjSAMEFRAME_BODY, "cap": S.mjSAMEFRAME_INERTIA,  # set-up
                      "box": S.mjSAMEFRAME_BODYROT, "cyl": S.mjSAMEFRAME_NONE}, frames
    b = m.body("b").id
    m.body_ipos[b] += (0.0, 0.2, 0.05)              # centre-of-mass randomisation moves "cap"
    q = np.array([0.9, 0.1, -0.3, 0.2])
    m.body_iquat[b] = q / np.linalg.norm(q)
    m.geom_pos[m.geom("origin").id] = (2.0, 0.0, 0.0)  # MuJoCo keeps it at the world origin
    q = np.array([0.8, 0.0, 0.6, 0.0])
    m.geom_quat[m.geom("box").id] = q / np.linalg.norm(q)  # BODYROT: MuJoCo keeps the body's rotation
    m.geom_pos[m.geom("box").id] = (0.0, -0.1, 0.3)        # ... and takes this position
    return m


def _decoded(scene_cls, update):
    """The encoded ``SceneUpdate`` read back with protobuf from the log's own schema."""
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    from monitor.log import topics

    name, _, fds_bytes = scene_cls.schemas()[topics.SCENE]
    pool = descriptor_pool.DescriptorPool()
    for f in descriptor_pb2.FileDescriptorSet.FromString(fds_bytes).file:
        pool.Add(f)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(name)).FromString(update.encode())


def test_scene_geoms_are_drawn_where_mujoco_places_them():
    pytest.importorskip("foxglove")
    from scipy.spatial.transform import Rotation

    from monitor.log.foxglove_scene import FoxgloveScene

    m = _edited_model()
    d = mujoco.MjData(m)
    rng = np.random.default_rng(7)
    for j in (m.joint(0).id, m.joint(1).id):
        a = m.jnt_qposadr[j]
        q = rng.normal(size=4)
        d.qpos[a:a + 7] = np.concatenate([rng.uniform(-1, 1, 3), q / np.linalg.norm(q)])
    mujoco.mj_kinematics(m, d)
    update = _decoded(FoxgloveScene, FoxgloveScene(m).geometry(0))
    seen = set()
    for e in update.entities:
        g = int(next(kv.value for kv in e.metadata if kv.key == "geom_id"))
        b = int(m.geom_bodyid[g])
        assert e.frame_id == (m.body(b).name or "world") if b else e.frame_id == "world"
        Rb, pb = d.xmat[b].reshape(3, 3), d.xpos[b]
        prims = [*e.cubes, *e.cylinders, *e.spheres]
        pose = prims[0].pose                     # the geom's own frame (a capsule's cylinder)
        p = np.array([pose.position.x, pose.position.y, pose.position.z])
        o = pose.orientation
        R = Rotation.from_quat([o.x, o.y, o.z, o.w]).as_matrix()
        np.testing.assert_allclose(Rb @ p + pb, d.geom_xpos[g], atol=1e-9, err_msg=m.geom(g).name)
        np.testing.assert_allclose(Rb @ R, d.geom_xmat[g].reshape(3, 3), atol=1e-9, err_msg=m.geom(g).name)
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE:  # the end caps on MuJoCo's axis
            axis, half = d.geom_xmat[g].reshape(3, 3)[:, 2], m.geom_size[g, 1]
            ends = sorted(tuple(Rb @ [s.pose.position.x, s.pose.position.y, s.pose.position.z] + pb)
                          for s in e.spheres)
            want = sorted(tuple(d.geom_xpos[g] + k * half * axis) for k in (-1.0, 1.0))
            np.testing.assert_allclose(ends, want, atol=1e-9)
        seen.add(m.geom(g).name)
    assert seen == {"origin", "cap", "box", "cyl"}
