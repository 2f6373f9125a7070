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

The curves themselves (:class:`RationalBezier`, :class:`RigidBezier`, :func:`quaternion_motion`)
live in :mod:`monitor.motion.bezier` (re-exported here); :class:`monitor.motion.bezier.BezierMotion`
makes them a Trajectory for :func:`monitor.certify`. The paper's section 7 fixtures
(``paper71_motion``, ``octagon``, ``paper72_case``, ``run_paper72``) are in
:mod:`monitor.bench.paper_bezier`. This module only uses the public subdivision interface of
:mod:`monitor.certify.toleranced` (``BallProvider``, ``Frontier``, ``PairData``, ``subdivide``).
"""

from __future__ import annotations

import numpy as np

from monitor.certify.common import Budget
from monitor.certify.toleranced import (
    BallProvider,
    FixedFeatures,
    Frontier,
    MovingFeatures,
    PairData,
    SubdivisionResult,
    subdivide,
)
from monitor.motion.bezier import RationalBezier, RigidBezier, de_casteljau_half, quaternion_motion
from monitor.motion.metric import Metric
from monitor.tolerances import DEFAULT, Tolerances

_U = 2.0**-53


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

    def balls(self, fr: Frontier):
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

    def split(self, fr: Frontier, keep: np.ndarray):
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
    pds = [PairData(moving[i], fixed[j], r) for i, j in pairs]
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
    pd = PairData(moving, fixed, r)
    prov = _BezierBalls([moving.metric], curve.degree)
    return first_interval_dfs(pd, prov, 0.0, 1.0, epsilon, tolerances, np.asarray(curve.H, float)[None])


__all__ = ["RationalBezier", "RigidBezier", "de_casteljau_half", "check_bezier", "first_interval_bezier",
           "quaternion_motion"]
