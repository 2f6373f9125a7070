"""Schröcker & Weber section 7 fixtures: the rational Bézier motions and surfaces of our reproductions.

Moved out of the algorithm package (:mod:`monitor.certify.bezier` keeps only the checker):

* :func:`paper71_motion`: the degree-8 motion of the section 7.1 octagon reproduction
  (tests/test_paper_71.py);
* :func:`octagon`: the octagons of section 7.1;
* :func:`paper72_case` / :func:`run_paper72`: the section 7.2 n x n squares.

Each motion is also available as a public :class:`monitor.motion.bezier.RigidBezier`
(:func:`paper71_rigid`), usable in a :class:`monitor.motion.bezier.BezierMotion`.
"""

from __future__ import annotations

import numpy as np

from monitor.certify.bezier import check_bezier
from monitor.certify.common import Budget
from monitor.errors import InvalidInputError
from monitor.motion.bezier import RationalBezier, RigidBezier, quaternion_motion
from monitor.motion.metric import make_metric

_P71_QUAT = np.array([[1.0, 0.0, 0.0, 0.0], [0.95, 0.25, 0.1, 0.0], [0.85, 0.1, 0.45, 0.15],
                      [0.9, -0.2, 0.3, 0.3], [1.0, -0.3, 0.0, 0.2]])


def paper71_rigid(shift: float = 0.0) -> RigidBezier:
    """:func:`paper71_motion` as a :class:`RigidBezier` (quaternion form, for BezierMotion)."""
    s = np.linspace(-1, 1, 9)
    trans = np.stack([2.6 * s, 0.5 * np.sin(np.pi * s), 0.62 + 0.15 * s**2 - shift], axis=1)
    return RigidBezier(_P71_QUAT, trans)


def paper71_motion(shift: float = 0.0) -> RationalBezier:
    """The degree-8 motion used for our section 7.1 reproduction (see tests/test_paper_71.py).

    A unit-circumradius octagon sweeps over a fixed one: the quaternion polynomial tilts it
    by up to ~50 degrees about varying axes while its centre follows a degree-8 arc 0.6 m
    above the fixed plane; ``shift`` lowers the whole motion (a constant translation).
    """
    return paper71_rigid(shift).curve()


def octagon(radius: float = 1.0, z: float = 0.0, phase: float = np.pi / 8) -> np.ndarray:
    """(8, 3) regular octagon in the plane z, circumradius ``radius``."""
    a = phase + np.arange(8) * np.pi / 4
    return np.stack([radius * np.cos(a), radius * np.sin(a), np.full(8, z)], axis=1)


def paper72_case(n: int, kind: str, mass: str = "global") -> dict:
    """Section 7.2 setting: two unit squares subdivided into n x n sub-squares.

    The fixed surface is the square [0, 1]^2 at z = 0; the moving one starts above it and
    undergoes a degree-8 rational motion whose rotation is the same for every ``kind``;
    the kinds differ by a constant translation: ``"collision"`` (a corner dips through the
    fixed square), ``"near"`` (the corner passes 1 cm above it), ``"clear"`` (10 cm).

    Args:
        n: subdivisions per side (1..10 in the paper).
        kind: "collision" | "near" | "clear".
        mass: "global" (one mass distribution for the moving surface: its grid vertices)
            or "per-square" (each sub-square its own: its 4 vertices + off-plane points).

    Returns:
        dict with ``curve`` (RationalBezier), ``moving`` (list of MovingFeatures, n^2),
        ``fixed`` (list of FixedFeatures, n^2), ``pairs`` (n^4 index pairs) and ``epsilon``
        (1 % of the square diameter, as in section 7.1), ready for :func:`check_bezier`.
    """
    from monitor.certify.toleranced import fixed_features, moving_features

    if kind not in ("collision", "near", "clear"):
        raise InvalidInputError(f"kind must be collision|near|clear, got {kind!r}")
    if mass not in ("global", "per-square"):
        raise InvalidInputError(f"mass must be global|per-square, got {mass!r}")
    g = np.linspace(0.0, 1.0, n + 1)
    squares = []
    for i in range(n):
        for j in range(n):
            squares.append(np.array([[g[i], g[j], 0], [g[i + 1], g[j], 0], [g[i + 1], g[j + 1], 0],
                                     [g[i], g[j + 1], 0]], float))
    gm = make_metric(np.array([[x, y, 0.0] for x in g for y in g])) if mass == "global" else None
    moving = [moving_features(polygon=s, metric=gm) for s in squares]
    fixed = [fixed_features(polygon=s) for s in squares]
    # rotation: tilt about a slowly turning horizontal axis; the moving square's corner
    # (0, 0, 0) in its frame swings down towards the fixed square's far corner region
    quat = np.array([[0.97, 0.17, -0.17, 0.0], [0.98, 0.12, -0.14, 0.05], [0.99, 0.08, -0.1, 0.08],
                     [0.995, 0.05, -0.08, 0.1], [1.0, 0.03, -0.05, 0.12]])
    lift = {"collision": -0.03, "near": 0.01, "clear": 0.10}[kind]
    s = np.linspace(0, 1, 9)
    trans = np.stack([0.15 + 0.5 * s, 0.1 + 0.4 * s, 0.25 * (2 * s - 1) ** 2], axis=1)
    curve0 = quaternion_motion(quat, trans)
    # place the lowest point of the moving surface over time at height `lift`
    ts = np.linspace(0, 1, 401)
    L, p = curve0.evaluate(ts)
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    zmin = (np.einsum("tij,kj->tki", L, corners) + p[:, None, :])[..., 2].min()
    trans[:, 2] += lift - zmin
    curve = quaternion_motion(quat, trans)
    pairs = [(a, b) for a in range(n * n) for b in range(n * n)]
    return {"curve": curve, "moving": moving, "fixed": fixed, "pairs": pairs,
            "epsilon": 0.01 * np.sqrt(2.0)}


def run_paper72(n: int, kind: str, mass: str = "global", *, epsilon: float | None = None,
                budget: Budget | None = None) -> dict:
    """Run one section 7.2 configuration (for the benchmark table).

    Returns:
        dict with ``seconds`` (wall, excluding the setup), ``unit_tests`` (square vs fat
        square), ``row_tests``, ``max_depth``, ``pairs`` (n^4), ``pairs_not_excluded`` and
        ``setup_seconds``.
    """
    import time

    t = time.perf_counter()
    case = paper72_case(n, kind, mass)
    t_setup = time.perf_counter() - t
    eps = case["epsilon"] if epsilon is None else epsilon
    t = time.perf_counter()
    res = check_bezier(case["curve"], case["moving"], case["fixed"], case["pairs"], epsilon=eps,
                       budget=budget)
    secs = time.perf_counter() - t
    return {"n": n, "kind": kind, "mass": mass, "seconds": secs, "setup_seconds": t_setup,
            "unit_tests": int(res.unit_tests.sum()), "row_tests": int(res.row_tests.sum()),
            "max_depth": int(res.max_depth.max()), "pairs": len(case["pairs"]),
            "pairs_not_excluded": int(sum(1 for iv in res.intervals if iv))}


__all__ = ["paper71_motion", "paper71_rigid", "octagon", "paper72_case", "run_paper72"]
