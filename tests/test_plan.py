from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from monitor.errors import InvalidInputError
from monitor.motion.base import Trajectory, chord
from monitor.motion.plan import Plan

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <body name="base" pos="0 0 .1"><geom name="base" type="box" size=".1 .1 .1"/>
      <body name="l1" pos="0 0 .2" quat="0.9 0.1 0.3 0.2">
        <joint name="h1" type="hinge" axis="0 1 1" pos=".05 0 0" ref="0.3"/>
        <joint name="s1" type="slide" axis="1 0 0"/>
        <geom name="l1" type="capsule" size=".03 .2" pos="0 0 .2"/>
        <body name="l2" pos="0 0 .4">
          <joint name="b2" type="ball" pos="0 0 .02"/>
          <geom name="l2a" type="sphere" size=".05" pos=".2 0 0"/>
          <geom name="l2b" type="box" size=".05 .02 .02" pos="-.1 0 0"/>
          <body name="l3" pos=".3 0 0"><inertial pos=".1 .2 .3" mass="1" diaginertia=".1 .1 .1"/></body>
        </body>
      </body>
    </body>
    <body name="cube" pos="1 0 1"><freejoint name="f"/><geom name="cube" type="box" size=".1 .1 .1"/></body>
    <body name="target" mocap="true" pos=".5 .5 .5" quat="0 1 0 0">
      <geom name="target" type="sphere" size=".05" contype="0" conaffinity="0"/>
      <body name="target_child" pos=".1 0 0"><geom name="tc" type="sphere" size=".02"/></body>
    </body>
    <body name="slider" pos="0 1 0"><joint name="sx" type="slide" axis="1 0 0"/>
      <joint name="sy" type="slide" axis="0 1 0"/><geom name="slider" size=".05"/></body>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(XML)


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _random_qpos(model, K, rng):
    q = np.tile(np.array(model.qpos0), (K, 1))
    for k in range(K):
        q[k, 0] = rng.uniform(-3, 3)  # h1
        q[k, 1] = rng.uniform(-0.3, 0.3)  # s1
        q[k, 2:6] = _unit(rng.normal(size=4))  # b2
        q[k, 6:9] = rng.uniform(-1, 1, 3)  # free pos
        q[k, 9:13] = _unit(rng.normal(size=4))  # free quat
        q[k, 13:15] = rng.uniform(-1, 1, 2)  # sx, sy
    return q


def _plan(model, K=4, seed=0, **kw):
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.1, 1.0, K))
    return Plan(times, _random_qpos(model, K, rng), model=model, **kw)


def _fresh_fk(model, qpos, mocap_pos=None, mocap_quat=None):
    d = mujoco.MjData(model)
    d.qpos[:] = qpos
    if mocap_pos is not None:
        d.mocap_pos[:] = mocap_pos
    if mocap_quat is not None:
        d.mocap_quat[:] = mocap_quat
    mujoco.mj_kinematics(model, d)
    return d.xpos.copy(), d.xmat.reshape(-1, 3, 3).copy()


# --------------------------------------------------------------------- poses
def test_protocol(model):
    plan = _plan(model)
    assert isinstance(plan, Trajectory)
    assert plan.model is model and plan.nbody == model.nbody
    assert plan.window == (plan.times[0], plan.times[-1]) == (plan.t0, plan.t1)
    assert plan.qpos.shape == (4, model.nq) and plan.ref_points.shape == (model.nbody, 3)


