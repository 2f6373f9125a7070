"""Property tests of the compiled motion kernels (monitor.motion.kernel / pack).

Oracles, independent of the kernels:
* poses: ``Plan.body_poses`` (MuJoCo ``mj_kinematics``) and, for the bounds, an
  independent interpolation (numpy ``interp`` + scipy ``Slerp``) fed into
  ``mj_kinematics`` on a fresh ``MjData`` (helpers of tests/test_motion_bounds.py);
* bounds: dense sampling (200 times + 20 random per sub-interval) at points near the
  body and far from it (5-50 m) must never exceed trans + chord(angle) * |p - ref|;
* the numpy implementation ``Plan.motion_bounds`` / ``BodyMotion.motion_bounds`` for
  tightness (ratio reported; the kernel may be tighter or looser, it must be sound).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp
from test_motion_bounds import (
    _oracle_poses,
    _oracle_qpos,
    _rand_quat,
    _random_chain_xml,
    _random_qpos,
    stress_plan,
)

from monitor.errors import InvalidInputError
from monitor.motion import kernel as KN
from monitor.motion.base import chord
from monitor.motion.bodymotion import BodyMotion
from monitor.motion.pack import MotionPack, body_poses, pack_trajectory, poses_and_bounds
from monitor.motion.plan import Plan

N_SAMPLES = 200


def _intervals(rng, times):
    """Each segment, the whole window, 3 random sub-intervals and a tiny one."""
    K = times.shape[0]
    iv = [(times[k], times[k + 1]) for k in range(K - 1)] + [(times[0], times[-1])]
    for _ in range(3):
        a, b = np.sort(rng.uniform(times[0], times[-1], 2))
        iv.append((a, b))
    c = rng.uniform(times[0], times[-1])
    w = 1e-3 * (times[-1] - times[0])
    iv.append((max(c - w, times[0]), min(c + w, times[-1])))
    return np.array([x[0] for x in iv]), np.array([x[1] for x in iv])


def _check_samples(pos, mat, ref, trans, angle, rng, far=True, tag=""):
    """Assert dense-sample deviations <= bound for every body; returns near-point tightness ratios.

    pos (T+1, nbody, 3), mat (T+1, nbody, 3, 3): index 0 is the midpoint pose.
    """
    ratios = []
    for b in range(1, pos.shape[1]):
        near = ref[b] + rng.uniform(-0.5, 0.5, (12, 3))
        pts = [near, ref[b][None], np.zeros((1, 3))]
        if far:
            d = rng.normal(size=(6, 3))
            pts.append(ref[b] + d / np.linalg.norm(d, axis=1, keepdims=True) * rng.uniform(5, 50, (6, 1)))
        pts = np.concatenate(pts)
        world = pos[:, b, None, :] + np.einsum("tij,nj->tni", mat[:, b], pts)
        dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)
        bound = trans[b] + chord(angle[b]) * np.linalg.norm(pts - ref[b], axis=-1)
        viol = dev > bound
        assert not viol.any(), f"{tag} body {b}: deviation {dev[viol]} > bound {bound[viol]}"
        if trans[b] > 0 and dev[:12].max() > 1e-9:
            ratios.append(dev[:12].max() / bound[:12][np.argmax(dev[:12])])
    return ratios


def _random_plan(rng):
    m = mujoco.MjModel.from_xml_string(_random_chain_xml(rng))
    K = int(rng.integers(2, 6))
    times = np.cumsum(rng.uniform(0.05, 1.0, K)) + rng.uniform(-1, 1)
    qpos = _random_qpos(rng, m, K)
    mocap_pos = rng.uniform(-1, 1, (m.nmocap, 3)) if m.nmocap else None
    mocap_quat = np.array([_rand_quat(rng) for _ in range(m.nmocap)]) if m.nmocap else None
    return m, times, Plan(times, qpos, model=m, mocap_pos=mocap_pos, mocap_quat=mocap_quat)


def test_pack_is_numba_typable_flat_arrays():
    rng = np.random.default_rng(1)
    _, _, plan = _random_plan(rng)
    mp = pack_trajectory(plan)
    assert isinstance(mp, MotionPack)
    for name, arr in zip(mp._fields, mp, strict=True):
        assert isinstance(arr, np.ndarray), name
        assert arr.dtype in (np.float64, np.int64), name
        assert arr.flags.c_contiguous, name


def test_fk_matches_mujoco_random_trees():
    """Kernel FK == Plan.body_poses (mj_kinematics) at waypoints and random times, incl. mocap."""
    rng = np.random.default_rng(20261123)
    worst = 0.0
    for _ in range(60):
        m, times, plan = _random_plan(rng)
        mp = pack_trajectory(plan)
        ts = np.concatenate([times, rng.uniform(times[0], times[-1], 5)])
        pos, mat = body_poses(mp, ts)
        ref_pos, ref_mat = plan.body_poses(ts)
        np.testing.assert_allclose(pos, ref_pos, rtol=0, atol=1e-12)
        np.testing.assert_allclose(mat, ref_mat, rtol=0, atol=1e-12)
        worst = max(worst, float(np.abs(pos - ref_pos).max(initial=0.0)))
        # Single-body pose kernel agrees with the tree pass.
        p = np.empty(3)
        R = np.empty((3, 3))
        for b in range(m.nbody):
            KN.body_pose(mp, b, ts[-1], p, R)
            np.testing.assert_array_equal(p, pos[-1, b])
            np.testing.assert_array_equal(R, mat[-1, b])
    print(f"\nkernel FK vs mj_kinematics: max |dp| = {worst:.2e} m")


def test_random_trees_bounds_never_exceeded(record_property):
    """Random hinge/slide/ball/free trees with mocap, K = 2..5, big and small motions."""
    rng = np.random.default_rng(777001)
    ratios = []
    vs_plan = []
    kinds = set()
    n_cases = 0
    for chain in range(120):
        m, times, plan = _random_plan(rng)
        kinds.update(int(x) for x in m.jnt_type)
        mp = pack_trajectory(plan)
        ta, tb = _intervals(rng, times)
        pos_m, mat_m, mb = poses_and_bounds(mp, ta, tb)
        ref_mb = plan.motion_bounds(ta, tb)
        ref = plan.ref_points
        np.testing.assert_array_equal(mp.ref_points, ref)
        for i in range(ta.shape[0]):
            ts = np.concatenate([np.linspace(ta[i], tb[i], N_SAMPLES), rng.uniform(ta[i], tb[i], 20)])
            tm = 0.5 * (ta[i] + tb[i])
            Q = _oracle_qpos(m, times, plan.qpos, np.concatenate([[tm], ts]))
            pos, mat = _mocap_poses(m, Q, plan)
            np.testing.assert_allclose(pos_m[i], pos[0], rtol=0, atol=1e-12)
            tag = f"chain {chain} iv {i}"
            ratios += _check_samples(pos, mat, ref, mb.trans[i], mb.angle[i], rng, tag=tag)
            mv = ref_mb.trans[i] > 0
            vs_plan += list(mb.trans[i][mv] / ref_mb.trans[i][mv])
            n_cases += 1
            # body_bound (ancestors only) gives the same numbers as the tree pass.
            b = int(rng.integers(0, m.nbody))
            p = np.empty(3)
            R = np.empty((3, 3))
            tr, an = KN.body_bound(mp, b, ta[i], tb[i], p, R)
            assert tr == mb.trans[i, b] and an == mb.angle[i, b]
            np.testing.assert_array_equal(p, pos_m[i, b])
    assert kinds == {0, 1, 2, 3}
    med = float(np.median(ratios))
    med_plan = float(np.median(vs_plan))
    record_property("kernel_tightness_median_near", med)
    record_property("kernel_over_plan_trans_median", med_plan)
    print(f"\nkernel bounds over {n_cases} intervals: median sampled-max/bound near = {med:.3f}; "
          f"kernel trans / Plan trans: median {med_plan:.4f}, min {min(vs_plan):.4f}, max {max(vs_plan):.4f}")
    assert len(ratios) > 300


def _mocap_poses(m, Q, plan):
    d = mujoco.MjData(m)
    d.mocap_pos[:] = plan.mocap_pos
    d.mocap_quat[:] = plan.mocap_quat
    pos = np.empty((Q.shape[0], m.nbody, 3))
    mat = np.empty((Q.shape[0], m.nbody, 3, 3))
    for k in range(Q.shape[0]):
        d.qpos[:] = Q[k]
        mujoco.mj_kinematics(m, d)
        pos[k] = d.xpos
        mat[k] = d.xmat.reshape(-1, 3, 3)
    return pos, mat


@pytest.mark.parametrize("seed", [1, 2])
def test_deep_subdivision(seed):
    """2048 tiny sub-intervals (the checkers' regime): sound, and the velocity bound kicks in."""
    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(_random_chain_xml(rng))
    while m.nv == 0:
        m = mujoco.MjModel.from_xml_string(_random_chain_xml(rng))
    times = np.cumsum(rng.uniform(0.1, 1.0, 4))
    plan = Plan(times, _random_qpos(rng, m, 4), model=m)
    mp = pack_trajectory(plan)
    edges = np.linspace(times[0], times[-1], 2049)
    _, _, mb = poses_and_bounds(mp, edges[:-1], edges[1:])
    ref_mb = plan.motion_bounds(edges[:-1], edges[1:])
    mv = ref_mb.trans > 0
    np.testing.assert_array_equal(mb.trans > 0, mv)
    # Same derivation: the compiled bounds equal the numpy ones up to rounding.
    np.testing.assert_allclose(mb.trans[mv], ref_mb.trans[mv], rtol=1e-9)
    for i in rng.choice(2048, 30, replace=False):
        ts = np.linspace(edges[i], edges[i + 1], 50)
        tm = 0.5 * (edges[i] + edges[i + 1])
        pos, mat = _oracle_poses(m, _oracle_qpos(m, times, plan.qpos, np.concatenate([[tm], ts])))
        _check_samples(pos, mat, plan.ref_points, mb.trans[i], mb.angle[i], rng, tag=f"iv {i}")


@pytest.mark.parametrize("step", [1e-11, 1e-8, 1e-4])
def test_large_coordinates_tiny_motions(step):
    """1e4 m offsets, joint values ~1e3, motions down to 1e-11: the pads cover rounding."""
    rng = np.random.default_rng(int(-np.log10(step)) + 100)
    m, plan, times = stress_plan(step, rng)
    mp = pack_trajectory(plan)
    edges = np.linspace(times[0], times[-1], 65)
    _, _, mb = poses_and_bounds(mp, edges[:-1], edges[1:])
    for i in range(0, 64, 3):
        ts = np.linspace(edges[i], edges[i + 1], 40)
        tm = 0.5 * (edges[i] + edges[i + 1])
        tt = np.concatenate([[tm], ts])
        for pos, mat in (body_poses(mp, tt), plan.body_poses(tt),
                         _oracle_poses(m, _oracle_qpos(m, times, plan.qpos, tt))):
            for b in range(1, m.nbody):
                spread = np.array([1, 1, 1, 1, 1, 100, 100, 100, 1e3, 0])[:, None]
                pts = plan.ref_points[b] + rng.normal(size=(10, 3)) * spread
                world = pos[:, b, None, :] + np.einsum("tij,nj->tni", mat[:, b], pts)
                dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)
                r = np.linalg.norm(pts - plan.ref_points[b], axis=-1)
                bound = mb.trans[i, b] + chord(mb.angle[i, b]) * r
                assert (dev <= bound).all(), (step, i, b, dev, bound)


