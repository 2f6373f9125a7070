"""The compiled fat-feature level kernel (monitor.certify.fat_kernels) against its oracles.

Oracles:
* the numpy kernels of ``toleranced.py`` (themselves checked against brute force in
  tests/test_toleranced.py): identical unit answers on random balls, identical
  pre-filter answers, identical subdivision results (intervals, counts) on seeded motions;
* brute force directly: a unit the compiled kernel leaves clear has no sampled overlap;
* dense sampling of the motion: a pair the compiled path certifies has no sample time
  with the cores closer than r (exact distance, upper bound).
"""

import zlib

import numpy as np
import pytest

import monitor.certify.toleranced as TT
from monitor.certify.toleranced import (
    _PairData,
    fat_units_fire,
    fixed_features,
    moving_features,
    prefilter_separated,
    prepare_pair,
)
from monitor.geometry.polytope import (
    box_polytope,
    capsule_shape,
    halfspace_shape,
    polytope_from_points,
    sphere_shape,
)

SHAPES_A = ["box", "hull", "capsule", "sphere", "polygon"]
SHAPES_B = ["box", "hull", "capsule", "sphere", "polygon", "halfspace"]


def _rot(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _octagon(rng, rad):
    from scipy.spatial import ConvexHull
    ang = np.sort(rng.uniform(0, 2 * np.pi, 8))
    rr = rad * rng.uniform(0.7, 1.0, 8)
    P = np.stack([rr * np.cos(ang), rr * np.sin(ang), np.zeros(8)], axis=1)
    return P[ConvexHull(P[:, :2]).vertices]


def _make(kind, rng):
    if kind == "box":
        return box_polytope(rng.uniform(0.2, 0.8, 3))
    if kind == "hull":
        return polytope_from_points(rng.normal(size=(9, 3)) * 0.5)
    if kind == "capsule":
        return capsule_shape(0.1, rng.uniform(0.1, 0.6))
    if kind == "sphere":
        return sphere_shape(0.2, rng.normal(size=3) * 0.1)
    if kind == "polygon":
        return _octagon(rng, 0.8)
    return halfspace_shape()


def _pair(ka, kb, rng, r):
    A, B = _make(ka, rng), _make(kb, rng)
    mf = moving_features(polygon=A) if isinstance(A, np.ndarray) else moving_features(A)
    fb = fixed_features(polygon=B) if isinstance(B, np.ndarray) else fixed_features(B)
    return _PairData(mf, fb, r)


@pytest.mark.parametrize("ka", SHAPES_A)
@pytest.mark.parametrize("kb", SHAPES_B)
def test_units_and_prefilter_match_numpy_oracle(ka, kb):
    """Random centres (rigid and affine) and radii from tiny to huge, most near the threshold."""
    rng = np.random.default_rng(zlib.crc32(f"fat-{ka}-{kb}".encode()))
    n_fired = n_units = n_sep = 0
    for case in range(40):
        pd = _pair(ka, kb, rng, [0.0, 0.05, 0.3][case % 3])
        L = _rot(rng)
        if case % 3 == 2:
            L = L @ (np.eye(3) + 0.1 * rng.normal(size=(3, 3)))
        p = rng.normal(size=3) * rng.uniform(0.05, 1.5)
        R = float(np.exp(rng.uniform(np.log(1e-3), np.log(3.0))))
        want = fat_units_fire(pd, L, p, R)
        got = fat_units_fire(pd, L, p, R, compiled=True)
        assert got.dtype == bool and got.shape == want.shape
        assert np.array_equal(got, want), (case, np.nonzero(got != want)[0])
        s_want = prefilter_separated(pd, L, p, R)
        assert prefilter_separated(pd, L, p, R, compiled=True) == s_want, case
        n_fired += int(want.sum())
        n_units += len(want)
        n_sep += s_want
    # the comparison covers both answers (a test that cannot fail is a defect)
    assert 0 < n_fired < n_units, (n_fired, n_units)
    if kb in ("box", "hull", "polygon"):
        assert n_sep > 0


def _dist_point_polygon(y, P):
    o = P.mean(axis=0)
    n = np.cross(P[1] - P[0], P[2] - P[0])
    n /= np.linalg.norm(n)
    h = (y - o) @ n
    proj = y - h[:, None] * n
    inside = np.ones(len(y), bool)
    c = np.cross(P[1] - P[0], P[2] - P[0])
    for i in range(len(P)):
        a, b = P[i], P[(i + 1) % len(P)]
        inside &= (np.cross(b - a, proj - a) @ c) >= 0
    d = np.full(len(y), np.inf)
    for i in range(len(P)):
        a, b = P[i], P[(i + 1) % len(P)]
        dd = b - a
        t = np.clip((y - a) @ dd / (dd @ dd), 0, 1)
        d = np.minimum(d, np.linalg.norm(y - (a + t[:, None] * dd), axis=1))
    return np.where(inside, np.abs(h), d)


def test_compiled_clear_means_no_sampled_overlap_polygon_vs_polygon():
    """Brute force: fat moving square vs fixed square; a clear answer has no sampled x with
    dist(g(x), B) <= R rho(x) + r (the orbit's ball of x meets B)."""
    rng = np.random.default_rng(12)
    sq = np.array([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]], float)
    mf = moving_features(polygon=sq)
    fb = fixed_features(polygon=sq * 1.3)
    u = rng.uniform(0, 1, size=(4000, 2))
    X = np.stack([u[:, 0] - 0.5, u[:, 1] - 0.5, np.zeros(len(u))], axis=1)
    X = np.concatenate([X, sq])
    rho = mf.metric.rho(X)
    checked = clear = 0
    for _ in range(200):
        L, p = _rot(rng), rng.normal(size=3) * 0.8
        R = float(np.exp(rng.uniform(np.log(1e-3), np.log(1.0))))
        r = 0.02
        pd = _PairData(mf, fb, r)
        fire = fat_units_fire(pd, L, p, R, compiled=True)
        d = _dist_point_polygon(X @ L.T + p, sq * 1.3)
        touch = bool((d <= R * rho + r - 1e-12).any())
        checked += 1
        if not fire.any():
            clear += 1
            assert not touch
    assert 0 < clear < checked


