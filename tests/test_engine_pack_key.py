"""The pack check's tree key (``monitor.motion.pack.static_key``, read by ``kernels._pack_agrees``).

The packed tree is one buffer; the key is read from it in one piece when the pack's arrays
ARE the tree's views, else field by field. Oracle: the field-by-field path on copies of the
arrays (what any pack not sharing the buffer gets), which must give the same key; and edits
of the tree (in place, or a copied array with one value changed) must change it.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify import kernels as K
from monitor.motion import pack as PK

_XML = """<mujoco><worldbody>
  <geom name="post" type="box" size="0.05 0.05 0.5" pos="0.8 0 0"/>
  <body name="upper"><joint name="shoulder" type="hinge" axis="0 0 1"/>
    <geom name="ua" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
    <body name="fore" pos="0.3 0 0"><joint name="elbow" type="hinge" axis="0 1 0" pos="0 0 0.01"/>
      <geom name="fa" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body name="hand" pos="0.3 0 0"><joint name="wrist" type="ball"/>
        <geom name="h" type="box" size="0.04 0.02 0.01" pos="0.05 0 0"/></body></body></body>
  {mocap}
</worldbody></mujoco>"""
_MOCAP = '<body name="target" mocap="true" pos="0.5 0.5 0"><geom name="t" type="sphere" size="0.05"/></body>'


def _plan(m, seed):
    rng = np.random.default_rng(seed)
    q = np.zeros((3, m.nq))
    q[:, 0] = [0.0, 0.3 + 0.1 * rng.random(), 0.7]
    q[:, 1] = 0.4
    q[:, 2:6] = np.array([0.9, 0.1, 0.3, 0.2]) / np.sqrt(0.95)
    kw = {}
    if m.nmocap:
        kw = {"mocap_pos": rng.normal(size=(1, 3)), "mocap_quat": np.array([[0.0, 1.0, 0.0, 0.0]])}
    return monitor.Plan([0.0, 0.05, 0.1], q, m, **kw)


def _copied(mp):
    """The same pack with every array a fresh copy (no array shared with the tree buffer)."""
    return PK.MotionPack(*[np.array(a, copy=True) for a in mp])


@pytest.mark.parametrize("mocap", [False, True])
def test_buffer_key_equals_field_by_field_key(mocap):
    m = mujoco.MjModel.from_xml_string(_XML.format(mocap=_MOCAP if mocap else ""))
    plan = _plan(m, 0)
    mp = PK.pack_trajectory(plan)
    st = K._pack_static(plan)
    assert st is not None and (mp.body_pos is st.body_pos) == (not mocap)
    fast = PK.static_key(mp, st)
    assert fast == PK.static_key(mp) == PK.static_key(_copied(mp), st) == PK.static_key(_copied(mp))
    # another plan of the model (other mocap pose): the same tree, the same key
    assert PK.static_key(PK.pack_trajectory(_plan(m, 1)), st) == fast


@pytest.mark.parametrize("mocap", [False, True])
@pytest.mark.parametrize("field, idx", [("jnt_axis", (1, 2)), ("body_parent", 3), ("jnt_pos", (0, 1)),
                                        ("body_pos", (2, 0)), ("body_quat", (3, 1)), ("ref_points", (1, 0)),
                                        ("body_mocap", 1), ("qt_adr", 0)])
def test_any_tree_edit_changes_the_key(mocap, field, idx):
    m = mujoco.MjModel.from_xml_string(_XML.format(mocap=_MOCAP if mocap else ""))
    plan = _plan(m, 0)
    mp = PK.pack_trajectory(plan)
    st = K._pack_static(plan)
    key = PK.static_key(mp, st)
    bad = getattr(mp, field).copy()
    bad[idx] += 1
    assert PK.static_key(mp._replace(**{field: bad}), st) != key      # a copied array, one value changed
    shared = getattr(mp, field)
    if shared is getattr(st, field):                                 # in place, in the shared buffer
        old = shared.copy()
        try:
            shared[idx] += 1
            assert PK.static_key(mp, st) != key
            assert PK.static_key(mp, st) == PK.static_key(_copied(mp))
        finally:
            shared[...] = old
    assert PK.static_key(mp, st) == key                              # the memo follows the bytes back


def test_mocap_rows_are_not_part_of_the_key():
    m = mujoco.MjModel.from_xml_string(_XML.format(mocap=_MOCAP))
    mp = PK.pack_trajectory(_plan(m, 0))
    st = K._pack_static(_plan(m, 0))
    bp = mp.body_pos.copy()
    bp[4] += 0.25                                                   # the mocap body's held pose
    assert PK.static_key(mp._replace(body_pos=bp), st) == PK.static_key(mp, st)


def test_cached_kernel_parameter_row_is_never_written():
    """``engine._plan_inputs`` keeps the kernel's ``prm`` row per plan and reuses it on later calls.

    That is sound only while ``window_kernel`` reads ``prm`` and never writes it: after calls with
    two margins on one plan, each cached row must still hold exactly the values it was built from.
    """
    from monitor.certify import engine
    from monitor.certify.kernels import trajectory_pack_memo

    model = mujoco.MjModel.from_xml_string(_XML.format(mocap=""))
    scene = monitor.Scene.from_model(model, pairs="all")
    q0 = model.qpos0.copy()
    q1 = q0.copy()
    q1[0] += 0.4
    plan = monitor.Plan(np.array([0.0, 0.1]), np.stack([q0, q1]), model=model)
    for margin in (0.0, 0.01, 0.0):
        monitor.certify(scene, plan, margin=margin, epsilon=1e-3)
        _, memo = trajectory_pack_memo(plan)
        t0, t1, m, eps, tol, prm = memo["prm"]
        assert m == margin
        want = np.array([t0, t1, m, eps, tol.rel_pad, tol.abs_pad, tol.scale_pad, float(tol.max_depth),
                         float(engine._kernels().WHOLE_SHAPE_MAX_TESTS)])
        np.testing.assert_array_equal(prm, want)
