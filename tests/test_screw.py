"""Screw (constant twist) interpolation of :class:`monitor.BodyMotion`.

Oracles: an independent SE(3) exponential built from scipy's matrix exponential of the
4x4 twist matrix (no code shared with monitor.motion._screw), and dense sampling of the
contract inequality of monitor/motion/base.py with random body points.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm, logm

from monitor import BodyMotion
from monitor.errors import InvalidInputError, UnsupportedGeometryError
from monitor.motion.base import chord


def _qmat(q):
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _T(R, x):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, x
    return T


def _rand_quat(rng, max_angle=np.pi * 0.95):
    ax = rng.normal(size=3)
    ax /= np.linalg.norm(ax)
    a = rng.uniform(0, max_angle)
    return np.concatenate([[np.cos(a / 2)], np.sin(a / 2) * ax])


def _random_motion(rng, K=None, nbody=3, small=False):
    K = int(rng.integers(2, 5)) if K is None else K
    times = np.cumsum(rng.uniform(0.05, 0.5, size=K))
    pos = np.zeros((K, nbody, 3))
    quat = np.zeros((K, nbody, 4))
    quat[:, 0, 0] = 1.0
    for b in range(1, nbody):
        q = np.array([1.0, 0, 0, 0])
        x = rng.normal(size=3)
        for k in range(K):
            step = _rand_quat(rng, 1e-6 if small else 2.5)
            w0, v0 = q[0], q[1:]
            w1, v1 = step[0], step[1:]
            q = np.concatenate([[w0 * w1 - v0 @ v1], w0 * v1 + w1 * v0 + np.cross(v1, v0)])
            q /= np.linalg.norm(q)
            if rng.random() < 0.5:
                q = -q
            quat[k, b] = q
            x = x + rng.normal(scale=0.5, size=3)
            pos[k, b] = x
    ref = rng.normal(scale=0.3, size=(nbody, 3))
    ref[0] = 0.0
    return BodyMotion(times, pos, quat, ref_points=ref, interpolation="screw")


def test_screw_matches_independent_se3_exponential():
    rng = np.random.default_rng(1)
    for _ in range(20):
        bm = _random_motion(rng, K=2, nbody=2)
        T0 = _T(_qmat(bm.quat[0, 1]), bm.pos[0, 1])
        T1 = _T(_qmat(bm.quat[1, 1]), bm.pos[1, 1])
        # expm/logm: the principal log is the shortest arc (angles < pi here)
        Xi = np.real(logm(T1 @ np.linalg.inv(T0)))
        ts = np.linspace(bm.t0, bm.t1, 9)
        pos, rot = bm.body_poses(ts)
        for j, t in enumerate(ts):
            s = (t - bm.t0) / (bm.t1 - bm.t0)
            Ts = expm(s * Xi) @ T0
            assert np.allclose(rot[j, 1], Ts[:3, :3], atol=1e-9)
            assert np.allclose(pos[j, 1], Ts[:3, 3], atol=1e-9)


def test_screw_hits_waypoints_exactly_and_differs_from_lerp():
    rng = np.random.default_rng(2)
    bm = _random_motion(rng, K=4)
    pos, _ = bm.body_poses(bm.times)
    assert np.array_equal(pos, bm.pos)
    lerp = BodyMotion(bm.times, bm.pos, bm.quat)
    mid = 0.5 * (bm.times[:-1] + bm.times[1:])
    assert np.abs(bm.body_poses(mid)[0] - lerp.body_poses(mid)[0]).max() > 1e-3


def _sampled_ratio(bm, rng, n_int=40, n_pts=24, n_t=60):
    """Max over samples of (true displacement) / (bound) for random sub-intervals and points."""
    worst, ratios = 0.0, []
    for _ in range(n_int):
        a, b = np.sort(rng.uniform(bm.t0, bm.t1, size=2))
        if rng.random() < 0.3:   # short intervals inside one segment
            b = min(bm.t1, a + 0.05 * (bm.t1 - bm.t0))
        mb = bm.motion_bounds(np.array([a]), np.array([b]))
        ts = np.concatenate([np.linspace(a, b, n_t), [0.5 * (a + b)]])
        pos, rot = bm.body_poses(ts)
        for body in range(1, bm.nbody):
            pts = bm.ref_points[body] + rng.normal(scale=rng.choice([0.01, 0.5, 3.0]), size=(n_pts, 3))
            pts[0] = bm.ref_points[body]
            W = np.einsum("tij,nj->tni", rot[:, body], pts) + pos[:, body, None, :]
            disp = np.linalg.norm(W[:-1] - W[-1], axis=-1).max(axis=0)        # (n_pts,)
            bound = mb.displacement(body, pts, bm.ref_points[body])[0]
            assert np.all(disp <= bound), (disp - bound).max()
            # rotation angle bound
            Rm = rot[-1, body]
            c = np.clip((np.einsum("tij,ij->t", rot[:-1, body], Rm) - 1) / 2, -1, 1)
            assert np.all(np.arccos(c) <= mb.angle[0, body] + 1e-7)
            worst = max(worst, float((disp / bound).max()))
            ratios.append(float(disp[0] / bound[0]) if bound[0] > 0 else 1.0)
    return worst, ratios


def test_screw_motion_bound_property_dense_sampling():
    rng = np.random.default_rng(3)
    ratios = []
    for _ in range(30):
        _, r = _sampled_ratio(_random_motion(rng), rng)
        ratios += r
    med = float(np.median(ratios))
    print(f"screw motion bound: ref-point tightness (sampled / bound) median {med:.4f}, "
          f"min {min(ratios):.4f} over {len(ratios)} (interval, body)")
    assert med > 0.5   # a loose (e.g. Lipschitz-only) bound would fail this


def test_screw_tiny_rotation_is_stable():
    rng = np.random.default_rng(4)
    bm = _random_motion(rng, K=3, small=True)
    lerp = BodyMotion(bm.times, bm.pos, bm.quat)
    ts = np.linspace(bm.t0, bm.t1, 50)
    assert np.abs(bm.body_poses(ts)[0] - lerp.body_poses(ts)[0]).max() < 1e-4
    _sampled_ratio(bm, rng, n_int=10)


def test_single_segment_bound_is_exact_helix():
    # rotation about z by 90 deg about an axis through (1, 0, 0), advancing 0.2 along z
    th = np.pi / 2
    times = np.array([0.0, 1.0])
    pos = np.zeros((2, 2, 3))
    quat = np.zeros((2, 2, 4))
    quat[:, :, 0] = 1.0
    quat[1, 1] = [np.cos(th / 2), 0, 0, np.sin(th / 2)]
    c = np.array([1.0, 0, 0])
    pos[1, 1] = _qmat(quat[1, 1]) @ (-c) + c + [0, 0, 0.2]
    bm = BodyMotion(times, pos, quat, interpolation="screw")
    mb = bm.motion_bounds(np.array([0.0]), np.array([1.0]))
    # origin at distance 1 from the axis; half interval: angle pi/4, advance 0.1
    expect = np.hypot(0.1, chord(np.pi / 4))
    assert expect <= mb.trans[0, 1] <= expect + 1e-10   # exact up to the rounding pad
    assert np.pi / 4 <= mb.angle[0, 1] <= np.pi / 4 + 1e-10
    p, _ = bm.body_poses(np.array([0.5]))
    assert np.allclose(p[0, 1], c + _qmat([np.cos(th / 4), 0, 0, np.sin(th / 4)]) @ (-c) + [0, 0, 0.1])


def test_screw_translation_segments_and_moving_bodies():
    rng = np.random.default_rng(5)
    bm = _random_motion(rng, K=3)
    assert bm.translation_segments(1) is None
    assert bm.moving_bodies().tolist() == [False, True, True]
    times = np.array([0.0, 1.0])
    pos = np.zeros((2, 2, 3))
    pos[1, 1] = [1.0, 2.0, 3.0]
    quat = np.zeros((2, 2, 4))
    quat[:, :, 0] = 1.0
    pure = BodyMotion(times, pos, quat, interpolation="screw")
    br, org = pure.translation_segments(1)
    assert np.array_equal(org, pos[:, 1])
    assert np.array_equal(pure.body_poses(np.array([0.25]))[0], BodyMotion(times, pos, quat).body_poses(
        np.array([0.25]))[0])


def test_bad_interpolation_and_pack_refuse():
    times = np.array([0.0, 1.0])
    pos = np.zeros((2, 2, 3))
    quat = np.zeros((2, 2, 4))
    quat[:, :, 0] = 1.0
    with pytest.raises(InvalidInputError, match="interpolation"):
        BodyMotion(times, pos, quat, interpolation="cubic")
    from monitor.motion.pack import pack_trajectory

    with pytest.raises(UnsupportedGeometryError, match="screw"):
        pack_trajectory(BodyMotion(times, pos, quat, interpolation="screw"))


# --------------------------------------------------------------------------- certify vs oracle
def _screw_case(rng):
    from _motion_oracle_cases import scene_model

    model = scene_model(rng)
    K = int(rng.integers(2, 4))
    times = np.linspace(0.0, 1.0, K)
    pos = np.zeros((K, 2, 3))
    quat = np.zeros((K, 2, 4))
    quat[:, 0, 0] = 1.0
    for k in range(K):
        pos[k, 1] = rng.uniform(-0.6, 0.6, size=3)
        quat[k, 1] = _rand_quat(rng, np.pi)
    bm = BodyMotion(times, pos, quat, interpolation="screw")
    Ts = [_T(_qmat(quat[k, 1]), pos[k, 1]) for k in range(K)]
    # independent screw: expm of the principal log, with the shortest arc as in slerp
    logs = []
    for k in range(K - 1):
        q1 = quat[k + 1, 1]
        T1 = _T(_qmat(q1), pos[k + 1, 1])
        logs.append(np.real(logm(T1 @ np.linalg.inv(Ts[k]))))

    def pose(t):
        k = min(int(np.searchsorted(times, t, side="right") - 1), K - 2)
        s = (t - times[k]) / (times[k + 1] - times[k])
        X = expm(s * logs[k]) @ Ts[k]
        return X[:3, 3], X[:3, :3]

    return model, bm, pose


def _run_screw_hunt(n, seed=14):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _motion_oracle_cases import hunt

    c = hunt(_screw_case, n, seed=seed, label="screw")
    print(f"screw hunt: {c}")
    assert c["false_negatives"] == 0 and c["targeted_fn"] == 0, c["fn_cases"]
    assert c["certified"] > 0 and c["oracle_contact"] > 0   # both sides exercised


def test_screw_certify_no_false_negatives_quick():
    _run_screw_hunt(12)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [140, 141])
def test_screw_certify_no_false_negatives_200(seed):
    """200 seeded cases in two halves of 100 (each run stays short)."""
    _run_screw_hunt(100, seed)


def test_screw_bodymotion_log_roundtrip_keeps_interpolation():
    """A logged screw motion must replay as a screw motion, never silently as lerp + slerp."""
    from monitor.log.writer import _plan_payload
    from monitor.review import _rebuild_plan

    bm = _random_motion(np.random.default_rng(6), K=3)
    rebuilt = _rebuild_plan(None, _plan_payload(bm))
    ts = np.linspace(bm.t0, bm.t1, 7)
    assert np.allclose(rebuilt.body_poses(ts)[0], bm.body_poses(ts)[0])


def test_certify_follows_the_screw_not_the_lerp():
    """Quarter turn about a vertical axis through (1, 0, 0): the origin's screw path is an arc
    through (1 - 1/sqrt2, -1/sqrt2, 0), where an obstacle sits; the straight lerp path passes
    0.29 m from it. Screw must not certify (the oracle has a witness), lerp+slerp certifies."""
    import sys
    from pathlib import Path

    import mujoco

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from redteam_oracle import TrajectoryOracle, motion_min

    from monitor import Scene, certify

    c, y = float(1.0 - np.sqrt(0.5)), float(-np.sqrt(0.5))
    xml = (f'<mujoco><worldbody><geom name="obs" type="sphere" size=".1" pos="{c!r} {y!r} 0"/>'
           '<body name="m" mocap="true"><geom name="mv" type="sphere" size=".05"/></body>'
           '</worldbody></mujoco>')
    model = mujoco.MjModel.from_xml_string(xml)
    th = np.pi / 2
    pos = np.zeros((2, 2, 3))
    quat = np.zeros((2, 2, 4))
    quat[:, :, 0] = 1.0
    quat[1, 1] = [np.cos(th / 2), 0, 0, np.sin(th / 2)]
    pos[1, 1] = [1.0, -1.0, 0.0]
    scene = Scene.from_model(model, pairs="all")
    screw = BodyMotion([0.0, 1.0], pos, quat, interpolation="screw")
    lerp = BodyMotion([0.0, 1.0], pos, quat)
    assert motion_min(TrajectoryOracle(model, screw), 0, 1, 0.0, 1.0, n=200).upper < -0.04
    assert motion_min(TrajectoryOracle(model, lerp), 0, 1, 0.0, 1.0, n=200).upper > 0.1
    assert certify(scene, screw, 0.0, 1e-3).verdict == "violation"
    assert certify(scene, lerp, 0.0, 1e-3).verdict == "certified"
