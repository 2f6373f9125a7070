"""monitor.motion.pack: the per-window parts of a pack (issue 12, per-window packing).

* ``_derive_and_scale`` (one compiled call) fills the flags, magnitudes and rounding scale with the
  very bytes of the former separate calls (``derive``, ``+=``, ``batch(BATCH_SCALE)`` from Python),
  and the scale is ``Plan._scale`` (MuJoCo FK + the plan's own bounds: an independent oracle, 1e-9).
* ``static_key`` compares a pack's pose rows run by run around the mocap rows: oracle, the
  field-by-field key of a copied pack, with mocap bodies between ordinary bodies.
* ``plan_data_agrees`` compares the mocap rows as one slice when they are contiguous with ids in
  order, else by index: both refuse a pack whose held pose differs by one ulp.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify import kernels as K
from monitor.motion import kernel as KN
from monitor.motion import pack as PK

# a hinge chain with a ball wrist, a free body, and mocap bodies placed by {mid} / {end}
_XML = """<mujoco><worldbody>
  <body name="upper"><joint type="hinge" axis="0 0 1"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
    <body name="fore" pos="0.3 0 0"><joint type="hinge" axis="0 1 0" pos="0 0 0.01"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body name="hand" pos="0.3 0 0"><joint type="ball"/>
        <geom type="box" size="0.04 0.02 0.01" pos="0.05 0 0"/></body></body></body>
  {mid}
  <body name="puck" pos="0.6 0.2 0"><freejoint/><geom type="sphere" size="0.04"/></body>
  {end}
