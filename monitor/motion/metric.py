"""Object-oriented metric on R^12 (Schröcker & Weber, section 2) and the metric data of features.

An affine map alpha(x) = A x + t of R^3 is a point of R^12. A *mass distribution*
(feature points ``m_i`` with positive weights ``w_i``, in the moving body's frame)
gives the squared distance

    dist^2(alpha, beta) = sum_i w_i || alpha(m_i) - beta(m_i) ||^2 .

With total mass ``M``, barycentre ``b`` and CENTRED inertia
``J = sum_i w_i (m_i - b)(m_i - b)^T`` (the paper's eq. 3 with b = 0), every affine
``delta`` satisfies, by Cauchy-Schwarz row by row,

    || delta(x) || <= || delta || * rho(x),   rho(x)^2 = 1/M + (x - b)^T J^-1 (x - b)   (eq. 4),

with equality for some delta. So the orbit of a point x under the ball B_R(g) is the
ball of radius R rho(x) about g(x) (fat point), for ANY affine centre g.

Restricted to a line ``x = v0 + s d`` the function is a convex quadratic
``rho^2 = k0 + k1 s + k2 s^2``; the paper's canonical form (eq. 5)
``rho^2(a + s' b) = rho0^2 + s'^2 / nu^2`` (|b| = 1) follows from it. On a plane
``x = o + U w`` (U (3, 2)) it is ``k0 + 2 kg.w + w^T K w``, canonical form eq. 7 by the
principal axes of K. The checkers use the polynomial (non-canonical) form, which
needs no eigen-decomposition per test; :func:`edge_metric_data` and
:func:`face_metric_data` give the paper's data (rho0, nu, a, b) / (rho0, nu1, nu2,
frame) for reporting and tests.

Degenerate distributions (flat plates, segments, points) have a singular J. As in
the paper's section 7.1 (a point over the barycentre of a flat polygon), we add
feature points off the degenerate directions: for every principal direction e_k
whose eigenvalue is below ``_FLAT`` times the largest (or every direction if J = 0),
two points ``b +- h e_k`` with unit weight, ``h = _OFF * scale``. They keep b and make
J positive definite, so no eigenvalue is ever zero. Any positive weights give a valid
metric: the ball radius is always computed with the SAME feature points (see
:meth:`Metric.ball_radius`), so this choice affects speed, never soundness.

Rounding: J^-1 is formed from the eigen-decomposition with cond(J) <= 1/_FLAT = 1e6,
whose relative error is below ~1e6 * 3 * 2^-53 ~ 3e-10. We store ``Jinv`` and ``inv_mass``
inflated by the relative factor ``1 + _KAPPA`` (1e-8), so that the stored rho^2 is an
upper bound of the exact one for the stored b (sound: a larger rho only enlarges orbits).

Metrics are cached per shape object (shapes are immutable, compared by identity).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # layering: metric.py sits below monitor.geometry, so no runtime import
    from monitor.geometry.shapes import ConvexShape

_FLAT = 1e-6
"""Eigenvalues of J below this fraction of the largest count as degenerate."""

_OFF = 0.25
"""Offset of the added off-plane feature points, as a fraction of the shape scale."""

_KAPPA = 1e-8
"""Relative upward inflation of J^-1 and 1/M (covers eigen/inverse rounding, cond <= 1e6)."""


@dataclass(frozen=True, eq=False)
class Metric:
    """Mass distribution of a moving shape and its derived quantities (body frame).

    Attributes:
        points: (n, 3) feature points m_i (m).
        weights: (n,) positive weights w_i.
        mass: total mass M = sum w_i.
        barycentre: (3,) b (m).
        inertia: (3, 3) centred inertia J (m^2 mass units).
        eigvals: (3,) eigenvalues mu_k of J (all > 0), ascending.
        eigvecs: (3, 3) columns are the principal axes.
        inv_mass: 1/M, inflated by 1 + _KAPPA.
        Jinv: (3, 3) J^-1, inflated by 1 + _KAPPA (symmetric).
        added: number of off-plane points added for degenerate distributions.
    """

    points: np.ndarray
    weights: np.ndarray
    mass: float
    barycentre: np.ndarray
    inertia: np.ndarray
    eigvals: np.ndarray
    eigvecs: np.ndarray
    inv_mass: float
    Jinv: np.ndarray
    added: int

    def rho2(self, x: np.ndarray) -> np.ndarray:
        """Squared distortion rate rho(x)^2 (eq. 4) at points x (..., 3), body frame; an upper bound."""
        y = np.asarray(x, float) - self.barycentre
        return self.inv_mass + np.einsum("...i,ij,...j->...", y, self.Jinv, y)

    def rho(self, x: np.ndarray) -> np.ndarray:
        """Distortion rate (eq. 4) at points x (..., 3); returns (...)."""
        return np.sqrt(self.rho2(x))

    def norm(self, L: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Metric norm ||(L, p)|| of affine maps x -> L x + p; L (..., 3, 3), p (..., 3) -> (...)."""
        img = np.einsum("...ij,nj->...ni", L, self.points) + np.asarray(p)[..., None, :]
        return np.sqrt(np.einsum("n,...ni,...ni->...", self.weights, img, img))

    def ball_radius(self, delta: np.ndarray) -> np.ndarray:
        """Ball radius R from per-feature-point displacement bounds.

        Args:
            delta: (..., n) bounds (m) on ||alpha(m_i) - g(m_i)|| for the feature points.

        Returns:
            (...) R = sqrt(sum_i w_i delta_i^2): every alpha with those bounds lies in B_R(g).
            (Not padded here; callers pad.)
        """
        d = np.asarray(delta, float)
        return np.sqrt(np.einsum("n,...n->...", self.weights, d * d))


