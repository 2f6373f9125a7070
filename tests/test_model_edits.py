"""Issue 11: a certificate is about the model as it is when ``certify`` runs.

In-place edits of the MjModel (domain randomisation, tuning) must reach the scene's
shapes and pairs (``Scene.sync``) and the plan's frozen joint frames (``Plan.is_current``).
Oracle: a fresh ``Scene``/``Plan`` built on the edited model, and MuJoCo's own signed
distance where it is exact (sphere vs box).
"""

from __future__ import annotations

import pickle

import mujoco
import numpy as np
import pytest

import monitor
from monitor.errors import ModelMismatchError, UnsupportedGeometryError

WALL_XML = """<mujoco><worldbody>
 <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.5 0 0"/>
 <body name="b"><joint name="s" type="slide" axis="0 1 0"/>
  <geom name="ball" type="sphere" size="0.1" pos="0.3 0 0"/></body>
</worldbody></mujoco>"""


def _wall():
    m = mujoco.MjModel.from_xml_string(WALL_XML)
    return m, monitor.Scene.from_model(m, pairs="all")


def _slide_plan(m):
    return monitor.Plan([0, 0.1], [[-0.2], [0.2]], m)


def _mj_distance(m, g1, g2) -> float:
    """MuJoCo's signed distance of two geoms at qpos0 (exact for sphere vs box)."""
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    return mujoco.mj_geomDistance(m, d, m.geom(g1).id, m.geom(g2).id, 1.0, None)


def test_unedited_is_certified_and_sync_is_a_noop():
    m, scene = _wall()
    assert monitor.certify(scene, _slide_plan(m)).verdict == "certified"
    assert scene.sync() is False
    assert scene.version == 0


def test_geom_size_edit_is_seen():
    """Issue reproduction: the ball grows into the wall after the scene was built."""
    m, scene = _wall()
    m.geom_size[m.geom("ball").id][0] = 0.2
    assert _mj_distance(m, "ball", "wall") < 0  # MuJoCo: in contact
    cert = monitor.certify(scene, _slide_plan(m))
    assert cert.verdict == "violation"
    assert scene.version == 1
    assert scene.geom("ball").shape.radius == pytest.approx(0.2)
    fresh = monitor.certify(monitor.Scene.from_model(m, pairs="all"), _slide_plan(m))
    assert fresh.verdict == cert.verdict


def test_geom_pos_edit_is_seen():
    m, scene = _wall()
    m.geom_pos[m.geom("ball").id][0] = 0.4
    assert _mj_distance(m, "ball", "wall") < 0
    assert monitor.certify(scene, _slide_plan(m)).verdict == "violation"


def test_edit_then_restore_certifies_again():
    m, scene = _wall()
    g = m.geom("ball").id
    m.geom_size[g][0] = 0.2
    assert monitor.certify(scene, _slide_plan(m)).verdict == "violation"
    m.geom_size[g][0] = 0.1
    assert monitor.certify(scene, _slide_plan(m)).verdict == "certified"
    assert scene.version == 2


def test_plan_built_and_used_before_a_body_pos_edit():
    """The same Plan object, whose poses were cached before the edit, must not be trusted."""
    m, scene = _wall()
    plan = _slide_plan(m)
    assert monitor.certify(scene, plan).verdict == "certified"  # fills the plan's caches
    assert plan.is_current()
    m.body_pos[m.body("b").id][0] = 0.1  # the ball centre moves to x = 0.4: overlap 0.05
    assert _mj_distance(m, "ball", "wall") < 0
    assert not plan.is_current()
    cert = monitor.certify(scene, plan)
    assert cert.verdict == "violation"
    assert cert.witness is not None


def test_plan_refreshed_matches_a_fresh_plan():
    m = mujoco.MjModel.from_xml_path(str(_arm_path()))
    rng = np.random.default_rng(3)
    q = np.stack([m.qpos0, m.qpos0 + rng.uniform(-0.5, 0.5, m.nq)])
    plan = monitor.Plan([0.0, 0.2], q, m)
    m.jnt_axis[0] = m.jnt_axis[0][[1, 2, 0]]  # rotate the first joint's axis
    assert not plan.is_current()
    new = plan.refreshed()
    ref = monitor.Plan([0.0, 0.2], q, m)
    assert new.is_current()
    ts = np.linspace(0.0, 0.2, 5)
    np.testing.assert_array_equal(new.body_poses(ts)[0], ref.body_poses(ts)[0])
    mb_new, mb_ref = new.motion_bounds(ts[:-1], ts[1:]), ref.motion_bounds(ts[:-1], ts[1:])
    np.testing.assert_array_equal(mb_new.trans, mb_ref.trans)


def _arm_path():
    from pathlib import Path
    return Path(__file__).resolve().parents[1] / "models" / "arm" / "scene.xml"