@pytest.mark.parametrize("R", [np.inf, np.nan, 1e300])
def test_non_finite_ball_fires_every_unit(R):
    a = box_polytope(np.array([0.5, 0.5, 0.5]))
    pd = prepare_pair(a, a, 0.0)
    assert fat_units_fire(pd, np.eye(3), np.array([3.0, 0, 0]), R, compiled=True).all()
    assert not prefilter_separated(pd, np.eye(3), np.array([3.0, 0, 0]), R, compiled=True)


def test_nan_centre_fires_every_unit():
    a = box_polytope(np.array([0.5, 0.5, 0.5]))
    pd = prepare_pair(a, a, 0.0)
    assert fat_units_fire(pd, np.eye(3), np.array([np.nan, 0, 0]), 1e-3, compiled=True).all()
    assert not prefilter_separated(pd, np.eye(3), np.array([np.nan, 0, 0]), 1e-3, compiled=True)


def _motion(rng, kind, reach=(0.9, 1.4)):
    from monitor.motion.bodymotion import BodyMotion
    K = 3
    pos = np.zeros((K, 2, 3))
    quat = np.tile([1.0, 0, 0, 0], (K, 2, 1))
    start = rng.normal(size=3)
    start *= rng.uniform(*reach) / np.linalg.norm(start)
    pos[:, 1] = start[None] + np.linspace(0, 1, K)[:, None] * rng.normal(size=3) * 0.4
    qs = rng.normal(size=(K, 4))
    quat[:, 1] = qs / np.linalg.norm(qs, axis=1, keepdims=True)
    return BodyMotion(np.array([0.0, 0.5, 1.0]), pos, quat,
                      interpolation="screw" if kind == "screw" else "lerp_slerp")