@pytest.mark.parametrize("seed", range(5))
def test_poses_match_mujoco_fk_at_waypoints(model, seed):
    rng = np.random.default_rng(100 + seed)
    mp = rng.uniform(-1, 1, (1, 3))
    mq = _unit(rng.normal(size=(1, 4)))
    plan = _plan(model, K=5, seed=seed, mocap_pos=mp, mocap_quat=mq)
    pos, mat = plan.body_poses(plan.times)
    for k in range(5):
        p_ref, R_ref = _fresh_fk(model, plan.qpos[k], mp, mq)
        np.testing.assert_allclose(pos[k], p_ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(mat[k], R_ref, rtol=0, atol=1e-12)


def test_default_mocap_is_fresh_mjdata(model):
    plan = _plan(model)
    d = mujoco.MjData(model)
    np.testing.assert_array_equal(plan.mocap_pos, d.mocap_pos)
    np.testing.assert_array_equal(plan.mocap_quat, d.mocap_quat)
    pos, _ = plan.body_poses(plan.times[:1])
    p_ref, _ = _fresh_fk(model, plan.qpos[0])
    np.testing.assert_allclose(pos[0], p_ref, atol=1e-12)
    tgt = model.body("target").id
    assert not plan.moving_bodies()[tgt] and not plan.moving_bodies()[model.body("target_child").id]


def test_live_data_untouched(model):
    live = mujoco.MjData(model)
    live.qpos[:] = _random_qpos(model, 1, np.random.default_rng(5))[0]
    live.mocap_pos[:] = [[3.0, 2.0, 1.0]]
    mujoco.mj_kinematics(model, live)
    before = (live.qpos.copy(), live.xpos.copy(), live.mocap_pos.copy(), live.time)
    plan = _plan(model)
    plan.body_poses(np.linspace(plan.t0, plan.t1, 7))
    plan.motion_bounds(np.array([plan.t0]), np.array([plan.t1]))
    np.testing.assert_array_equal(live.qpos, before[0])
    np.testing.assert_array_equal(live.xpos, before[1])
    np.testing.assert_array_equal(live.mocap_pos, before[2])
    assert live.time == before[3]


def test_interpolation(model):
    times = np.array([0.0, 2.0])
    q = np.tile(np.array(model.qpos0), (2, 1))
    q[:, 0] = [0.0, 1.0]
    q[:, 13] = [-1.0, 3.0]
    q[:, 6:9] = [[0, 0, 0], [2, 4, 6]]
    # Ball: identity -> 120 deg about z, given with a NEGATIVE w (same rotation): shortest arc.
    r = Rotation.from_euler("z", 120, degrees=True).as_quat()  # x y z w
    q[1, 2:6] = -np.array([r[3], r[0], r[1], r[2]])
    q[0, 2:6] = [1, 0, 0, 0]
    q[:, 9:13] = [1, 0, 0, 0]
    plan = Plan(times, q, model=model)
    mid = plan.qpos_at(0.5)
    assert mid.shape == (model.nq,)
    assert mid[0] == pytest.approx(0.25) and mid[13] == pytest.approx(0.0)
    np.testing.assert_allclose(mid[6:9], [0.5, 1.0, 1.5])
    rot = Rotation.from_quat(np.r_[mid[3:6], mid[2]])
    np.testing.assert_allclose(rot.as_rotvec(), [0, 0, np.deg2rad(30)], atol=1e-12)
    assert plan.qpos_at(np.array([0.0, 2.0])).shape == (2, model.nq)
    np.testing.assert_array_equal(plan.qpos_at(2.0), plan.qpos[1])
    with pytest.raises(InvalidInputError, match="outside the window"):
        plan.qpos_at(2.5)


def test_motion_bound_closed_form_single_hinge():
    m = mujoco.MjModel.from_xml_string("""<mujoco><worldbody><body pos="1 2 3">
        <joint type="hinge" axis="0 0 1" pos=".5 0 0"/><geom type="sphere" size=".1" pos="1.5 0 0"/>
        </body></worldbody></mujoco>""")
    plan = Plan(np.array([0.0, 1.0]), np.array([[0.0], [0.8]]), model=m)
    np.testing.assert_allclose(plan.ref_points[1], [1.5, 0, 0])
    mb = plan.motion_bounds(np.array([0.0, 0.25]), np.array([1.0, 0.5]))
    # Deviation from the midpoint: dq = 0.4 and 0.1; the reference point is 1.0 from the axis.
    # Exact up to the rounding pad (which must be upwards and tiny).
    for got, exact in ((mb.angle[:, 1], np.array([0.4, 0.1])),
                       (mb.trans[:, 1], 2 * np.sin(np.array([0.4, 0.1]) / 2))):
        assert (got >= exact).all() and (got - exact < 1e-10).all(), (got, exact)
    assert mb.trans.shape == (2, 2) and (mb.trans[:, 0] == 0).all()


def test_structure_flags_and_translation_segments(model):
    times = np.array([0.0, 1.0, 3.0])
    q = np.tile(np.array(model.qpos0), (3, 1))
    q[:, 13] = [0.0, 1.0, -1.0]  # sx moves
    q[:, 6:9] = [[0, 0, 1], [1, 0, 1], [1, 1, 1]]  # free position moves, quaternion held
    plan = Plan(times, q, model=model)
    moving = plan.moving_bodies()
    ids = {n: model.body(n).id for n in ("base", "l1", "l2", "l3", "cube", "target", "slider")}
    assert moving[ids["slider"]] and moving[ids["cube"]]
    assert not moving[[ids["base"], ids["l1"], ids["l2"], ids["l3"], ids["target"], 0]].any()
    bp, org = plan.translation_segments(ids["slider"])
    np.testing.assert_array_equal(bp, times)
    np.testing.assert_allclose(org[:, 0], [0.0, 1.0, -1.0])
    np.testing.assert_allclose(org[:, 1], 1.0)
    bp, org = plan.translation_segments(ids["cube"])
    np.testing.assert_allclose(org, q[:, 6:9])
    bp, org = plan.translation_segments(ids["l2"])
    np.testing.assert_array_equal(bp, [0.0, 3.0])
    np.testing.assert_array_equal(org[0], org[1])
    mb = plan.motion_bounds(times[:-1], times[1:])
    assert (mb.trans[:, ~moving] == 0).all() and (mb.angle == 0).all()
    # Any rotation on the chain: no translation segments (child of a hinge too).
    q[1, 0] = 0.5
    plan = Plan(times, q, model=model)
    assert plan.translation_segments(ids["l1"]) is None and plan.translation_segments(ids["l3"]) is None
    assert plan.moving_bodies()[ids["l3"]]
    with pytest.raises(InvalidInputError, match="body index"):
        plan.translation_segments(model.nbody)


def test_ref_points(model):
    plan = _plan(model)
    np.testing.assert_allclose(plan.ref_points[model.body("l3").id], [0.1, 0.2, 0.3])
    # l2: sphere r=.05 at x=.2 and a box (rbound = |(.05,.02,.02)|) at x=-.1
    rb = np.linalg.norm([0.05, 0.02, 0.02])
    np.testing.assert_allclose(plan.ref_points[model.body("l2").id][0], 0.5 * (0.25 + (-0.1 - rb)))


# ----------------------------------------------------------------- validation
def _valid(model):
    rng = np.random.default_rng(9)
    return np.array([0.0, 0.5, 1.0]), _random_qpos(model, 3, rng)


def test_model_not_mjmodel(model):
    t, q = _valid(model)
    with pytest.raises(InvalidInputError, match="MjModel"):
        Plan(t, q, model="scene.xml")


def test_nan_time(model):
    t, q = _valid(model)
    t[1] = np.nan
    with pytest.raises(InvalidInputError, match=r"times.*non-finite.*\(1,\)"):
        Plan(t, q, model=model)


def test_inf_qpos(model):
    t, q = _valid(model)
    q[2, 13] = -np.inf
    with pytest.raises(InvalidInputError, match=r"qpos.*non-finite.*\(2, 13\)"):
        Plan(t, q, model=model)


def test_nan_qpos(model):
    t, q = _valid(model)
    q[0, 4] = np.nan
    with pytest.raises(InvalidInputError, match=r"qpos.*non-finite.*\(0, 4\)"):
        Plan(t, q, model=model)


def test_wrong_shapes(model):
    t, q = _valid(model)
    with pytest.raises(InvalidInputError, match="times must have shape"):
        Plan(t[None], q, model=model)
    with pytest.raises(InvalidInputError, match="qpos must have shape"):
        Plan(t, q[0], model=model)
    with pytest.raises(InvalidInputError, match="qpos must have shape"):
        Plan(t, q[:2], model=model)
    with pytest.raises(InvalidInputError, match="not a numeric array"):
        Plan(t, [[1, 2], [3]], model=model)


def test_wrong_nq(model):
    t, q = _valid(model)
    with pytest.raises(InvalidInputError, match=f"nq = {model.nq - 1}.*nq = {model.nq}"):
        Plan(t, q[:, :-1], model=model)


def test_non_increasing_times(model):
    t, q = _valid(model)
    t[2] = 0.4
    with pytest.raises(InvalidInputError, match=r"strictly increasing: times\[2\]"):
        Plan(t, q, model=model)


def test_fewer_than_two_waypoints(model):
    t, q = _valid(model)
    with pytest.raises(InvalidInputError, match="at least 2 waypoints, got 1"):
        Plan(t[:1], q[:1], model=model)


@pytest.mark.parametrize("col, joint", [(2, "b2"), (9, "f")])
def test_non_unit_quaternion(model, col, joint):
    t, q = _valid(model)
    q[1, col:col + 4] *= 1.01
    with pytest.raises(InvalidInputError, match=rf"joint '{joint}'.*index \(1,\).*norm"):
        Plan(t, q, model=model)


def test_quaternion_within_tolerance_normalised(model):
    t, q = _valid(model)
    q[1, 2:6] *= 1.0 + 1e-7
    plan = Plan(t, q, model=model)
    assert abs(np.linalg.norm(plan.qpos[1, 2:6]) - 1.0) < 1e-15
    assert plan.qpos is not q  # the caller's array is not modified in place
    assert abs(np.linalg.norm(q[1, 2:6]) - 1.0) > 5e-8


def test_mocap_validation(model):
    t, q = _valid(model)
    with pytest.raises(InvalidInputError, match=r"mocap_pos must have shape \(1, 3\)"):
        Plan(t, q, model=model, mocap_pos=np.zeros(3))
    with pytest.raises(InvalidInputError, match="mocap_pos.*non-finite"):
        Plan(t, q, model=model, mocap_pos=np.array([[0.0, np.nan, 0.0]]))
    with pytest.raises(InvalidInputError, match=r"mocap_quat.*index \(0,\)"):
        Plan(t, q, model=model, mocap_quat=np.array([[2.0, 0, 0, 0]]))


def test_interval_validation(model):
    plan = _plan(model)
    with pytest.raises(InvalidInputError, match="sub-interval 1"):
        plan.motion_bounds(np.array([plan.t0, plan.t0]), np.array([plan.t1, plan.t1 + 1]))
    with pytest.raises(InvalidInputError, match="t0.*non-finite"):
        plan.motion_bounds(np.array([np.nan]), np.array([plan.t1]))
    with pytest.raises(InvalidInputError, match="shape"):
        plan.motion_bounds(np.array([plan.t0, plan.t0]), np.array([plan.t1]))
    with pytest.raises(InvalidInputError, match="outside the window"):
        plan.body_poses(np.array([plan.t0 - 1e-9]))


def test_chunked_bounds_equal_unchunked(model, monkeypatch):
    """Many waypoints and many long sub-intervals: chunking must not change any bound."""
    import functools

    from monitor.motion import _kinematics

    rng = np.random.default_rng(11)
    K = 60
    times = np.cumsum(rng.uniform(0.01, 0.1, K))
    plan = Plan(times, _random_qpos(model, K, rng), model=model)
    ta = rng.uniform(times[0], times[-1], 300)
    tb = np.minimum(ta + rng.uniform(0, 3, 300), times[-1])
    ref = plan.motion_bounds(ta, tb)
    small = functools.partial(_kinematics.interval_chunks, budget=500)
    chunks = small(times, ta, tb, width=model.nq)
    assert len(chunks) > 10
    assert chunks[0].start == 0 and chunks[-1].stop == 300
    assert all(a.stop == b.start for a, b in zip(chunks[:-1], chunks[1:]))
    monkeypatch.setattr(_kinematics, "interval_chunks", small)
    got = plan.motion_bounds(ta, tb)
    np.testing.assert_array_equal(got.trans, ref.trans)
    np.testing.assert_array_equal(got.angle, ref.angle)


def test_sub_intervals_at_and_across_waypoints_one_ulp():
    """Sub-intervals touching a waypoint, down to one ulp wide, stay certified (no h = 0 shortcut)."""
    m = mujoco.MjModel.from_xml_string("""<mujoco><worldbody><body>
        <joint type="hinge" axis="0 0 1"/><geom size=".1" pos="1 0 0"/>
        <body pos="1 0 0"><joint type="ball"/><geom size=".1" pos="0 1 0"/></body>
        </body></worldbody></mujoco>""")
    times = np.array([0.0, 0.3, 1.0])
    qpos = np.array([[0.0, 1, 0, 0, 0], [2.0, 0, 1, 0, 0], [-1.0, 0, 0, 1, 0]])
    plan = Plan(times, qpos, model=m)
    w = times[1]
    cases = [(np.nextafter(w, 0), w), (w, np.nextafter(w, 1)), (np.nextafter(w, 0), np.nextafter(w, 1)),
             (w - 1e-9, w), (w, w + 1e-9), (w - 1e-9, w + 1e-9), (w, w), (0.0, w), (w, 1.0)]
    ta = np.array([c[0] for c in cases])
    tb = np.array([c[1] for c in cases])
    mb = plan.motion_bounds(ta, tb)
    for i in range(len(cases)):
        ts = np.unique(np.concatenate([[ta[i], tb[i]], np.linspace(ta[i], tb[i], 50)]))
        pos, mat = plan.body_poses(np.concatenate([[0.5 * (ta[i] + tb[i])], ts]))
        for b in (1, 2):
            pts = plan.ref_points[b] + np.array([[0, 0, 0], [3, 0, 0], [0, -5, 2]])
            world = pos[:, b, None] + np.einsum("tij,nj->tni", mat[:, b], pts)
            dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)
            r = np.linalg.norm(pts - plan.ref_points[b], axis=-1)
            assert (dev <= mb.trans[i, b] + chord(mb.angle[i, b]) * r).all(), (cases[i], b)