def test_hinge_plan_after_jnt_pos_edit_is_sound():
    """A hinge whose anchor moves after the plan was built: bounds must use the live frame.

    A capsule arm of length 0.5 swings about z by 0.6 rad; a post stands 0.45 m from the
    original hinge, out of reach. Moving the hinge anchor 0.3 m towards the post puts the
    post in the swept area: MuJoCo's distance along a dense sampling goes negative.
    """
    xml = """<mujoco><worldbody>
      <geom name="post" type="cylinder" size="0.03 0.2" pos="0.0 0.75 0"/>
      <body name="arm"><joint name="h" type="hinge" axis="0 0 1"/>
        <geom name="link" type="capsule" fromto="0 0 0 0.5 0 0" size="0.03"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    scene = monitor.Scene.from_model(m, pairs="all")
    plan = monitor.Plan([0.0, 1.0], [[0.0], [np.pi / 2]], m)
    assert monitor.certify(scene, plan).verdict == "certified"
    m.body_pos[1] = [0.0, 0.3, 0.0]
    d = mujoco.MjData(m)
    dists = []
    for q in np.linspace(0.0, np.pi / 2, 200):
        d.qpos[0] = q
        mujoco.mj_kinematics(m, d)
        dists.append(mujoco.mj_geomDistance(m, d, m.geom("link").id, m.geom("post").id, 1.0, None))
    assert min(dists) < -0.01  # the live motion collides
    assert monitor.certify(scene, plan).verdict == "violation"


def test_contype_edit_under_mujoco_pairs():
    """pairs="mujoco": enabling collisions on a geom adds its pairs."""
    xml = WALL_XML.replace('size="0.1" pos="0.3 0 0"', 'size="0.2" pos="0.3 0 0" contype="0" conaffinity="0"')
    m = mujoco.MjModel.from_xml_string(xml)
    scene = monitor.Scene.from_model(m, pairs="mujoco")
    assert scene.candidate_pairs == ()
    assert monitor.certify(scene, _slide_plan(m)).stats["nothing_checked"] is True
    g = m.geom("ball").id
    m.geom_contype[g] = 1
    m.geom_conaffinity[g] = 1
    cert = monitor.certify(scene, _slide_plan(m))
    assert scene.candidate_pairs == (("wall", "ball"),)
    assert cert.verdict == "violation"
    assert cert.stats["nothing_checked"] is False


def test_geom_group_edit_under_group_hazards():
    """hazards=["group:N"]: moving a geom into the hazard group in place adds its pairs.

    On the old code ``geom_group`` was not watched by ``Scene.sync``: the wall moved into group 3
    stayed unmonitored and the slide through it was ``certified``.
    """
    xml = (WALL_XML.replace('pos="0.5 0 0"/>', 'pos="0.5 0 0" group="0"/>\n'
                            ' <geom name="post" type="box" size="0.01 0.01 0.01" pos="0 0 2" group="3"/>')
           .replace('size="0.1" pos="0.3 0 0"/>', 'size="0.2" pos="0.3 0 0" group="1"/>'))
    m = mujoco.MjModel.from_xml_string(xml)
    scene = monitor.Scene.from_model(m, hazards=["group:3"])
    assert scene.candidate_pairs == (("post", "ball"),)
    assert monitor.certify(scene, _slide_plan(m)).verdict == "certified"
    m.geom_group[m.geom("wall").id] = 3
    cert = monitor.certify(scene, _slide_plan(m))
    assert set(scene.candidate_pairs) == {("post", "ball"), ("wall", "ball")}
    assert cert.verdict == "violation"


def test_mesh_vertex_edit_is_seen():
    xml = """<mujoco><asset><mesh name="m" vertex="-.1 -.1 -.1  .1 -.1 -.1  -.1 .1 -.1  .1 .1 -.1
      -.1 -.1 .1  .1 -.1 .1  -.1 .1 .1  .1 .1 .1"/></asset><worldbody>
      <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.5 0 0"/>
      <body name="b"><joint name="s" type="slide" axis="0 1 0"/>
       <geom name="cube" type="mesh" mesh="m" pos="0.3 0 0"/></body></worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    scene = monitor.Scene.from_model(m, pairs="all")
    assert monitor.certify(scene, _slide_plan(m)).verdict == "certified"
    m.mesh_vert[:] *= 2.0  # the cube now reaches x = 0.3 + 0.2 > 0.45
    assert _mj_distance(m, "cube", "wall") < 0
    assert monitor.certify(scene, _slide_plan(m)).verdict == "violation"


def test_disableflags_edit_rebuilds_pairs():
    m = mujoco.MjModel.from_xml_path(str(_arm_path()))
    scene = monitor.Scene.from_model(m, pairs="mujoco")
    before = scene.candidate_pairs
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
    assert scene.sync() is True
    assert set(before) <= set(scene.candidate_pairs)
    assert scene.candidate_pairs == monitor.Scene.from_model(m, pairs="mujoco").candidate_pairs