def make_metric(points: np.ndarray, weights: np.ndarray | None = None, *,
                scale: float | None = None) -> Metric:
    """Metric from feature points (degenerate directions get off-plane points, see module doc).

    Args:
        points: (n, 3) feature points (m), n >= 1, body frame.
        weights: (n,) positive weights; default all 1.
        scale: length (m) for the off-plane offset; default the points' extent
            (or 1e-3 m if the points coincide).

    Returns:
        The :class:`Metric`.
    """
    P = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    w = np.ones(len(P)) if weights is None else np.asarray(weights, dtype=np.float64).reshape(-1)
    if len(w) != len(P) or len(P) == 0 or not (w > 0).all():
        raise ValueError("make_metric needs n >= 1 points with n positive weights")
    ext = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
    s = scale if scale is not None and scale > 0 else (ext if ext > 0 else 1e-3)
    added = 0
    for _ in range(2):
        M = float(w.sum())
        b = (w[:, None] * P).sum(axis=0) / M
        Y = P - b
        J = (w[:, None, None] * Y[:, :, None] * Y[:, None, :]).sum(axis=0)
        J = 0.5 * (J + J.T)
        mu, V = np.linalg.eigh(J)
        top = float(mu[-1])
        bad = mu <= _FLAT * top if top > 0 else np.ones(3, bool)
        if not bad.any():
            break
        extra = []
        for k in np.nonzero(bad)[0]:
            extra += [b + _OFF * s * V[:, k], b - _OFF * s * V[:, k]]
        # unit weight scaled to the existing mean weight keeps the distribution balanced
        wx = float(w.mean())
        P = np.vstack([P, np.array(extra)])
        w = np.concatenate([w, np.full(len(extra), wx)])
        added += len(extra)
    else:  # pragma: no cover - two passes always suffice (added points span the bad directions)
        raise RuntimeError("degenerate mass distribution could not be regularised")
    Jinv = (V / mu) @ V.T
    Jinv = 0.5 * (Jinv + Jinv.T) * (1.0 + _KAPPA)
    return Metric(P, w, M, b, J, mu, V, (1.0 / M) * (1.0 + _KAPPA), Jinv, added)


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def shape_metric(shape: ConvexShape) -> Metric:
    """Cached default metric of a shape: its core vertices with equal weights (+ off-plane points).

    The scale of the off-plane points is the core extent, or the radius for a sphere.
    Half-spaces have no metric (they never move in the checker's frame).
    """
    m = _CACHE.get(shape)
    if m is None:
        if shape.kind == "halfspace":
            raise ValueError("a half-space has no mass distribution")
        ext = float(np.linalg.norm(shape.points.max(axis=0) - shape.points.min(axis=0)))
        scale = ext if ext > 0 else max(float(shape.radius), 1e-3)
        m = make_metric(shape.points, scale=scale)
        _CACHE[shape] = m
    return m


