"""Compiled min-norm and first-contact kernels of the extrusion checker (issue 12 item 4).

Oracles, independent of the kernels:
* closed forms: a point against a box (clamp in the box frame), a sphere's first contact
  time with a box face (a root of a linear equation);
* dense sampling of ``d(tau)`` with the Lipschitz margin ``|w| h / 2`` (``d`` is
  ``|w|``-Lipschitz: ``d(tau) = dist(-w tau, K)``), distances by the former pure-Python
  min-norm (``min_norm_reference``: its own verified bounds, a different algorithm start);
* convexity of ``d`` (a mathematical fact, not the code): if ``d(t - eta) >= level`` and
  ``d(t) < level`` then nothing before ``t - eta`` is below ``level``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from monitor.certify.extrusion_kernels import first_time_kernel
from monitor.certify.extrusion_null import (
    Leaf,
    min_norm,
    min_norm_reference,
    quadratic_first_time,
    quadratic_first_time_bisection,
)
from monitor.tolerances import DEFAULT

REL, ABS = DEFAULT.rel_pad, DEFAULT.abs_pad


def _leaf(V: np.ndarray, v: np.ndarray) -> Leaf:
    return Leaf("polytope", np.zeros((0, 3)), np.zeros(0), np.asarray(V, float), np.asarray(v, float), 0.0)


def _box(half: np.ndarray, R: np.ndarray, c: np.ndarray) -> np.ndarray:
    s = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    return (s * half) @ R.T + c


def _point_box_distance(p: np.ndarray, half: np.ndarray, R: np.ndarray, c: np.ndarray) -> float:
    """Closed form: distance from p to the box (half extents, rotation R, centre c)."""
    q = R.T @ (p - c)
    return float(np.linalg.norm(np.maximum(np.abs(q) - half, 0.0)))


def _oracle_bounds(A, va, B, vb, t):
    D = ((A + va * t)[:, None, :] - (B + vb * t)[None, :, :]).reshape(-1, 3)
    lo, up, _ = min_norm_reference(D, DEFAULT)
    return lo, up


def _first(A, va, B, vb, t0, t1, level):
    point = np.empty(3)
    tau, solves, steps = first_time_kernel(A, va, B, vb, t0, t1, level, REL, ABS, point)
    return tau, solves, steps, point


def _check_against_oracle(A, va, B, vb, t0, t1, level, n_grid=401):
    """Dense-sampling + convexity oracle for one first-contact query; returns the kernel's tau."""
    tau, solves, _steps, point = _first(A, va, B, vb, t0, t1, level)
    assert t0 <= tau <= t1
    # (1) the returned instant is a contact: even the oracle's lower bound is below level
    lo_t, _ = _oracle_bounds(A, va, B, vb, tau)
    assert lo_t < level, (tau, lo_t, level)
    if tau == t0:
        return tau
    # (2) dense grid on [t0, tau]: no sampled instant before the answer is in contact (the oracle's
    # upper bound), and the Lipschitz margin proves cells clear up to the first open one, which
    # must not lie after the answer (an answer inside a proved-clear stretch would be a false contact)
    L = float(np.linalg.norm(va - vb))
    ts = np.linspace(t0, tau, n_grid)
    h = ts[1] - ts[0]
    ub = np.array([_oracle_bounds(A, va, B, vb, t)[1] for t in ts[:-1]])
    assert np.all(ub >= level), "a sampled instant before the answer is already in contact"
    lbs = np.array([_oracle_bounds(A, va, B, vb, t)[0] for t in ts])
    cell_clear = np.minimum(lbs[:-1], lbs[1:]) - L * h / 2 >= level
    assert not cell_clear.all(), "the Lipschitz oracle proves [t0, tau] clear"
    # (3) convexity: just before the answer the distance is not below level (up to the pad)
    eta = 1e-9 * (t1 - t0)
    if tau - eta > t0:
        _, up_e = _oracle_bounds(A, va, B, vb, tau - eta)
        assert up_e >= level, (tau, up_e, level)
    return tau


# ----------------------------------------------------------------------------- min-norm


