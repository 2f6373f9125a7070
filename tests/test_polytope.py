"""Polytope builders: hull structure, containment of the true primitives, degenerate inputs."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial import ConvexHull

from monitor.errors import InvalidInputError
from monitor.geometry.polytope import (
    box_polytope,
    capsule_shape,
    cylinder_polytope,
    ellipsoid_distance_upper,
    ellipsoid_polytope,
    halfspace_shape,
    polytope_from_points,
    sphere_shape,
)


def unit(rng, n):
    u = rng.normal(size=(n, 3))
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def volume(shape):
    vol = 0.0
    for loop in shape.faces:
        v = shape.points[loop]
        for k in range(1, len(v) - 1):
            vol += np.dot(v[0], np.cross(v[k], v[k + 1])) / 6.0
    return vol


def check_valid(shape, scale=1.0, vertex_tol=0.0):
    """Structural invariants of a polytope ConvexShape (vertex_tol: allowed H-rep excess, m)."""
    V, N, o = shape.points, shape.normals, shape.offsets
    assert shape.kind == "polytope" and V.shape[1] == 3 and len(V) >= 4
    assert shape.edges.dtype == np.int64 and shape.edges.shape[1] == 2
    assert len(shape.faces) == len(N) == len(o)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-14)
    # every vertex inside the H-rep
    assert (V @ N.T - o).max() <= vertex_tol
    directed = set()
    for f, loop in enumerate(shape.faces):
        assert loop.dtype == np.int64 and len(loop) >= 3
        P = V[loop]
        # planar: every loop vertex on its face plane
        assert np.abs(P @ N[f] - o[f]).max() <= 1e-12 * scale
        # convex and CCW seen from outside: each turn has a positive component along the normal
        for k in range(len(loop)):
            a, b, c = P[k], P[(k + 1) % len(P)], P[(k + 2) % len(P)]
            assert np.cross(b - a, c - b) @ N[f] > -1e-15 * scale**2
        newell = sum(np.cross(P[k], P[(k + 1) % len(P)]) for k in range(len(P)))
        assert newell @ N[f] > 0
        for k in range(len(loop)):
            e = (int(loop[k]), int(loop[(k + 1) % len(loop)]))
            assert e not in directed
            directed.add(e)
    # closed 2-manifold: each edge used once in each direction; edges list matches
    assert all((j, i) in directed for i, j in directed)
    und = {(min(i, j), max(i, j)) for i, j in directed}
    assert und == {tuple(e) for e in shape.edges.tolist()}
    assert len(shape.edges) == len(und)
    assert len(V) - len(und) + len(shape.faces) == 2
    assert volume(shape) > 0


# --------------------------------------------------------------------------- polytope_from_points


@pytest.mark.parametrize("seed", range(6))
def test_random_hulls(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 300))
    kind = seed % 3
    if kind == 0:
        P = rng.uniform(-1, 1, (n, 3)) * rng.uniform(0.01, 3, 3)
    elif kind == 1:
        P = unit(rng, n) * rng.uniform(0.5, 2)  # all points extreme
    else:
        P = np.round(rng.uniform(-1, 1, (n, 3)), 1)  # many coplanar / duplicate points
    P = P + rng.uniform(-5, 5, 3)
    shape = polytope_from_points(P)
    check_valid(shape, scale=10.0)
    assert shape.approx_error == 0.0
    # vertices are input points; input points are inside
    assert all((np.abs(P - v).sum(axis=1) == 0).any() for v in shape.points)
    assert (P @ shape.normals.T - shape.offsets).max() <= 0.0
    # same set as qhull's hull: volume and support function
    assert volume(shape) == pytest.approx(ConvexHull(P).volume, rel=1e-12)
    D = unit(rng, 300)
    np.testing.assert_allclose((D @ shape.points.T).max(axis=1), (D @ P.T).max(axis=1), atol=1e-14)


def test_box_with_redundant_points_merges_faces():
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-2, 2) for z in (-0.5, 0.5)], float)
    face_centres = np.array([[1, 0, 0], [-1, 0, 0], [0, 2, 0], [0, -2, 0], [0, 0, 0.5], [0, 0, -0.5]], float)
    edge_mids = (corners[:, None] + corners[None]).reshape(-1, 3) / 2
    interior = np.random.default_rng(1).uniform(-0.4, 0.4, (50, 3))
    P = np.concatenate([corners, corners, face_centres, edge_mids, interior])
    shape = polytope_from_points(P)
    check_valid(shape, 4.0)
    assert (len(shape.points), len(shape.edges), len(shape.faces)) == (8, 12, 6)
    assert all(len(f) == 4 for f in shape.faces)
    assert volume(shape) == pytest.approx(8.0, rel=1e-14)


def test_box_polytope_exact():
    h = np.array([0.3, 0.2, 0.1])
    shape = box_polytope(h)
    check_valid(shape)
    assert (len(shape.points), len(shape.edges), len(shape.faces)) == (8, 12, 6)
    assert volume(shape) == pytest.approx(8 * h.prod(), rel=1e-14)
    D = unit(np.random.default_rng(2), 500)
    np.testing.assert_allclose((D @ shape.points.T).max(axis=1), np.abs(D) @ h, rtol=1e-15, atol=1e-16)
    for bad in ([1, 1], [1, 0, 1], [1, -1, 1], [1, np.nan, 1]):
        with pytest.raises(InvalidInputError):
            box_polytope(bad)


def test_bad_point_input():
    with pytest.raises(InvalidInputError, match="row 2"):
        polytope_from_points([[0, 0, 0], [1, 0, 0], [0, np.nan, 0], [0, 0, 1]])
    with pytest.raises(InvalidInputError, match="shape"):
        polytope_from_points(np.zeros((4, 2)))
    with pytest.raises(InvalidInputError, match="shape"):
        polytope_from_points(np.zeros((0, 3)))
    with pytest.raises(InvalidInputError, match="thicken"):
        polytope_from_points(np.eye(3), thicken=-1.0)
    with pytest.raises(InvalidInputError, match="numeric"):
        polytope_from_points([["a", "b", "c"]])


def _hull_excess_lp(X, P):
    """Max over rows of X of the L-infinity distance to conv(P), by LP (independent oracle)."""
    worst = 0.0
    n = len(P)
    for x in X:
        # min s  s.t.  |P^T lam - x|_inf <= s, sum lam = 1, lam >= 0
        c = np.r_[np.zeros(n), 1.0]
        A = np.block([[P.T, -np.ones((3, 1))], [-P.T, -np.ones((3, 1))]])
        b = np.r_[x, -x]
        res = linprog(c, A_ub=A, b_ub=b, A_eq=np.r_[np.ones(n), 0.0][None], b_eq=[1.0],
                      bounds=[(0, None)] * n + [(0, None)], method="highs")
        assert res.status == 0
        worst = max(worst, res.fun)
    return worst


@pytest.mark.parametrize("case", ["flat", "near_flat", "collinear", "point"])
def test_degenerate_sets(case):
    rng = np.random.default_rng(3)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    if case == "flat":
        P = np.c_[rng.uniform(-1, 1, (30, 2)), np.zeros(30)]
    elif case == "near_flat":
        P = np.c_[rng.uniform(-1, 1, (30, 2)), rng.uniform(-1e-11, 1e-11, 30)]
    elif case == "collinear":
        P = np.c_[rng.uniform(-1, 1, 10), np.zeros((10, 2))]
    else:
        P = np.zeros((3, 3))
    P = P @ R.T + np.array([0.5, -2.0, 1.0])
    with pytest.raises(InvalidInputError, match="coplanar|collinear|single point"):
        polytope_from_points(P)
    t = 1e-4
    shape = polytope_from_points(P, thicken=t)
    check_valid(shape, scale=3.0)
    # contains the input, over-approximation reported and honest
    assert (P @ shape.normals.T - shape.offsets).max() <= 0.0
    assert shape.approx_error >= t
    excess = _hull_excess_lp(shape.points, P)  # L-inf distance <= Euclidean distance
    assert excess <= shape.approx_error
    assert shape.approx_error <= 4 * t + 1e-9  # tight: a few t, not the set size


def test_thin_but_full_rank_is_kept_exact():
    rng = np.random.default_rng(4)
    P = np.c_[rng.uniform(-1, 1, (40, 2)), rng.uniform(-1e-6, 1e-6, 40)]
    shape = polytope_from_points(P)
    check_valid(shape)
    assert shape.approx_error == 0.0
    assert volume(shape) == pytest.approx(ConvexHull(P).volume, rel=1e-9)


# --------------------------------------------------------------------------- primitives


@pytest.mark.parametrize("facets", [3, 6, 16, 40])
def test_cylinder_contains_and_reports(facets):
    r, hl = 0.07, 0.2
    shape = cylinder_polytope(r, hl, facets)
    check_valid(shape)
    assert len(shape.faces) == facets + 2
    rng = np.random.default_rng(facets)
    th = rng.uniform(0, 2 * np.pi, 4000)
    pts = np.c_[r * np.cos(th), r * np.sin(th), rng.uniform(-hl, hl, 4000)]
    rim = np.c_[r * np.cos(th), r * np.sin(th), rng.choice([-hl, hl], 4000)]
    for X in (pts, rim):
        assert (X @ shape.normals.T - shape.offsets).max() <= 1e-12
    want = r * (1 / np.cos(np.pi / facets) - 1)
    assert shape.approx_error == pytest.approx(want, rel=1e-12)
    assert shape.approx_error >= want
    # support: >= true support, <= true support + approx_error
    D = unit(rng, 500)
    h_true = r * np.hypot(D[:, 0], D[:, 1]) + hl * np.abs(D[:, 2])
    h = (D @ shape.points.T).max(axis=1)
    assert (h >= h_true - 1e-15).all() and (h <= h_true + shape.approx_error + 1e-15).all()


def test_cylinder_bad_input():
    for args in [(0, 1, 8), (1, -1, 8), (1, 1, 2), (1, 1, 3.5), (np.inf, 1, 8)]:
        with pytest.raises(InvalidInputError):
            cylinder_polytope(*args)


def ellipsoid_lower_distance(V, e, D):
    """Lower bounds on dist(v, E) by separating planes: max_d (d . v - h_E(d)) over unit d."""
    h = np.linalg.norm(D * e, axis=1)
    return np.maximum((V @ D.T - h).max(axis=1), 0.0)


@pytest.mark.parametrize("radii,facets", [((0.1, 0.2, 0.3), 16), ((1, 1, 1), 16), ((1, 1, 1), 4),
                                          ((0.5, 0.01, 0.05), 12), ((2, 2, 0.3), 7),
                                          ((1000, 1, 0.001), 16)])
def test_ellipsoid_contains_and_reports(radii, facets):
    e = np.array(radii, float)
    shape = ellipsoid_polytope(e, facets)
    check_valid(shape, scale=float(e.max()))
    rng = np.random.default_rng(int(facets))
    S = unit(rng, 20000) * e
    assert (S @ shape.normals.T - shape.offsets).max() <= 1e-12
    # approx_error is a true upper bound (>= separating-plane lower bound) and tight
    # (<= distance to a dense surface sample, an upper bound on the true distance)
    D = unit(rng, 20000)
    D_near = shape.points / np.linalg.norm(shape.points, axis=1, keepdims=True)
    G = shape.points / e**2  # outward normals at radially projected points: good separators
    G /= np.linalg.norm(G, axis=1, keepdims=True)
    lower = ellipsoid_lower_distance(shape.points, e, np.concatenate([D, D_near, G]))
    assert shape.approx_error >= lower.max()
    upper = np.array([np.linalg.norm(S - v, axis=1).min() for v in shape.points])
    assert shape.approx_error <= upper.max() + 1e-12
    if facets == 4:
        assert len(shape.faces) == 6
        if np.all(e == 1):
            assert shape.approx_error == pytest.approx(np.sqrt(3) - 1, rel=1e-12)


def test_ellipsoid_distance_upper_sphere():
    rng = np.random.default_rng(5)
    Y = unit(rng, 100) * rng.uniform(0, 3, (100, 1))
    d = ellipsoid_distance_upper(Y, np.array([1.0, 1.0, 1.0]))
    np.testing.assert_allclose(d, np.maximum(np.linalg.norm(Y, axis=1) - 1, 0), atol=1e-14)


def test_ellipsoid_bad_input():
    for radii, f in [((1, 1), 8), ((1, 0, 1), 8), ((1, 1, 1), 2)]:
        with pytest.raises(InvalidInputError):
            ellipsoid_polytope(radii, f)


def test_round_shapes_and_halfspace():
    s = sphere_shape(0.2, [1, 2, 3])
    assert s.kind == "sphere" and s.radius == 0.2 and s.points.tolist() == [[1, 2, 3]]
    c = capsule_shape(0.1, 0.3)
    assert c.kind == "capsule" and c.points.tolist() == [[0, 0, -0.3], [0, 0, 0.3]]
    assert c.edges.tolist() == [[0, 1]]
    h = halfspace_shape()
    assert h.kind == "halfspace" and h.normals.tolist() == [[0, 0, 1]] and h.offsets.tolist() == [0]
    for bad in (lambda: sphere_shape(0), lambda: capsule_shape(-1, 1), lambda: capsule_shape(1, np.nan)):
        with pytest.raises(InvalidInputError):
            bad()


def test_transformed_polytope_keeps_hrep():
    rng = np.random.default_rng(6)
    shape = cylinder_polytope(0.1, 0.3, 8)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    p = rng.normal(size=3)
    moved = shape.transformed(R, p)
    check_valid(moved, scale=3.0, vertex_tol=1e-15)  # transformed() rounds
    X = rng.uniform(-0.5, 0.5, (2000, 3))
    inside = (X @ shape.normals.T - shape.offsets).max(axis=1)
    inside_moved = ((X @ R.T + p) @ moved.normals.T - moved.offsets).max(axis=1)
    np.testing.assert_allclose(inside, inside_moved, atol=1e-14)


def test_merge_chain_fallback_keeps_faces_planar():
    """If merging chains near-coplanar triangles into a non-planar face, the hull falls back to
    one face per triangle (forced here with a huge merge tolerance)."""
    from monitor.geometry.polytope import _COPLANAR_REL, _hull_polytope

    P = unit(np.random.default_rng(8), 300)
    shape = _hull_polytope(P, scale=0.01 / _COPLANAR_REL)  # merge tolerance 1 cm on a unit sphere
    check_valid(shape)
    assert len(shape.faces) == len(ConvexHull(P).simplices)
