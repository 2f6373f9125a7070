"""Object-oriented metric on R^12: eq. 4 bound, metric data eqs. 5/7, degenerate distributions."""

import numpy as np
import pytest

from monitor.geometry.polytope import box_polytope, capsule_shape, polytope_from_points, sphere_shape
from monitor.motion.metric import (
    edge_coefficients,
    edge_metric_data,
    face_coefficients,
    face_metric_data,
    make_metric,
    shape_metric,
)


def _random_affine(rng, n):
    return rng.normal(size=(n, 3, 3)), rng.normal(size=(n, 3))


def test_rho_bounds_every_affine_displacement_and_is_tight():
    rng = np.random.default_rng(0)
    m = make_metric(rng.normal(size=(7, 3)), rng.uniform(0.5, 2.0, 7))
    D, d = _random_affine(rng, 2000)
    x = rng.normal(size=(50, 3)) * 2
    norms = m.norm(D, d)                                   # (2000,)
    img = np.einsum("nij,kj->nki", D, x) + d[:, None, :]   # (2000, 50, 3)
    ratio = np.linalg.norm(img, axis=2) / norms[:, None]
    assert (ratio <= m.rho(x)[None, :] * (1 + 1e-12)).all()
    # tightness: the Cauchy-Schwarz equality case delta(y) = e (1/M + (x-b)^T J^-1 (y-b))
    for xi in x[:5]:
        c = m.Jinv @ (xi - m.barycentre) / (1 + 1e-8)
        e = np.array([1.0, 0, 0])
        L = np.outer(e, c)
        p = e * (1.0 / m.mass - c @ m.barycentre)
        val = np.linalg.norm(L @ xi + p) / m.norm(L, p)
        assert val == pytest.approx(float(m.rho(xi)), rel=1e-7)


def test_edge_and_face_metric_data_match_rho():
    rng = np.random.default_rng(1)
    m = shape_metric(polytope_from_points(rng.normal(size=(12, 3))))
    v0, v1 = rng.normal(size=3), rng.normal(size=3)
    md = edge_metric_data(m, v0, v1)
    s = rng.uniform(-3, 3, 20)
    x = md["a"] + s[:, None] * md["b"]
    assert np.allclose(m.rho2(x), md["rho0"] ** 2 + s**2 / md["nu"] ** 2, rtol=1e-10)
    k = edge_coefficients(m, v0, v1 - v0)
    t = rng.uniform(0, 1, 20)
    assert np.allclose(m.rho2(v0 + t[:, None] * (v1 - v0)), k[0] + k[1] * t + k[2] * t * t, rtol=1e-10)
    P = np.array([[0, 0, 0], [1, 0, 0.2], [1, 1, 0.4], [0, 1, 0.2]], float) + rng.normal(size=3)
    fd = face_metric_data(m, P)
    F = fd["frame"]
    st = rng.uniform(-2, 2, (20, 2))
    x = fd["a"] + st[:, :1] * F[0] + st[:, 1:] * F[1]
    want = fd["rho0"] ** 2 + st[:, 0] ** 2 / fd["nu"][0] ** 2 + st[:, 1] ** 2 / fd["nu"][1] ** 2
    assert np.allclose(m.rho2(x), want, rtol=1e-9)
    assert np.allclose(F @ F.T, np.eye(3), atol=1e-12)
    o, U = P[0], np.stack([F[0], F[1]], axis=1)
    k0, kg, K = face_coefficients(m, o, U)
    w = rng.normal(size=2)
    assert float(m.rho2(o + U @ w)) == pytest.approx(k0 + 2 * kg @ w + w @ K @ w, rel=1e-10)


@pytest.mark.parametrize("shape", [
    sphere_shape(0.1), capsule_shape(0.05, 0.3),
    polytope_from_points(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])),
])
def test_degenerate_and_regular_shapes_have_positive_definite_inertia(shape):
    m = shape_metric(shape)
    assert (m.eigvals > 0).all()
    assert np.isfinite(m.Jinv).all()
    assert shape_metric(shape) is m  # cached per shape object
    if shape.kind == "sphere":
        assert m.added == 6
    if shape.kind == "capsule":
        assert m.added == 4


def test_flat_polygon_gets_off_plane_points_like_paper_71():
    ang = np.arange(8) * np.pi / 4
    P = np.stack([np.cos(ang), np.sin(ang), np.zeros(8)], axis=1)
    m = make_metric(P)
    assert m.added == 2
    assert abs(m.barycentre[2]) < 1e-15
    off = m.points[8:]
    assert np.allclose(off[:, :2], 0) and np.all(np.abs(off[:, 2]) > 0)
    # in-plane rho is unaffected by the off-plane direction
    assert np.isfinite(m.rho(P)).all()


def test_box_metric_barycentre_and_rho_max_at_vertices():
    b = box_polytope(np.array([0.1, 0.2, 0.3]))
    m = shape_metric(b)
    assert np.allclose(m.barycentre, 0, atol=1e-15)
    rng = np.random.default_rng(2)
    inside = rng.uniform(-1, 1, (500, 3)) * [0.1, 0.2, 0.3]
    assert m.rho(inside).max() <= m.rho(b.points).max() + 1e-15