# -- Plan._trusted (the gate's constructor) and the vectorised quaternion normalisation -----------

_QXML = """<mujoco><worldbody>
<body name="a"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
<body name="b" pos="0 1 0"><joint name="ball" type="ball"/><geom type="sphere" size=".1"/>
  <body name="c" pos=".3 0 0"><joint type="hinge" axis="0 1 1"/><joint type="slide" axis="1 0 0"/>
    <geom type="capsule" size=".05 .2"/></body></body>
<body name="m" mocap="true" pos="1 1 1"><geom type="sphere" size=".1"/></body>
<body name="m2" mocap="true" pos="2 1 1"><geom type="sphere" size=".1"/></body>
</worldbody></mujoco>"""


def _quat_inputs(rng, K):
    """Seeded waypoints of _QXML with quaternions off unit norm by up to 1e-9 (within tolerance)."""
    t = np.cumsum(rng.uniform(0.01, 0.1, K))
    q = rng.normal(size=(K, 13))
    for a in (3, 7):
        q[:, a:a + 4] /= np.linalg.norm(q[:, a:a + 4], axis=1, keepdims=True)
        q[:, a:a + 4] *= 1.0 + rng.uniform(-1e-9, 1e-9, (K, 1))
    mq = rng.normal(size=(2, 4))
    mq /= np.linalg.norm(mq, axis=1, keepdims=True)
    return t, q, rng.normal(size=(2, 3)), mq * (1.0 + 1e-10)


