"""Compiled kernels of the extrusion checker's exact swept stage: min-norm point and first contact.

Two nopython numba kernels (``cache=True``) used by :mod:`monitor.certify.extrusion_null`:

:func:`min_norm_kernel`
    Distance from the origin to ``conv(P)`` for ``P`` (m, 3) by Wolfe's min-norm-point
    method (Wolfe 1976), with rigorous float64 bounds. The corral's affine min-norm point
    is a 3 x k Householder least-squares solve (no LAPACK). The answer is *verified*, not
    trusted: the weights give a point of the hull (upper bound) and one of a few unit
    directions a separating plane (lower bound ``min_p p . n``), both padded.

:func:`first_time_kernel`
    Earliest ``tau`` of a span at which two translating convex cores come closer than
    ``level`` (the earliest witness of Cameron 1990, §4.2 / §6: the first instant of the
    swept overlap, here of the cores inflated by ``level``). By conservative advancement
    from the span start, then a short bisection of the remaining bracket. The argument is
    in the kernel's docstring.

Both kernels compile on first use (or load from numba's on-disk cache); a
:class:`~monitor.certify.common.Budget` does not count that time, and
:func:`monitor.certify.extrusion_null.warm_small_lp` (called by ``python -m monitor
warmup``) compiles them ahead of time.

Pads (same conventions as the Python code they replace): a quantity computed from
coordinates of magnitude ``scale`` carries ``16 * rel_pad * scale + abs_pad`` (``rel_pad``
is 64 ulp, so this is about 1000 ulp of the operands: a dot product of three terms and
the point differences need fewer than 10).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from monitor._jit_cache import bind_caches, purge_if_changed

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)

_ULP = 2.0**-52


@njit(cache=True)
def _affine_weights(Q, k, alpha):
    """Barycentric weights ``alpha[:k]`` of the min-norm point of the affine hull of ``Q[:k]`` (k <= 5).

    ``x = q0 + sum_i beta_i (q_i - q0)``, ``beta`` by a Householder QR least-squares solve
    of the 3 x (k-1) system (absolute error ~ulp * |Q| even near the origin). Columns that
    are numerically dependent get ``beta = 0`` (an affine point of the hull, not the
    minimum; Wolfe's minor cycle and the verified bounds tolerate that).
    """
    if k == 1:
        alpha[0] = 1.0
        return
    n = k - 1
    M = np.empty((3, 4))
    b = np.empty(3)
    for r in range(3):
        b[r] = -Q[0, r]
        for c in range(n):
            M[r, c] = Q[c + 1, r] - Q[0, r]
    colnorm = 0.0
    for c in range(n):
        s = 0.0
        for r in range(3):
            s += M[r, c] * M[r, c]
        colnorm = max(colnorm, np.sqrt(s))
    ncol = min(n, 3)
    for j in range(ncol):
        s = 0.0
        for r in range(j, 3):
            s += M[r, j] * M[r, j]
        s = np.sqrt(s)
        if s == 0.0:
            continue
        a0 = -s if M[j, j] >= 0.0 else s
        v = np.zeros(3)
        for r in range(j, 3):
            v[r] = M[r, j]
        v[j] -= a0
        vn2 = 0.0
        for r in range(j, 3):
            vn2 += v[r] * v[r]
        if vn2 == 0.0:
            continue
        for c in range(j, n):
            dot = 0.0
            for r in range(j, 3):
                dot += v[r] * M[r, c]
            f = 2.0 * dot / vn2
            for r in range(j, 3):
                M[r, c] -= f * v[r]
        dot = 0.0
        for r in range(j, 3):
            dot += v[r] * b[r]
        f = 2.0 * dot / vn2
        for r in range(j, 3):
            b[r] -= f * v[r]
    beta = np.zeros(4)
    tiny = 1e-13 * colnorm
    for j in range(ncol - 1, -1, -1):
        if abs(M[j, j]) <= tiny:
            beta[j] = 0.0
            continue
        s = b[j]
        for c in range(j + 1, ncol):
            s -= M[j, c] * beta[c]
        beta[j] = s / M[j, j]
    total = 0.0
    for c in range(n):
        alpha[c + 1] = beta[c]
        total += beta[c]
    alpha[0] = 1.0 - total


@njit(cache=True)
def _wolfe(P, S, lam):
    """Wolfe's min-norm-point iterations on ``P`` (m, 3); corral ``S[:k]``, weights ``lam[:k]``.

    Starts from the vertex nearest the origin; returns ``k``. Finite in exact arithmetic;
    capped at 100 major cycles (the caller's bounds are verified, not trusted).
    """
    m = P.shape[0]
    scale = 0.0
    best = np.inf
    j0 = 0
    for i in range(m):
        s = 0.0
        for c in range(3):
            scale = max(scale, abs(P[i, c]))
            s += P[i, c] * P[i, c]
        if s < best:
            best, j0 = s, i
    S[0] = j0
    lam[0] = 1.0
    k = 1
    eps = 16 * _ULP * scale
    Q = np.empty((5, 3))
    alpha = np.empty(5)
    x = np.empty(3)
    for _major in range(100):
        for c in range(3):
            x[c] = 0.0
            for i in range(k):
                x[c] += lam[i] * P[S[i], c]
        nx = np.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        j = 0
        pj = np.inf
        for i in range(m):
            d = P[i, 0] * x[0] + P[i, 1] * x[1] + P[i, 2] * x[2]
            if d < pj:
                pj, j = d, i
        if nx <= eps or (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - pj <= eps * (nx + scale):
            break
        present = False
        for i in range(k):
            if S[i] == j:
                present = True
        if present:
            break
        S[k] = j
        lam[k] = 0.0
        k += 1
        for _minor in range(8):
            for i in range(k):
                for c in range(3):
                    Q[i, c] = P[S[i], c]
            _affine_weights(Q, k, alpha)
            allpos = True
            for i in range(k):
                if not alpha[i] > 1e-14:
                    allpos = False
            if allpos:
                for i in range(k):
                    lam[i] = alpha[i]
                break
            theta = np.inf
            for i in range(k):
                if alpha[i] <= 1e-14:
                    den = lam[i] - alpha[i]
                    if den > 0.0:
                        theta = min(theta, lam[i] / den)
            theta = min(max(theta, 0.0), 1.0)
            for i in range(k):
                lam[i] = lam[i] + theta * (alpha[i] - lam[i])
            imax = 0
            for i in range(k):
                if lam[i] > lam[imax]:
                    imax = i
            nkeep = 0
            for i in range(k):
                if lam[i] > 1e-14:
                    nkeep += 1
            kk = 0
            total = 0.0
            for i in range(k):
                if lam[i] > 1e-14 or (nkeep == 0 and i == imax):
                    S[kk] = S[i]
                    lam[kk] = lam[i] if nkeep > 0 else 1.0
                    total += lam[kk]
                    kk += 1
            k = kk
            for i in range(k):
                lam[i] /= total
        if k > 4:  # numerical safety: keep the 4 heaviest
            for _drop in range(k - 4):
                imin = 0
                for i in range(k):
                    if lam[i] < lam[imin]:
                        imin = i
                for i in range(imin, k - 1):
                    S[i] = S[i + 1]
                    lam[i] = lam[i + 1]
                k -= 1
            total = 0.0
            for i in range(k):
                total += lam[i]
            for i in range(k):
                lam[i] /= total
    return k


@njit(cache=True)
def _dir_lower(P, d0, d1, d2, q, pad):
    """``min_p p . n - pad`` for ``n`` = (d0, d1, d2) normalised, oriented along ``q`` (-inf if unusable)."""
    nd = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    if not (nd > 0.0 and np.isfinite(nd)):
        return -np.inf, 0.0, 0.0, 0.0
    sg = d0 * q[0] + d1 * q[1] + d2 * q[2]
    if sg == 0.0:
        return -np.inf, 0.0, 0.0, 0.0
    f = (1.0 if sg > 0.0 else -1.0) / nd
    n0, n1, n2 = d0 * f, d1 * f, d2 * f
    mn = np.inf
    for i in range(P.shape[0]):
        mn = min(mn, P[i, 0] * n0 + P[i, 1] * n1 + P[i, 2] * n2)
    return mn - pad, n0, n1, n2


@njit(cache=True)
def min_norm_kernel(P, rel_pad, abs_pad, lam_out, n_out):
    """Rigorous bounds on ``dist(0, conv P)`` for ``P`` (m, 3), m >= 1 (Wolfe's method, verified).

    Args:
        P: (m, 3) points (m).
        rel_pad, abs_pad: :class:`~monitor.tolerances.Tolerances` pads.
        lam_out: (m,) output, barycentric weights of the upper-bound point (>= 0, sum 1).
        n_out: (3,) output, the unit direction of the best lower bound (zeros when the
            lower bound is the trivial ``-pad``).

    Returns:
        ``(lower, upper)`` with ``lower <= dist(0, conv P) <= upper`` (m). ``upper`` is the
        norm of the hull point ``P^T lam`` plus the pad; ``lower`` is ``max(-pad, max_n
        min_p p . n - pad)`` over the candidate unit directions ``n``: ``q / |q|``, the
        normal of the final corral's best triangle (3-4 points) or of its edge towards the
        origin (2 points). Any unit ``n`` bounds the distance below: ``dist >= min_p p . n``.
    """
    m = P.shape[0]
    scale = 0.0
    for i in range(m):
        for c in range(3):
            scale = max(scale, abs(P[i, c]))
    pad = 16 * rel_pad * scale + abs_pad
    S = np.zeros(5, np.int64)
    lam = np.zeros(5)
    k = _wolfe(P, S, lam)
    for i in range(m):
        lam_out[i] = 0.0
    for i in range(k):
        lam_out[S[i]] += lam[i]
    q = np.zeros(3)
    for i in range(k):
        for c in range(3):
            q[c] += lam[i] * P[S[i], c]
    nq = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
    upper = nq + pad
    lower = -pad
    n_out[0] = 0.0
    n_out[1] = 0.0
    n_out[2] = 0.0
    if nq > pad:
        lb, n0, n1, n2 = _dir_lower(P, q[0], q[1], q[2], q, pad)
        if lb > lower:
            lower = lb
            n_out[0], n_out[1], n_out[2] = n0, n1, n2
        if k >= 3:  # a (coplanar) face of the hull: the normal of the corral's best triangle
            b0 = b1 = b2 = 0.0
            bn2 = -1.0
            for i in range(k):
                for j in range(i + 1, k):
                    for kk in range(j + 1, k):
                        si, sj, sk = S[i], S[j], S[kk]
                        x0, x1, x2 = P[sj, 0] - P[si, 0], P[sj, 1] - P[si, 1], P[sj, 2] - P[si, 2]
                        y0, y1, y2 = P[sk, 0] - P[si, 0], P[sk, 1] - P[si, 1], P[sk, 2] - P[si, 2]
                        c0 = x1 * y2 - x2 * y1
                        c1 = x2 * y0 - x0 * y2
                        c2 = x0 * y1 - x1 * y0
                        n2 = c0 * c0 + c1 * c1 + c2 * c2
                        if n2 > bn2:
                            bn2 = n2
                            b0, b1, b2 = c0, c1, c2
            lb, n0, n1, n2 = _dir_lower(P, b0, b1, b2, q, pad)
            if lb > lower:
                lower = lb
                n_out[0], n_out[1], n_out[2] = n0, n1, n2
        elif k == 2:  # an edge: the component of its first point normal to it
            s0, s1 = S[0], S[1]
            a0, a1, a2 = P[s0, 0], P[s0, 1], P[s0, 2]
            e0, e1, e2 = P[s1, 0] - a0, P[s1, 1] - a1, P[s1, 2] - a2
            # e x (a x e)
            t0 = a1 * e2 - a2 * e1
            t1 = a2 * e0 - a0 * e2
            t2 = a0 * e1 - a1 * e0
            c0 = e1 * t2 - e2 * t1
            c1 = e2 * t0 - e0 * t2
            c2 = e0 * t1 - e1 * t0
            lb, n0, n1, n2 = _dir_lower(P, c0, c1, c2, q, pad)
            if lb > lower:
                lower = lb
                n_out[0], n_out[1], n_out[2] = n0, n1, n2
    return max(lower, -pad), upper


@njit(cache=True)
def _fill(A, va, B, vb, tau, P):
    """``P[i * nb + k] = (A_i + va tau) - (B_k + vb tau)`` (the core difference at ``tau``)."""
    nb = B.shape[0]
    for i in range(A.shape[0]):
        for k in range(nb):
            for c in range(3):
                P[i * nb + k, c] = (A[i, c] + va[c] * tau) - (B[k, c] + vb[c] * tau)


@njit(cache=True)
def _plane_lower(A, va, B, vb, tau, n, level, rel_pad, abs_pad):
    """Rigorous lower bound of ``min_{i,k} ((A_i + va tau) - (B_k + vb tau)) . n - level``, and the magnitude.

    The exact value (real arithmetic, ``n`` the float64 vector as given, ``|n| <= 1 + 1e-15``)
    is at least the float64 one minus the pad; the pad covers the point arithmetic, the
    dot product and the non-unit norm of ``n`` (relative to ``|level|``).

    Returns:
        ``(bound, mag)``; the pad is ``16 rel_pad mag + abs_pad``.
    """
    mag = 0.0
    ma = 0.0
    for i in range(A.shape[0]):
        ma = max(ma, abs(A[i, 0]) + abs(A[i, 1]) + abs(A[i, 2]))
    mb = 0.0
    for k in range(B.shape[0]):
        mb = max(mb, abs(B[k, 0]) + abs(B[k, 1]) + abs(B[k, 2]))
    at = abs(tau)
    mag = ma + mb + (abs(va[0]) + abs(va[1]) + abs(va[2]) + abs(vb[0]) + abs(vb[1]) + abs(vb[2])) * at
    mag += abs(level)
    pad = 16 * rel_pad * mag + abs_pad
    mn = np.inf
    for i in range(A.shape[0]):
        for k in range(B.shape[0]):
            s = 0.0
            for c in range(3):
                s += ((A[i, c] + va[c] * tau) - (B[k, c] + vb[c] * tau)) * n[c]
            mn = min(mn, s)
    return mn - pad - level, mag


@njit(cache=True)
def first_time_kernel(A, va, B, vb, tau_lo, tau_hi, level, rel_pad, abs_pad, point_out):
    """Earliest ``tau`` in ``[tau_lo, tau_hi]`` with core distance ``< level``; conservative advancement.

    The cores are ``conv(A_i + va tau)`` and ``conv(B_k + vb tau)`` (A (na, 3), B (nb, 3),
    centred world frame, tau in s from the span start). Their distance ``d(tau)`` is the
    distance from the origin to ``K + w tau`` (``K`` the core difference, ``w = va - vb``):
    convex in tau, so ``{d < level}`` is one interval (the earliest witness of Cameron
    §4.2 / §6: the first instant of the swept overlap of the cores inflated by ``level``).

    Precondition (the caller's): ``d(tau_hi) < level`` (proved by an upper bound).

    **Advancement (proved).** For any unit ``n``, ``d(tau) >= min_i (D_i + w tau) . n``,
    which is *linear* in tau over the whole span (every difference point moves with the
    same ``w``). From ``lo`` (where this bound is ``>= level``, with ``n`` the min-norm
    direction at ``lo``), the step to where the line reaches ``level`` skips no instant
    with ``d < level``; the bound is re-evaluated in float64 with a pad at the new ``lo``
    (:func:`_plane_lower`) before it is accepted (a line >= level at both ends is >= level
    between them), and halved up to 4 times if rounding fails it. With ``n = q/|q|`` this
    is Newton's method on the convex ``d(tau) - level`` from the left (conservative
    advancement, Mirtich / Cameron's §6 earliest witness): monotone, never past the root,
    quadratic near a root where ``d`` is smooth. It stops when the proved gap is gone
    (``lower bound <= level``), the step is below ``2^-52`` of the span, the line does not
    decrease, or after 64 steps.

    **Bracket refinement (today's bisection rule).** ``hi`` starts at ``tau_hi``; a probe
    just past ``lo`` (Newton's prediction of the crossing, doubled, then galloping x4) and
    then bisection keep the invariant ``d(hi) < level`` proved by an upper bound, and move
    ``lo`` to a point whose upper bound is ``>= level`` (by convexity of ``d`` the
    interval ``{d < level}`` that contains ``hi`` cannot reach left of such a point, up to
    the pad: exactly the argument of the bisection this replaces). Stop when
    ``hi - lo <= 2^-52 max(|tau_lo|, |tau_hi|, tau_hi - tau_lo)``, the same precision as
    the 60-solve bisection, which now starts from a bracket of about ``pad / |w|``.

    Args:
        A, va, B, vb: (na, 3), (3,), (nb, 3), (3,) vertices at tau = 0 and velocities.
        tau_lo, tau_hi: the interval (s from span start).
        level: the distance threshold (m).
        rel_pad, abs_pad: rounding pads.
        point_out: (3,) output, the midpoint between the cores' closest points at the answer.

    Returns:
        ``(tau, solves, advanced)``: the earliest time (proved ``d(tau) < level`` unless the
        precondition failed, then ``tau_hi``), the number of min-norm solves, and the
        number of accepted advancement steps.
    """
    na = A.shape[0]
    nb = B.shape[0]
    m = na * nb
    P = np.empty((m, 3))
    lam = np.empty(m)
    n = np.empty(3)
    w = np.empty(3)
    for c in range(3):
        w[c] = va[c] - vb[c]
    _fill(A, va, B, vb, tau_lo, P)
    lower, up = min_norm_kernel(P, rel_pad, abs_pad, lam, n)
    solves = 1
    steps = 0
    lo = tau_lo
    hi = tau_hi
    if up < level:
        hi = tau_lo
    else:
        tiny = _ULP * max(abs(tau_hi), abs(tau_lo), tau_hi - tau_lo)
        vsum = 0.0
        for c in range(3):
            vsum += abs(va[c]) + abs(vb[c])
        slope = 0.0
        up_lo = up
        # --- conservative advancement (every accepted step proved by the plane bound)
        for _it in range(64):
            if n[0] == 0.0 and n[1] == 0.0 and n[2] == 0.0:
                break
            g, mag = _plane_lower(A, va, B, vb, lo, n, level, rel_pad, abs_pad)
            slope = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
            # aim short of the line's crossing by the pad's growth over the step and the
            # rounding of both evaluations (~ulp * mag each), so the check below passes
            g -= 32 * _ULP * mag
            if not (g > 0.0) or not (slope < 0.0):
                break
            t1 = lo + g / (-slope + 16 * rel_pad * vsum)
            ok = False
            for _shrink in range(5):
                if not (t1 < hi):
                    t1 = lo + 0.5 * (hi - lo)
                if not (t1 > lo):
                    break
                if _plane_lower(A, va, B, vb, t1, n, level, rel_pad, abs_pad)[0] >= 0.0:
                    ok = True
                    break
                t1 = lo + 0.5 * (t1 - lo)
            if not ok:
                break
            adv = t1 - lo
            lo = t1
            steps += 1
            _fill(A, va, B, vb, lo, P)
            lower, up_lo = min_norm_kernel(P, rel_pad, abs_pad, lam, n)
            solves += 1
            if up_lo < level:  # pragma: no cover - contradicts the proved plane bound
                hi = lo
                break
            if adv <= tiny:
                break
        # --- bracket refinement: Newton's predicted crossing, doubled, galloping
        if hi > lo and slope < 0.0 and np.isfinite(up_lo):
            delta = max(2.0 * (up_lo - level) / (-slope), 4.0 * tiny)
            for _g in range(12):
                t = lo + delta
                if not (t < hi) or hi - lo <= tiny:
                    break
                _fill(A, va, B, vb, t, P)
                _, u = min_norm_kernel(P, rel_pad, abs_pad, lam, n)
                solves += 1
                if u < level:
                    hi = t
                    break
                lo = t
                delta *= 4.0
        # --- bisection (the rule of the code this replaces)
        while hi - lo > tiny and solves < 200:
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            _fill(A, va, B, vb, mid, P)
            _, u = min_norm_kernel(P, rel_pad, abs_pad, lam, n)
            solves += 1
            if u < level:
                hi = mid
            else:
                lo = mid
    # the point between the cores at hi
    _fill(A, va, B, vb, hi, P)
    min_norm_kernel(P, rel_pad, abs_pad, lam, n)
    solves += 1
    for c in range(3):
        pa = 0.0
        pb = 0.0
        for i in range(na):
            for k in range(nb):
                lk = lam[i * nb + k]
                pa += lk * (A[i, c] + va[c] * hi)
                pb += lk * (B[k, c] + vb[c] * hi)
        point_out[c] = 0.5 * (pa + pb)
    return hi, solves, steps


def warm() -> None:
    """Compile (or load from the numba cache) both kernels."""
    A = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    B = np.array([[3.0, 0.0, 0.0], [3.0, 1.0, 0.0], [3.0, 0.0, 1.0]])
    point = np.empty(3)
    first_time_kernel(A, np.array([1.0, 0.0, 0.0]), B, np.zeros(3), 0.0, 2.0, 0.5, 64 * _ULP, 1e-12, point)


__all__ = ["min_norm_kernel", "first_time_kernel", "warm"]


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