def test_impossible_rebuild_raises_model_mismatch():
    """An explicit pair of two geoms that an edit turned into planes has no test."""
    m, _ = _wall()
    scene = monitor.Scene.from_model(m, pairs=[("wall", "ball")])
    m.geom_type[m.geom("wall").id] = int(mujoco.mjtGeom.mjGEOM_PLANE)
    m.geom_type[m.geom("ball").id] = int(mujoco.mjtGeom.mjGEOM_PLANE)
    with pytest.raises(ModelMismatchError, match="geom_type"):
        monitor.certify(scene, _slide_plan(m))
    with pytest.raises(ModelMismatchError):  # and again: never a stale certificate
        scene.sync()


def test_model_hash_follows_the_edit():
    m, scene = _wall()
    h0 = scene.model_hash
    m.geom_size[m.geom("ball").id][0] = 0.2
    scene.sync()
    assert scene.model_hash != h0
    assert scene.model_hash == monitor.Scene.from_model(m, pairs="all").model_hash


def test_pickled_scene_still_syncs():
    m, scene = _wall()
    back = pickle.loads(pickle.dumps(scene))
    assert back.sync() is False
    back.model.geom_size[back.model.geom("ball").id][0] = 0.2
    assert back.sync() is True
    assert scene.version == 0  # the original model was not touched


def test_flex_is_refused_by_name():
    xml = """<mujoco><worldbody>
      <flexcomp name="cloth" type="grid" count="3 3 1" spacing="0.1 0.1 0.1" dim="2">
        <edge equality="false"/></flexcomp>
      <body name="b"><joint type="slide" axis="1 0 0"/><geom type="sphere" size="0.1"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    assert m.nflex == 1
    with pytest.raises(UnsupportedGeometryError, match="cloth"):
        monitor.Scene.from_model(m, pairs="all")


def _model_with_everything():
    """A model where every watched array is non-empty (mesh, exclude, pair, joints)."""
    xml = """<mujoco><asset><mesh name="m" vertex="0 0 0  .1 0 0  0 .1 0  0 0 .1"/></asset>
      <worldbody><geom name="floor" type="plane" size="1 1 .1"/>
      <body name="a" pos="0 0 .5"><joint name="ja" type="hinge" axis="0 0 1"/>
        <geom name="ga" type="mesh" mesh="m"/>
        <body name="b" pos=".2 0 0"><joint name="jb" type="slide" axis="1 0 0"/>
          <geom name="gb" type="box" size=".05 .05 .05"/></body></body>
      <body name="c" pos="0 .5 .5"><freejoint/><geom name="gc" type="sphere" size=".05"/></body>
      </worldbody><contact><exclude body1="a" body2="c"/><pair geom1="gb" geom2="gc"/></contact>
    </mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


def test_every_watched_field_is_seen_through_the_snapshot():
    """Each SYNC_FIELDS array edited in place (through a fresh attribute view, as users do)
    is reported by the snapshot; restoring it makes the snapshot clean again. This guards
    against a field whose attribute returns a copy instead of a view of the model buffer."""
    from monitor.scene import SYNC_FIELDS

    m = _model_with_everything()
    scene = monitor.Scene.from_model(m, pairs="mujoco")
    for f in SYNC_FIELDS:
        arr = getattr(m, f)
        assert arr.size, f
        old = arr.flat[0].copy()
        getattr(m, f).flat[0] = old + 1
        assert scene._snapshot.changed() == [f], f
        getattr(m, f).flat[0] = old
        assert scene._snapshot.changed() == [], f


def test_every_plan_field_is_seen_by_is_current():
    from monitor.motion.plan import _STRUCT_FIELDS

    m = _model_with_everything()
    plan = monitor.Plan([0.0, 1.0], [m.qpos0, m.qpos0], m)
    for f in _STRUCT_FIELDS:
        arr = getattr(m, f)
        old = arr.flat[0].copy()
        getattr(m, f).flat[0] = old + 1
        assert not plan.is_current(), f
        getattr(m, f).flat[0] = old
        assert plan.is_current(), f


def test_compiled_stage_sees_an_edit_that_only_collides_mid_window():
    """The compiled whole-shape stage caches packed geometry per scene: after an in-place edit
    whose start pose is still clear (so the engine's start-pose test cannot catch it), the
    stage must use the rebuilt shapes, not the cached ones."""
    xml = """<mujoco><worldbody>
      <geom name="post" type="box" size="0.05 0.05 0.5" pos="0.5 0 0"/>
      <body name="b"><joint name="h" type="hinge" axis="0 0 1"/>
        <geom name="ball" type="sphere" size="0.1" pos="0.3 0 0"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    scene = monitor.Scene.from_model(m, pairs="all")
    plan = monitor.Plan([0.0, 0.1], [[-1.0], [1.0]], m)  # a rotating pass, 0.15 m from the post face
    cert = monitor.certify(scene, plan)
    assert cert.verdict == "certified" and "toleranced/whole-shape" in cert.stats["checker_mix"], cert.stats
    m.geom_size[m.geom("ball").id][0] = 0.17  # start still clear (0.35 m), the pass now overlaps 2 cm
    cert = monitor.certify(scene, monitor.Plan([0.0, 0.1], [[-1.0], [1.0]], m))
    assert cert.verdict == "violation", cert.stats