def test_trusted_plans_equal_validating_ones_and_per_joint_normalisation():
    """Oracle: the per-joint ``normalize_quats`` (the former loop) on the caller's arrays; both
    constructors give the same bits for every quaternion, flag and magnitude."""
    from monitor.motion import _kinematics as KM
    from monitor.tolerances import DEFAULT

    m = mujoco.MjModel.from_xml_string(_QXML)
    rng = np.random.default_rng(12)
    for trial in range(40):
        t, q, mp, mq = _quat_inputs(rng, int(rng.integers(2, 8)))
        if trial % 3 == 0:
            q[:, 7:13] = q[0, 7:13]           # ball and hinge/slide held: only the free body moves
        want = q.copy()
        for a, label in ((3, "a"), (7, "b")):
            want[:, a:a + 4] = KM.normalize_quats(label, q[:, a:a + 4], DEFAULT)
        want_mq = KM.normalize_quats("mocap_quat", mq, DEFAULT)
        p1 = Plan(t, q, m, mocap_pos=mp, mocap_quat=mq)
        p2 = Plan._trusted(t.copy(), q.copy(), m, mocap_pos=mp.copy(), mocap_quat=mq.copy())
        for p in (p1, p2):
            assert p.qpos.tobytes() == want.tobytes()
            assert p.mocap_quat.tobytes() == want_mq.tobytes()
        assert p1._moving.tobytes() == p2._moving.tobytes()
        assert p1._rotating.tobytes() == p2._rotating.tobytes()
        assert p1._magnitude == p2._magnitude
        assert p1._magnitude["q"] == float(np.abs(want).max()) + p1._st.qpos0_mag
        for j, tr in p1._quat_tracks.items():
            assert tr.cum.tobytes() == p2._quat_tracks[j].cum.tobytes()


