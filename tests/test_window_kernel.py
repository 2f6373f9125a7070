"""The engine's compiled window (monitor.certify.kernels.window_kernel) and its caches.

Oracles: the Python pipeline of the same engine (``engine._certify``, reached by turning the
compiled path off), the numpy swept-sphere broad phase (``broadphase.swept_geom_spheres`` +
``sphere_pair_gaps``), closed forms (a ball on a hinge passing a post). Seeded; no timings.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

import monitor
from monitor.bench.suites import scaling_scene
from monitor.certify import engine
from monitor.certify import kernels as K
from monitor.certify.broadphase import sphere_pair_gaps, swept_geom_spheres
from monitor.certify.certificate import Certificate

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench_cases import QUICK_CASES_GROUP, quick_cases  # noqa: E402  (the bench's quick set, built once per process)

_HINGE_XML = """<mujoco><worldbody>
  <geom name="post" type="box" size="0.05 0.05 0.5" pos="0.5 0 0"/>
  <body name="b"><joint name="h" type="hinge" axis="0 0 1"/>
    <geom name="ball" type="sphere" size="0.1" pos="0.3 0 0"/></body>
</worldbody></mujoco>"""


def _python_path(monkeypatch):
    monkeypatch.setattr(engine, "_fast_inputs", lambda scene, plan: None)


def _both(monkeypatch, scene, plan, **kw):
    fast = monitor.certify(scene, plan, **kw)
    with monkeypatch.context() as mp:
        _python_path(mp)
        old = monitor.certify(scene, plan, **kw)
    return fast, old


@pytest.mark.xdist_group(QUICK_CASES_GROUP)
def test_same_pairs_as_the_python_pipeline_on_the_peers_cases(monkeypatch):
    """Verdicts, methods, intervals, clearances and witness times equal the Python pipeline's.

    Differences allowed: the culled clearance (motion bounds of the compiled kernel vs
    numpy, equal up to rounding) and a whole-shape witness's point / distance (the kernel's
    exact static test at the same time instead of the Python re-confirmation; both below
    the margin)."""
    cases = [c for c in quick_cases() if "1e-04" not in c.name]  # 1e-4: fat-feature checker
    assert len(cases) >= 20
    for c in cases:
        scene, bm = c.scene(16), c.body_motion()
        fast, old = _both(monkeypatch, scene, bm, margin=0.0, epsilon=1e-3, method="toleranced")
        assert fast.verdict == old.verdict, c.name
        assert fast.stats["checker_mix"] == old.stats["checker_mix"], c.name
        assert fast.stats["tests"] == old.stats["tests"], c.name
        assert len(fast.pairs) == len(old.pairs) == 1
        pf, po = fast.pairs[0], old.pairs[0]
        assert (pf.geoms, pf.bodies, pf.verdict, pf.method, pf.tests, pf.max_depth) == \
               (po.geoms, po.bodies, po.verdict, po.method, po.tests, po.max_depth), c.name
        assert pf.intervals == po.intervals, c.name
        if pf.verdict == "violation":
            assert fast.witness.time == old.witness.time and fast.witness.geoms == old.witness.geoms
            assert fast.witness.distance < 0.0 and fast.earliest_time == old.earliest_time
        else:
            assert fast.clearance == pytest.approx(old.clearance, rel=1e-9, abs=1e-12), c.name


def test_broad_phase_gaps_equal_the_numpy_sphere_test():
    """Every culled pair's clearance (incl. those the AABB pre-test skipped) and the window's
    minimum equal the numpy swept-sphere broad phase on the same motion (up to rounding)."""
    model, bm = scaling_scene(64, "sparse", "rotating", seed=3)
    scene = monitor.Scene.from_model(model, pairs="all")
    cert = monitor.certify(scene, bm, epsilon=1e-3, budget={"seconds": 60})
    assert cert.verdict == "certified" and cert.stats["checker_mix"] == {"culled": len(scene.pair_ids)}
    shapes = [g.shape for g in scene.geoms]
    sph = swept_geom_spheres(bm, shapes, np.array([g.body_id for g in scene.geoms]), (0.0, 0.1), 8)
    want = sphere_pair_gaps(sph, scene.pair_ids[:, 0], scene.pair_ids[:, 1])
    got = np.array([p.clearance for p in cert.pairs])
    assert all(p.method == "culled" for p in cert.pairs)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert cert.clearance == pytest.approx(want.min(), rel=1e-9)
    assert cert.clearance == min(got)


def test_plan_edit_is_never_served_from_a_stale_pack():
    """The motion pack is cached per trajectory object. A model edit that only matters
    mid-window (the hinge's body moved 10 cm towards the post: the start pose stays clear)
    must be certified on the edited model, with the SAME Plan object passed again.
    (A cache keyed on the plan's waypoints would serve the old pack here: see the notes.)"""
    m = mujoco.MjModel.from_xml_string(_HINGE_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    plan = monitor.Plan([0.0, 0.1], [[-1.0], [1.0]], m)   # the ball passes 5 cm from the post face
    cert = monitor.certify(scene, plan)
    assert cert.verdict == "certified" and "toleranced/whole-shape" in cert.stats["checker_mix"], cert.stats
    m.body_pos[m.body("b").id][0] += 0.1                  # now it passes 5 cm INTO the post
    cert = monitor.certify(scene, plan)
    assert cert.verdict == "violation", cert.stats
    assert 0.0 < cert.witness.time < 0.1                 # mid-window: the start pose is clear
    m.body_pos[m.body("b").id][0] -= 0.1
    assert monitor.certify(scene, plan).verdict == "certified"


def _ball_motion(x_end: float) -> monitor.BodyMotion:
    pos = np.zeros((2, 3, 3))
    pos[:, 1] = [[0.0, 0.0, 0.0], [x_end, 0.0, 0.0]]
    pos[:, 2] = [0.5, 0.0, 0.0]
    quat = np.zeros((2, 3, 4))
    quat[..., 0] = 1.0
    return monitor.BodyMotion([0.0, 0.1], pos, quat)


def test_new_trajectory_objects_never_reuse_a_dead_ones_pack():
    """Trajectories are created and dropped in a loop, alternately clear and colliding;
    CPython reuses the ids of freed objects, so a cache keyed on id() would serve a
    dead trajectory's pack. Waypoint arrays are read-only (no in-place mutation)."""
    xml = """<mujoco><worldbody>
      <body name="a"><freejoint/><geom name="ga" type="sphere" size="0.1"/></body>
      <body name="b"><freejoint/><geom name="gb" type="box" size="0.1 0.1 0.1"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    scene = monitor.Scene.from_model(m, pairs="all")
    for k in range(12):
        collide = k % 2 == 1
        cert = monitor.certify(scene, _ball_motion(0.35 if collide else 0.2), method="toleranced")
        assert cert.verdict == ("violation" if collide else "certified"), (k, cert.stats)
    bm = _ball_motion(0.2)
    with pytest.raises(ValueError):
        bm.pos[1, 1, 0] = 0.35
    with pytest.raises(ValueError):
        bm.times[1] = 0.2


@pytest.mark.xdist_group(QUICK_CASES_GROUP)
def test_lazy_pairs_read_like_a_tuple(monkeypatch):
    c = [c for c in quick_cases() if c.name == "rot-box-box-collide"][0]
    scene, bm = c.scene(16), c.body_motion()
    fast, old = _both(monkeypatch, scene, bm, method="toleranced")
    assert "_pairs_store" in fast.__dict__ and not isinstance(fast.__dict__["_pairs_store"], tuple)
    assert isinstance(fast.pairs, tuple) and fast.pairs is fast.pairs      # built once, then kept
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.pairs = ()                                                  # type: ignore[misc]
    back = Certificate.from_dict(json.loads(json.dumps(fast.to_dict())))
    assert back.pairs[0].verdict == fast.pairs[0].verdict == old.pairs[0].verdict == "violation"
    assert set(fast.to_dict()) == set(old.to_dict())
    assert dataclasses.replace(fast, stats={}).pairs == fast.pairs


def test_a_tiny_seconds_budget_on_many_survivors_is_uncertain():
    """Dense rotating boxes (neighbours' swept boxes meet: many pairs survive the cull):
    the compiled stage runs in chunks and stops on the clock; never certified."""
    model, bm = scaling_scene(27, "dense", "rotating", seed=1)
    scene = monitor.Scene.from_model(model, pairs="all")
    full = monitor.certify(scene, bm, epsilon=1e-3, budget={"seconds": 60})
    assert full.stats["pairs"] - full.stats["pairs_culled"] > 20
    cut = monitor.certify(scene, bm, epsilon=1e-3, budget={"seconds": 1e-4})
    assert cut.verdict in ("uncertain", "violation") and cut.stats["budget_exhausted"]
    assert any(p.verdict == "uncertain" for p in cut.pairs)


def test_window_kernel_is_the_path_taken():
    """The compiled window runs for a packable trajectory (a guard for the tests above)."""
    m = mujoco.MjModel.from_xml_string(_HINGE_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    plan = monitor.Plan([0.0, 0.1], [[-1.0], [1.0]], m)
    assert engine._fast_inputs(scene, plan) is not None
    assert K.trajectory_pack(plan) is K.trajectory_pack(plan)


# -- the pack check (kernels._pack_agrees): tree verified once per key, data every plan ----------

_ARM_XML = """<mujoco><worldbody>
  <geom name="post" type="box" size="0.05 0.05 0.5" pos="0.8 0 0"/>
  <body name="upper"><joint name="shoulder" type="hinge" axis="0 0 1"/>
    <geom name="ua" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
    <body name="fore" pos="0.3 0 0"><joint name="elbow" type="hinge" axis="0 1 0" pos="0 0 0.01"/>
      <geom name="fa" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body name="hand" pos="0.3 0 0"><joint name="wrist" type="ball"/>
        <geom name="h" type="box" size="0.04 0.02 0.01" pos="0.05 0 0"/></body></body></body>
  <body name="target" mocap="true" pos="0.5 0.5 0"><geom name="t" type="sphere" size="0.05"/></body>
</worldbody></mujoco>"""


def _arm_plan(m, seed):
    """A plan that moves only the shoulder (elbow and wrist held at nonzero constant values)."""
    rng = np.random.default_rng(seed)
    q = np.zeros((3, m.nq))
    q[:, 0] = [0.0, 0.3 + 0.1 * rng.random(), 0.7]
    q[:, 1] = 0.4
    q[:, 2:6] = np.array([0.9, 0.1, 0.3, 0.2]) / np.sqrt(0.95)
    return monitor.Plan([0.0, 0.05, 0.1], q, m)


def _corrupt(field, fn):
    """A replacement for pack.pack_trajectory whose packs have ``field`` changed by ``fn`` (new arrays)."""
    from monitor.motion import pack as PK

    real = PK.pack_trajectory

    def bad(traj):
        mp = real(traj)
        return mp._replace(**{field: fn(getattr(mp, field).copy())})
    return bad


def _set(idx, val):
    def fn(a):
        a[idx] = val
        return a
    return fn


@pytest.mark.parametrize("field, fn", [
    ("jnt_axis", _set(1, (0.0, 0.0, 1.0))),          # elbow axis y -> z (the plan holds the elbow at 0.4)
    ("body_parent", _set(3, 1)),                       # hand hung from the upper arm instead of the forearm
    ("jnt_pos", _set(0, (0.0, 0.01, 0.0))),            # shoulder anchor off by 1 cm
    ("body_mocap", _set(4, 0)),                        # the mocap target treated as a fixed body
])
def test_a_corrupted_tree_is_refused_on_first_use_even_after_a_good_one(monkeypatch, field, fn):
    """A pack with a wrong joint axis / parent / anchor / mocap flag is never used: the engine
    falls back to the Python pipeline for it, although a correct pack of the same model (and
    the same moving joints) was verified just before."""
    from monitor.motion import pack as PK

    m = mujoco.MjModel.from_xml_string(_ARM_XML)
    good = K.trajectory_pack(_arm_plan(m, 0))
    assert good is not None
    monkeypatch.setattr(PK, "pack_trajectory", _corrupt(field, fn))
    for seed in (1, 2):
        plan = _arm_plan(m, seed)
        assert K.trajectory_pack(plan) is None, (field, seed)
    scene = monitor.Scene.from_model(m, pairs="all")
    assert engine._fast_inputs(scene, _arm_plan(m, 3)) is None


def test_an_in_place_edit_of_the_shared_tree_is_refused():
    """Packs of one model share their tree arrays; editing them in place (after they were
    verified) changes the tree key, so the next pack is checked again and refused."""
    m = mujoco.MjModel.from_xml_string(_ARM_XML)
    mp = K.trajectory_pack(_arm_plan(m, 10))
    assert mp is not None
    old = mp.jnt_axis.copy()
    try:
        mp.jnt_axis[1] = (0.0, 0.0, 1.0)
        assert K.trajectory_pack(_arm_plan(m, 11)) is None
    finally:
        mp.jnt_axis[:] = old
    assert K.trajectory_pack(_arm_plan(m, 12)) is not None


def test_the_per_plan_data_is_checked_on_every_plan(monkeypatch):
    """After the tree is verified, a pack whose qpos or mocap pose is not the plan's own is refused."""
    from monitor.motion import pack as PK

    m = mujoco.MjModel.from_xml_string(_ARM_XML)
    assert K.trajectory_pack(_arm_plan(m, 20)) is not None
    real = PK.pack_trajectory

    def shifted_qpos(traj):
        mp = real(traj)
        q = mp.qpos.copy()
        q[1, 1] += 1e-6
        return mp._replace(qpos=q)

    def moved_target(traj):
        mp = real(traj)
        bp = mp.body_pos.copy()
        bp[4, 0] += 1e-6
        return mp._replace(body_pos=bp)

    for bad in (shifted_qpos, moved_target):
        monkeypatch.setattr(PK, "pack_trajectory", bad)
        assert K.trajectory_pack(_arm_plan(m, 21)) is None, bad.__name__


def test_verified_packs_give_the_same_certificates_as_the_full_check(monkeypatch):
    """Plans after the first of a model (tree check skipped) certify exactly as with the full
    per-plan pose check (the former behaviour)."""
    m = mujoco.MjModel.from_xml_string(_ARM_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    plans = [_arm_plan(m, s) for s in range(30, 34)]
    fast = [monitor.certify(scene, p, margin=0.01, epsilon=1e-3) for p in plans]
    monkeypatch.setattr(K, "_pack_agrees", K._poses_match)
    K._MOTION_PACKS.clear()
    full = [monitor.certify(scene, p, margin=0.01, epsilon=1e-3) for p in plans]
    for a, b in zip(fast, full):
        assert a.verdict == b.verdict and a.stats["checker_mix"] == b.stats["checker_mix"]
        assert a.clearance == b.clearance


def test_a_key_whose_first_plan_failed_its_own_check_checks_every_later_plan(monkeypatch):
    """If a plan's own full pose check fails after its tree passed the probes, later plans of
    the same tree are not trusted on the tree check alone: each gets its own full check."""
    m = mujoco.MjModel.from_xml_string(_ARM_XML.replace('pos="0.8 0 0"', 'pos="0.85 0 0"'))  # a fresh key
    bad, later = _arm_plan(m, 40), _arm_plan(m, 41)
    real = K._poses_match
    calls = []

    def spy(traj, mp):
        calls.append(traj)
        return False if traj is bad else real(traj, mp)

    monkeypatch.setattr(K, "_poses_match", spy)
    assert K.trajectory_pack(bad) is None
    calls.clear()
    assert K.trajectory_pack(later) is not None
    assert any(c is later for c in calls)
    calls.clear()
    third = _arm_plan(m, 42)
    assert K.trajectory_pack(third) is not None
    assert any(c is third for c in calls)


_THREE_XML = """<mujoco><worldbody>
  <body name="a"><freejoint/><geom name="ga" type="box" size="0.05 0.08 0.03"/></body>
  <body name="b"><freejoint/><geom name="gb" type="box" size="0.06 0.04 0.05"/></body>
  <body name="c"><freejoint/><geom name="gc" type="sphere" size="0.05"/></body>
</worldbody></mujoco>"""


def _three_body_motion(rng, gap_b: float) -> monitor.BodyMotion:
    """a spins and slides along x; b starts ``gap_b`` beyond a's reach and drifts; c stays 5 m away."""
    pos = np.zeros((2, 4, 3))
    pos[:, 1] = [[0.0, 0.0, 0.0], [rng.uniform(0.0, 0.2), rng.uniform(-0.05, 0.05), 0.0]]
    pos[0, 2] = [0.2 + gap_b, rng.uniform(-0.05, 0.05), 0.0]
    pos[1, 2] = pos[0, 2] + rng.uniform(-0.1, 0.1, 3)
    pos[:, 3] = [5.0, 0.0, 0.0]
    quat = np.zeros((2, 4, 4))
    quat[..., 0] = 1.0
    axis = rng.normal(size=3)
    ang = rng.uniform(0.0, 2.0)
    quat[1, 1] = [np.cos(ang / 2), *(np.sin(ang / 2) * axis / np.linalg.norm(axis))]
    return monitor.BodyMotion([0.0, 0.1], pos, quat)


def test_early_survival_gives_the_full_broad_phase_outcome(monkeypatch):
    """Stage 0 first tries the middle sub-range: when it shows every selected pair within the margin,
    the other sub-ranges are skipped. Oracles: the numpy swept-sphere broad phase (which pairs are
    culled) and the full stage 0 (the same pair certified together with a far pair that it culls, so
    the early path cannot be taken): the pair's result is the same, field for field."""
    m = mujoco.MjModel.from_xml_string(_THREE_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    shapes = [g.shape for g in scene.geoms]
    bodies = np.array([g.body_id for g in scene.geoms])
    names = [g.name for g in scene.geoms]
    ia, ib = names.index("ga"), names.index("gb")
    infos = []
    orig = engine._window_kernel

    def spy(*a):
        out = orig(*a)
        if a[7] == 0:
            infos.append(a[-1].copy())
        return out

    monkeypatch.setattr(engine, "_window_kernel", spy)
    rng = np.random.default_rng(20261128)
    early = full_only = 0
    for k in range(20):
        bm = _three_body_motion(rng, rng.uniform(-0.12, 0.25))
        sph = swept_geom_spheres(bm, shapes, bodies, (0.0, 0.1), 8)
        want_gap = float(sphere_pair_gaps(sph, np.array([ia]), np.array([ib]))[0])
        if abs(want_gap) < 1e-9:
            continue
        infos.clear()
        lone = monitor.certify(scene, bm, pairs=[("ga", "gb")], epsilon=1e-3, method="toleranced")
        assert (lone.pairs[0].method == "culled") == (want_gap > 0.0), (k, want_gap, lone.pairs[0])
        took_early = bool(np.isnan(infos[0][K.WI_PAD]))
        assert not (took_early and want_gap > 0.0), k           # never for a pair the spheres cull
        early += took_early
        full_only += not took_early
        infos.clear()
        both = monitor.certify(scene, bm, pairs=[("ga", "gb"), ("ga", "gc")], epsilon=1e-3,
                               method="toleranced")
        assert not np.isnan(infos[0][K.WI_PAD]), k             # ga-gc is culled: the full stage 0
        assert both.pairs[1].method == "culled"
        assert both.pairs[0].to_dict() == lone.pairs[0].to_dict(), k      # incl. witness, floats exactly
        if lone.verdict == "violation":
            assert (both.witness.time, both.witness.distance) == (lone.witness.time, lone.witness.distance)
    assert early >= 4 and full_only >= 4, (early, full_only)


_HAND_XML = """<mujoco><worldbody>
  <body name="base"><joint name="x" type="slide" axis="1 0 0"/><joint name="yaw" type="hinge" axis="0 0 1"/>
    <geom name="palm" type="box" size="0.09 0.02 0.01"/>
    <body name="f1" pos="{half} 0 -0.02"><joint name="j1" type="hinge" axis="0 1 0"/>
      <geom name="g1" type="capsule" fromto="0 0 0 0 0 -0.08" size="0.008"/></body>
    <body name="f2" pos="-{half} 0 -0.02"><joint name="j2" type="hinge" axis="0 1 0"/>
      <geom name="g2" type="capsule" fromto="0 0 0 0 0 -0.08" size="0.008"/></body>
  </body>
</worldbody></mujoco>"""


def _fingers(half: float, bend: float):
    """Two fingers on a base that slides 0.8 m and yaws 1 rad; each finger bends by +-bend (rad)."""
    m = mujoco.MjModel.from_xml_string(_HAND_XML.format(half=half))
    t = np.linspace(0.0, 0.3, 16)
    s = t / t[-1]
    q = np.stack([0.8 * s, 1.0 * s, bend * s, -bend * s], axis=1)     # f1 bends towards -x, f2 towards +x
    return m, monitor.Scene.from_model(m, pairs=[("g1", "g2")]), monitor.Plan(t, q, m)


def _sampled_min_distance(m, plan, n=400):
    d = mujoco.MjData(m)
    a, b = (mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in ("g1", "g2"))
    out = np.inf
    for q in plan.qpos_at(np.linspace(plan.t0, plan.t1, n)):
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        out = min(out, mujoco.mj_geomDistance(m, d, a, b, 1.0, None))
    return out


@pytest.mark.parametrize("bend", [0.02, 0.1])
def test_fingers_of_one_moving_base_are_culled_by_their_relative_spheres(bend):
    """Stage 0 culls a pair whose geoms' swept spheres in their common ancestor's frame are apart
    (issue 12, hand30). Oracles: the numpy swept-sphere broad phase on the world motion does NOT
    cull the pair (the base moves 0.8 m), so the relative spheres did; MuJoCo's distance on dense
    samples stays above the culled pair's certified gap."""
    m, scene, plan = _fingers(0.07, bend)
    cert = monitor.certify(scene, plan, epsilon=1e-3, method="toleranced")
    shapes = [g.shape for g in scene.geoms]
    sph = swept_geom_spheres(plan, shapes, np.array([g.body_id for g in scene.geoms]), (plan.t0, plan.t1), 8)
    names = [g.name for g in scene.geoms]
    absolute = float(sphere_pair_gaps(sph, np.array([names.index("g1")]), np.array([names.index("g2")]))[0])
    assert absolute < 0.0
    (p,) = cert.pairs
    assert cert.verdict == "certified" and p.method == "culled", p
    assert 0.0 < p.clearance <= _sampled_min_distance(m, plan), p.clearance


def test_fingers_of_one_moving_base_that_touch_are_not_culled():
    """The same fingers bent into each other: the relative spheres overlap, the pair goes on to the
    whole-shape stage and its collision is found (oracle: MuJoCo's distance on dense samples < 0)."""
    m, scene, plan = _fingers(0.05, 1.2)
    assert _sampled_min_distance(m, plan) < 0.0
    cert = monitor.certify(scene, plan, epsilon=1e-3, method="toleranced")
    assert cert.verdict == "violation" and cert.witness.geoms == ("g1", "g2")
    assert cert.pairs[0].method != "culled"