def _random_body_motion(rng, K, nbody, big):
    times = np.cumsum(rng.uniform(0.05, 1.0, K)) + rng.uniform(-5, 5)
    off = rng.normal(size=3) * (1e4 if big else 1.0)
    pos = off + rng.normal(size=(K, nbody, 3)) * (1e-6 if rng.random() < 0.3 else 1.0)
    quat = rng.normal(size=(K, nbody, 4))
    quat /= np.linalg.norm(quat, axis=-1, keepdims=True)
    pos[:, 0] = pos[0, 0]
    quat[:, 0] = quat[0, 0]
    hold = rng.random(nbody) < 0.2
    pos[:, hold] = pos[0, hold]
    quat[:, hold] = quat[0, hold]
    return BodyMotion(times, pos, quat, ref_points=rng.uniform(-1, 1, (nbody, 3)))


def _oracle_body_motion(bm, t):
    """numpy interp + scipy Slerp, then quaternion -> matrix by scipy."""
    nb = bm.nbody
    pos = np.stack([np.stack([np.interp(t, bm.times, bm.pos[:, b, c]) for c in range(3)], -1)
                    for b in range(nb)], 1)
    mat = np.empty((t.shape[0], nb, 3, 3))
    for b in range(nb):
        q = bm.quat[:, b]
        if (q == q[0]).all():
            mat[:, b] = Rotation.from_quat(q[0, [1, 2, 3, 0]]).as_matrix()
        else:
            mat[:, b] = Slerp(bm.times, Rotation.from_quat(q[:, [1, 2, 3, 0]]))(t).as_matrix()
    return pos, mat