@pytest.mark.parametrize("bad", ["nan_q", "inf_q", "inf_t0", "inf_t1", "nan_t", "decreasing", "quat_norm",
                                 "nan_mocap_pos", "nan_mocap_quat"])
def test_trusted_refuses_what_the_validating_constructor_refuses(bad):
    m = mujoco.MjModel.from_xml_string(_QXML)
    t, q, mp, mq = _quat_inputs(np.random.default_rng(3), 4)
    if bad == "nan_q":
        q[2, 12] = np.nan
    elif bad == "inf_q":
        q[1, 0] = -np.inf
    elif bad == "inf_t0":
        t[0] = -np.inf
    elif bad == "inf_t1":
        t[-1] = np.inf
    elif bad == "nan_t":
        t[1] = np.nan
    elif bad == "decreasing":
        t[2] = t[0]
    elif bad == "quat_norm":
        q[2, 8] += 0.5
    elif bad == "nan_mocap_pos":
        mp[1, 0] = np.nan
    else:
        mq[0, 2] = np.nan
    with pytest.raises(InvalidInputError) as want:
        Plan(t, q, m, mocap_pos=mp, mocap_quat=mq)
    with pytest.raises(InvalidInputError) as got:
        Plan._trusted(t.copy(), q.copy(), m, mocap_pos=mp.copy(), mocap_quat=mq.copy())
    assert str(got.value) == str(want.value)


def test_reference_points_stay_read_only_through_pickles_and_copies(model):
    """``Plan.ref_points`` and the per-model structure's arrays lie over immutable bytes: they
    cannot be made writable again (a read-only array that owns its memory can), also after a
    pickle or deepcopy round trip (unpickled arrays are writable)."""
    import copy
    import pickle

    q0 = model.qpos0.copy()
    plan = Plan([0.0, 0.1], np.stack([q0, q0]), model)
    for p in (plan, pickle.loads(pickle.dumps(plan)), copy.deepcopy(plan)):
        for arr in (p.ref_points, p._st.ref, p._st.ref_norms):
            for owner in (arr, arr.base):
                with pytest.raises(ValueError):
                    owner.setflags(write=True)
