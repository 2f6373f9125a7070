"""Elementary tests of the toleranced checker against brute force.

Oracle: for a unit (moving feature set f_A, fixed f_B), the fat f_A meets f_B iff
max_{x in f_A} q(x) - dist(g(x), f_B)^2 >= 0 with q = R^2 rho^2 + Delta. The inner
distance is exact (closest point on a convex polygon / segment / point / half-space),
the outer max is sampled densely (vertices, edges, interior). A sampled value > tol
means the unit MUST fire (soundness); a fired unit whose sampled max is far below 0
is reported (exactness, looser).
"""

import zlib

import numpy as np
import pytest

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
from monitor.motion.metric import make_metric


def _rot(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _dist_point_segment(y, a, b):
    d = b - a
    dd = d @ d
    t = np.zeros(len(y)) if dd == 0 else np.clip((y - a) @ d / dd, 0, 1)
    return np.linalg.norm(y - (a + t[:, None] * d), axis=1)


def _dist_point_polygon(y, P):
    """Exact distance from points y (n, 3) to a planar convex polygon P (k, 3)."""
    o = P.mean(axis=0)
    n = np.cross(P[1] - P[0], P[2] - P[0])
    n /= np.linalg.norm(n)
    h = (y - o) @ n
    proj = y - h[:, None] * n
    k = len(P)
    inside = np.ones(len(y), bool)
    sgn = None
    for i in range(k):
        c = np.cross(P[(i + 1) % k] - P[i], proj - P[i]) @ n
        s = c >= -1e-12
        if sgn is None:
            sgn = np.sign(np.cross(P[1] - P[0], P[2] - P[1]) @ n)
        inside &= (c * sgn >= -1e-12)
    del s
    edge = np.min([_dist_point_segment(y, P[i], P[(i + 1) % k]) for i in range(k)], axis=0)
    return np.where(inside, np.abs(h), edge)


def _samples_polygon(P, rng, n=1000):
    k = len(P)
    w = rng.dirichlet(np.full(k, 0.3), size=n)
    pts = [w @ P, P]
    t = np.linspace(0, 1, 200)[:, None]
    for i in range(k):
        pts.append(P[i] + t * (P[(i + 1) % k] - P[i]))
    return np.vstack(pts)


def _unit_sets(shape_or_poly, moving):
    """List of point-sampler inputs per unit, mirroring moving/fixed_features unit order."""
    if isinstance(shape_or_poly, np.ndarray):
        return [("poly", shape_or_poly)]
    s = shape_or_poly
    if s.kind == "sphere":
        return [("pt", s.points[0])]
    if s.kind == "capsule":
        return [("seg", s.points)]
    if s.kind == "halfspace":
        return [("half", (s.normals[0], s.offsets[0]))]
    return [("poly", s.points[np.asarray(f)]) for f in s.faces]


def _oracle(unitA, unitB, metric, L, p, R, r, rng):
    kind, data = unitA
    if kind == "poly":
        X = _samples_polygon(data, rng)
    elif kind == "seg":
        X = data[0] + np.linspace(0, 1, 3000)[:, None] * (data[1] - data[0])
    else:
        X = data[None, :]
    rho_max = metric.rho(X).max()
    q = R * R * metric.rho2(X) + r * r + 2 * r * R * rho_max
    Y = X @ L.T + p
    kb, db = unitB
    if kb == "poly":
        d = _dist_point_polygon(Y, db)
    elif kb == "seg":
        d = _dist_point_segment(Y, db[0], db[1])
    elif kb == "pt":
        d = np.linalg.norm(Y - db, axis=1)
    else:
        n, off = db
        d = np.maximum(Y @ n - off, 0.0)
    return float((q - d * d).max()), float(q.max())


def _octagon(rng, rad=1.0):
    ang = np.sort(rng.uniform(0, 2 * np.pi, 8))
    rr = rad * rng.uniform(0.7, 1.0, 8)
    P = np.stack([rr * np.cos(ang), rr * np.sin(ang), np.zeros(8)], axis=1)
    from scipy.spatial import ConvexHull
    h = ConvexHull(P[:, :2])
    return P[h.vertices]


SHAPES_A = ["box", "hull", "capsule", "sphere", "polygon"]
SHAPES_B = ["box", "hull", "capsule", "sphere", "polygon", "halfspace"]


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


@pytest.mark.parametrize("ka", SHAPES_A)
@pytest.mark.parametrize("kb", SHAPES_B)
def test_unit_fire_matches_brute_force(ka, kb):
    rng = np.random.default_rng(zlib.crc32(f"{ka}-{kb}".encode()))
    sound_viol, loose, fired_total, must_total, n_sep = [], 0, 0, 0, 0
    for case in range(10):
        A = _make(ka, rng)
        B = _make(kb, rng)
        if isinstance(A, np.ndarray):
            mf = moving_features(polygon=A)
        else:
            mf = moving_features(A)
        fb = fixed_features(polygon=B) if isinstance(B, np.ndarray) else fixed_features(B)
        r = [0.0, 0.05, 0.3][case % 3]
        pd = _PairData(mf, fb, r)
        # affine (non-rigid) centre in a third of the cases
        L = _rot(rng)
        if case % 3 == 2:
            L = L @ (np.eye(3) + 0.1 * rng.normal(size=(3, 3)))
        p = rng.normal(size=3) * rng.uniform(0.3, 1.5)
        if kb == "halfspace":
            p[2] = rng.uniform(-0.5, 1.5)
        ua = _unit_sets(A, True)
        ub = _unit_sets(B, False)
        if kb == "halfspace":
            pairs = [(("pt", v), ub[0]) for v in mf.verts]
        else:
            pairs = [(x, y) for x in ua for y in ub]
        # near-threshold radius: orbit size comparable to the static gap at the centre pose
        gap0 = max(_oracle(uA, uB, mf.metric, L, p, 0.0, 0.0, rng)[0] for uA, uB in pairs)
        dmin = np.sqrt(max(-gap0, 0.0))
        if dmin > 0 and case % 4 != 3:
            rho_typ = float(np.median(mf.metric.rho(mf.verts)))
            R = max(dmin - r, 0.02) * rng.uniform(0.5, 1.6) / rho_typ
        else:
            R = float(np.exp(rng.uniform(np.log(0.01), np.log(3.0)))) * np.sqrt(mf.metric.inv_mass)
        fire = fat_units_fire(pd, L, p, R)
        sep = prefilter_separated(pd, L, p, R)
        n_sep += sep
        assert len(pairs) == len(fire)
        for (uA, uB), f in zip(pairs, fire):
            val, qmax = _oracle(uA, uB, mf.metric, L, p, R, r, rng)
            if val > 1e-9 * max(1.0, qmax):
                must_total += 1
                if not f or sep:
                    sound_viol.append((case, val, "prefilter" if sep else "unit"))
            if f:
                fired_total += 1
                if val < -0.05 * max(qmax, 1e-6):
                    loose += 1
    print(ka, kb, "must", must_total, "fired", fired_total, "loose", loose, "prefiltered", n_sep)
    assert not sound_viol, f"unit said clear but brute force found overlap: {sound_viol}"
    # exactness: few fired units should be clearly clear by brute force
    assert loose <= max(2, 0.1 * fired_total), (loose, fired_total, must_total)


def test_listing2_misses_edge_through_fat_face_interior_but_we_do_not():
    """A long fixed segment piercing a moving square far from its edges, end points far away."""
    sq = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    mf = moving_features(polygon=sq)
    seg = np.array([[0.1, 0.05, -5.0], [0.1, 0.05, 5.0]])
    # fixed side: a thin triangle whose edges pierce the square (vertices far above/below)
    tri = np.array([[0.1, 0.05, -5.0], [0.1, 0.05, 5.0], [0.12, 0.05, 5.0]])
    fb = fixed_features(polygon=tri)
    pd = _PairData(mf, fb, 0.0)
    assert fat_units_fire(pd, np.eye(3), np.zeros(3), 1e-3).all()
    del seg
    # segment (capsule core) piercing the square: FE row (fat face vs edge) must fire
    from monitor.geometry.shapes import ConvexShape
    cap = ConvexShape("capsule", np.array([[0.1, 0.05, -5.0], [0.1, 0.05, 5.0]]), 0.0,
                      np.array([[0, 1]]))
    pd2 = _PairData(mf, fixed_features(cap), 0.0)
    assert fat_units_fire(pd2, np.eye(3), np.zeros(3), 1e-3).all()


def test_clear_configuration_is_excluded_and_inflation_counts():
    a = box_polytope(np.array([0.5, 0.5, 0.5]))
    b = box_polytope(np.array([0.5, 0.5, 0.5]))
    for margin, expect in [(0.0, False), (0.99, False), (1.01, True)]:
        pd = prepare_pair(a, b, margin)
        # A centred at x = 2 (gap 1.0), tiny ball
        fire = fat_units_fire(pd, np.eye(3), np.array([2.0, 0, 0]), 1e-4)
        assert fire.any() == expect, margin


def test_metric_of_polygon_uses_off_plane_point():
    m = make_metric(_octagon(np.random.default_rng(3)))
    assert m.added == 2


def test_check_pairs_start_containment_and_clear_motion():
    from monitor.certify.toleranced import check_pairs
    from monitor.motion.bodymotion import BodyMotion

    box = box_polytope(np.array([0.5, 0.5, 0.5]))
    ball = sphere_shape(0.05)
    K = 2
    pos = np.zeros((K, 3, 3))
    quat = np.tile([1.0, 0, 0, 0], (K, 3, 1))
    pos[:, 1] = [[0.0, 0, 0], [0.2, 0.1, 0]]        # ball moves inside the box (never touches a face)
    pos[:, 2] = [[2.0, 0, 0], [2.0, 0.5, 0]]        # a second box far away
    bm = BodyMotion(np.array([0.0, 1.0]), pos, quat)
    out = check_pairs(bm, [(ball, 1, box, 0), (box, 2, box, 0)], (0.0, 1.0), 0.0, 1e-3)
    assert out[0].verdict == "unresolved" and out[0].info.get("start_overlap")
    assert out[1].verdict == "certified" and (out[1].tests > 0 or out[1].info["prefiltered"] > 0)
    # without the start test the boundary tests alone would (wrongly) clear the contained ball
    out2 = check_pairs(bm, [(ball, 1, box, 0)], (0.0, 1.0), 0.0, 1e-3, check_start=False)
    assert out2[0].verdict == "certified"


def test_overflow_or_nan_never_excludes():
    a = box_polytope(np.array([0.5, 0.5, 0.5]))
    pd = prepare_pair(a, a, 0.0)
    for R in (np.inf, np.nan, 1e300):
        assert fat_units_fire(pd, np.eye(3), np.array([3.0, 0, 0]), R).all()
    assert fat_units_fire(pd, np.eye(3), np.array([np.nan, 0, 0]), 1e-3).all()
    assert not prefilter_separated(pd, np.eye(3), np.array([3.0, 0, 0]), np.nan)
