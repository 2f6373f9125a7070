from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from monitor.errors import InvalidInputError
from monitor.motion.base import Trajectory, chord
from monitor.motion.bodymotion import BodyMotion


def _rand_quats(rng, shape):
    q = rng.normal(size=shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _motion(rng, K=4, nbody=4, ref=None):
    times = np.cumsum(rng.uniform(0.1, 1.0, K))
    pos = rng.uniform(-1, 1, (K, nbody, 3))
    quat = _rand_quats(rng, (K, nbody))
    pos[:, 0] = 0.0
    quat[:, 0] = [1, 0, 0, 0]
    return times, pos, quat


def _oracle(times, pos, quat, t):
    """Independent lerp (np.interp) + geodesic slerp (scipy) per body."""
    nbody = pos.shape[1]
    P = np.stack([[np.interp(t, times, pos[:, b, c]) for c in range(3)] for b in range(nbody)], axis=0)
    P = P.transpose(2, 0, 1)
    R = np.stack([Slerp(times, Rotation.from_quat(quat[:, b][:, [1, 2, 3, 0]]))(t).as_matrix()
                  for b in range(nbody)], axis=1)
    return P, R


def test_protocol_and_waypoints_exact():
    rng = np.random.default_rng(0)
    times, pos, quat = _motion(rng)
    bm = BodyMotion(times, pos, quat)
    assert isinstance(bm, Trajectory)
    assert bm.window == (times[0], times[-1]) and bm.nbody == 4
    P, R = bm.body_poses(times)
    np.testing.assert_array_equal(P, pos)
    R_ref = Rotation.from_quat(quat.reshape(-1, 4)[:, [1, 2, 3, 0]]).as_matrix().reshape(R.shape)
    np.testing.assert_allclose(R, R_ref, atol=1e-14)


def test_interpolation_matches_scipy_slerp():
    rng = np.random.default_rng(1)
    times, pos, quat = _motion(rng, K=5)
    bm = BodyMotion(times, pos, quat)
    t = rng.uniform(times[0], times[-1], 300)
    P, R = bm.body_poses(t)
    P_o, R_o = _oracle(times, pos, quat, t)
    np.testing.assert_allclose(P, P_o, atol=1e-12)
    np.testing.assert_allclose(R, R_o, atol=1e-12)


def test_bounds_never_exceeded_random():
    rng = np.random.default_rng(2)
    ratios = []
    for _ in range(60):
        K = int(rng.integers(2, 6))
        nb = int(rng.integers(2, 5))
        times, pos, quat = _motion(rng, K=K, nbody=nb)
        if rng.random() < 0.3:  # small motions
            pos[1:] = pos[:1] + 1e-3 * (pos[1:] - pos[:1])
        ref = rng.uniform(-0.5, 0.5, (nb, 3)) if rng.random() < 0.6 else None
        bm = BodyMotion(times, pos, quat, ref_points=ref)
        ta = np.concatenate([times[:-1], rng.uniform(times[0], times[-1], 4), [times[0]]])
        tb = np.concatenate([times[1:], np.minimum(ta[K - 1:-1] + rng.uniform(0, 0.5, 4), times[-1]),
                             [times[-1]]])
        mb = bm.motion_bounds(ta, tb)
        for i in range(ta.shape[0]):
            ts = np.linspace(ta[i], tb[i], 200)
            tm = 0.5 * (ta[i] + tb[i])
            P, R = _oracle(times, pos, quat, np.concatenate([[tm], ts]))
            for b in range(1, nb):
                pts = np.concatenate([bm.ref_points[b] + rng.uniform(-0.5, 0.5, (10, 3)),
                                      rng.normal(size=(4, 3)) * 20.0])
                w = P[:, b, None] + np.einsum("tij,nj->tni", R[:, b], pts)
                dev = np.linalg.norm(w[1:] - w[0], axis=-1).max(axis=0)
                r = np.linalg.norm(pts - bm.ref_points[b], axis=-1)
                bound = mb.trans[i, b] + chord(mb.angle[i, b]) * r
                assert (dev <= bound).all(), (i, b, dev, bound)
                ratios.append((dev[:10] / bound[:10]).max())
    med = float(np.median(ratios))
    print(f"\nBodyMotion tightness: median sampled-max/bound = {med:.3f} over {len(ratios)} cases")
    assert med > 0.5  # the direct bound is nearly exact; a loose bound would be a regression


def test_static_and_translating_bodies():
    rng = np.random.default_rng(3)
    times, pos, quat = _motion(rng, K=3, nbody=3)
    pos[:, 1] = pos[0, 1]
    quat[:, 1] = quat[0, 1]  # body 1 static
    quat[:, 2] = quat[0, 2]  # body 2 translates only
    bm = BodyMotion(times, pos, quat)
    np.testing.assert_array_equal(bm.moving_bodies(), [False, False, True])
    mb = bm.motion_bounds(times[:-1], times[1:])
    assert (mb.trans[:, :2] == 0).all() and (mb.angle[:, :2] == 0).all()
    assert (mb.angle[:, 2] == 0).all() and (mb.trans[:, 2] > 0).all()
    bp, org = bm.translation_segments(1)
    np.testing.assert_array_equal(bp, [times[0], times[-1]])
    np.testing.assert_array_equal(org, [pos[0, 1], pos[0, 1]])
    bp, org = bm.translation_segments(2)
    np.testing.assert_array_equal(bp, times)
    np.testing.assert_array_equal(org, pos[:, 2])
    times2, pos2, quat2 = _motion(rng, K=3, nbody=2)
    assert BodyMotion(times2, pos2, quat2).translation_segments(1) is None
    with pytest.raises(InvalidInputError, match="body index"):
        bm.translation_segments(7)


def _valid(rng=None):
    rng = rng or np.random.default_rng(4)
    return _motion(rng, K=3, nbody=2)


@pytest.mark.parametrize("field, index", [("times", 1), ("pos", (2, 1, 0)), ("quat", (1, 1, 3))])
def test_nonfinite_rejected(field, index):
    times, pos, quat = _valid()
    arrs = {"times": times, "pos": pos, "quat": quat}
    arrs[field][index] = np.nan
    with pytest.raises(InvalidInputError, match=f"{field}.*non-finite.*{np.ravel(index)[0]}"):
        BodyMotion(arrs["times"], arrs["pos"], arrs["quat"])


def test_inf_rejected():
    times, pos, quat = _valid()
    pos[1, 1, 2] = np.inf
    with pytest.raises(InvalidInputError, match=r"pos.*\(1, 1, 2\)"):
        BodyMotion(times, pos, quat)


def test_wrong_shapes_rejected():
    times, pos, quat = _valid()
    with pytest.raises(InvalidInputError, match="pos must have shape"):
        BodyMotion(times, pos[:, :, :2], quat)
    with pytest.raises(InvalidInputError, match="quat must have shape"):
        BodyMotion(times, pos, quat[:2])
    with pytest.raises(InvalidInputError, match="times must have shape"):
        BodyMotion(times[:, None], pos, quat)
    with pytest.raises(InvalidInputError, match="ref_points"):
        BodyMotion(times, pos, quat, ref_points=np.zeros((3, 3)))


def test_non_increasing_times_rejected():
    times, pos, quat = _valid()
    times[2] = times[1]
    with pytest.raises(InvalidInputError, match=r"strictly increasing: times\[2\]"):
        BodyMotion(times, pos, quat)


def test_too_few_waypoints_rejected():
    times, pos, quat = _valid()
    with pytest.raises(InvalidInputError, match="at least 2 waypoints"):
        BodyMotion(times[:1], pos[:1], quat[:1])


def test_quaternion_norm():
    times, pos, quat = _valid()
    quat[1, 1] *= 1.0 + 1e-8  # within tolerance: normalised silently
    bm = BodyMotion(times, pos, quat)
    assert abs(np.linalg.norm(bm.quat[1, 1]) - 1.0) < 1e-15
    quat[2, 1] *= 1.1
    with pytest.raises(InvalidInputError, match=r"quaternion at index \(2, 1\)"):
        BodyMotion(times, pos, quat)


def test_moving_world_rejected():
    times, pos, quat = _valid()
    pos[2, 0, 0] = 1.0
    with pytest.raises(InvalidInputError, match="world body.*waypoint 2"):
        BodyMotion(times, pos, quat)


def test_queries_outside_window_rejected():
    times, pos, quat = _valid()
    bm = BodyMotion(times, pos, quat)
    with pytest.raises(InvalidInputError, match="outside the window"):
        bm.body_poses(np.array([times[-1] + 1.0]))
    with pytest.raises(InvalidInputError, match="sub-interval 0"):
        bm.motion_bounds(np.array([times[1]]), np.array([times[0]]))