def edge_coefficients(metric: Metric, v0: np.ndarray, d: np.ndarray) -> np.ndarray:
    """rho^2 on x = v0 + s d as k0 + k1 s + k2 s^2.

    Args:
        metric: the metric.
        v0: (..., 3) start points; d: (..., 3) direction vectors (not normalised).

    Returns:
        (..., 3) array (k0, k1, k2) (upper-bounding, see module doc).
    """
    y = np.asarray(v0, float) - metric.barycentre
    d = np.asarray(d, float)
    Jy = y @ metric.Jinv
    k0 = metric.inv_mass + np.einsum("...i,...i->...", Jy, y)
    k1 = 2.0 * np.einsum("...i,...i->...", Jy, d)
    k2 = np.einsum("...i,ij,...j->...", d, metric.Jinv, d)
    return np.stack([k0, k1, k2], axis=-1)


def face_coefficients(metric: Metric, o: np.ndarray, U: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """rho^2 on x = o + U w (w in R^2) as k0 + 2 kg.w + w^T K w.

    Args:
        metric: the metric.
        o: (..., 3) plane origins; U: (..., 3, 2) in-plane basis.

    Returns:
        k0 (...), kg (..., 2), K (..., 2, 2).
    """
    y = np.asarray(o, float) - metric.barycentre
    Jy = y @ metric.Jinv
    k0 = metric.inv_mass + np.einsum("...i,...i->...", Jy, y)
    kg = np.einsum("...i,...ik->...k", Jy, U)
    K = np.einsum("...ik,ij,...jl->...kl", U, metric.Jinv, U)
    return k0, kg, 0.5 * (K + np.swapaxes(K, -1, -2))


def edge_metric_data(metric: Metric, v0: np.ndarray, v1: np.ndarray) -> dict[str, np.ndarray | float]:
    """The paper's metric data of the line through an edge (eq. 5).

    Returns:
        dict with ``rho0`` (min of rho on the line), ``nu`` (rho^2(a + s b) = rho0^2 + s^2/nu^2),
        ``a`` (3,) foot point (rho-minimiser), ``b`` (3,) unit direction, and the edge's
        parameter range ``s`` (2,) of v0, v1 measured from a along b.
    """
    v0 = np.asarray(v0, float)
    d = np.asarray(v1, float) - v0
    L = float(np.linalg.norm(d))
    if L == 0:
        raise ValueError("zero-length edge has no line metric data")
    b = d / L
    k0, k1, k2 = edge_coefficients(metric, v0, b)
    s_min = -k1 / (2 * k2)
    a = v0 + s_min * b
    rho0 = float(np.sqrt(k0 - k1 * k1 / (4 * k2)))
    return {"rho0": rho0, "nu": float(1.0 / np.sqrt(k2)), "a": a, "b": b,
            "s": np.array([-s_min, L - s_min])}


def face_metric_data(metric: Metric, points: np.ndarray) -> dict[str, np.ndarray | float]:
    """The paper's metric data of the plane of a planar polygon (eq. 7).

    Args:
        metric: the metric.
        points: (k, 3) polygon vertices (k >= 3, coplanar).

    Returns:
        dict with ``rho0``, ``nu`` (2,) (nu1, nu2), ``a`` (3,) rho-minimiser in the plane,
        ``frame`` (3, 3) rows b1, b2, n (orthonormal, principal axes of rho^2 in the plane).
    """
    P = np.asarray(points, float)
    o = P.mean(axis=0)
    n = np.cross(P[1] - P[0], P[2] - P[0])
    for i in range(3, len(P)):
        if np.linalg.norm(n) > 0:
            break
        n = np.cross(P[i - 1] - P[0], P[i] - P[0])
    n = n / np.linalg.norm(n)
    u1 = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
    u1 /= np.linalg.norm(u1)
    U = np.stack([u1, np.cross(n, u1)], axis=1)
    k0, kg, K = face_coefficients(metric, o, U)
    w_min = -np.linalg.solve(K, kg)
    a = o + U @ w_min
    lam, E = np.linalg.eigh(K)
    B = U @ E
    rho0 = float(np.sqrt(k0 + kg @ w_min))
    return {"rho0": rho0, "nu": 1.0 / np.sqrt(lam), "a": a,
            "frame": np.stack([B[:, 0], B[:, 1], np.cross(B[:, 0], B[:, 1])])}


__all__ = ["Metric", "make_metric", "shape_metric", "edge_coefficients", "face_coefficients",
           "edge_metric_data", "face_metric_data"]