def _shape(kind, rng):
    if kind == "box":
        return box_polytope(rng.uniform(0.1, 0.4, 3))
    if kind == "hull":
        return polytope_from_points(rng.normal(size=(10, 3)) * 0.25)
    if kind == "capsule":
        return capsule_shape(0.05, rng.uniform(0.1, 0.3))
    if kind == "sphere":
        return sphere_shape(0.1)
    return halfspace_shape()


@pytest.mark.parametrize("short_circuit", [False, True])
@pytest.mark.parametrize("interp", ["lerp_slerp", "screw"])
def test_subdivision_identical_to_numpy_and_certified_is_sampled_clear(interp, short_circuit, monkeypatch):
    """Seeded two-body motions: compiled and numpy subdivisions agree exactly (intervals,
    row/unit/item counts, depth; with the short circuit: everything but the row count, which
    can only drop); every certified pair is clear at 2001 sample times."""
    from monitor.certify.toleranced import check_pairs
    from monitor.geometry.distance import shape_distance

    monkeypatch.setattr(TT, "SHORT_CIRCUIT", short_circuit)
    fewer = 0

    rng = np.random.default_rng(zlib.crc32(interp.encode()))
    kinds_a = ["box", "hull", "capsule", "sphere"]
    kinds_b = ["box", "hull", "capsule", "halfspace"]
    verdicts = []
    ts = np.linspace(0.0, 1.0, 2001)
    for case in range(16):
        bm = _motion(rng, interp)
        sa, sb = _shape(kinds_a[case % 4], rng), _shape(kinds_b[(case // 4) % 4], rng)
        items = [(sa, 1, sb, 0)]             # body 1 moves, body 0 stays at the origin
        margin = 0.01
        want = check_pairs(bm, items, (0.0, 1.0), margin, 2e-3, compiled=False)[0]
        got = check_pairs(bm, items, (0.0, 1.0), margin, 2e-3, compiled=True)[0]
        assert got.verdict == want.verdict, case
        assert got.intervals == want.intervals, case
        assert got.max_depth == want.max_depth, case
        if short_circuit:
            assert got.tests <= want.tests and got.info["row_tests"] == got.tests, case
            fewer += got.tests < want.tests
        else:
            assert got.tests == want.tests and got.info["row_tests"] == want.info["row_tests"], case
        for k in ("unit_tests", "items", "prefiltered", "frontier_capped"):
            assert got.info[k] == want.info[k], (case, k)
        verdicts.append(got.verdict)
        if got.verdict == "certified":
            pos, rot = bm.body_poses(ts)
            (s1, b1, s2, b2), = items
            for j in range(len(ts)):   # shape distance (radii included) must exceed the margin
                d = shape_distance(s1, (rot[j, b1], pos[j, b1]), s2, (rot[j, b2], pos[j, b2]))
                assert d.upper > margin - 1e-9, (case, ts[j], d.upper)
    assert "certified" in verdicts and "unresolved" in verdicts, verdicts
    assert fewer > 0 or not short_circuit


@pytest.mark.parametrize("interp", ["lerp_slerp", "screw"])
def test_trajectory_balls_compiled_match_numpy(interp):
    """Centre g and radius R of the compiled provider against the numpy one (both bodies move),
    and every sampled relative pose of each sub-interval inside the compiled ball (the oracle).

    lerp_slerp takes poses and bounds from the motion pack (the compiled kernels' bound: the
    minimum of the chain and Taylor bounds, so it can be tighter than BodyMotion's across
    waypoints); screw takes the Trajectory protocol's (radii equal up to rounding).
    """
    from monitor.certify.toleranced import _Frontier, _TrajectoryBalls
    from monitor.motion.bodymotion import BodyMotion

    rng = np.random.default_rng(zlib.crc32(("balls-" + interp).encode()))
    K, nb = 4, 4
    pos = rng.normal(size=(K, nb, 3))
    pos[:, 0] = 0.0
    q = rng.normal(size=(K, nb, 4))
    q /= np.linalg.norm(q, axis=2, keepdims=True)
    q[:, 0] = [1.0, 0, 0, 0]
    bm = BodyMotion(np.array([0.0, 0.3, 0.7, 1.0]), pos, q, interpolation=interp,
                    ref_points=rng.normal(size=(nb, 3)) * 0.1)
    shapes = [box_polytope(np.array([0.2, 0.3, 0.1])), polytope_from_points(rng.normal(size=(9, 3)) * 0.3)]
    metrics = [moving_features(s).metric for s in shapes]
    ba, bb = np.array([1, 2]), np.array([3, 0])
    num = _TrajectoryBalls(bm, ba, bb, metrics)
    com = _TrajectoryBalls(bm, ba, bb, metrics, compiled=True)
    assert (com.pack is not None) == (interp == "lerp_slerp")
    N = 300
    t0 = np.sort(rng.uniform(0, 1, N))
    t1 = np.minimum(1.0, t0 + np.exp(rng.uniform(np.log(1e-6), 0.0, N)))
    fr = _Frontier(rng.integers(0, 2, N), t0, t1, np.zeros(N, np.int64), np.zeros(0, np.int64),
                   np.zeros(0, np.int64))
    L0, p0, R0 = num.balls(fr)
    L1, p1, R1 = com.balls(fr)
    assert np.allclose(L1, L0, rtol=0, atol=1e-14)
    assert np.allclose(p1, p0, rtol=0, atol=1e-13)
    assert np.all(R1 <= R0 * (1 + 1e-7)), np.max(R1 / R0)
    if interp == "screw":
        assert np.allclose(R1, R0, rtol=1e-12, atol=0)
    assert R0.min() > 0
    # sampled relative poses X_BA(t) lie in B_R(g): sqrt(sum_i w_i |X_BA(t) m_i - g(m_i)|^2) <= R
    worst = 0.0
    for n in range(0, N, 5):
        k = int(fr.pair[n])
        ts = np.linspace(t0[n], t1[n], 41)
        P, Rt = bm.body_poses(ts)
        a, b = ba[k], bb[k]
        m, w = metrics[k].points, metrics[k].weights
        xa = np.einsum("tij,mj->tmi", Rt[:, a], m) + P[:, a, None, :]
        rel = np.einsum("tji,tmj->tmi", Rt[:, b], xa - P[:, b, None, :])
        g = m @ L1[n].T + p1[n]
        dist = np.sqrt(np.einsum("m,tm->t", w, ((rel - g) ** 2).sum(axis=2)))
        assert dist.max() <= R1[n] * (1 + 1e-9) + 1e-12, (n, dist.max(), R1[n])
        worst = max(worst, float(dist.max() / R1[n]))
    assert worst > 0.3, worst     # the samples come near the radius (the check has teeth)


def test_merged_intervals_equal_sorted_sequential_merge():
    """The vectorised interval union of the driver against the sequential one (toleranced._merge)."""
    from monitor.certify.toleranced import _merge, _merged_intervals

    rng = np.random.default_rng(5)
    for _ in range(50):
        chunks, ref = [], [[] for _ in range(4)]
        for _ in range(rng.integers(0, 5)):
            n = int(rng.integers(0, 30))
            pr = rng.integers(0, 4, n)
            grid = rng.integers(0, 64, n) / 64.0                 # dyadic ends: touching intervals
            w = rng.integers(0, 4, n) / 64.0                      # including points (w = 0)
            chunks.append((pr, grid, grid + w))
            for k, a, b in zip(pr, grid, grid + w):
                ref[k].append((float(a), float(b)))
        got = _merged_intervals(chunks, 4)
        assert got == [_merge(sorted(x)) for x in ref]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_screw_poses_bounds_match_bodymotion(seed):
    """The compiled screw poses and bounds against BodyMotion's numpy ones (the oracle), on
    random multi-waypoint screw motions with offset reference points, a static and a
    translating body; sub-intervals from the whole window down to 1e-9 s, and at the ends."""
    from monitor.certify.toleranced import _screw_poses_bounds
    from monitor.motion.bodymotion import BodyMotion

    rng = np.random.default_rng(100 + seed)
    K, nb = 5, 4
    times = np.cumsum(np.concatenate([[0.0], rng.uniform(0.1, 0.5, K - 1)]))
    pos = rng.normal(size=(K, nb, 3))
    pos[:, 0] = 0.0
    pos[:, 1] = pos[0, 1]                          # body 1 static
    q = rng.normal(size=(K, nb, 4))
    q /= np.linalg.norm(q, axis=2, keepdims=True)
    q[:, 0] = [1.0, 0, 0, 0]
    q[:, 1] = q[0, 1]
    q[:, 2] = q[0, 2]                              # body 2 translates only
    if seed == 2:
        q[3, 3] = -q[2, 3]                          # a sign flip (same rotation)
    bm = BodyMotion(times, pos, q, interpolation="screw", ref_points=rng.normal(size=(nb, 3)) * 0.2)
    T = times[-1]
    N = 400
    t0 = rng.uniform(0, T, N)
    w = np.exp(rng.uniform(np.log(1e-9), np.log(T), N))
    t1 = np.minimum(T, t0 + w)
    t0[:3], t1[:3] = [0.0, 0.0, T], [T, 1e-6, T]
    t0[3], t1[3] = times[2], times[2]
    pos_c, rot_c, mb_c = _screw_poses_bounds(bm, bm.screw_arrays(), t0, t1)
    pos_n, rot_n = bm.body_poses(0.5 * (t0 + t1))
    mb_n = bm.motion_bounds(t0, t1)
    assert np.allclose(pos_c, pos_n, rtol=0, atol=1e-13)
    assert np.allclose(rot_c, rot_n, rtol=0, atol=1e-14)
    assert np.allclose(mb_c.trans, mb_n.trans, rtol=1e-12, atol=1e-15)
    assert np.allclose(mb_c.angle, mb_n.angle, rtol=1e-12, atol=1e-15)
    assert np.all(mb_c.trans[:, 1] == 0) and np.all(mb_c.angle[:, 2] == 0)
    assert mb_c.trans[:, 3].max() > 0.1 and mb_c.angle[:, 3].max() > 0.1


def test_warm_kernels_compiles_the_three_entry_points():
    from monitor.certify import fat_kernels as FK
    from monitor.certify.toleranced import warm_kernels

    warm_kernels()
    assert FK.fat_level.signatures and FK.traj_balls.signatures and FK.screw_poses_bounds.signatures


@pytest.mark.slow
@pytest.mark.parametrize("interp", ["lerp_slerp", "screw"])
def test_sweep_compiled_equals_numpy_and_certified_is_sampled_clear(interp):
    """Slow sweep: 60 seeded motions per interpolation, margins 0 / 0.02; the compiled and the
    numpy subdivisions give the same verdict and intervals, and every certified pair is clear
    at 4001 sample times."""
    from monitor.certify.toleranced import check_pairs
    from monitor.geometry.distance import shape_distance

    rng = np.random.default_rng(zlib.crc32(("sweep-" + interp).encode()))
    kinds = ["box", "hull", "capsule", "sphere"]
    ts = np.linspace(0.0, 1.0, 4001)
    n_cert = 0
    for case in range(60):
        bm = _motion(rng, interp, reach=(0.3, 0.9))
        sa, sb = _shape(kinds[case % 4], rng), _shape(kinds[(case // 4) % 4], rng)
        margin = [0.0, 0.02][case % 2]
        want = check_pairs(bm, [(sa, 1, sb, 0)], (0.0, 1.0), margin, 1e-3, compiled=False)[0]
        got = check_pairs(bm, [(sa, 1, sb, 0)], (0.0, 1.0), margin, 1e-3, compiled=True)[0]
        assert (got.verdict, got.intervals) == (want.verdict, want.intervals), case
        if got.verdict == "certified":
            n_cert += 1
            pos, rot = bm.body_poses(ts)
            for j in range(len(ts)):
                d = shape_distance(sa, (rot[j, 1], pos[j, 1]), sb, (rot[j, 0], pos[j, 0]))
                assert d.upper > margin - 1e-9, (case, ts[j], d.upper)
    assert 0 < n_cert < 60