</worldbody></mujoco>"""
_M1 = '<body name="m1" mocap="true" pos="0.5 0.5 0"><geom type="sphere" size="0.05"/></body>'
_M2 = '<body name="m2" mocap="true" pos="-0.5 0.5 0"><geom type="sphere" size="0.05"/></body>'
LAYOUTS = {"none": ("", ""), "end": ("", _M1), "end2": ("", _M1 + _M2), "split": (_M1, _M2)}


def _model(layout):
    mid, end = LAYOUTS[layout]
    return mujoco.MjModel.from_xml_string(_XML.format(mid=mid, end=end))


def _plan(m, seed, still=False):
    """A seeded 4-waypoint Plan of every joint (or a motionless one), random held mocap poses."""
    rng = np.random.default_rng(seed)
    q = np.tile(m.qpos0, (4, 1))
    if not still:
        q[:, 0] = np.cumsum(rng.uniform(0.1, 0.5, 4))
        q[:, 1] = rng.uniform(-1.0, 1.0, 4)
        u = rng.normal(size=(4, 4))
        q[:, 2:6] = u / np.linalg.norm(u, axis=1, keepdims=True)
        q[:, 6:9] += rng.uniform(-0.2, 0.2, (4, 3))
        u = rng.normal(size=(4, 4))
        q[:, 9:13] = u / np.linalg.norm(u, axis=1, keepdims=True)
    u = rng.normal(size=(m.nmocap, 4))
    kw = {"mocap_pos": rng.uniform(-1.0, 1.0, (m.nmocap, 3)),
          "mocap_quat": u / np.linalg.norm(u, axis=1, keepdims=True)} if m.nmocap else {}
    return monitor.Plan([0.0, 0.05, 0.12, 0.2], q, m, **kw)


def _separate_calls(mp, qpos0_mag):
    """(moving, rotating, tol) as the former Python sequence: derive, +=, moving.any(), batch."""
    nbody = mp.nbody
    moving = np.empty(nbody, dtype=np.int64)
    rotating = np.empty(nbody, dtype=np.int64)
    tol = mp.tol.copy()
    tol[KN.TOL_SCALE] = tol[KN.TOL_QMAG] = 0.0
    KN.derive(mp.qpos, mp.body_parent, mp.body_mocap, mp.body_jntadr, mp.body_jntnum, mp.jnt_type,
              mp.jnt_qposadr, moving, rotating, tol)
    tol[KN.TOL_QMAG] += qpos0_mag
    if moving.any():
        z = np.zeros(1)
        tol[KN.TOL_SCALE] = KN.batch(mp._replace(body_moving=moving, body_rotating=rotating, tol=tol),
                                     KN.BATCH_SCALE, z, z, np.empty((1, nbody, 3)),
                                     np.empty((1, nbody, 3, 3)), np.empty((1, nbody)), np.empty((1, nbody)))
    return moving, rotating, tol


@pytest.mark.parametrize("layout", sorted(LAYOUTS))
@pytest.mark.parametrize("still", [False, True])
def test_one_compiled_call_gives_the_bytes_of_the_separate_calls(layout, still):
    m = _model(layout)
    plan = _plan(m, 3, still)
    mp = PK.pack_trajectory(plan)
    moving, rotating, tol = _separate_calls(mp, K._pack_static(plan).qpos0_mag)
    assert mp.body_moving.tobytes() == moving.tobytes()
    assert mp.body_rotating.tobytes() == rotating.tobytes()
    assert mp.tol.tobytes() == tol.tobytes()
    assert (mp.body_moving != 0).tolist() == plan._moving.tolist()        # Plan._setup's own flags
    if still:
        assert mp.tol[KN.TOL_SCALE] == 0.0 and not mp.body_moving.any()
    else:
        assert mp.tol[KN.TOL_SCALE] == pytest.approx(plan._scale, rel=1e-9)  # MuJoCo FK + Plan bounds


def test_body_motion_pack_matches_the_separate_calls():
    rng = np.random.default_rng(5)
    pos = rng.uniform(-1.0, 1.0, (3, 4, 3))
    u = rng.normal(size=(3, 4, 4))
    pos[:, 0] = (0.1, 0.2, 0.3)                           # a constant, non-identity world pose
    u[:, 0] = (0.8, 0.2, 0.1, 0.3)
    bm = monitor.BodyMotion([0.0, 0.1, 0.3], pos, u / np.linalg.norm(u, axis=-1, keepdims=True))
    mp = PK.pack_trajectory(bm)
    moving, rotating, tol = _separate_calls(mp, 0.0)
    assert (mp.body_moving.tobytes(), mp.body_rotating.tobytes(), mp.tol.tobytes()) == (
        moving.tobytes(), rotating.tobytes(), tol.tobytes())
    assert mp.tol[KN.TOL_SCALE] > 0.0


@pytest.mark.parametrize("layout", sorted(LAYOUTS))
def test_static_key_compares_pose_rows_around_the_mocap_rows(layout):
    m = _model(layout)
    plan = _plan(m, 0)
    mp = PK.pack_trajectory(plan)
    st = K._pack_static(plan)
    rows = np.flatnonzero(np.asarray(m.body_mocapid) >= 0).tolist()
    kept = [r for i, j in st.keep_runs for r in range(i, j)]
    assert kept == [r for r in range(m.nbody) if r not in rows]
    key = PK.static_key(mp, st)
    copied = PK.MotionPack(*[np.array(a, copy=True) for a in mp])
    assert key == PK.static_key(mp) == PK.static_key(copied, st)
    for field in ("body_pos", "body_quat"):
        for r in range(m.nbody):
            a = getattr(mp, field).copy()
            a[r, 1] = np.nextafter(a[r, 1], np.inf)
            edited = PK.static_key(mp._replace(**{field: a}), st)
            assert edited == PK.static_key(mp._replace(**{field: a})), (field, r)  # field-by-field oracle
            assert (edited == key) == (r in rows), (field, r)      # a held mocap pose is not the tree


@pytest.mark.parametrize("layout, run", [("none", None), ("end", (5, 6)), ("end2", (5, 7)), ("split", None)])
def test_plan_data_agrees_checks_every_held_mocap_pose(layout, run):
    m = _model(layout)
    plan = _plan(m, 1)
    mp = PK.pack_trajectory(plan)
    assert PK.plan_data_agrees(plan, mp)
    if m.nmocap:
        assert PK._mocap_run(plan._st) == run
        assert PK._mocap_run(plan._st) == run          # the cached answer
    for r in np.flatnonzero(np.asarray(m.body_mocapid) >= 0):
        for field in ("body_pos", "body_quat"):
            a = getattr(mp, field).copy()
            a[r, 2] = np.nextafter(a[r, 2], -np.inf)
            assert not PK.plan_data_agrees(plan, mp._replace(**{field: a})), (layout, r, field)
    other = _plan(m, 2)                                   # another plan's times / qpos / held poses
    assert not PK.plan_data_agrees(other, mp) and not PK.plan_data_agrees(plan, PK.pack_trajectory(other))