def test_min_norm_kernel_brackets_independent_distance_and_matches_reference():
    rng = np.random.default_rng(31)
    for _ in range(400):
        m = int(rng.integers(1, 70))
        scale, shift = rng.choice([1e-3, 1.0, 50.0]), rng.choice([0, 0.5, 3])
        P = rng.normal(size=(m, 3)) * scale + rng.normal(size=3) * shift
        lo, up, lam = min_norm(P, DEFAULT)
        lo_r, up_r, _ = min_norm_reference(P, DEFAULT)
        assert lo <= up and lo_r <= up and lo <= up_r
        assert up - lo < 1e-10 * max(1.0, np.abs(P).max())
        assert np.all(lam >= 0) and lam.sum() == pytest.approx(1.0)
        assert np.linalg.norm(P.T @ lam) <= up
        assert np.linalg.norm(P, axis=1).min() >= lo


def test_min_norm_kernel_closed_form_point_box_and_degenerate_sets():
    rng = np.random.default_rng(32)
    for _ in range(200):
        half = rng.uniform(0.01, 1.0, 3)
        R = Rotation.random(random_state=rng).as_matrix()
        c = rng.normal(size=3) * 2
        p = rng.normal(size=3) * 2
        d = _point_box_distance(p, half, R, c)
        lo, up, _ = min_norm(p - _box(half, R, c), DEFAULT)
        assert lo <= d <= up and up - lo < 1e-11
    # duplicates, collinear, coplanar points; the origin inside and on the hull
    P = np.array([[1.0, 0, 0]] * 5)
    assert min_norm(P, DEFAULT)[0] <= 1.0 <= min_norm(P, DEFAULT)[1]
    seg = np.array([[1.0, -1, 0], [1.0, 1, 0], [1.0, 0, 0], [1.0, 0.5, 0]])
    lo, up, _ = min_norm(seg, DEFAULT)
    assert lo <= 1.0 <= up and up - lo < 1e-11
    sq = np.array([[-1.0, -1, 2], [1, -1, 2], [1, 1, 2], [-1, 1, 2], [0, 0, 2]])
    lo, up, _ = min_norm(sq, DEFAULT)
    assert lo <= 2.0 <= up and up - lo < 1e-11
    cube = _box(np.ones(3), np.eye(3), np.zeros(3))
    lo, up, _ = min_norm(cube, DEFAULT)
    assert lo <= 0.0 <= up < 1e-11
    face = _box(np.ones(3), np.eye(3), np.array([1.0, 0, 0]))  # origin on a face
    lo, up, _ = min_norm(face, DEFAULT)
    assert lo <= 0.0 <= up < 1e-11


# ----------------------------------------------------------------------------- first contact


def test_first_time_sphere_centre_against_box_face_closed_form():
    """A point moving head-on at a face: first time the distance reaches level, closed form."""
    rng = np.random.default_rng(33)
    for _ in range(60):
        half = rng.uniform(0.05, 0.5, 3)
        R = Rotation.random(random_state=rng).as_matrix()
        B = _box(half, R, np.zeros(3))
        level = float(rng.choice([1e-6, 1e-3, 0.05]))
        x0 = float(half[0] + level + rng.uniform(0.1, 2.0))
        start = R @ np.array([x0, rng.uniform(-0.5, 0.5) * half[1], rng.uniform(-0.5, 0.5) * half[2]])
        speed = float(rng.uniform(0.5, 20.0))
        va = -speed * R[:, 0]
        t_exact = (x0 - half[0] - level) / speed
        t1 = (x0 - half[0]) / speed  # face contact: d = 0 < level
        tau, solves, steps, point = _first(start[None, :], va, B, np.zeros(3), 0.0, t1, level)
        assert tau == pytest.approx(t_exact, abs=1e-11 * max(1.0, t1))
        assert tau >= t_exact - 1e-13  # never earlier than the closed form by more than rounding
        assert _point_box_distance(start + va * tau, half, R, np.zeros(3)) < level
        assert steps <= 3 and solves <= 40
        # point: midway between the sphere centre and the face point
        assert np.linalg.norm(point - (start + va * tau)) == pytest.approx(0.5 * level, rel=1e-5, abs=1e-12)


def test_first_time_random_polytopes_against_sampling_oracle():
    rng = np.random.default_rng(34)
    n_done = 0
    while n_done < 30:
        na, nb = int(rng.integers(1, 9)), int(rng.integers(1, 9))
        A = rng.normal(size=(na, 3)) * 0.3
        B = rng.normal(size=(nb, 3)) * 0.3 + np.array([2.0, 0, 0])
        va = np.array([4.0, 0, 0]) + rng.normal(size=3)
        vb = rng.normal(size=3) * 0.3
        level = float(rng.choice([1e-4, 1e-2, 0.2]))
        ts = np.linspace(0.0, 1.0, 101)
        ups = [_oracle_bounds(A, va, B, vb, t)[1] for t in ts]
        k = int(np.argmin(ups))
        if ups[k] >= level or k == 0:
            continue
        tau = _check_against_oracle(A, va, B, vb, 0.0, float(ts[k]), level)
        # the same answer as the former bisection, to its precision
        t_old, _, _ = quadratic_first_time_bisection(_leaf(A, va), _leaf(B, vb), 0.0, 0.0, float(ts[k]),
                                                     level, DEFAULT)
        assert tau == pytest.approx(t_old, abs=1e-12)
        n_done += 1