def test_body_motion_bounds_and_poses():
    """BodyMotion path: poses equal BodyMotion.body_poses; bounds sound (scipy oracle)."""
    rng = np.random.default_rng(99)
    vs_ref = []
    for trial in range(60):
        bm = _random_body_motion(rng, int(rng.integers(2, 6)), int(rng.integers(1, 6)), big=trial % 3 == 0)
        mp = pack_trajectory(bm)
        ta, tb = _intervals(rng, bm.times)
        pos_m, mat_m, mb = poses_and_bounds(mp, ta, tb)
        P, R = bm.body_poses(0.5 * (ta + tb))
        np.testing.assert_allclose(pos_m, P, rtol=0, atol=1e-12 * (1 + np.abs(P).max()))
        np.testing.assert_allclose(mat_m, R, rtol=0, atol=1e-13)
        ref_mb = bm.motion_bounds(ta, tb)
        np.testing.assert_array_equal(mb.trans == 0, ref_mb.trans == 0)
        mv = ref_mb.trans > 0
        vs_ref += list(mb.trans[mv] / ref_mb.trans[mv])
        for i in range(ta.shape[0]):
            ts = np.concatenate([[0.5 * (ta[i] + tb[i])], np.linspace(ta[i], tb[i], N_SAMPLES)])
            for pos, mat in (_oracle_body_motion(bm, ts), bm.body_poses(ts)):
                _check_samples(pos, mat, bm.ref_points, mb.trans[i], mb.angle[i], rng, tag=f"trial {trial}")
    print(f"\nBodyMotion: kernel trans / BodyMotion trans median {np.median(vs_ref):.4f}, "
          f"max {np.max(vs_ref):.4f}")


