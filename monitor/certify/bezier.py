"""Rational Bézier motions in R^12 and their bounding balls (Schröcker & Weber, sections 5 and 7).

A motion is a rational Bézier curve ``c(t) = sum_k B_k(t) w_k P_k / sum_k B_k(t) w_k``
(t in [0, 1], Bernstein basis B_k of degree n) whose control points P_k are affine maps
x -> L_k x + p_k (R^12 = 9 entries of L_k row-major + 3 of p_k) and whose weights w_k
are POSITIVE. It is stored in homogeneous form ``H_k = (w_k, w_k P_k)`` (n+1, 13).

Bounding ball (proof obligation). With positive weights, c(t) is a convex combination of
the P_k (coefficients B_k w_k / sum B_j w_j >= 0, summing to 1), so the curve lies in the
convex hull of the control points, and so does every de Casteljau sub-curve (its control
points are again positive-weight homogeneous points). Hence B_R(g) with ANY centre g and
``R = max_k ||P_k - g||`` (metric of the moving shape, :mod:`monitor.motion.metric`) covers
the (sub-)curve. We use g = c(1/2), a point of the curve (the paper's choice), i.e. the
pose at the sub-interval midpoint. g is affine; for a curve on SE(3) it is rigid up to
rounding, but the checker does not rely on it: it works in the world frame with A's
features mapped by g (rho is evaluated in A's body frame, the metric frames of edges and
faces are the ones mapped by g's linear part; see :mod:`monitor.certify.toleranced`).

Rounding: de Casteljau halving is exact except for additions (error <= u |a + b| / 2 per
step), so after d subdivisions of a degree-n curve the homogeneous control points are off
by at most ~ (d + 1) n u max|H|. We enlarge R by
``sqrt(M) (1 + max|m_i|) sqrt(12) * 16 (d + 1) (n + 1) u max|H| / min w`` (M = total mass),
which bounds the metric norm of that perturbation of the P_k.

Also here: :func:`quaternion_motion` builds the degree-8 rational motion on SE(3) from a
degree-4 quaternion polynomial (rotation = quadratic form / |Q|^2) and degree-8 translation
control points sharing the weights |Q|^2; and :func:`paper72_case` the section 7.2 setting.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

from monitor.certify.common import Budget
from monitor.certify.toleranced import (
    BallProvider,
    FixedFeatures,
    MovingFeatures,
    SubdivisionResult,
    _Frontier,
    _PairData,
    subdivide,
)
from monitor.errors import InvalidInputError
from monitor.motion.metric import Metric, make_metric
from monitor.tolerances import DEFAULT, Tolerances

_U = 2.0**-53


@dataclass(frozen=True)
class RationalBezier:
    """Rational Bézier curve in R^12 with positive weights (homogeneous control points).

    Attributes:
        H: (n+1, 13) homogeneous control points (w_k, w_k * vec(L_k), w_k * p_k).
    """

    H: np.ndarray

    def __post_init__(self) -> None:
        H = np.asarray(self.H, float)
        if H.ndim != 2 or H.shape[1] != 13 or len(H) < 2:
            raise InvalidInputError(f"H must have shape (n+1, 13) with n >= 1, got {H.shape}")
        if not np.isfinite(H).all():
            raise InvalidInputError("Bezier control points must be finite")
        if not (H[:, 0] > 0).all():
            raise InvalidInputError(f"Bezier weights must be positive, got {H[:, 0]}")

    @classmethod
    def from_affine(cls, weights: np.ndarray, L: np.ndarray, p: np.ndarray) -> RationalBezier:
        """From weights (n+1,), linear parts (n+1, 3, 3) and translations (n+1, 3)."""
        w = np.asarray(weights, float)
        X = np.concatenate([np.asarray(L, float).reshape(len(w), 9), np.asarray(p, float)], axis=1)
        return cls(np.concatenate([w[:, None], w[:, None] * X], axis=1))

    @property
    def degree(self) -> int:
        """Polynomial degree n."""
        return len(self.H) - 1

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Affine maps at parameters t (T,): L (T, 3, 3), p (T, 3)."""
        t = np.atleast_1d(np.asarray(t, float))
        n = self.degree
        B = np.stack([comb(n, k) * t**k * (1 - t) ** (n - k) for k in range(n + 1)], axis=1)
        h = B @ self.H
        x = h[:, 1:] / h[:, :1]
        return x[:, :9].reshape(-1, 3, 3), x[:, 9:]

    def affine_points(self) -> np.ndarray:
        """(n+1, 12) control points P_k (dehomogenised)."""
        return self.H[:, 1:] / self.H[:, :1]