def test_first_time_grazing_edges_and_large_offsets():
    """Edge-edge (curved d), a graze that dips 1e-9 m below level, and cores 1e4 m from the origin."""
    rng = np.random.default_rng(35)
    for case in range(24):
        R = Rotation.random(random_state=rng).as_matrix()
        A = np.array([[0.0, -1, 0], [0.0, 1, 0]]) @ R.T  # a segment along R y
        B = np.array([[-1.0, 0, 0], [1.0, 0, 0]]) @ R.T  # a segment along R x
        # A (x = -1.5 + 1.5 t, y in [-1.3, 0.7] + 0.3 t, z = gap) passes over B (x in [-1, 1]):
        # d = sqrt((1.5 t - 0.5)^2 + gap^2) until t = 1/3, then gap
        level = 0.01
        graze = case % 3 == 0
        gap = level - (1e-9 if graze else 0.004)
        offset = 1e4 * rng.normal(size=3) if case % 3 == 1 else np.zeros(3)  # pad 2e-9 m there
        va = R @ np.array([1.5, 0.3, 0.0])
        A = A + R @ np.array([-1.5, -0.3, gap]) + offset
        B = B + offset
        t_exact = 1.0 / 3.0 - np.sqrt(level**2 - gap**2) / 1.5
        tau = _check_against_oracle(A, va, B, np.zeros(3), 0.0, 1.0, level, n_grid=201)
        # slope of d at the crossing: 1.5 * sqrt(level^2 - gap^2) / level (6.7e-4 m/s for the graze)
        slope = 1.5 * np.sqrt(level**2 - gap**2) / level
        pad = 16 * REL * np.abs(A).max() * 2 + ABS
        assert t_exact - 1e-12 <= tau <= t_exact + 4 * pad / slope + 1e-12


def test_first_time_start_inside_and_window_offsets():
    A = np.array([[0.0, 0, 0]])
    B = _box(np.full(3, 0.5), np.eye(3), np.array([0.6, 0, 0]))
    # start inside the inflated core: the span start is returned, with one solve
    tau, solves, steps, _ = _first(A, np.array([1.0, 0, 0]), B, np.zeros(3), 0.0, 1.0, 0.2)
    assert tau == 0.0 and steps == 0 and solves == 2
    # the same with a span that does not start at 0 (tau_lo > 0) and moves away then back
    tau, *_ = _first(A, np.array([-1.0, 0, 0]), B, np.array([-2.0, 0, 0]), 0.5, 2.0, 0.05)
    # box face at x = 0.1 - 2 t, point at x = -t: gap 0.1 - t, already -0.4 at tau_lo = 0.5
    assert tau == 0.5
    tau, *_ = _first(A, np.array([1.0, 0, 0]), B, np.zeros(3), 0.02, 0.2, 0.05)
    assert 0.05 <= tau <= 0.05 + 1e-11


def test_quadratic_first_time_wrapper_matches_kernel_and_bisection():
    rng = np.random.default_rng(36)
    a = _leaf(_box(np.array([0.1, 0.2, 0.3]), Rotation.random(random_state=rng).as_matrix(), np.zeros(3)),
              np.array([3.0, 0.1, 0.0]))
    b = _leaf(_box(np.array([0.2, 0.2, 0.2]), Rotation.random(random_state=rng).as_matrix(),
                   np.array([2.0, 0.0, 0.0])), np.zeros(3))
    t_new, p_new, n_new = quadratic_first_time(a, b, 0.01, 0.0, 1.0, 0.01, DEFAULT)
    t_old, p_old, n_old = quadratic_first_time_bisection(a, b, 0.01, 0.0, 1.0, 0.01, DEFAULT)
    assert t_new == pytest.approx(t_old, abs=1e-15)
    assert np.allclose(p_new, p_old, atol=1e-9)
    assert n_new < n_old