def test_huge_motions_never_nan():
    """1e8 rad hinge jumps and 1e150 m slides: bounds are huge or inf, never NaN, and still sound."""
    xml = """<mujoco><worldbody>
      <body><joint type="hinge" axis="0 0 1" pos="1 0 0"/><geom size=".1" pos="0 1 0"/>
        <body pos="0 2 0"><joint type="slide" axis="1 0 0"/><geom size=".1"/></body></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    rng = np.random.default_rng(5)
    for hinge_jump, slide_jump in ((1e8, 1.0), (1.0, 1e150), (1e8, 1e300)):
        qpos = np.array([[0.0, 0.0], [hinge_jump, slide_jump], [-hinge_jump, -slide_jump]])
        times = np.array([0.0, 1.0, 2.0])
        plan = Plan(times, qpos, model=m)
        mp = pack_trajectory(plan)
        ta, tb = _intervals(rng, times)
        pos_m, _, mb = poses_and_bounds(mp, ta, tb)
        assert not np.isnan(mb.trans).any() and not np.isnan(mb.angle).any()
        assert (mb.angle <= np.pi).all()
        assert (mb.trans[:, 1:] > 1.0).all()
        if slide_jump < 1e100:
            for i in range(ta.shape[0]):
                ts = np.concatenate([[0.5 * (ta[i] + tb[i])], np.linspace(ta[i], tb[i], 50)])
                pos, mat = body_poses(mp, ts)
                _check_samples(pos, mat, plan.ref_points, mb.trans[i], mb.angle[i], rng, far=False)


def test_errors_are_typed():
    with pytest.raises(InvalidInputError, match="traj"):
        pack_trajectory("not a trajectory")
    bm = BodyMotion([0.0, 1.0], np.zeros((2, 2, 3)), np.tile([1.0, 0, 0, 0], (2, 2, 1)))
    mp = pack_trajectory(bm)
    with pytest.raises(InvalidInputError, match="window"):
        poses_and_bounds(mp, [0.0], [2.0])
    with pytest.raises(InvalidInputError, match="t0"):
        poses_and_bounds(mp, [np.nan], [1.0])
    with pytest.raises(InvalidInputError, match="window"):
        body_poses(mp, [3.0])
    # A static trajectory: exactly zero bounds and bit-exact poses.
    pos, rot, mb = poses_and_bounds(mp, [0.0, 0.25], [1.0, 0.5])
    assert (mb.trans == 0).all() and (mb.angle == 0).all()
    assert (pos == 0).all()


def test_half_turn_picks_the_trajectorys_own_arc():
    """Regression (false negative found by h12b through test_redteam's half-turn slerp): at an exact
    half turn the slerp branch is the sign of a dot product that is +-0 by rounding; the pack used to
    recompute it with a different summation order and could interpolate the OTHER arc. The pack now
    copies the trajectory's own QuatTrack arrays: poses must equal the trajectory's at every time."""
    from test_redteam import _Q0, _Q1, _V

    free_xml = ('<mujoco><worldbody><body name="b"><freejoint/><geom name="s" type="sphere" size=".1" '
                'pos="1 0 0"/></body></worldbody></mujoco>')
    ball_xml = ('<mujoco><worldbody><body name="h"><inertial pos="0 0 0" mass="1" diaginertia=".1 .1 .1"/>'
                '<joint type="hinge" axis="0 0 1"/><body name="c" pos=".5 0 0">'
                '<inertial pos="0 0 0" mass="1" diaginertia=".1 .1 .1"/><joint type="ball"/>'
                '<geom type="sphere" size=".1" pos="1 0 0"/></body></body></worldbody></mujoco>')
    m_free = mujoco.MjModel.from_xml_string(free_xml)
    m_ball = mujoco.MjModel.from_xml_string(ball_xml)
    rng = np.random.default_rng(11)
    pairs = [(np.array(_Q0), np.array(_Q1))]
    for _ in range(60):  # random (near-)orthogonal pairs, +-1e-17 along q0
        q0 = _rand_quat(rng)
        r = rng.normal(size=4)
        r -= (r @ q0) * q0
        r /= np.linalg.norm(r)
        pairs.append((q0, r + rng.choice([0.0, 1e-17, -1e-17]) * q0))
    ts = np.array([0.0, 0.1, 0.37, 0.5, 0.53, 0.9, 1.0])
    for q0, q1 in pairs:
        v = 0.5 * np.array(_V)
        trajs = [Plan([0.0, 1.0], np.array([[*(-v), *q0], [*v, *q1]]), m_free),
                 Plan([0.0, 1.0], np.array([[0.0, *q0], [0.7, *q1]]), m_ball),
                 BodyMotion([0.0, 1.0], np.array([[[0, 0, 0], [1, 2, 3]], [[0, 0, 0], [2, 2, 3]]], float),
                            np.array([[[1, 0, 0, 0], q0], [[1, 0, 0, 0], q1]]))]
        for traj in trajs:
            mp = pack_trajectory(traj)
            pos, mat = body_poses(mp, ts)
            ref_pos, ref_mat = traj.body_poses(ts)
            np.testing.assert_allclose(pos, ref_pos, rtol=0, atol=1e-12)
            np.testing.assert_allclose(mat, ref_mat, rtol=0, atol=1e-12)
            for tm, h in ((0.5, 1e-3), (0.53, 1e-2), (0.5, 0.5)):
                _, _, mb = poses_and_bounds(mp, [tm - h], [tm + h])
                tt = np.concatenate([[tm], np.linspace(tm - h, tm + h, 101)])
                P, R = traj.body_poses(tt)
                _check_samples(P, R, traj.ref_points, mb.trans[0], mb.angle[0], rng, far=False,
                               tag=f"half turn {type(traj).__name__}")


def test_kernel_and_pack_do_not_import_mujoco():
    """kernel.py is numpy + numba only; pack.py recognises a Plan without importing mujoco."""
    import subprocess
    import sys
    from pathlib import Path

    code = ("import sys, monitor.motion.kernel, monitor.motion.pack; "
            "print(sorted(m for m in ('mujoco', 'gymnasium', 'mcap') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], cwd=Path(__file__).resolve().parents[1],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_pair_bound_equals_two_body_bounds():
    """pair_bound (one pass over both chains, reused workspace) == two body_bound calls, bit for bit.

    (``relative=0``: the absolute bounds; a single body, index -1 for the other, with ``relative=1``.)

    Random hinge/slide/ball/free trees with mocap; random body pairs (also a body with itself,
    an ancestor with its descendant, the world) and intervals; one workspace reused across all
    calls of a tree, so left-over scratch contents from a previous call would show. A skipped
    body (index -1) leaves its outputs untouched.
    """
    rng = np.random.default_rng(20261124)
    n = 0
    for _ in range(40):
        m, times, plan = _random_plan(rng)
        mp = pack_trajectory(plan)
        ta, tb = _intervals(rng, times)
        pws = KN.pair_workspace(mp)
        for i in range(ta.shape[0]):
            for _ in range(3):
                ba, bb = (int(x) for x in rng.integers(0, m.nbody, 2))
                pa, Ra, pb, Rb = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
                got = KN.pair_bound(mp, ba, bb, ta[i], tb[i], pa, Ra, pb, Rb, pws, 0)
                p1, R1, p2, R2 = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
                want = KN.body_bound(mp, ba, ta[i], tb[i], p1, R1)
                want += KN.body_bound(mp, bb, ta[i], tb[i], p2, R2)
                assert got == want, (ba, bb, got, want)
                for x, y in ((pa, p1), (Ra, R1), (pb, p2), (Rb, R2)):
                    np.testing.assert_array_equal(x, y)
                n += 1
            keep = np.full(3, 7.0)
            got = KN.pair_bound(mp, -1, ba, ta[i], tb[i], keep, np.empty((3, 3)), pb, Rb, pws, 1)
            assert got[:2] == (0.0, 0.0) and (keep == 7.0).all()
            assert got[2:] == KN.body_bound(mp, ba, ta[i], tb[i], p1, R1)
    assert n > 500



def _ancestors_of(m, b):
    out = [b]
    while b != 0:
        b = int(m.body_parentid[b])
        out.append(b)
    return out


def test_pair_bound_relative_to_the_common_ancestor_holds_on_dense_samples():
    """pair_bound(relative=1) bounds each body's motion relative to the pair's deepest common ancestor.

    Oracle: MuJoCo FK (``mj_kinematics``) at the oracle's interpolated qpos (``_oracle_qpos``) at the
    midpoint m and on dense samples t of [ta, tb]; the common ancestor C (from ``body_parentid``, not
    the pack) maps each sample by X_WC(m) X_WC(t)^-1 (one rigid map per time for both bodies, which
    keeps every distance between them); the mapped deviations from the pose at m must stay within
    ``trans + chord(angle) |x - ref|`` (``_check_samples``: near and far points). Where C is the world,
    the numbers must be the absolute ones bit for bit; where C moves, the relative bound is checked
    to be the smaller one on most pairs (it drops the common chain's motion).
    """
    rng = np.random.default_rng(20261128)
    n_rel = n_abs = n_smaller = 0
    for tree in range(60):
        m, times, plan = _random_plan(rng)
        if m.nbody < 3:
            continue
        mp = pack_trajectory(plan)
        ta, tb = _intervals(rng, times)
        pws = KN.pair_workspace(mp)
        ref = plan.ref_points
        for i in range(ta.shape[0]):
            ba, bb = (int(x) for x in rng.integers(1, m.nbody, 2))
            anc_b = _ancestors_of(m, bb)
            C = next(c for c in _ancestors_of(m, ba) if c in anc_b)
            pa, Ra, pb, Rb = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
            got = KN.pair_bound(mp, ba, bb, ta[i], tb[i], pa, Ra, pb, Rb, pws, 1)
            absolute = KN.pair_bound(mp, ba, bb, ta[i], tb[i], np.empty(3), np.empty((3, 3)), np.empty(3),
                                     np.empty((3, 3)), pws, 0)
            if C == 0 or mp.body_moving[C] == 0:
                assert got == absolute, (tree, i, ba, bb, got, absolute)
                n_abs += 1
                continue
            ts = np.concatenate([np.linspace(ta[i], tb[i], 60), rng.uniform(ta[i], tb[i], 20)])
            Q = _oracle_qpos(m, times, plan.qpos, np.concatenate([[0.5 * (ta[i] + tb[i])], ts]))
            pos, mat = _mocap_poses(m, Q, plan)
            np.testing.assert_allclose(pa, pos[0, ba], rtol=0, atol=1e-12)   # world poses at m
            np.testing.assert_allclose(pb, pos[0, bb], rtol=0, atol=1e-12)
            # X_WC(m) X_WC(t)^-1 applied to every body at every sample (index 0: m, the identity)
            G = np.einsum("ij,tkj->tik", mat[0, C], mat[:, C])
            mpos = np.einsum("tij,tnj->tni", G, pos - pos[:, C, None, :]) + pos[0, C]
            mmat = np.einsum("tij,tnjk->tnik", G, mat)
            trans, angle = np.zeros(m.nbody), np.zeros(m.nbody)
            trans[ba], angle[ba] = got[0], got[1]
            trans[bb], angle[bb] = got[2], got[3]
            keep = [0, ba, bb]
            _check_samples(mpos[:, keep], mmat[:, keep], ref[keep], trans[keep], angle[keep], rng,
                           tag=f"tree {tree} iv {i} pair {ba},{bb} base {C}")
            n_rel += 1
            n_smaller += got[0] + got[2] < absolute[0] + absolute[2]
    assert n_rel > 60 and n_abs > 60, (n_rel, n_abs)
    assert n_smaller > 0.5 * n_rel, (n_smaller, n_rel)

def test_rounding_scale_equals_its_definition_with_static_bodies():
    """The pack's rounding scale (``tol[TOL_SCALE]``, ``batch(BATCH_SCALE)``) is exactly its
    definition, ``(max_b (|x_b(m)| + 2 |ref_b| + W_b) + max_b W_b + 3 max_b |ref_b|) * SCALE_ROUND_UP``
    (poses at the window's midpoint m by ``tree_poses``, W the whole-window bound at scale 0), equals
    ``Plan._scale`` (MuJoCo FK + the plan's own numpy bounds, 1e-9), and is at least (i) the
    former definition (max over waypoints and bodies of |origin| by MuJoCo FK, + max W +
    3 max |ref|: pads only grow) and (ii) every body's |origin| and |reference point| at 64
    dense times of the window (MuJoCo FK: the magnitude it stands for). Random trees get some
    coordinates frozen (static bodies between moving ones), some frozen at +-0 alternately
    (equal, so not moving, but not the same bits)."""
    rng = np.random.default_rng(20261128)
    n_static = 0
    for _ in range(40):
        m = mujoco.MjModel.from_xml_string(_random_chain_xml(rng))
        K = int(rng.integers(2, 7))
        times = np.cumsum(rng.uniform(0.05, 1.0, K))
        qpos = _random_qpos(rng, m, K)
        for j in range(m.njnt):
            if rng.random() < 0.5:
                a = m.jnt_qposadr[j]
                w = {0: 7, 1: 4}.get(int(m.jnt_type[j]), 1)
                qpos[:, a:a + w] = qpos[0, a:a + w]
                if w == 1 and rng.random() < 0.5:
                    qpos[:, a] = np.where(np.arange(K) % 2 == 0, 0.0, -0.0)
        mocap_pos = rng.uniform(-1, 1, (m.nmocap, 3)) if m.nmocap else None
        mocap_quat = np.array([_rand_quat(rng) for _ in range(m.nmocap)]) if m.nmocap else None
        plan = Plan(times, qpos, model=m, mocap_pos=mocap_pos, mocap_quat=mocap_quat)
        mp = pack_trajectory(plan)
        nbody = m.nbody
        n_static += int(np.count_nonzero(mp.body_moving[1:] == 0))
        if not mp.body_moving.any():
            assert mp.tol[KN.TOL_SCALE] == 0.0
            continue
        scale = mp.tol[KN.TOL_SCALE]
        mid = 0.5 * (mp.times[:1] + mp.times[-1:])
        pos_m, _ = body_poses(mp, mid)                     # tree_poses at the midpoint
        rho = np.linalg.norm(mp.ref_points, axis=-1)
        mp0 = mp._replace(tol=mp.tol.copy())
        mp0.tol[KN.TOL_SCALE] = 0.0
        tr = np.empty((1, nbody))
        KN.batch(mp0, KN.BATCH_BOUNDS, mp.times[:1].copy(), mp.times[-1:].copy(), np.empty((1, nbody, 3)),
                 np.empty((1, nbody, 3, 3)), tr, np.empty((1, nbody)))
        whole = tr[0]
        per_body = np.linalg.norm(pos_m[0], axis=-1) + 2.0 * rho + whole
        defined = float(per_body.max()) + float(whole.max()) + 3.0 * float(rho.max())
        assert scale == defined * KN.SCALE_ROUND_UP
        assert scale == pytest.approx(plan._scale, rel=1e-9)
        wp_pos, _ = plan.body_poses(plan.times)           # MuJoCo FK at every waypoint
        former = float(np.linalg.norm(wp_pos, axis=-1).max()) + float(whole.max()) + 3.0 * float(rho.max())
        assert scale >= former * (1.0 - 1e-12)
        dense = np.linspace(plan.t0, plan.t1, 64)
        pos_d, mat_d = plan.body_poses(dense)
        ref_d = pos_d + np.einsum("tbij,bj->tbi", mat_d, plan.ref_points)
        assert float(np.linalg.norm(pos_d, axis=-1).max()) <= scale * (1.0 + 1e-12)
        assert float(np.linalg.norm(ref_d, axis=-1).max()) <= scale * (1.0 + 1e-12)
    assert n_static > 20


def _former_fk(mp, q):
    """The former view-based ``_fk`` (before it was written on scalars), in plain Python on float64.

    The same operations in the same order as the helpers it called (their ``py_func``): the
    oracle of the compiled FK's bits. Returns xpos (nbody, 3), xmat (nbody, 3, 3).
    """
    qm, qn, q2m, rv = (KN._quat_mul.py_func, KN._quat_normalize.py_func, KN._quat_to_mat.py_func,
                       KN._rot_vec.py_func)
    nb, nj = mp.body_parent.shape[0], mp.jnt_type.shape[0]
    xpos, xquat, xmat = np.zeros((nb, 3)), np.zeros((nb, 4)), np.zeros((nb, 3, 3))
    janchor, jaxis, tmp3, qloc = np.zeros((nj, 3)), np.zeros((nj, 3)), np.zeros(3), np.zeros(4)
    for b in range(nb):
        if b == 0 or mp.body_mocap[b] != 0:
            xpos[b], xquat[b] = mp.body_pos[b], mp.body_quat[b]
            qn(xquat[b])
            q2m(xquat[b], xmat[b])
            continue
        ja, jn = mp.body_jntadr[b], mp.body_jntnum[b]
        if jn >= 1 and mp.jnt_type[ja] == 0:
            adr = mp.jnt_qposadr[ja]
            xpos[b], xquat[b] = q[adr:adr + 3], q[adr + 3:adr + 7]
            qn(xquat[b])
            q2m(xquat[b], xmat[b])
            continue
        p = mp.body_parent[b]
        for r in range(3):
            xpos[b, r] = xpos[p, r] + (xmat[p, r, 0] * mp.body_pos[b, 0] + xmat[p, r, 1] * mp.body_pos[b, 1]
                                       + xmat[p, r, 2] * mp.body_pos[b, 2])
        qm(xquat[p], mp.body_quat[b], xquat[b])
        for j in range(ja, ja + jn):
            typ, adr = mp.jnt_type[j], mp.jnt_qposadr[j]
            rv(xquat[b], mp.jnt_pos[j], tmp3)
            for c in range(3):
                janchor[j, c] = tmp3[c] + xpos[b, c]
            rv(xquat[b], mp.jnt_axis[j], tmp3)
            jaxis[j] = tmp3
            if typ == 2:
                d = q[adr] - mp.qpos0[adr]
                for c in range(3):
                    xpos[b, c] += jaxis[j, c] * d
                continue
            if typ == 1:
                qloc[:] = q[adr:adr + 4]
                qn(qloc)
            else:
                ang = q[adr] - mp.qpos0[adr]
                if ang == 0.0:
                    qloc[:] = (1.0, 0.0, 0.0, 0.0)
                else:
                    sh = np.sin(0.5 * ang)
                    qloc[0] = np.cos(0.5 * ang)
                    for c in range(3):
                        qloc[1 + c] = sh * mp.jnt_axis[j, c] / mp.jnt_axis_norm[j]
            qm(xquat[b], qloc, xquat[b])
            rv(xquat[b], mp.jnt_pos[j], tmp3)
            for c in range(3):
                xpos[b, c] = janchor[j, c] - tmp3[c]
        qn(xquat[b])
        q2m(xquat[b], xmat[b])
    return xpos, xmat


def test_fk_on_scalars_gives_the_former_fks_bits():
    """The compiled FK (written on scalars) == the former view-based FK, bit for bit, on random
    trees (hinge, slide, ball, free joints, mocap bodies) at every waypoint."""
    rng = np.random.default_rng(7)
    n = 0
    for _ in range(25):
        m, times, plan = _random_plan(rng)
        mp = pack_trajectory(plan)
        pos, mat = body_poses(mp, mp.times)
        K = mp.times.shape[0]
        scalar = np.ones(mp.qpos.shape[1], bool)     # columns body_poses lerps (quaternions: slerp)
        for a in mp.qt_adr:
            scalar[a:a + 4] = False
        for k in range(K):
            q = mp.qpos[k].copy()     # the interpolation at waypoint k: a + 0 (b - a), or the last row
            if k < K - 1:
                q[scalar] = q[scalar] + 0.0 * (mp.qpos[k + 1, scalar] - q[scalar])
            p_ref, R_ref = _former_fk(mp, q)
            assert pos[k].tobytes() == p_ref.tobytes() and mat[k].tobytes() == R_ref.tobytes(), (k, m.nbody)
            n += 1
    assert n > 50


def test_no_nrt_option_follows_the_installed_numba(monkeypatch):
    """``NO_NRT`` holds numba's private ``_nrt`` option only while numba has it: a numba without
    it would raise "Unrecognized options" at the first call of every kernel compiled with it."""
    from numba.core import options

    from monitor.motion import kernel as MK

    assert MK.NO_NRT == ({"_nrt": False} if hasattr(options.DefaultOptions, "_nrt") else {})
    monkeypatch.delattr(options.DefaultOptions, "_nrt", raising=False)
    assert MK._no_nrt_option() == {}