def de_casteljau_half(H: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split homogeneous control points (..., n+1, d) at t = 1/2.

    Returns:
        left (..., n+1, d), right (..., n+1, d), and the curve point c(1/2) (..., d).
    """
    H = np.asarray(H, float)
    n = H.shape[-2] - 1
    left = [H[..., 0, :]]
    right = [H[..., n, :]]
    cur = H
    for _ in range(n):
        cur = 0.5 * (cur[..., :-1, :] + cur[..., 1:, :])
        left.append(cur[..., 0, :])
        right.append(cur[..., -1, :])
    return np.stack(left, axis=-2), np.stack(right[::-1], axis=-2), cur[..., 0, :]


class _BezierBalls(BallProvider):
    """Balls of sub-curves: centre c(1/2), radius = max metric distance to control points.

    All items derive from ONE curve, so items with the same (t0, t1) have identical control
    points: de Casteljau and the radius are computed once per node (and per distinct
    metric), which makes a global mass distribution as cheap as per-square ones.
    """

    def __init__(self, metrics: list[Metric], degree: int):
        uniq: dict[int, int] = {}
        ms: list[Metric] = []
        for m in metrics:
            if id(m) not in uniq:
                uniq[id(m)] = len(ms)
                ms.append(m)
        self.midx = np.array([uniq[id(m)] for m in metrics], np.int64)   # per pair
        self.nm = len(ms)
        self.mp_off = np.cumsum([0] + [len(m.points) for m in ms])
        self.mp_all = np.concatenate([m.points for m in ms])
        self.mw_all = np.concatenate([m.weights for m in ms])
        self.mass = np.array([m.mass for m in ms])
        self.mext = np.array([np.abs(m.points).max() for m in ms])
        self.n = degree
        self._halves = None
        self._node_inv = None

    def balls(self, fr: _Frontier):
        keys = np.stack([fr.t0, fr.t1], axis=1)
        _, first, inv = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        inv = inv.reshape(-1)
        H = fr.extra[first]                            # (U, n+1, 13) one per node
        left, right, mid = de_casteljau_half(H)
        self._halves = (left, right)
        self._node_inv = inv
        g = mid[:, 1:] / mid[:, :1]
        P = H[:, :, 1:] / H[:, :, :1]                  # (U, n+1, 12)
        D = P - g[:, None, :]
        DL = D[:, :, :9].reshape(len(H), -1, 3, 3)
        Dp = D[:, :, 9:]
        # radius per (node, metric) combination present in the frontier
        combo = inv * self.nm + self.midx[fr.pair]
        ucombo, cinv = np.unique(combo, return_inverse=True)
        node, met = ucombo // self.nm, ucombo % self.nm
        cnt = self.mp_off[met + 1] - self.mp_off[met]
        row = np.repeat(np.arange(len(ucombo)), cnt)
        start = np.repeat(self.mp_off[met] - np.cumsum(np.concatenate([[0], cnt[:-1]])), cnt)
        j = np.arange(cnt.sum()) + start
        m, w = self.mp_all[j], self.mw_all[j]
        img = np.einsum("nkab,nb->nka", DL[node[row]], m) + Dp[node[row]]   # (rows, n+1, 3)
        sq = w[:, None] * np.einsum("nka,nka->nk", img, img)
        R2 = np.zeros((len(ucombo), self.n + 1))
        np.add.at(R2, row, sq)
        Rc = np.sqrt(R2.max(axis=1))
        # de Casteljau rounding (module doc)
        scale = np.abs(H).max(axis=(1, 2)) / H[:, :, 0].min(axis=1)
        depth = np.zeros(len(H))
        np.maximum.at(depth, inv, fr.depth)
        err = 16.0 * (depth + 1) * (self.n + 1) * _U * scale
        Rc = Rc + np.sqrt(self.mass[met]) * (1.0 + self.mext[met]) * np.sqrt(12.0) * err[node]
        R = Rc[cinv.reshape(-1)]
        return g[inv, :9].reshape(-1, 3, 3), g[inv, 9:], R

    def split(self, fr: _Frontier, keep: np.ndarray):
        """Children's control points (left halves then right halves) of items ``keep``."""
        left, right = self._halves
        k = self._node_inv[keep]
        return np.concatenate([left[k], right[k]])


def check_bezier(curve: RationalBezier, moving: list[MovingFeatures], fixed: list[FixedFeatures],
                 pairs: list[tuple[int, int]] | None = None, *, margin: float = 0.0,
                 epsilon: float = 1e-3, tolerances: Tolerances = DEFAULT,
                 budget: Budget | None = None, prefilter: bool = False) -> SubdivisionResult:
    """Toleranced check of moving feature sets (body frame) under ``curve`` vs fixed sets (world).

    The moving sets are tested as wholes (polygons, segments, points, or every face of a
    polytope); for polytope SOLIDS the caller must also know the start pose is clear
    (boundary tests cannot see containment). Each moving set's own ``metric`` is used
    (pass the same :class:`Metric` to all of them for a global mass distribution).

    Args:
        curve: the motion, parameter t in [0, 1].
        moving: moving feature sets (see :func:`monitor.certify.toleranced.moving_features`).
        fixed: fixed feature sets in the world frame.
        pairs: (i_moving, j_fixed) index pairs; default all combinations.
        margin: clearance (m) that counts as safe.
        epsilon: termination: R * rho_max < epsilon.
        tolerances: pads and max depth.
        budget: optional work limit.
        prefilter: run the cheap separating-plane pre-test first (off by default so that
            the polygon-vs-fat-polygon counts are comparable with the paper's).

    Returns:
        :class:`SubdivisionResult` per pair: intervals (parameter t), ``unit_tests``
        (polygon-vs-fat-polygon tests), ``row_tests``, ``max_depth``.
    """
    if pairs is None:
        pairs = [(i, j) for i in range(len(moving)) for j in range(len(fixed))]
    r = float(margin) + tolerances.pad(float(margin))
    pds = [_PairData(moving[i], fixed[j], r) for i, j in pairs]
    prov = _BezierBalls([pd.A.metric for pd in pds], curve.degree)
    H0 = np.repeat(np.asarray(curve.H, float)[None], len(pds), axis=0)
    return subdivide(pds, prov, 0.0, 1.0, epsilon, tolerances, budget, extra0=H0, prefilter=prefilter)


def first_interval_bezier(curve: RationalBezier, moving: MovingFeatures, fixed: FixedFeatures, *,
                          margin: float = 0.0, epsilon: float = 1e-3,
                          tolerances: Tolerances = DEFAULT) -> tuple[tuple[float, float] | None, int, int]:
    """Depth-first, stop-at-first-interval run (the paper's Listing 1 order), for count comparisons.

    Returns:
        (first interval of possible collision or None, polygon-vs-fat-polygon tests, max depth).
    """
    from monitor.certify.toleranced import first_interval_dfs

    r = float(margin) + tolerances.pad(float(margin))
    pd = _PairData(moving, fixed, r)
    prov = _BezierBalls([moving.metric], curve.degree)
    return first_interval_dfs(pd, prov, 0.0, 1.0, epsilon, tolerances, np.asarray(curve.H, float)[None])


# ---------------------------------------------------------------------------- SE(3) motions


def _bern_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bernstein coefficients of the product of two Bernstein polynomials (last axis = coeffs)."""
    n, m = a.shape[-1] - 1, b.shape[-1] - 1
    out = np.zeros(np.broadcast_shapes(a.shape[:-1], b.shape[:-1]) + (n + m + 1,))
    for i in range(n + 1):
        for j in range(m + 1):
            out[..., i + j] += comb(n, i) * comb(m, j) / comb(n + m, i + j) * a[..., i] * b[..., j]
    return out


def quaternion_motion(quat_ctrl: np.ndarray, trans_ctrl: np.ndarray) -> RationalBezier:
    """Degree-8 rational motion on SE(3) from a degree-4 quaternion polynomial.

    Rotation: Q(t) = sum_k B^4_k(t) Q_k (quaternions (w, x, y, z), not normalised);
    R(t) = M(Q(t)) / |Q(t)|^2 with M the quadratic form of the unit-quaternion rotation
    matrix, so R(t) is exactly a rotation and both numerator and denominator are degree 8.
    Translation: p(t) = sum_k B^8_k w_k T_k / sum_k B^8_k w_k with the same weights
    w_k (Bernstein coefficients of |Q|^2) and the given control points T_k.

    Args:
        quat_ctrl: (5, 4) quaternion Bernstein coefficients.
        trans_ctrl: (9, 3) translation control points (m).

    Returns:
        The degree-8 :class:`RationalBezier` (raises InvalidInputError if a weight
        of |Q|^2 is not positive: move the quaternion control points closer together).
    """
    Q = np.asarray(quat_ctrl, float).T            # (4, 5)
    T = np.asarray(trans_ctrl, float)
    if Q.shape != (4, 5) or T.shape != (9, 3):
        raise InvalidInputError("quat_ctrl must be (5, 4) and trans_ctrl (9, 3)")
    w, x, y, z = Q
    P = _bern_product
    ww, xx, yy, zz = P(w, w), P(x, x), P(y, y), P(z, z)
    xy, xz, yz, wx, wy, wz = P(x, y), P(x, z), P(y, z), P(w, x), P(w, y), P(w, z)
    M = np.array([[ww + xx - yy - zz, 2 * (xy - wz), 2 * (xz + wy)],
                  [2 * (xy + wz), ww - xx + yy - zz, 2 * (yz - wx)],
                  [2 * (xz - wy), 2 * (yz + wx), ww - xx - yy + zz]])    # (3, 3, 9)
    W = ww + xx + yy + zz
    if not (W > 0).all():
        raise InvalidInputError(f"weights |Q|^2 have a non-positive Bernstein coefficient: {W}")
    H = np.concatenate([W[:, None], np.moveaxis(M, -1, 0).reshape(9, 9), W[:, None] * T], axis=1)
    return RationalBezier(H)


def paper71_motion(shift: float = 0.0) -> RationalBezier:
    """The degree-8 motion used for our section 7.1 reproduction (see tests/test_paper_71.py).

    A unit-circumradius octagon sweeps over a fixed one: the quaternion polynomial tilts it
    by up to ~50 degrees about varying axes while its centre follows a degree-8 arc 0.6 m
    above the fixed plane; ``shift`` lowers the whole motion (a constant translation).
    """
    quat = np.array([[1.0, 0.0, 0.0, 0.0], [0.95, 0.25, 0.1, 0.0], [0.85, 0.1, 0.45, 0.15],
                     [0.9, -0.2, 0.3, 0.3], [1.0, -0.3, 0.0, 0.2]])
    s = np.linspace(-1, 1, 9)
    trans = np.stack([2.6 * s, 0.5 * np.sin(np.pi * s), 0.62 + 0.15 * s**2 - shift], axis=1)
    return quaternion_motion(quat, trans)


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


__all__ = ["RationalBezier", "de_casteljau_half", "check_bezier", "first_interval_bezier",
           "quaternion_motion", "paper71_motion", "octagon", "paper72_case", "run_paper72"]
