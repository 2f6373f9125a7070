"""numba kernels of the exact static distance test (see :mod:`monitor.geometry.distance`).

Everything here works on the *cores* (convex hulls of vertex sets: a point, a
segment or a polytope) in a **relative frame** whose origin is the translation
of shape A. Distances are translation invariant, so only the rounded offset
``p_B - p_A`` enters, never the absolute world coordinates: a pair 1e4 m from
the origin is as accurate as one at the origin.

Bounds (D = A - B, the Minkowski difference of the cores, h_D its support function):

* For every direction n, ``-h_D(n) / |n|`` is a lower bound on the signed core
  distance (separated: a separating-axis gap; overlapping: minus an upper bound
  on the penetration depth, which is ``min_n h_D(n)``).
* A convex combination ``x = sum lam_i (a_i - b_i)`` of Minkowski-difference
  vertices with ``lam >= 0`` gives the points ``sum lam_i a_i`` of A and
  ``sum lam_i b_i`` of B at distance ``|x| / sum lam``: an upper bound.
* A tetrahedron of Minkowski-difference vertices containing the ball B(0, r)
  proves a penetration depth >= r: the upper bound ``-r``. EPA grows such a
  region to the penetration depth; its triangle surface is verified after the
  fact (closed, oriented, winding number 1, certified face distances), so the
  bound never depends on EPA's topology bookkeeping being right.

All returned bounds are rounding padded with ``pad = 2 * rel_pad * S + abs_pad``
(S = largest coordinate magnitude in the relative frame): the factor 2 covers
the transform to the relative frame (<= 4 ulp * S per coordinate) plus the
dot products / sums of the kernel (<= ~20 ulp * S), against rel_pad = 64 ulp.

GJK (Gilbert-Johnson-Keerthi) uses an enumerating distance sub-algorithm: for
the simplex (<= 4 points) every face, edge and vertex whose affine projection
of the origin has positive barycentric coordinates is a candidate and the
smallest one wins. Each candidate is a genuine convex combination, so rounding
can make GJK sub-optimal but never make a bound wrong. Projections are computed
in the numerically stable form (triangle: cross-product normal; edge:
re-orthogonalised perpendicular), so the direction is accurate to ~1 ulp even
at 1e-9 m separation, which keeps the separating-axis lower bound tight.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from monitor._jit_cache import bind_caches, purge_if_changed

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)

_U = 2.0**-53
"""Unit roundoff of float64."""

# status codes written to out[0]
SEPARATED = 0
"""Cores separated: ``upper`` from the closest points, ``lower`` from their direction."""
TOUCHING = 1
"""Core distance below rounding: a common point (up to rounding), SAT lower bound."""
OVERLAP = 2
"""A GJK tetrahedron encloses the origin: common point; maybe a negative upper bound."""

KIND_POINT = 0
KIND_SEGMENT = 1
KIND_POLYTOPE = 2

OUT_SIZE = 12
"""Layout of the output row: status, estimate, lower, upper, p_a (3), p_b (3), pad, iters."""


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _transform(P, R, t, out):
    """out[i] = R @ P[i] + t."""
    for i in range(P.shape[0]):
        for r in range(3):
            out[i, r] = R[r, 0] * P[i, 0] + R[r, 1] * P[i, 1] + R[r, 2] * P[i, 2] + t[r]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _rotate(N, R, out):
    for i in range(N.shape[0]):
        for r in range(3):
            out[i, r] = R[r, 0] * N[i, 0] + R[r, 1] * N[i, 1] + R[r, 2] * N[i, 2]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _support_max(V, d):
    """(index, value) of max_i V[i] . d."""
    best = -np.inf
    bi = 0
    for i in range(V.shape[0]):
        s = V[i, 0] * d[0] + V[i, 1] * d[1] + V[i, 2] * d[2]
        if s > best:
            best = s
            bi = i
    return bi, best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _support_min(V, d):
    """(index, value) of min_i V[i] . d."""
    best = np.inf
    bi = 0
    for i in range(V.shape[0]):
        s = V[i, 0] * d[0] + V[i, 1] * d[1] + V[i, 2] * d[2]
        if s < best:
            best = s
            bi = i
    return bi, best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _axis_bound(VA, VB, n):
    """-h_D(n) / |n| = (min_b n.b - max_a n.a) / |n|: a lower bound on the signed distance.

    Here the direction n points from A to B. Returns -inf for a zero direction.
    """
    nn = np.sqrt(_dot(n, n))
    if not nn > 0.0:
        return -np.inf
    _, ha = _support_max(VA, n)
    _, lb = _support_min(VB, n)
    return (lb - ha) / nn


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _subalgorithm(W, k, lam_out, v_out, tiny_len2, tiny_area2):
    """Min-norm point of conv(W[:k]) (k <= 4) by enumerating faces, edges, vertices.

    Args:
        W: (4, 3) simplex points.
        k: number of points in use.
        lam_out: (4,) barycentric coordinates of the result (>= 0, sum 1).
        v_out: (3,) the min-norm point (stably computed).
        tiny_len2: squared edge length below which an edge is degenerate.
        tiny_area2: squared (2 x area) below which a triangle is degenerate.

    Returns:
        (mask, inside): bit mask of the supporting sub-simplex; ``inside`` True
        when k == 4 and the origin lies in the tetrahedron (v_out = 0).

    No array is allocated (issue 12, kernel cost: the nine scratch arrays of each call were
    a third of an early-exit GJK's time): the cross and dot products are written out on
    scalars with the same operations in the same order as ``_cross`` / ``_dot``, so the
    results are bit for bit those of the array version; the running best is kept in
    ``lam_out`` / ``v_out`` (zeros / the best point so far; only written, never read).
    """
    best = np.inf
    best_mask = 0
    for q in range(4):
        lam_out[q] = 0.0
    # tetrahedron: origin inside?
    if k == 4:
        # barycentric coordinates of the origin by signed volumes
        e0, e1, e2 = W[1, 0] - W[0, 0], W[1, 1] - W[0, 1], W[1, 2] - W[0, 2]
        f0, f1, f2 = W[2, 0] - W[0, 0], W[2, 1] - W[0, 1], W[2, 2] - W[0, 2]
        g0, g1, g2 = W[3, 0] - W[0, 0], W[3, 1] - W[0, 1], W[3, 2] - W[0, 2]
        # n = f x g
        n0 = f1 * g2 - f2 * g1
        n1 = f2 * g0 - f0 * g2
        n2 = f0 * g1 - f1 * g0
        vol = e0 * n0 + e1 * n1 + e2 * n2
        if vol != 0.0:
            # lam_j = det with column j replaced by -W0
            c0, c1, c2 = -W[0, 0], -W[0, 1], -W[0, 2]
            lt1 = (c0 * n0 + c1 * n1 + c2 * n2) / vol
            # n = c x g
            m0 = c1 * g2 - c2 * g1
            m1 = c2 * g0 - c0 * g2
            m2 = c0 * g1 - c1 * g0
            lt2 = (e0 * m0 + e1 * m1 + e2 * m2) / vol
            # n = f x c
            m0 = f1 * c2 - f2 * c1
            m1 = f2 * c0 - f0 * c2
            m2 = f0 * c1 - f1 * c0
            lt3 = (e0 * m0 + e1 * m1 + e2 * m2) / vol
            lt0 = 1.0 - lt1 - lt2 - lt3
            if lt0 >= 0.0 and lt1 >= 0.0 and lt2 >= 0.0 and lt3 >= 0.0:
                lam_out[0] = lt0
                lam_out[1] = lt1
                lam_out[2] = lt2
                lam_out[3] = lt3
                v_out[0] = 0.0
                v_out[1] = 0.0
                v_out[2] = 0.0
                return 15, True
    # vertices
    for i in range(k):
        d = W[i, 0] ** 2 + W[i, 1] ** 2 + W[i, 2] ** 2
        if d < best:
            best = d
            best_mask = 1 << i
            for j in range(4):
                lam_out[j] = 0.0
            lam_out[i] = 1.0
            for j in range(3):
                v_out[j] = W[i, j]
    # edges
    for i in range(k):
        for j in range(i + 1, k):
            e0, e1, e2 = W[j, 0] - W[i, 0], W[j, 1] - W[i, 1], W[j, 2] - W[i, 2]
            ee = e0 * e0 + e1 * e1 + e2 * e2
            if ee <= tiny_len2:
                continue
            t = -(W[i, 0] * e0 + W[i, 1] * e1 + W[i, 2] * e2) / ee
            if not (t > 0.0 and t < 1.0):
                continue
            p0, p1, p2 = W[i, 0] + t * e0, W[i, 1] + t * e1, W[i, 2] + t * e2
            # re-orthogonalise: removes the along-edge rounding residue
            s = (p0 * e0 + p1 * e1 + p2 * e2) / ee
            p0 -= s * e0
            p1 -= s * e1
            p2 -= s * e2
            d = p0 * p0 + p1 * p1 + p2 * p2
            if d < best:
                best = d
                best_mask = (1 << i) | (1 << j)
                for q in range(4):
                    lam_out[q] = 0.0
                lam_out[i] = 1.0 - t
                lam_out[j] = t
                v_out[0] = p0
                v_out[1] = p1
                v_out[2] = p2
    # triangles
    for i in range(k):
        for j in range(i + 1, k):
            for m in range(j + 1, k):
                e0, e1, e2 = W[j, 0] - W[i, 0], W[j, 1] - W[i, 1], W[j, 2] - W[i, 2]
                f0, f1, f2 = W[m, 0] - W[i, 0], W[m, 1] - W[i, 1], W[m, 2] - W[i, 2]
                n0 = e1 * f2 - e2 * f1
                n1 = e2 * f0 - e0 * f2
                n2 = e0 * f1 - e1 * f0
                nn = n0 * n0 + n1 * n1 + n2 * n2
                if nn <= tiny_area2:
                    continue
                s = (n0 * W[i, 0] + n1 * W[i, 1] + n2 * W[i, 2]) / nn
                p0, p1, p2 = s * n0, s * n1, s * n2
                # barycentric coordinates of p (in the plane) by signed areas
                e0, e1, e2 = W[j, 0] - p0, W[j, 1] - p1, W[j, 2] - p2
                f0, f1, f2 = W[m, 0] - p0, W[m, 1] - p1, W[m, 2] - p2
                x0 = e1 * f2 - e2 * f1
                x1 = e2 * f0 - e0 * f2
                x2 = e0 * f1 - e1 * f0
                li = (x0 * n0 + x1 * n1 + x2 * n2) / nn
                e0, e1, e2 = W[m, 0] - p0, W[m, 1] - p1, W[m, 2] - p2
                f0, f1, f2 = W[i, 0] - p0, W[i, 1] - p1, W[i, 2] - p2
                x0 = e1 * f2 - e2 * f1
                x1 = e2 * f0 - e0 * f2
                x2 = e0 * f1 - e1 * f0
                lj = (x0 * n0 + x1 * n1 + x2 * n2) / nn
                lm = 1.0 - li - lj
                if not (li > 0.0 and lj > 0.0 and lm > 0.0):
                    continue
                d = p0 * p0 + p1 * p1 + p2 * p2
                if d < best:
                    best = d
                    best_mask = (1 << i) | (1 << j) | (1 << m)
                    for q in range(4):
                        lam_out[q] = 0.0
                    lam_out[i] = li
                    lam_out[j] = lj
                    lam_out[m] = lm
                    v_out[0] = p0
                    v_out[1] = p1
                    v_out[2] = p2
    return best_mask, False


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _compact(mask, k, W, IA, IB, lam):
    """Keep the simplex points in ``mask``; returns the new count."""
    m = 0
    for i in range(k):
        if mask & (1 << i):
            if m != i:
                for r in range(3):
                    W[m, r] = W[i, r]
                IA[m] = IA[i]
                IB[m] = IB[i]
                lam[m] = lam[i]
            m += 1
    for i in range(m, 4):
        lam[i] = 0.0
    return m


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _depth_at(V, N, x):
    """min_i (h_V(N_i) - N_i . x) / |N_i|: the depth of x in the polytope conv(V).

    Exact (up to rounding) when the face normals N are complete; negative outside.
    """
    best = np.inf
    if N.shape[0] == 0:
        return -np.inf
    for i in range(N.shape[0]):
        nn = np.sqrt(_dot(N[i], N[i]))
        if not nn > 0.0:
            continue
        _, h = _support_max(V, N[i])
        d = (h - _dot(N[i], x)) / nn
        if d < best:
            best = d
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _low_dim_depth(V, N, C, x_out):
    """Deepest point of a point / segment core C (1 or 2 rows) inside the polytope (V, N).

    The depth along the segment, t -> depth(c0 + t (c1 - c0)), is concave and
    piecewise linear: bisection on the sign of the active face's slope finds its
    maximum. Returns the depth at the chosen point (written to ``x_out``); any
    point of C gives a valid bound, so the search accuracy only affects tightness.
    """
    x = np.empty(3)
    e = np.empty(3)
    for r in range(3):
        x[r] = C[0, r]
        e[r] = C[C.shape[0] - 1, r] - C[0, r]
    best = _depth_at(V, N, x)
    for r in range(3):
        x_out[r] = x[r]
    if C.shape[0] == 1 or _dot(e, e) == 0.0:
        return best
    nf = N.shape[0]
    h = np.empty(nf)
    nrm = np.empty(nf)
    for i in range(nf):
        nrm[i] = np.sqrt(_dot(N[i], N[i]))
        _, h[i] = _support_max(V, N[i])
    lo = 0.0
    hi = 1.0
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        for r in range(3):
            x[r] = C[0, r] + mid * e[r]
        dmin = np.inf
        slope = 0.0
        for i in range(nf):
            if not nrm[i] > 0.0:
                continue
            d = (h[i] - _dot(N[i], x)) / nrm[i]
            if d < dmin:
                dmin = d
                slope = -_dot(N[i], e) / nrm[i]
        if slope > 0.0:
            lo = mid
        else:
            hi = mid
    for t in (1.0, lo, hi):
        for r in range(3):
            x[r] = C[0, r] + t * e[r]
        d = _depth_at(V, N, x)
        if d > best:
            best = d
            for r in range(3):
                x_out[r] = x[r]
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _tetra_inradius(W, pad_coord, rel_pad):
    """Certified radius r of a ball B(0, r) inside the tetrahedron W (4, 3), or 0.

    ``pad_coord`` bounds the coordinate error of every W row; the plane
    distance pads cover that perturbation and the cross-product rounding.
    """
    # (scalars, no scratch arrays: the same operations in the same order as _cross / _dot,
    # so the same numbers bit for bit; issue 12, kernel cost)
    r_min = np.inf
    for o in range(4):
        i = (o + 1) % 4
        j = (o + 2) % 4
        m = (o + 3) % 4
        e0, e1, e2 = W[j, 0] - W[i, 0], W[j, 1] - W[i, 1], W[j, 2] - W[i, 2]
        f0, f1, f2 = W[m, 0] - W[i, 0], W[m, 1] - W[i, 1], W[m, 2] - W[i, 2]
        g0, g1, g2 = W[o, 0] - W[i, 0], W[o, 1] - W[i, 1], W[o, 2] - W[i, 2]
        n0 = e1 * f2 - e2 * f1
        n1 = e2 * f0 - e0 * f2
        n2 = e0 * f1 - e1 * f0
        nn = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if not nn > 0.0:
            return 0.0
        # outward: away from the opposite vertex
        sgn = -1.0 if n0 * g0 + n1 * g1 + n2 * g2 > 0.0 else 1.0
        # distance from origin to the plane, + if inside
        dist = sgn * (n0 * W[i, 0] + n1 * W[i, 1] + n2 * W[i, 2]) / nn
        le = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        lf = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        lw = np.sqrt(W[i, 0] * W[i, 0] + W[i, 1] * W[i, 1] + W[i, 2] * W[i, 2])
        dn = 4.0 * pad_coord * (le + lf) + 4.0 * rel_pad * le * lf
        pad = pad_coord + 2.0 * dn * lw / nn + rel_pad * abs(dist)
        r = dist - pad
        if r < r_min:
            r_min = r
    return max(r_min, 0.0)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _face_plane(P, i, j, k, pad_coord, rel_pad, nout):
    """Oriented triangle (i, j, k) of P: unit normal (Pj-Pi)x(Pk-Pi) into ``nout``.

    Returns (dist, certified): the signed distance from the origin to the plane
    (positive when the origin is on the inner side) and that distance minus a pad
    covering vertex perturbations of ``pad_coord`` and the cross-product rounding.
    """
    # (scalars, no scratch arrays: the same operations in the same order as _cross / _dot)
    e0, e1, e2 = P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2]
    f0, f1, f2 = P[k, 0] - P[i, 0], P[k, 1] - P[i, 1], P[k, 2] - P[i, 2]
    nout[0] = e1 * f2 - e2 * f1
    nout[1] = e2 * f0 - e0 * f2
    nout[2] = e0 * f1 - e1 * f0
    nn = np.sqrt(nout[0] * nout[0] + nout[1] * nout[1] + nout[2] * nout[2])
    if not nn > 0.0:
        return -np.inf, -np.inf
    for r in range(3):
        nout[r] /= nn
    dist = nout[0] * P[i, 0] + nout[1] * P[i, 1] + nout[2] * P[i, 2]
    le = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    lf = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
    lw = np.sqrt(P[i, 0] * P[i, 0] + P[i, 1] * P[i, 1] + P[i, 2] * P[i, 2])
    dn = 4.0 * pad_coord * (le + lf) + 4.0 * rel_pad * le * lf
    pad = pad_coord + 2.0 * dn * lw / nn + 2.0 * rel_pad * (abs(dist) + lw)
    return dist, dist - pad


@njit(cache=True, no_cfunc_wrapper=True)
def _epa_inradius(VA, VB, W, pad_coord, rel_pad, max_iter, lb_out):
    """Certified radius r of a ball B(0, r) inside the Minkowski difference, by EPA.

    Expanding-polytope iterations start from the GJK tetrahedron W (4, 3) around
    the origin and push the face nearest the origin out to the support point in
    its normal, so the nearest face distance converges to the penetration depth.
    The result is *verified* independently of how it was built: the faces must
    form a closed, consistently oriented triangle surface (every directed edge
    once, its reverse once) whose planes all have the origin strictly on the inner
    side (certified distances > 0) and whose solid angles at the origin sum to
    4 pi (winding number 1). Then every ray from the origin crosses exactly one
    face, at a distance >= that face plane's distance, so B(0, min distance) lies
    in the star-shaped region bounded by the surface, which lies in the (convex)
    Minkowski difference because its vertices do. Convexity is not needed.
    Returns 0 when anything fails (the caller keeps its other bounds).

    ``lb_out[0]`` receives the best separating-axis value ``-h_D(n)`` over the
    face normals tried (a lower bound on the signed distance whatever happens;
    it converges to minus the penetration depth).
    """
    maxv = 4 + max_iter
    maxf = 4 + 48 * max_iter
    P = np.empty((maxv, 3))
    for q in range(4):
        for r in range(3):
            P[q, r] = W[q, r]
    nv = np.int64(4)   # not the literal 4: numba would compile _face_plane for Literal[int](4) too
    F = np.empty((maxf, 3), np.int64)
    alive = np.zeros(maxf, np.bool_)
    fn = np.empty((maxf, 3))
    fd = np.empty(maxf)
    nrm = np.empty(3)
    nf = 0
    for o in range(4):
        i = (o + 1) % 4
        j = (o + 2) % 4
        k = (o + 3) % 4
        d, _ = _face_plane(P, i, j, k, pad_coord, rel_pad, nrm)
        if _dot(nrm, P[o]) - d > 0.0:
            j, k = k, j
            d, _ = _face_plane(P, i, j, k, pad_coord, rel_pad, nrm)
        if not d > 0.0:
            return 0.0
        F[nf, 0] = i
        F[nf, 1] = j
        F[nf, 2] = k
        alive[nf] = True
        fd[nf] = d
        for r in range(3):
            fn[nf, r] = nrm[r]
        nf += 1
    vis = np.zeros(maxf, np.bool_)
    hor = np.empty((3 * maxf, 2), np.int64)
    w = np.empty(3)
    for _ in range(max_iter):
        best = -1
        bd = np.inf
        for g in range(nf):
            if alive[g] and fd[g] < bd:
                bd = fd[g]
                best = g
        if best < 0 or nv >= maxv:
            break
        ia, sa = _support_max(VA, fn[best])
        ib, sb = _support_min(VB, fn[best])
        # -h_D(n) = min_b n.b - max_a n.a (|n| = 1 up to rounding: divide anyway)
        lb = (sb - sa) / np.sqrt(_dot(fn[best], fn[best]))
        if lb > lb_out[0]:
            lb_out[0] = lb
        for r in range(3):
            w[r] = VA[ia, r] - VB[ib, r]
        if _dot(fn[best], w) - bd <= 1e-10 * bd + 4.0 * pad_coord:
            break
        # faces visible from w
        nvis = 0
        for g in range(nf):
            vis[g] = False
            if alive[g]:
                s = 0.0
                for r in range(3):
                    s += fn[g, r] * (w[r] - P[F[g, 0], r])
                if s > 0.0:
                    vis[g] = True
                    nvis += 1
        if not vis[best]:
            break
        # horizon: directed edges of visible faces whose reverse is not in a visible face
        nh = 0
        for g in range(nf):
            if not vis[g]:
                continue
            for q in range(3):
                a = F[g, q]
                b = F[g, (q + 1) % 3]
                shared = False
                for h in range(nf):
                    if vis[h] and h != g:
                        for t in range(3):
                            if F[h, t] == b and F[h, (t + 1) % 3] == a:
                                shared = True
                if not shared:
                    hor[nh, 0] = a
                    hor[nh, 1] = b
                    nh += 1
        if nf + nh > maxf:
            break
        for r in range(3):
            P[nv, r] = w[r]
        for g in range(nf):
            if vis[g]:
                alive[g] = False
        ok = True
        for q in range(nh):
            d, _ = _face_plane(P, hor[q, 0], hor[q, 1], nv, pad_coord, rel_pad, nrm)
            if not d > 0.0:
                ok = False
            F[nf, 0] = hor[q, 0]
            F[nf, 1] = hor[q, 1]
            F[nf, 2] = nv
            alive[nf] = True
            fd[nf] = d
            for r in range(3):
                fn[nf, r] = nrm[r]
            nf += 1
        nv += 1
        if not ok:
            return 0.0
    # ---- verification
    nalive = 0
    for g in range(nf):
        if alive[g]:
            nalive += 1
    keys = np.empty(3 * nalive, np.int64)
    m = 0
    for g in range(nf):
        if alive[g]:
            for q in range(3):
                keys[m] = F[g, q] * maxv + F[g, (q + 1) % 3]
                m += 1
    # sort (insertion sort: the same order as np.sort for integers, and no separate compile of
    # numba's quicksort and searchsorted; the verification runs only on overlapping pairs)
    for q in range(1, m):
        key = keys[q]
        i = q - 1
        while i >= 0 and keys[i] > key:
            keys[i + 1] = keys[i]
            i -= 1
        keys[i + 1] = key
    # closedness: every directed edge (a, b) exactly once and its reverse (b, a) present
    for q in range(m):
        if q > 0 and keys[q] == keys[q - 1]:
            return 0.0
        a = keys[q] // maxv
        b = keys[q] % maxv
        rk = b * maxv + a
        lo_i, hi_i = 0, m            # np.searchsorted(keys, rk) (side="left"), by bisection
        while lo_i < hi_i:
            mid = (lo_i + hi_i) // 2
            if keys[mid] < rk:
                lo_i = mid + 1
            else:
                hi_i = mid
        pos = lo_i
        if pos >= m or keys[pos] != rk:
            return 0.0
    r_min = np.inf
    omega = 0.0
    for g in range(nf):
        if not alive[g]:
            continue
        _, dc = _face_plane(P, F[g, 0], F[g, 1], F[g, 2], pad_coord, rel_pad, nrm)
        if not dc > 0.0:
            return 0.0
        if dc < r_min:
            r_min = dc
        # solid angle (Van Oosterom - Strackee)
        pa_ = P[F[g, 0]]
        pb_ = P[F[g, 1]]
        pc_ = P[F[g, 2]]
        _cross(pb_, pc_, nrm)
        det = _dot(pa_, nrm)
        la = np.sqrt(_dot(pa_, pa_))
        lb = np.sqrt(_dot(pb_, pb_))
        lc = np.sqrt(_dot(pc_, pc_))
        den = la * lb * lc + _dot(pa_, pb_) * lc + _dot(pa_, pc_) * lb + _dot(pb_, pc_) * la
        omega += 2.0 * np.arctan2(det, den)
    if not abs(omega - 4.0 * np.pi) < 1e-3:
        return 0.0
    return max(r_min, 0.0)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _sat_lower(VA, VB, EA, EB, NA, NB, any_polytope, max_edge_pairs, v):
    """Max over candidate directions of -h_D(n)/|n| (A-to-B directions).

    Candidates: the GJK direction, coordinate axes, face normals of both cores
    (both signs), cross products of edge pairs (both signs; skipped when edge
    pairs x vertices exceeds ``max_edge_pairs``) and, when no core is a
    polytope, crosses of edges with the axes. For two polytopes with complete
    edge/face lists this is the exact signed distance (separating-axis theorem);
    in general a valid lower bound.
    """
    best = -np.inf
    n = np.empty(3)
    a = np.empty(3)
    b = np.empty(3)
    for s in (-1.0, 1.0):
        for r in range(3):
            n[r] = s * v[r]
        best = max(best, _axis_bound(VA, VB, n))
        for ax in range(3):
            for r in range(3):
                n[r] = 0.0
            n[ax] = s
            best = max(best, _axis_bound(VA, VB, n))
        for i in range(NA.shape[0]):
            for r in range(3):
                n[r] = s * NA[i, r]
            best = max(best, _axis_bound(VA, VB, n))
        for i in range(NB.shape[0]):
            for r in range(3):
                n[r] = s * NB[i, r]
            best = max(best, _axis_bound(VA, VB, n))
    if EA.shape[0] * EB.shape[0] * (VA.shape[0] + VB.shape[0]) <= max_edge_pairs:
        for i in range(EA.shape[0]):
            for r in range(3):
                a[r] = VA[EA[i, 1], r] - VA[EA[i, 0], r]
            for j in range(EB.shape[0]):
                for r in range(3):
                    b[r] = VB[EB[j, 1], r] - VB[EB[j, 0], r]
                _cross(a, b, n)
                best = max(best, _axis_bound(VA, VB, n))
                for r in range(3):
                    n[r] = -n[r]
                best = max(best, _axis_bound(VA, VB, n))
    if not any_polytope:
        for side in range(2):
            V = VA if side == 0 else VB
            E = EA if side == 0 else EB
            for i in range(E.shape[0]):
                for r in range(3):
                    a[r] = V[E[i, 1], r] - V[E[i, 0], r]
                for ax in range(3):
                    for r in range(3):
                        b[r] = 0.0
                    b[ax] = 1.0
                    _cross(a, b, n)
                    best = max(best, _axis_bound(VA, VB, n))
                    for r in range(3):
                        n[r] = -n[r]
                    best = max(best, _axis_bound(VA, VB, n))
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _simplex_directions_bound(VA, VB, W, k):
    """Best axis bound over directions from the sub-simplices of W[:k] (A-to-B sign).

    Vertices w_i, perpendiculars from the origin to edge lines (re-orthogonalised)
    and triangle normals: each is accurate when its own feature is well shaped.
    """
    best = -np.inf
    n = np.empty(3)
    e = np.empty(3)
    f = np.empty(3)
    for i in range(k):
        for r in range(3):
            n[r] = -W[i, r]
        best = max(best, _axis_bound(VA, VB, n))
        for j in range(i + 1, k):
            for r in range(3):
                e[r] = W[j, r] - W[i, r]
            ee = _dot(e, e)
            if ee > 0.0:
                t = -_dot(W[i], e) / ee
                for r in range(3):
                    n[r] = W[i, r] + t * e[r]
                s = _dot(n, e) / ee
                for r in range(3):
                    n[r] = -(n[r] - s * e[r])
                best = max(best, _axis_bound(VA, VB, n))
            for m in range(j + 1, k):
                for r in range(3):
                    f[r] = W[m, r] - W[i, r]
                _cross(e, f, n)
                if _dot(n, W[i]) > 0.0:
                    for r in range(3):
                        n[r] = -n[r]
                best = max(best, _axis_bound(VA, VB, n))
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _edge_perp_bound(VA, VB, EA, EB, v):
    """Best axis bound over v projected perpendicular to each edge direction of A and B."""
    best = -np.inf
    d = np.empty(3)
    n = np.empty(3)
    for side in range(2):
        V = VA if side == 0 else VB
        E = EA if side == 0 else EB
        for i in range(E.shape[0]):
            for r in range(3):
                d[r] = V[E[i, 1], r] - V[E[i, 0], r]
            dd = _dot(d, d)
            if not dd > 0.0:
                continue
            s = _dot(v, d) / dd
            for r in range(3):
                n[r] = v[r] - s * d[r]
            s = _dot(n, d) / dd
            for r in range(3):
                n[r] -= s * d[r]
            best = max(best, _axis_bound(VA, VB, n))
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def pose_relative(PA, RA, tA, NA, PB, RB, tB, NB):
    """Both cores posed in the world frame shifted by ``tA`` (A's translation becomes 0).

    Working relative to A keeps far-from-origin scenes (1e4 m) accurate.

    Returns:
        VA (nA, 3), VB (nB, 3) posed vertices; WNA (fA, 3), WNB (fB, 3) rotated face normals.
    """
    VA = np.empty((PA.shape[0], 3))
    VB = np.empty((PB.shape[0], 3))
    d = np.empty(3)
    for r in range(3):
        d[r] = tB[r] - tA[r]
    _transform(PA, RA, np.zeros(3), VA)
    _transform(PB, RB, d, VB)
    WNA = np.empty((NA.shape[0], 3))
    WNB = np.empty((NB.shape[0], 3))
    _rotate(NA, RA, WNA)
    _rotate(NB, RB, WNB)
    return VA, VB, WNA, WNB


@njit(cache=True, no_cfunc_wrapper=True)
def core_distance(PA, RA, tA, EA, NA, PB, RB, tB, EB, NB, kind_a, kind_b, dpad_a, dpad_b, rel_pad,
                  abs_pad, eps_rel, max_iter, max_edge_pairs, out):
    """Signed distance bounds of two cores (point / segment / polytope vertex sets).

    Args:
        PA, PB: (n, 3) body-frame core vertices.
        RA, RB: (3, 3) rotations (body -> world).
        tA, tB: (3,) translations (body -> world).
        EA, EB: (m, 2) int64 edges (vertex index pairs).
        NA, NB: (f, 3) body-frame face normals (empty for point / segment).
        kind_a, kind_b: KIND_POINT / KIND_SEGMENT / KIND_POLYTOPE.
        dpad_a, dpad_b: metres by which a depth measured with the face normals
            may exceed the true depth in the vertex hull (normals' completeness
            defect, see ``distance._core``); inf disables depth certificates.
        rel_pad, abs_pad: rounding pads (``Tolerances``).
        eps_rel: GJK relative duality-gap tolerance.
        max_iter: GJK iteration cap.
        max_edge_pairs: work cap (edge pairs x vertices) on the edge x edge SAT candidates.
        out: (OUT_SIZE,) float64 output: status, estimate, lower, upper (core
            signed distance, metres), p_a (3), p_b (3) in the frame shifted by
            tA (add tA for world), pad, iterations.
    """
    any_polytope = kind_a == KIND_POLYTOPE or kind_b == KIND_POLYTOPE
    # the scratch vectors as rows of three arrays (three allocations instead of fifteen; the rows
    # are C-contiguous, so the helpers keep their one specialisation; issue 12, kernel cost)
    fbuf = np.zeros((15, 3))
    ibuf = np.zeros((4, 4), np.int64)
    lbuf = np.zeros((2, 4))
    xc = fbuf[14]
    na = PA.shape[0]
    nb = PB.shape[0]
    VA, VB, WNA, WNB = pose_relative(PA, RA, tA, NA, PB, RB, tB, NB)
    S = 0.0
    for i in range(na):
        for r in range(3):
            S = max(S, abs(VA[i, r]))
    for i in range(nb):
        for r in range(3):
            S = max(S, abs(VB[i, r]))
    pad = 2.0 * rel_pad * S + abs_pad
    pad_coord = 2.0 * rel_pad * S
    tiny = 8.0 * _U * S
    tiny_len2 = (1e-14 * S) ** 2
    tiny_area2 = (1e-14 * S * S) ** 2

    W = fbuf[0:4]
    IA = ibuf[0]
    IB = ibuf[1]
    lam = lbuf[0]
    v = fbuf[8]
    vn = fbuf[9]
    w = fbuf[10]
    # best snapshot
    bW = fbuf[4:8]
    bIA = ibuf[2]
    bIB = ibuf[3]
    blam = lbuf[1]
    # start: the pair of first vertices
    k = 1
    IA[0] = 0
    IB[0] = 0
    lam[0] = 1.0
    for r in range(3):
        W[0, r] = VA[0, r] - VB[0, r]
        v[r] = W[0, r]
    vv = _dot(v, v)
    best_lower = -np.inf
    status = SEPARATED
    it = 0
    while it < max_iter:
        it += 1
        if vv <= tiny * tiny:
            status = TOUCHING
            break
        # support of D in -v: w = a - b with a minimising v.a, b maximising v.b
        ia, sa = _support_min(VA, v)
        ib, sb = _support_max(VB, v)
        for r in range(3):
            w[r] = VA[ia, r] - VB[ib, r]
        vw = _dot(v, w)
        # every x in D has v.x >= v.w (up to rounding): a separating-axis lower bound
        lb = (sa - sb) / np.sqrt(vv)
        if lb > best_lower:
            best_lower = lb
        if vv - vw <= eps_rel * vv:
            break
        dup = False
        for q in range(k):
            if IA[q] == ia and IB[q] == ib:
                dup = True
        if dup:
            break
        # save snapshot
        for q in range(4):
            for r in range(3):
                bW[q, r] = W[q, r]
            bIA[q] = IA[q]
            bIB[q] = IB[q]
            blam[q] = lam[q]
        bk = k
        for r in range(3):
            W[k, r] = w[r]
        IA[k] = ia
        IB[k] = ib
        k += 1
        mask, inside = _subalgorithm(W, k, lam, vn, tiny_len2, tiny_area2)
        if inside:
            status = OVERLAP
            for r in range(3):
                v[r] = 0.0
            vv = 0.0
            break
        vnn = _dot(vn, vn)
        if not vnn < vv:
            # no progress (rounding): restore the previous simplex and stop
            for q in range(4):
                for r in range(3):
                    W[q, r] = bW[q, r]
                IA[q] = bIA[q]
                IB[q] = bIB[q]
                lam[q] = blam[q]
            k = bk
            break
        k = _compact(mask, k, W, IA, IB, lam)
        for r in range(3):
            v[r] = vn[r]
        vv = vnn

    # points of A and B from the barycentric coordinates (exact convex combinations)
    ls = 0.0
    for q in range(k):
        ls += lam[q]
    pa = fbuf[11]
    pb = fbuf[12]
    dv = fbuf[13]
    lw = 0.0
    for q in range(k):
        lq = lam[q] / ls
        for r in range(3):
            pa[r] += lq * VA[IA[q], r]
            pb[r] += lq * VB[IB[q], r]
            dv[r] += lq * (VA[IA[q], r] - VB[IB[q], r])
        lw = max(lw, np.sqrt(_dot(W[q], W[q])))
    upper = np.sqrt(_dot(dv, dv)) + pad + 8.0 * _U * lw

    if status == SEPARATED and vv > tiny * tiny:
        # final separating-axis bound in the (stably computed) direction -v (A to B)
        for r in range(3):
            vn[r] = -v[r]
        lb = _axis_bound(VA, VB, vn)
        if lb > best_lower:
            best_lower = lb
        sv = np.sqrt(vv)
        if sv - best_lower > 8.0 * rel_pad * S + 1e-13 * sv:
            # loose (e.g. a sliver simplex face whose cross-product normal lost
            # precision): try the sub-simplex directions, then the SAT candidates
            lb = _simplex_directions_bound(VA, VB, W, k)
            if lb > best_lower:
                best_lower = lb
        if sv - best_lower > 8.0 * rel_pad * S + 1e-13 * sv:
            lb = _sat_lower(VA, VB, EA, EB, WNA, WNB, any_polytope, max_edge_pairs, vn)
            if lb > best_lower:
                best_lower = lb
        if sv - best_lower > 8.0 * rel_pad * S + 1e-13 * sv:
            # parallel edges overlapping by a tiny amount: the Minkowski edge is tiny, so
            # its computed direction is poor, but the true normal is v made exactly
            # perpendicular to the (long, accurate) edge direction of A or B
            lb = _edge_perp_bound(VA, VB, EA, EB, vn)
            if lb > best_lower:
                best_lower = lb
        lower = best_lower - pad
        est = np.sqrt(vv)
        if est > upper:
            est = upper
        if est < lower:
            est = lower
    else:
        if status == SEPARATED:
            status = TOUCHING
        sat = best_lower
        if status == OVERLAP:
            r_in = _tetra_inradius(W, pad_coord, rel_pad)
            if any_polytope:
                lb_epa = np.full(1, -np.inf)
                # np.int64(32): the int64 specialisation Python callers get too (literal 32: another one)
                r_in = max(r_in, _epa_inradius(VA, VB, W, pad_coord, rel_pad, np.int64(32), lb_epa))
                if lb_epa[0] > sat:
                    sat = lb_epa[0]
            if r_in > 0.0 and -r_in < upper:
                upper = -r_in
        if not (sat > -np.inf and upper - sat <= 1e-9 * abs(sat) + 4.0 * pad):
            # not converged (touching, EPA stopped early or not applicable): SAT candidates
            lb = _sat_lower(VA, VB, EA, EB, WNA, WNB, any_polytope, max_edge_pairs, v)
            if lb > sat:
                sat = lb
        lower = sat - pad
        if kind_a == KIND_POLYTOPE and kind_b != KIND_POLYTOPE:
            dep = _low_dim_depth(VA, WNA, VB, xc) - 2.0 * pad - dpad_a
        elif kind_b == KIND_POLYTOPE and kind_a != KIND_POLYTOPE:
            dep = _low_dim_depth(VB, WNB, VA, xc) - 2.0 * pad - dpad_b
        else:
            dep = 0.0
        if dep > 0.0 and -dep < upper:
            # a ball of radius dep about a point of the point / segment core lies in the polytope
            upper = -dep
            for r in range(3):
                pa[r] = xc[r]
                pb[r] = xc[r]
        est = sat
        if est > upper:
            est = upper
        if est < lower:
            est = lower
    out[0] = status
    out[1] = est
    out[2] = lower
    out[3] = upper
    for r in range(3):
        out[4 + r] = pa[r]
        out[7 + r] = pb[r]
    out[10] = pad
    out[11] = it


@njit(cache=True, no_cfunc_wrapper=True)
def core_distance_batch(PA, RAs, tAs, EA, NA, PB, RBs, tBs, EB, NB, kind_a, kind_b, dpad_a, dpad_b,
                        rel_pad, abs_pad, eps_rel, max_iter, max_edge_pairs, out):
    """:func:`core_distance` for T poses: RAs (T, 3, 3), tAs (T, 3), ...; out (T, OUT_SIZE)."""
    for t in range(RAs.shape[0]):
        core_distance(PA, RAs[t], tAs[t], EA, NA, PB, RBs[t], tBs[t], EB, NB, kind_a, kind_b, dpad_a, dpad_b,
                      rel_pad, abs_pad, eps_rel, max_iter, max_edge_pairs, out[t])


@njit(cache=True, no_cfunc_wrapper=True)
def halfspace_distance(nH, bH, RH, tH, PC, RC, tC, rel_pad, abs_pad, out):
    """Signed distance of a core (vertex set PC posed by RC, tC) from a half-space.

    The half-space is ``{x : nH . x <= bH}`` in its body frame, posed by RH, tH.
    Closed form: min over core vertices of the plane's signed distance, in the
    frame shifted by tC. Output layout as :func:`core_distance` (p_a on the
    half-space: the projection of the deepest vertex, or the vertex itself when
    it is inside; p_b the vertex), coordinates relative to tC.
    """
    n = np.empty(3)
    for r in range(3):
        n[r] = RH[r, 0] * nH[0] + RH[r, 1] * nH[1] + RH[r, 2] * nH[2]
    nn = np.sqrt(_dot(n, n))
    dlt = np.empty(3)
    for r in range(3):
        dlt[r] = tH[r] - tC[r]
    # plane n . x <= b' in the frame shifted by tC
    bp = bH + _dot(n, dlt)
    V = np.empty((PC.shape[0], 3))
    z = np.zeros(3)
    _transform(PC, RC, z, V)
    S = abs(bH) + np.sqrt(_dot(dlt, dlt))
    for i in range(V.shape[0]):
        for r in range(3):
            S = max(S, abs(V[i, r]))
    pad = 2.0 * rel_pad * S + abs_pad
    bi, smin = _support_min(V, n)
    dist = (smin - bp) / nn
    pb = V[bi]
    out[0] = SEPARATED if dist > 0.0 else OVERLAP
    out[1] = dist
    out[2] = dist - pad
    out[3] = dist + pad
    for r in range(3):
        out[7 + r] = pb[r]
        out[4 + r] = pb[r] - max(dist, 0.0) * n[r] / nn
    out[10] = pad
    out[11] = 0


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
