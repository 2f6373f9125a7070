"""Exact null-set tests of the extrusion checker (Cameron §4.2), one convex leaf pair per call.

Within one time span both leaves translate with constant velocity. A leaf is
given at the span start in *centred* world coordinates (``x_c = x_W - c`` for a
centre ``c`` near the pair, which removes large offsets such as 1e4 m before
any solver sees the numbers) and ``tau = t - t_span_start``:

* polytope core: ``N @ x <= h + (N @ v) * tau``  (eq. 4 of the paper: the
  extruded half-space ``n.x - (n.v) tau - h <= 0``), vertices ``V + v tau``;
* point / segment core (sphere, capsule): vertices ``V + v tau`` and a radius;
* half-space: one row of the H-rep.

Three exact tests, chosen per pair by the *inflation* ``r = radius_a + radius_b + margin``:

``lp`` (r == 0, polytope against polytope)
    The paper's regularised semantics: the pair collides iff the 4-D
    intersection of the two extrusions has interior. With the slack LP

        max s  s.t.  G_i (x, tau) + s <= h_i  (every half-space of both leaves),
                     (x, tau) in a bounding 4-D box,

    the extrusions share interior iff max s > 0 (s is the radius of the largest
    ball, in metres, inside both at the best instant). The decision is
    *certificate based*, not a trust in the solver:

    * violation iff the primal point re-evaluated in float64 has slack
      ``> 0`` after subtracting a rounding pad (a point strictly inside both
      solids, hence a real overlap of positive 4-D measure);
    * certified iff the LP dual ``y >= 0, sum y = 1`` proves
      ``max s <= Tolerances.extrusion_slack`` (weak duality over the bounded box,
      residuals of ``G^T y`` charged against the box, rounding padded).

    Overlaps of inscribed depth in ``(pad, extrusion_slack]`` may be reported
    either way; outside this band the verdict is exact.

    :func:`dual_certificate` tries every 1- and 2-row dual ``y`` first (the
    certificate of two antiparallel faces or of a face against the box): the same
    weak-duality bound, no solver call.

``lp`` on offset half-spaces (r > 0, the engine's path)
    The caller moves each leaf's rows outward by its radius + margin/2 + delta
    (``Leaf.h`` already offset). A certificate ``max s <= extrusion_slack < delta``
    proves core distance > r; a positive slack proves nothing (the offset
    polytope over-approximates the rounded shape, by up to r(sqrt 3 - 1) at a box
    corner) and the caller falls back to the quadratic test below.

``quadratic`` (r > 0: the exact swept fallback)
    The exact quadratic extrusion ``{(x, tau) : dist(x, core(tau)) <= radius}``.
    For translating convex cores the core distance ``d(tau)`` is the distance
    from the origin to ``K + w tau`` (``K`` = Minkowski difference of the cores at
    tau = 0, ``w`` = relative velocity), so ``min d`` over the span is the distance
    from the origin to the convex hull of the *swept* difference
    ``conv(K + w tau_lo, K + w tau_hi)``: a least-distance problem solved by
    Wolfe's min-norm-point method, compiled
    (:func:`~monitor.certify.extrusion_kernels.min_norm_kernel`). The result is
    verified: the weights give a point of the hull (an upper bound on the
    distance) and its direction a separating plane (a lower bound). Violation iff
    upper < r; certified iff lower >= r - extrusion_slack. ``d`` is convex in tau,
    so the first-contact time (the earliest witness, Cameron §4.2 / §6) is found by
    proved conservative advancement with the linear bound ``min_i (D_i + w tau).n``
    and a short bisection of the rest (:func:`quadratic_first_time`).

``halfspace`` (one side a plane)
    ``d(tau) = min_i n.(p_i + w tau) - o`` is concave piecewise linear: its
    minimum is at a span end and first-contact times are closed forms.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit
from scipy.optimize import linprog, nnls

from monitor._jit_cache import bind_caches, purge_if_changed
from monitor.certify.common import Outcome
from monitor.certify.extrusion_kernels import first_time_kernel, min_norm_kernel
from monitor.certify.extrusion_kernels import warm as _warm_kernels
from monitor.tolerances import Tolerances

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)

_HIGHS_OPTIONS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10,
                  "presolve": True}


@dataclass(frozen=True)
class Leaf:
    """One convex geom during one span, centred world frame, time ``tau`` from the span start.

    Attributes:
        kind: ``"polytope" | "sphere" | "capsule" | "halfspace"``.
        N: (f, 3) outward normals (world); empty for sphere/capsule.
        h: (f,) offsets at tau = 0: the solid is ``N @ x <= h + (N @ v) tau``.
        V: (n, 3) core vertices at tau = 0 (m); for a half-space one point on the plane.
        v: (3,) velocity (m/s).
        radius: core radius (m).
    """

    kind: str
    N: np.ndarray
    h: np.ndarray
    V: np.ndarray
    v: np.ndarray
    radius: float

    @cached_property
    def G(self) -> np.ndarray:
        """(f, 4) rows ``(n, -(n.v))`` of the extruded half-spaces ``G @ (x, tau) <= h``.

        Built once per leaf (a leaf's arrays are never written after construction).
        """
        return np.hstack([self.N, -(self.N @ self.v)[:, None]])


@dataclass
class NullResult:
    """Outcome of one exact null test of a leaf pair on a 4-D box.

    Attributes:
        verdict: an :class:`~monitor.certify.common.Outcome` (``"certified" | "violation" |
            "unresolved"``; unresolved only on an LP solver failure in both HiGHS
            algorithms; never observed).
        lower: certified lower bound (m) of the decision quantity, which is negative
            exactly for a collision: ``-max slack`` for ``lp``; ``min core distance - r``
            for ``quadratic`` / ``halfspace``.
        upper: certified upper bound (m) of the same quantity.
        tau: time (s from span start) of the best point (max slack / min distance).
        point: (3,) centred world point at ``tau`` (inside both / between the cores).
        tests: number of LPs / NNLS solves.
    """

    verdict: Outcome
    lower: float
    upper: float
    tau: float
    point: np.ndarray
    tests: int = 1


def _solve(c, A, b, bounds):
    """HiGHS dual simplex, falling back to interior point; returns the result or None."""
    for method in ("highs-ds", "highs-ipm"):
        res = linprog(c, A_ub=A, b_ub=b, bounds=bounds, method=method, options=_HIGHS_OPTIONS)
        if res.status == 0:
            return res
    return None


@njit(cache=True)
def _solve_small(M, rhs, out):  # pragma: no cover - compiled
    """Gaussian elimination with partial pivoting on a copy of (n, n) ``M``; False if singular."""
    n = M.shape[0]
    A = M.copy()
    x = rhs.copy()
    for col in range(n):
        piv = col
        for r in range(col + 1, n):
            if abs(A[r, col]) > abs(A[piv, col]):
                piv = r
        if abs(A[piv, col]) < 1e-14:
            return False
        if piv != col:
            for k in range(n):
                A[col, k], A[piv, k] = A[piv, k], A[col, k]
            x[col], x[piv] = x[piv], x[col]
        for r in range(col + 1, n):
            f = A[r, col] / A[col, col]
            if f != 0.0:
                for k in range(col, n):
                    A[r, k] -= f * A[col, k]
                x[r] -= f * x[col]
    for r in range(n - 1, -1, -1):
        acc = x[r]
        for k in range(r + 1, n):
            acc -= A[r, k] * out[k]
        out[r] = acc / A[r, r]
    return True


@njit(cache=True)
def _dual_simplex_kernel(G, h, lo, hi, max_iter):  # pragma: no cover - compiled
    """Compiled body of :func:`small_slack_lp`; status 0 = optimal, 1 = failed."""
    m = h.shape[0]
    n = m + 8
    A = np.zeros((5, n))
    c = np.zeros(n)
    for i in range(m):
        for k in range(4):
            A[k, i] = G[i, k]
        A[4, i] = 1.0
        c[i] = h[i]
    for k in range(4):
        A[k, m + k] = 1.0
        A[k, m + 4 + k] = -1.0
        c[m + k] = hi[k]
        c[m + 4 + k] = -lo[k]
    b = np.zeros(5)
    b[4] = 1.0
    best, j = np.inf, 0
    for i in range(m):
        v = h[i]
        for k in range(4):
            v += max(-G[i, k] * lo[k], -G[i, k] * hi[k])
        if v < best:
            best, j = v, i
    basis = np.zeros(5, np.int64)
    basis[0] = j
    for k in range(4):
        basis[k + 1] = m + k if G[j, k] <= 0.0 else m + 4 + k
    scale = np.abs(c).max() + np.abs(A).max()
    tol = 1e-12 * scale
    z = np.zeros(4)
    y = np.zeros(m)
    B = np.zeros((5, 5))
    cB = np.zeros(5)
    xB = np.zeros(5)
    pi = np.zeros(5)
    u = np.zeros(5)
    inb = np.zeros(n, np.bool_)
    for it in range(max_iter):
        inb[:] = False
        for r in range(5):
            B[:, r] = A[:, basis[r]]
            cB[r] = c[basis[r]]
            inb[basis[r]] = True
        if not _solve_small(B, b, xB):
            return 1, z, 0.0, y
        Bt = B.T.copy()
        if not _solve_small(Bt, cB, pi):
            return 1, z, 0.0, y
        e = -1
        dmin = -tol
        for q in range(n):
            if inb[q]:
                continue
            d = c[q]
            for k in range(5):
                d -= A[k, q] * pi[k]
            if d < -tol:
                if it >= 50:  # Bland: first improving column
                    e = q
                    break
                if d < dmin:
                    dmin, e = d, q
        if e < 0:
            for r in range(5):
                if basis[r] < m:
                    y[basis[r]] = max(xB[r], 0.0)
            z[:] = pi[:4]
            return 0, z, pi[4], y
        if not _solve_small(B, A[:, e].copy(), u):
            return 1, z, 0.0, y
        leave = -1
        rmin = np.inf
        for r in range(5):
            if u[r] > 1e-12:
                ratio = max(xB[r], 0.0) / u[r]
                if leave < 0 or ratio < rmin * (1.0 - 1e-15) - 1e-300:
                    rmin, leave = ratio, r
                elif ratio <= rmin * (1.0 + 1e-15) + 1e-300 and basis[r] < basis[leave]:
                    leave = r  # Bland's tie-break
        if leave < 0:
            return 1, z, 0.0, y
        basis[leave] = e
    return 1, z, 0.0, y


def small_slack_lp(G: np.ndarray, h: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                   max_iter: int = 200) -> tuple[np.ndarray, float, np.ndarray] | None:
    """The slack LP ``max s : G z + s <= h, lo <= z <= hi`` by a dense revised simplex on its dual.

    Dual (standard form, 5 equality rows): ``min h.y + hi.p - lo.q`` subject to
    ``G^T y + p - q = 0``, ``1.y = 1``, ``y, p, q >= 0``. The start basis is the best
    single row ``y = e_j`` with ``p - q = -G_j`` (feasible, unit triangular), so no
    phase 1 is needed; Dantzig pricing, Bland's rule after 50 pivots (no cycling).
    The simplex multipliers are the primal ``(z, s)``. Compiled (numba).

    Nothing here is trusted: the caller verifies ``z`` (slack in float64) and ``y``
    (weak-duality bound) exactly as for the HiGHS answer, and falls back to HiGHS
    when neither proves a verdict.

    The kernel compiles (or loads from numba's on-disk cache) on first use; a
    :class:`~monitor.certify.common.Budget` does not count that time, and
    :func:`warm_small_lp` (``python -m monitor warmup``) does it ahead of time.

    Returns:
        ``(z (4,), s, y (m,))`` or None (non-finite box, iteration cap, singular basis).
    """
    if len(h) == 0 or not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        return None
    f64 = np.float64
    status, z, s, y = _dual_simplex_kernel(np.ascontiguousarray(G, f64), np.ascontiguousarray(h, f64),
                                           np.ascontiguousarray(lo, f64), np.ascontiguousarray(hi, f64),
                                           int(max_iter))
    if status != 0 or not (np.all(np.isfinite(z)) and np.isfinite(s) and np.all(np.isfinite(y))):
        return None
    return z, float(s), y


def warm_small_lp() -> None:
    """Compile (or load from the numba cache) the null-set stage's kernels: for ``monitor.warmup``.

    :func:`small_slack_lp`'s simplex and the exact swept stage's min-norm and
    first-contact kernels (:mod:`monitor.certify.extrusion_kernels`), and the engine's
    compiled first pass over translating pairs (:mod:`monitor.certify.extrusion_swept`).
    """
    G = np.array([[1.0, 0, 0, 0], [-1.0, 0, 0, 0], [0, 1.0, 0, 0]])
    _dual_simplex_kernel(G, np.ones(3), -np.ones(4), np.ones(4), 10)
    _warm_kernels()
    from monitor.certify.extrusion_swept import warm as _warm_swept

    _warm_swept()


def slack_lower(G: np.ndarray, h: np.ndarray, z: np.ndarray, tol: Tolerances) -> float:
    """Rigorous lower bound on ``min_i h_i - G_i z`` evaluated in float64 (m)."""
    terms = h - G @ z
    mag = np.abs(h) + np.abs(G) @ np.abs(z)
    return float(np.min(terms - 8 * tol.rel_pad * mag) - tol.abs_pad)


def lp_null_test(a: Leaf, b: Leaf, lo: np.ndarray, hi: np.ndarray, tol: Tolerances,
                 data_pad: float = 0.0) -> NullResult:
    """Slack LP of two extruded polytopes on the box ``lo <= (x, tau) <= hi`` (each (4,)).

    ``data_pad`` (m) bounds the rounding made when the leaves were built from the
    inputs (world placement, centring); it widens both bounds.

    Returns a :class:`NullResult` whose ``lower``/``upper`` bound ``-max_slack``
    (so that, as for distances, negative means overlap).
    """
    G = np.vstack([a.G, b.G])
    h = np.concatenate([a.h, b.h])
    fast = small_slack_lp(G, h, np.asarray(lo, float), np.asarray(hi, float))
    if fast is not None:
        res = _verify_slack(G, h, lo, hi, fast[0], fast[2], tol, data_pad)
        if res.verdict != Outcome.UNRESOLVED:
            return res
    A = np.hstack([G, np.ones((len(h), 1))])
    bounds = [(float(lo[k]), float(hi[k])) for k in range(4)] + [(None, None)]
    sol = _solve(np.array([0, 0, 0, 0, -1.0]), A, h, bounds)
    if sol is None:
        return NullResult(Outcome.UNRESOLVED, -np.inf, np.inf, float(lo[3]), 0.5 * (lo[:3] + hi[:3]))
    return _verify_slack(G, h, lo, hi, sol.x[:4], -sol.ineqlin.marginals, tol, data_pad)


def _verify_slack(G: np.ndarray, h: np.ndarray, lo: np.ndarray, hi: np.ndarray, z: np.ndarray,
                  y: np.ndarray, tol: Tolerances, data_pad: float) -> NullResult:
    """Float64 verification of a slack-LP answer: primal point ``z`` (4,) and dual ``y`` (m,)."""
    z = np.clip(z, lo, hi)
    s_lo = slack_lower(G, h, z, tol) - data_pad
    # dual certificate: s <= y.h - (G^T y).z for every feasible (z, s) when y >= 0, sum y = 1
    y = np.clip(y, 0.0, None)
    ub = np.inf
    if y.sum() > 0:
        y = y / y.sum()
        r = G.T @ y
        ub_raw = float(y @ h + np.sum(np.maximum(-r * lo, -r * hi)))
        zmax = np.maximum(np.abs(lo), np.abs(hi))
        mag = float(y @ (np.abs(h) + np.abs(G) @ zmax))
        ub = ub_raw + 16 * tol.rel_pad * mag + tol.abs_pad + data_pad
    if s_lo > 0.0:
        verdict = Outcome.VIOLATION
    elif ub <= tol.extrusion_slack:
        verdict = Outcome.CERTIFIED
    else:
        verdict = Outcome.UNRESOLVED
    return NullResult(verdict, -ub, -s_lo, float(z[3]), z[:3].copy())


def dual_certificate(a: Leaf, b: Leaf, lo: np.ndarray, hi: np.ndarray, tol: Tolerances,
                     data_pad: float = 0.0) -> float:
    """Best weak-duality bound on the max slack of :func:`lp_null_test` over 1- and 2-row duals.

    Any ``y >= 0`` with ``sum y = 1`` bounds the LP: ``max s <= y.h + sum_k max(-r_k lo_k,
    -r_k hi_k)`` with ``r = G^T y`` (the box absorbs the residual). Trying every single
    row and every pair (one row of each leaf, weights 1/2) finds the certificate of the
    usual separations (two antiparallel faces, a face against the box) without a solver
    call: same bound and padding as :func:`lp_null_test`, so ``<= extrusion_slack``
    certifies exactly as the LP would. Vectorised, O(f_a f_b).

    Returns:
        the smallest padded upper bound (m) on the max slack found (``inf`` if none).
    """
    Ga, Gb = a.G, b.G
    if len(Ga) == 0 or len(Gb) == 0:
        return float("inf")
    zmax = np.maximum(np.abs(lo), np.abs(hi))
    ma = np.abs(a.h) + np.abs(Ga) @ zmax  # (fa,) magnitudes for the rounding pad
    mb = np.abs(b.h) + np.abs(Gb) @ zmax
    R = 0.5 * (Ga[:, None, :] + Gb[None, :, :])  # (fa, fb, 4)
    H = 0.5 * (a.h[:, None] + b.h[None, :])
    ub = H + np.maximum(-R * lo, -R * hi).sum(axis=2) + 8 * tol.rel_pad * (ma[:, None] + mb[None, :])
    single = [h + np.maximum(-G * lo, -G * hi).sum(axis=1) + 16 * tol.rel_pad * m
              for G, h, m in ((Ga, a.h, ma), (Gb, b.h, mb))]
    best = min(float(ub.min()), float(single[0].min()), float(single[1].min()))
    return best + tol.abs_pad + data_pad


def lp_earliest(a: Leaf, b: Leaf, lo: np.ndarray, hi: np.ndarray, depth: float,
                tol: Tolerances) -> tuple[float, np.ndarray] | None:
    """Earliest ``tau`` in the box at which both extrusions contain a ball of radius ``depth``.

    ``depth = 0`` gives the exact first-contact time of the overlap episode (the
    max-slack function is concave in tau, so ``{slack >= 0}`` is one interval and
    its left end is the LP minimum of tau over the 4-D intersection polytope).
    Returns ``(tau, x)`` or None if the LP failed / is infeasible.
    """
    G = np.vstack([a.G, b.G])
    h = np.concatenate([a.h, b.h]) - depth
    bounds = [(float(lo[k]), float(hi[k])) for k in range(4)]
    res = _solve(np.array([0, 0, 0, 1.0]), G, h, bounds)
    if res is None:
        return None
    z = np.clip(res.x, lo, hi)
    return float(z[3]), z[:3].copy()


# ----------------------------------------------------------------------------- quadratic

def _cso(a: Leaf, b: Leaf) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (na*nb, 3) of the core difference A - B at tau = 0 and relative velocity w."""
    D = (a.V[:, None, :] - b.V[None, :, :]).reshape(-1, 3)
    return D, a.v - b.v


def _affine_min_norm(Q: np.ndarray) -> np.ndarray:
    """Barycentric weights (k,) of the min-norm point of the affine hull of Q (k, 3), k <= 4.

    Parametrised from the first point (``x = q0 + D^T beta``) and solved by
    least squares, which keeps the absolute error at ~ulp * |Q| even when the
    point is close to the origin.
    """
    if len(Q) == 1:
        return np.ones(1)
    D = Q[1:] - Q[0]
    beta, *_ = np.linalg.lstsq(D.T, -Q[0], rcond=None)
    return np.concatenate([[1.0 - beta.sum()], beta])


def _nnls_start(P: np.ndarray) -> tuple[list[int], np.ndarray]:
    """Warm start for Wolfe: the support (<= 4 points) of the NNLS least-distance solution.

    Lawson & Hanson (ch. 23): with ``E = [P^T; 1^T]`` and ``f = e_4`` the NNLS
    solution ``u`` gives barycentric weights ``u / sum(u)`` of the closest point
    (accurate to ~1e-8 only near contact, hence the Wolfe polish).
    """
    m = len(P)
    try:
        u, _ = nnls(np.vstack([P.T, np.ones(m)]), np.array([0.0, 0.0, 0.0, 1.0]), maxiter=20 * max(m, 4))
    except RuntimeError:  # pragma: no cover - iteration cap
        u = np.zeros(m)
    S = [int(i) for i in np.argsort(u)[::-1][:4] if u[i] > 0]
    if not S or u.sum() <= 0:
        return [int(np.argmin(np.einsum("ij,ij->i", P, P)))], np.ones(1)
    lam = u[S] / u[S].sum()
    return S, lam


def min_norm_reference(P: np.ndarray, tol: Tolerances) -> tuple[float, float, np.ndarray]:
    """Former (pure Python) :func:`min_norm`, kept as a test oracle for the compiled one.

    Wolfe (1976): keep a corral of at most 4 affinely independent points and
    barycentric weights; add the point most violating ``p . x >= |x|^2`` and
    move to the affine min-norm point of the corral, dropping points whose
    weight would go negative. Finite; the first guess comes from Lawson-Hanson
    NNLS least distance (``scipy.optimize.nnls``). The answer is *verified*,
    not trusted: the weights give a point of the hull (upper bound) and its
    direction a separating plane (lower bound ``min_p p . x / |x|``).

    Args:
        P: (m, 3) points (m).
        tol: tolerances (rounding pads).

    Returns:
        ``(lower, upper, lam)``: ``lower <= dist(0, conv P) <= upper`` (m), weights (m,).
    """
    m = len(P)
    scale = float(np.abs(P).max()) if m else 0.0
    pad = 16 * tol.rel_pad * scale + tol.abs_pad
    S, lam = _nnls_start(P)
    # stop when |x|^2 - min_p p.x is at rounding level: x carries ~ulp*scale absolute
    # error, which moves p.x by ~ulp*scale^2 (the verified bounds below do not rely on this)
    eps = 16 * 2.0**-52 * scale
    for _ in range(100):
        x = P[S].T @ lam
        nx = float(np.linalg.norm(x))
        j = int(np.argmin(P @ x))
        if nx <= eps or x @ x - P[j] @ x <= eps * (nx + scale) or j in S:
            break
        S.append(j)
        lam = np.append(lam, 0.0)
        for _minor in range(8):
            alpha = _affine_min_norm(P[S])
            if np.all(alpha > 1e-14):
                lam = alpha
                break
            neg = alpha <= 1e-14
            with np.errstate(divide="ignore", invalid="ignore"):
                ratios = np.where(neg, lam / (lam - alpha), np.inf)
            theta = float(np.clip(np.min(ratios), 0.0, 1.0))
            lam = lam + theta * (alpha - lam)
            keep = lam > 1e-14
            if not keep.any():
                keep[int(np.argmax(lam))] = True
            S = [s for s, k in zip(S, keep) if k]
            lam = lam[keep] / lam[keep].sum()
        if len(S) > 4:  # numerical safety: keep the 4 heaviest
            order = np.argsort(lam)[::-1][:4]
            S = [S[i] for i in order]
            lam = lam[order] / lam[order].sum()
    full = np.zeros(m)
    full[S] = lam
    q = P.T @ full
    nq = float(np.linalg.norm(q))
    upper = nq + pad
    lower = -pad
    if nq > pad:
        # any unit direction gives a valid lower bound min_p p.n; besides q/|q| try the
        # normal of the final corral computed from its edges (no cancellation through q)
        dirs = [q / nq]
        Q = P[S]
        if len(S) >= 3:  # a (coplanar) face of the hull: its normal from the best triangle
            tris = [np.cross(Q[j] - Q[i], Q[k] - Q[i]) for i in range(len(S))
                    for j in range(i + 1, len(S)) for k in range(j + 1, len(S))]
            dirs.append(max(tris, key=lambda c: float(c @ c)))
        elif len(S) == 2:
            e = Q[1] - Q[0]
            dirs.append(np.cross(e, np.cross(Q[0], e)))
        for d in dirs:
            nd = float(np.linalg.norm(d))
            if nd > 0 and np.isfinite(nd):
                d = d / nd * np.sign(d @ q)
                lower = max(lower, float(np.min(P @ d)) - pad)
    return max(lower, -pad), upper, full


def min_norm(P: np.ndarray, tol: Tolerances) -> tuple[float, float, np.ndarray]:
    """Distance from the origin to ``conv(P)`` with rigorous bounds (compiled Wolfe, verified).

    The compiled :func:`~monitor.certify.extrusion_kernels.min_norm_kernel`: Wolfe's
    min-norm-point method, then a verified upper bound (a hull point) and lower bound
    (``min_p p . n`` over a few unit directions), each with the pad
    ``16 rel_pad max|P| + abs_pad``, exactly as :func:`min_norm_reference` (the former
    Python implementation, kept as a test oracle).

    Args:
        P: (m, 3) points (m), m >= 1.
        tol: tolerances (rounding pads).

    Returns:
        ``(lower, upper, lam)``: ``lower <= dist(0, conv P) <= upper`` (m), weights (m,).
    """
    P = np.ascontiguousarray(P, dtype=np.float64)
    lam = np.empty(len(P))
    lower, upper = min_norm_kernel(P, float(tol.rel_pad), float(tol.abs_pad), lam, np.empty(3))
    return float(lower), float(upper), lam


def static_distance(a: Leaf, b: Leaf, tau: float, tol: Tolerances) -> tuple[float, float, np.ndarray]:
    """Bounds ``(lower, upper)`` on the core distance at ``tau`` and a midpoint (3,) between the cores."""
    A = a.V + a.v * tau
    B = b.V + b.v * tau
    D = (A[:, None, :] - B[None, :, :]).reshape(-1, 3)
    lo, up, lam = min_norm(D, tol)
    L = lam.reshape(len(A), len(B))
    pa = L.sum(axis=1) @ A
    pb = L.sum(axis=0) @ B
    return lo, up, 0.5 * (pa + pb)


def quadratic_null_test(a: Leaf, b: Leaf, r: float, tau_lo: float, tau_hi: float,
                        tol: Tolerances, data_pad: float = 0.0) -> NullResult:
    """Exact test of ``min_{tau in [tau_lo, tau_hi]} dist(core_a, core_b) < r`` (``r > 0``).

    ``lower``/``upper`` bound ``min distance - r`` (m).
    """
    D, w = _cso(a, b)
    P = np.vstack([D + w * tau_lo, D + w * tau_hi])
    lo, up, lam = min_norm(P, tol)
    lo, up = lo - data_pad, up + data_pad
    tau = float(np.clip(tau_lo + (tau_hi - tau_lo) * lam[len(D):].sum(), tau_lo, tau_hi))
    _, _, point = static_distance(a, b, tau, tol)
    if up < r:
        verdict = Outcome.VIOLATION
    elif lo >= r - tol.extrusion_slack:
        verdict = Outcome.CERTIFIED
    else:  # pragma: no cover - needs NNLS error beyond extrusion_slack
        verdict = Outcome.UNRESOLVED
    return NullResult(verdict, lo - r, up - r, tau, point)


def quadratic_first_time(a: Leaf, b: Leaf, r: float, tau_lo: float, tau_hi: float, level: float,
                         tol: Tolerances) -> tuple[float, np.ndarray, int]:
    """Earliest ``tau`` in ``[tau_lo, tau_hi]`` with core distance ``< level`` (Cameron §4.2, §6 witness).

    Compiled (:func:`~monitor.certify.extrusion_kernels.first_time_kernel`): conservative
    advancement from ``tau_lo`` with the linear lower bound ``min_i (D_i + w tau) . n``
    (Newton's method on the convex core distance from the left: it never passes the
    first contact, and every step is proved in float64 with a pad), then the former
    bisection rule on the remaining bracket of about ``pad / |w|`` seconds.

    Precondition: the distance at ``tau_hi`` is below ``level`` (upper bound).

    Contract (unchanged): the returned ``tau`` has a proved upper bound ``< level`` (or is
    ``tau_lo`` when the distance there is already proved below ``level``), and the
    interval ``{d < level}`` does not reach left of ``tau - 2^-52 max(|tau_lo|, |tau_hi|,
    tau_hi - tau_lo)`` except within the rounding pad; on ``[tau_lo, lo]`` of the
    advancement phase it is excluded by proof.

    Args:
        a, b: the leaves (cores ``V + v tau``); ``r`` is unused (kept for the callers).
        tau_lo, tau_hi: the interval (s from span start).
        level: the distance threshold (m).
        tol: tolerances (rounding pads).

    Returns:
        ``(tau, point, solves)``: tau (s from span start), a point (3,) between the cores
        at tau, and the number of min-norm solves.
    """
    point = np.empty(3)
    f64 = np.float64
    tau, solves, _steps = first_time_kernel(
        np.ascontiguousarray(a.V, f64), np.ascontiguousarray(a.v, f64),
        np.ascontiguousarray(b.V, f64), np.ascontiguousarray(b.v, f64),
        float(tau_lo), float(tau_hi), float(level), float(tol.rel_pad), float(tol.abs_pad), point)
    return float(tau), point, int(solves)


def quadratic_first_time_bisection(a: Leaf, b: Leaf, r: float, tau_lo: float, tau_hi: float, level: float,
                                   tol: Tolerances) -> tuple[float, np.ndarray, int]:
    """The former :func:`quadratic_first_time` (bisection to ``2^-52`` of the span): a test oracle.

    Bisection keeps ``d(hi) < level`` proved by an upper bound, and stops after the
    interval is below ``2^-52`` of the span (about 60 static solves).
    """
    lo_, up_, point = static_distance(a, b, tau_lo, tol)
    if up_ < level:
        return tau_lo, point, 1
    lo, hi = tau_lo, tau_hi
    n = 1
    while hi - lo > 2.0**-52 * max(abs(tau_hi), abs(tau_lo), tau_hi - tau_lo) and n < 200:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        _, up_, _ = static_distance(a, b, mid, tol)
        n += 1
        if up_ < level:
            hi = mid
        else:
            lo = mid
    _, _, point = static_distance(a, b, hi, tol)
    return hi, point, n + 1


# ----------------------------------------------------------------------------- half-space

def halfspace_null_test(plane: Leaf, other: Leaf, r: float, tau_lo: float, tau_hi: float,
                        tol: Tolerances, data_pad: float = 0.0) -> tuple[NullResult, float | None]:
    """Closed-form test of a core against a (possibly translating) half-space.

    The signed distance of the core to the plane ``{n.x <= o + (n.v_p) tau}`` is
    ``d(tau) = min_i n.(p_i + w tau) - o`` with ``w = v_core - v_plane``: concave
    and piecewise linear, so its minimum over the span is at an end, and the
    first time with ``d < r`` is the smallest per-vertex crossing time.

    Returns:
        ``(result, first_tau)``: ``lower``/``upper`` bound ``min d - r``; first_tau is
        the exact first-contact time (s from span start) or None when certified.
    """
    n = plane.N[0]
    o = float(plane.h[0])
    w = other.v - plane.v
    nw = float(n @ w)
    d0 = other.V @ n - o
    ends = np.stack([d0 + nw * tau_lo, d0 + nw * tau_hi])  # (2, nv)
    mag = np.abs(other.V) @ np.abs(n) + abs(o) + abs(nw) * max(abs(tau_lo), abs(tau_hi))
    pad = float(8 * tol.rel_pad * mag.max() + tol.abs_pad) + data_pad
    k = np.unravel_index(int(np.argmin(ends)), ends.shape)
    dmin = float(ends[k])
    tau = tau_lo if k[0] == 0 else tau_hi
    point = other.V[k[1]] + other.v * tau - 0.5 * dmin * n
    if dmin + pad < r:
        verdict = Outcome.VIOLATION
    elif dmin - pad >= r - tol.extrusion_slack:
        verdict = Outcome.CERTIFIED
    else:  # pragma: no cover - pad is far below extrusion_slack
        verdict = Outcome.UNRESOLVED
    res = NullResult(verdict, dmin - pad - r, dmin + pad - r, tau, point)
    if verdict != Outcome.VIOLATION:
        return res, None
    cross = (r - d0) / nw if nw < 0 else np.full(len(d0), np.inf)
    first = np.where(d0 + nw * tau_lo < r, tau_lo, np.clip(cross, tau_lo, tau_hi))
    return res, float(first.min())


__all__ = ["Leaf", "NullResult", "slack_lower", "small_slack_lp", "warm_small_lp", "lp_null_test",
           "dual_certificate", "lp_earliest", "min_norm", "min_norm_reference", "static_distance",
           "quadratic_null_test", "quadratic_first_time", "quadratic_first_time_bisection",
           "halfspace_null_test"]


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
