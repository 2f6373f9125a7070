"""Compiled fat-feature tests of the toleranced checker (Schröcker & Weber §3-§4, numba).

One call per subdivision level evaluates, for every frontier item (a sub-interval
covered by the ball B_R(g) of §5, eq. 9-10) and every unit that fired on the parent
(Remark 2 pruning), the elementary rows of :mod:`monitor.certify.toleranced`:

* the pre-filter (orbit of A inside conv{ball(g(v), F(v))}; §3: the orbit of a point
  under B_R(g) is the ball of radius R rho(x), eq. 4),
* VF / VH: a vertex's ball (§3, eq. 4) against a face of B / a half-space,
* EE: the fat edge (§3, the hyperboloid of eq. 6) against an edge of B,
* FE: the fat face (§3, the two-sheet hyperboloid of eq. 8 over sigma(P), Prop. 1)
  against an edge of B (§4, including the crossing case Listing 2 misses),
* EF: an edge of A crossing a face of B at the centre pose (§4).

Every test is the scalar transcription of the numpy oracle in ``toleranced.py``
(``_kernel_VF``, ``_kernel_EE``, ``_kernel_FE``, ``_kernel_EF``, ``_kernel_VH``,
``_Prefilter.separated``, ``_eps_items``, ``_Ball``): same quantities, same rounding pads,
same NaN rule (a non-finite value fires a row and never separates an item). The numpy
versions stay as the test oracle (``tests/test_fat_kernels.py``).

Layout. Features are the flat arrays of ``toleranced._Concat``; rows are the global
row table (``row_type``, ``row_a``, ``row_b``: for VH ``row_b`` is the pair index);
units are CSR (``unit_ptr``, ``unit_rows``). Rows shared by several units of the same
item are evaluated once (as ``np.unique`` over (item, row) keys in the oracle).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from monitor._jit_cache import bind_caches, purge_if_changed
from monitor.motion.kernel import _search_left, _search_right

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)

T_VF = 0
T_EE = 1
T_FE = 2
T_EF = 3
T_VH = 4
"""Row type codes, in the order of ``toleranced._TYPES``."""

_U = 2.0**-53
_ETA = 1e-9


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _mx(x, y):
    """np.maximum for scalars: NaN if either is NaN."""
    if x != x or y != y:
        return math.nan
    return x if x >= y else y


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _mn(x, y):
    """np.minimum for scalars: NaN if either is NaN."""
    if x != x or y != y:
        return math.nan
    return x if x <= y else y


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _pad2(S, e, rel):
    """Pad (m^2) of a quadratic value whose terms sum to S in absolute value (toleranced doc)."""
    S = abs(S)
    return 8.0 * rel * S + 2.0 * math.sqrt(S) * e + e * e


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _qmax01(a, b, c):
    """Max of a t^2 + b t + c over t in [0, 1] (vertex included if within [-eta, 1 + eta])."""
    best = _mx(c, a + b + c)
    t = -b / (2.0 * a)
    v = c - b * b / (4.0 * a)
    if a < 0 and t >= -_ETA and t <= 1 + _ETA:
        return _mx(best, v)
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _apply(L, p, it, x):
    """g(x) = L[it] x + p[it] for a (3,) body-frame point x; returns three floats."""
    y0 = L[it, 0, 0] * x[0] + L[it, 0, 1] * x[1] + L[it, 0, 2] * x[2] + p[it, 0]
    y1 = L[it, 1, 0] * x[0] + L[it, 1, 1] * x[1] + L[it, 1, 2] * x[2] + p[it, 1]
    y2 = L[it, 2, 0] * x[0] + L[it, 2, 1] * x[1] + L[it, 2, 2] * x[2] + p[it, 2]
    return y0, y1, y2


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _lin(L, it, x):
    """L[it] x for a (3,) direction x."""
    y0 = L[it, 0, 0] * x[0] + L[it, 0, 1] * x[1] + L[it, 0, 2] * x[2]
    y1 = L[it, 1, 0] * x[0] + L[it, 1, 1] * x[1] + L[it, 1, 2] * x[2]
    y2 = L[it, 2, 0] * x[0] + L[it, 2, 1] * x[1] + L[it, 2, 2] * x[2]
    return y0, y1, y2


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _clip(g0, h0, lo, hi, hn, hc, f, w0, w1, dw0, dw1, extra):
    """Intersect [lo, hi] with {s : g_k s <= h_k} for the half-planes of polygon f.

    Row k: g_k = hn[f, k] . dw, h_k = hc[f, k] - hn[f, k] . w + extra (the oracle's
    ``_clip_interval`` with EF's second constraint set). ``g0, h0`` unused placeholders
    keep the call shape uniform. Returns (lo, hi, empty).
    """
    upper = math.inf
    lower = -math.inf
    empty = False
    for k in range(hn.shape[1]):
        g = hn[f, k, 0] * dw0 + hn[f, k, 1] * dw1
        h = hc[f, k] - (hn[f, k, 0] * w0 + hn[f, k, 1] * w1) + extra
        ratio = h / g
        if g > 0:
            upper = _mn(upper, ratio)
        elif g < 0:
            lower = _mx(lower, ratio)
        elif g == 0 and h < 0:
            empty = True
    lo = _mx(lo, lower)
    hi = _mn(hi, upper)
    return lo, hi, empty or (lo > hi)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _row_vf(y0, y1, y2, a, b, it, R2, Dl, eps, aqv, bf_o, bf_n, bf_U, bf_hn, bf_hc, rel):
    """VF: vertex a of A at g(v) = y (ball of radius F(v), eq. 4) against the interior of face b of B."""
    r0, r1, r2 = y0 - bf_o[b, 0], y1 - bf_o[b, 1], y2 - bf_o[b, 2]
    h = r0 * bf_n[b, 0] + r1 * bf_n[b, 1] + r2 * bf_n[b, 2]
    w0 = r0 * bf_U[b, 0, 0] + r1 * bf_U[b, 1, 0] + r2 * bf_U[b, 2, 0]
    w1 = r0 * bf_U[b, 0, 1] + r1 * bf_U[b, 1, 1] + r2 * bf_U[b, 2, 1]
    e = eps[it]
    q = R2[it] * aqv[a] + Dl[it]
    for k in range(bf_hn.shape[1]):
        if bf_hn[b, k, 0] * w0 + bf_hn[b, k, 1] * w1 > bf_hc[b, k] + 4 * e:
            return False
    return not (q - h * h < -_pad2(q + h * h, e, rel))


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _row_vh(y0, y1, y2, a, pr, it, R2, Dl, eps, aqv, h_n, h_off, rel, pad0):
    """VH: vertex a of A at g(v) = y against the half-space of pair pr (h - F concave: vertices suffice)."""
    h = y0 * h_n[pr, 0] + y1 * h_n[pr, 1] + y2 * h_n[pr, 2] - h_off[pr]
    e = eps[it] + pad0 + rel * abs(h_off[pr])
    q = R2[it] * aqv[a] + Dl[it]
    return not ((h > 4 * e) and (q - h * h < -_pad2(q + h * h, e, rel)))


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _row_ee(y0, y1, y2, D0, D1, D2, a, b, R2i, Dl, e, ae_k, be_w0, be_e, rel):
    """EE: fat edge a of A (g(e(s)) = y + s D; hyperboloid of eq. 6, end balls) vs edge b of B."""
    E0, E1, E2 = be_e[b, 0], be_e[b, 1], be_e[b, 2]
    P0, P1, P2 = y0 - be_w0[b, 0], y1 - be_w0[b, 1], y2 - be_w0[b, 2]
    k0, k1, k2 = ae_k[a, 0], ae_k[a, 1], ae_k[a, 2]
    DD = D0 * D0 + D1 * D1 + D2 * D2
    EE = E0 * E0 + E1 * E1 + E2 * E2
    DE = D0 * E0 + D1 * E1 + D2 * E2
    PD = P0 * D0 + P1 * D1 + P2 * D2
    PE = P0 * E0 + P1 * E1 + P2 * E2
    PP = P0 * P0 + P1 * P1 + P2 * P2
    a_ss = R2i * k2 - DD
    a_tt = -EE
    a_st = 2.0 * DE
    b_s = R2i * k1 - 2.0 * PD
    b_t = 2.0 * PE
    c = R2i * k0 + Dl - PP
    sq = math.sqrt(PP) + math.sqrt(DD) + math.sqrt(EE)
    S = abs(R2i * k0) + Dl + abs(R2i * k1) + abs(R2i * k2) + sq * sq
    pad = _pad2(S, e, rel)
    best = _qmax01(a_tt, b_t, c)
    best = _mx(best, _qmax01(a_tt, b_t + a_st, c + a_ss + b_s))
    best = _mx(best, _qmax01(a_ss, b_s, c))
    best = _mx(best, _qmax01(a_ss, b_s + a_st, c + a_tt + b_t))
    fire = not (best < -pad)
    det = 4.0 * a_ss * a_tt - a_st * a_st
    band = 1e3 * _U * (4.0 * abs(a_ss * a_tt) + a_st * a_st)
    deg = (DD == 0) or (EE == 0)
    if (not deg) and abs(det) <= band:
        return True
    if (not deg) and a_ss < 0 and det > band:
        s_ = (-2.0 * a_tt * b_s + a_st * b_t) / det
        t_ = (-2.0 * a_ss * b_t + a_st * b_s) / det
        val = c + 0.5 * (b_s * s_ + b_t * t_)
        cc = 2 * abs(a_ss) + abs(a_st) + 2 * abs(a_tt)
        cond = cc * cc / det
        if s_ >= -_ETA and s_ <= 1 + _ETA and t_ >= -_ETA and t_ <= 1 + _ETA:
            Sx = S + abs(b_s * s_) + abs(b_t * t_)
            if val >= -_pad2(Sx, e, rel) * (1.0 + cond):
                fire = True
    return fire


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _face_frame(a, it, L, p, R2i, af_o, af_U, af_K, out):
    """Per (face a of A, item): g(o) (3), L U (3, 2) column-major (6), a11, a12, a22, det, band (5).

    The FE quantities that do not depend on B's edge (the 2x2 Hessian G - R^2 K, eq. 7-8).
    """
    o0, o1, o2 = _apply(L, p, it, af_o[a])
    u00 = L[it, 0, 0] * af_U[a, 0, 0] + L[it, 0, 1] * af_U[a, 1, 0] + L[it, 0, 2] * af_U[a, 2, 0]
    u10 = L[it, 1, 0] * af_U[a, 0, 0] + L[it, 1, 1] * af_U[a, 1, 0] + L[it, 1, 2] * af_U[a, 2, 0]
    u20 = L[it, 2, 0] * af_U[a, 0, 0] + L[it, 2, 1] * af_U[a, 1, 0] + L[it, 2, 2] * af_U[a, 2, 0]
    u01 = L[it, 0, 0] * af_U[a, 0, 1] + L[it, 0, 1] * af_U[a, 1, 1] + L[it, 0, 2] * af_U[a, 2, 1]
    u11 = L[it, 1, 0] * af_U[a, 0, 1] + L[it, 1, 1] * af_U[a, 1, 1] + L[it, 1, 2] * af_U[a, 2, 1]
    u21 = L[it, 2, 0] * af_U[a, 0, 1] + L[it, 2, 1] * af_U[a, 1, 1] + L[it, 2, 2] * af_U[a, 2, 1]
    a11 = (u00 * u00 + u10 * u10 + u20 * u20) - R2i * af_K[a, 0, 0]
    a12 = (u00 * u01 + u10 * u11 + u20 * u21) - R2i * af_K[a, 0, 1]
    a22 = (u01 * u01 + u11 * u11 + u21 * u21) - R2i * af_K[a, 1, 1]
    det = a11 * a22 - a12 * a12
    out[0], out[1], out[2] = o0, o1, o2
    out[3], out[4], out[5], out[6], out[7], out[8] = u00, u10, u20, u01, u11, u21
    out[9], out[10], out[11], out[12] = a11, a12, a22, det
    out[13] = 1e3 * _U * (abs(a11 * a22) + a12 * a12)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _row_fe(fr_, a, b, R2i, Dl, e, af_k0, af_kg, af_hn, af_hc, be_w0, be_e, rel):
    """FE: fat face a of A (two-sheet hyperboloid, eq. 8, Prop. 1) against edge b of B.

    ``fr_`` is the face's :func:`_face_frame` for the item.
    """
    o0, o1, o2 = fr_[0], fr_[1], fr_[2]
    u00, u10, u20, u01, u11, u21 = fr_[3], fr_[4], fr_[5], fr_[6], fr_[7], fr_[8]
    a11, a12, a22, det, band = fr_[9], fr_[10], fr_[11], fr_[12], fr_[13]
    E0, E1, E2 = be_e[b, 0], be_e[b, 1], be_e[b, 2]
    P0, P1, P2 = o0 - be_w0[b, 0], o1 - be_w0[b, 1], o2 - be_w0[b, 2]
    if not (abs(det) > band):
        return True            # ambiguous (or NaN): fire
    if not (a11 > 0 and det > band):
        return False           # some beta_i >= 1: the face part is empty (EE covers the boundary)
    ca0 = R2i * af_kg[a, 0] - (u00 * P0 + u10 * P1 + u20 * P2)
    ca1 = R2i * af_kg[a, 1] - (u01 * P0 + u11 * P1 + u21 * P2)
    cb0 = u00 * E0 + u10 * E1 + u20 * E2
    cb1 = u01 * E0 + u11 * E1 + u21 * E2
    wa0 = (a22 * ca0 - a12 * ca1) / det
    wa1 = (-a12 * ca0 + a11 * ca1) / det
    wb0 = (a22 * cb0 - a12 * cb1) / det
    wb1 = (-a12 * cb0 + a11 * cb1) / det
    EE_ = E0 * E0 + E1 * E1 + E2 * E2
    PE = P0 * E0 + P1 * E1 + P2 * E2
    PP = P0 * P0 + P1 * P1 + P2 * P2
    cbwb = cb0 * wb0 + cb1 * wb1
    cawb = ca0 * wb0 + ca1 * wb1
    cawa = ca0 * wa0 + ca1 * wa1
    k0 = af_k0[a]
    v2 = -EE_ + cbwb
    v1 = 2.0 * PE + 2.0 * cawb
    v0 = R2i * k0 + Dl - PP + cawa
    S = abs(R2i * k0) + Dl + PP + abs(cawa) + 2 * abs(PE) + 2 * abs(cawb) + EE_ + abs(cbwb)
    cc = abs(a11) + abs(a22) + 2 * abs(a12)
    cond = cc * cc / det
    pad = _pad2(S, e, rel) * (1.0 + cond)
    # tau-interval where w*(tau) = wa + tau wb lies in P (widened)
    wscale = 1.0 + math.sqrt(wa0 * wa0 + wa1 * wa1) + math.sqrt(wb0 * wb0 + wb1 * wb1)
    extra = _ETA * wscale * (1.0 + cond * 1e-6) + 4 * e
    lo, hi, empty = _clip(0.0, 0.0, -_ETA, 1.0 + _ETA, af_hn, af_hc, a, wa0, wa1, wb0, wb1, extra)
    ok = not empty
    lo_c = lo if ok else 0.0
    hi_c = hi if ok else 0.0
    best = _mx(v0 + v1 * lo_c + v2 * lo_c * lo_c, v0 + v1 * hi_c + v2 * hi_c * hi_c)
    tv = -v1 / (2.0 * v2)
    if v2 < 0 and tv >= lo_c and tv <= hi_c:
        best = _mx(best, v0 + v1 * tv + v2 * tv * tv)
    return (ok and not (best < -pad)) or not math.isfinite(best)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _row_ef(y0, y1, y2, D0, D1, D2, b, it, eps, bf_o, bf_n, bf_U, bf_hn, bf_hc):
    """EF: edge a of A at the centre pose, y + s D, crosses polygon b of B (slab |h| <= e, clipped by b)."""
    r0, r1, r2 = y0 - bf_o[b, 0], y1 - bf_o[b, 1], y2 - bf_o[b, 2]
    h0 = r0 * bf_n[b, 0] + r1 * bf_n[b, 1] + r2 * bf_n[b, 2]
    dh = D0 * bf_n[b, 0] + D1 * bf_n[b, 1] + D2 * bf_n[b, 2]
    e = 4 * eps[it]
    # slab -e <= h0 + s dh <= e as two rows (g, h) = (dh, e - h0), (-dh, e + h0)
    upper = math.inf
    lower = -math.inf
    empty = False
    for k in range(2):
        g = dh if k == 0 else -dh
        h = (e - h0) if k == 0 else (e + h0)
        ratio = h / g
        if g > 0:
            upper = _mn(upper, ratio)
        elif g < 0:
            lower = _mx(lower, ratio)
        elif g == 0 and h < 0:
            empty = True
    lo = _mx(-_ETA, lower)
    hi = _mn(1.0 + _ETA, upper)
    empty = empty or (lo > hi)
    w0 = r0 * bf_U[b, 0, 0] + r1 * bf_U[b, 1, 0] + r2 * bf_U[b, 2, 0]
    w1 = r0 * bf_U[b, 0, 1] + r1 * bf_U[b, 1, 1] + r2 * bf_U[b, 2, 1]
    dw0 = D0 * bf_U[b, 0, 0] + D1 * bf_U[b, 1, 0] + D2 * bf_U[b, 2, 0]
    dw1 = D0 * bf_U[b, 0, 1] + D1 * bf_U[b, 1, 1] + D2 * bf_U[b, 2, 1]
    lo2, hi2, empty2 = _clip(0.0, 0.0, lo, hi, bf_hn, bf_hc, b, w0, w1, dw0, dw1, e)
    return (not empty) and (not empty2)


@njit(cache=True, no_cfunc_wrapper=True, error_model="numpy")
def fat_level(pair, L, p, R, rho_max, r_pair, a_ext, b_ext, flat_a, flat_b, sqj,
              pf_V, pf_qv, pf_n, pf_off, pf_on, pf_two, use_prefilter,
              av, aqv, ae_v0, ae_d, ae_k, af_o, af_U, af_k0, af_kg, af_K, af_hn, af_hc,
              be_w0, be_e, bf_o, bf_n, bf_U, bf_hn, bf_hc, h_n, h_off,
              row_type, row_a, row_b, unit_ptr, unit_rows, unit_item, unit_id,
              rel_pad, abs_pad, scale_pad, short_circuit,
              sep, unit_fired, rows_per_item, units_per_item):
    """One subdivision level of the fat-feature stage (§6 Listing 1-2 inner tests, §3-§4).

    Args:
        pair: (N,) pair index of each item. L (N, 3, 3), p (N, 3): the centre g (A body
            frame -> B frame); R (N,): the padded ball radius (m, metric of §2).
        rho_max, r_pair, a_ext, b_ext, flat_a, flat_b, sqj: (P,) per pair: max rho over A
            (already widened), inflation radius r (m), coordinate extents (m), face
            non-planarity (m), sqrt(lambda_max(J^-1)).
        pf_*: the pre-filter tables (``toleranced._Prefilter``); ``use_prefilter`` 0/1.
        av ... h_off: the features (``toleranced._Concat``).
        row_type, row_a, row_b: (n_rows,) global row table; unit_ptr, unit_rows: unit CSR.
        unit_item, unit_id: (K,) active (item, unit) pairs.
        rel_pad, abs_pad, scale_pad: ``Tolerances`` fields.
        short_circuit: 1 = a unit stops at its first firing row (the unit's answer is the OR
            of its rows, so ``unit_fired`` is the same; fewer rows are evaluated and counted),
            0 = every row of every active unit is evaluated (the oracle's counts).
        sep: out (N,) bool, item excluded by the pre-filter.
        unit_fired: out (K,) bool. rows_per_item, units_per_item: out (N,) int64, distinct
            rows evaluated / units tested per item.

    Returns:
        Number of distinct (item, row) evaluations (the oracle's ``len(ukey)``).
    """
    N = pair.shape[0]
    R2 = np.empty(N)
    Dl = np.empty(N)
    eps = np.empty(N)
    for i in range(N):
        k = pair[i]
        Ri = R[i]
        R2[i] = Ri * Ri
        r = r_pair[k]
        ru = r + rel_pad * abs(r) + abs_pad
        Dl[i] = ru * ru + 2.0 * ru * Ri * rho_max[k]
        Lf = 0.0
        for a in range(3):
            for b in range(3):
                Lf += L[i, a, b] * L[i, a, b]
        Lf = math.sqrt(Lf)
        mag = a_ext[k] + b_ext[k] + math.sqrt(p[i, 0] * p[i, 0] + p[i, 1] * p[i, 1] + p[i, 2] * p[i, 2]) + 1.0
        eps[i] = abs_pad + (scale_pad + 8 * rel_pad) * mag + flat_a[k] * (Lf + Ri * sqj[k]) + flat_b[k]
        sep[i] = False
        rows_per_item[i] = 0
        units_per_item[i] = 0
        if use_prefilter and pf_on[k]:
            sep[i] = _separated(i, k, L, p, R2, Dl, eps, pf_V, pf_qv, pf_n, pf_off, pf_two[k], rel_pad)
    n_rows = row_type.shape[0]
    stamp = np.full(n_rows, -1, np.int64)
    val = np.zeros(n_rows, np.bool_)
    # per item, the A features mapped by g (computed on first use; same expressions as per row)
    yv = np.empty((av.shape[0], 3))
    st_v = np.full(av.shape[0], -1, np.int64)
    ye = np.empty((ae_v0.shape[0], 6))
    st_e = np.full(ae_v0.shape[0], -1, np.int64)
    ff = np.empty((af_o.shape[0], 14))
    st_f = np.full(af_o.shape[0], -1, np.int64)
    # units grouped by item, stable (counting sort; numba's argsort costs seconds of cold compile)
    start = np.zeros(N + 1, np.int64)
    for j in range(unit_item.shape[0]):
        start[unit_item[j] + 1] += 1
    for i in range(N):
        start[i + 1] += start[i]
    order = np.empty(unit_item.shape[0], np.int64)
    for j in range(unit_item.shape[0]):
        order[start[unit_item[j]]] = j
        start[unit_item[j]] += 1
    total = 0
    for j in range(order.shape[0]):
        ku = order[j]
        it = unit_item[ku]
        unit_fired[ku] = False
        if sep[it]:
            continue
        units_per_item[it] += 1
        u = unit_id[ku]
        fired = False
        for q in range(unit_ptr[u], unit_ptr[u + 1]):
            g = unit_rows[q]
            if stamp[g] == it:
                f = val[g]
            else:
                t, a, b = row_type[g], row_a[g], row_b[g]
                if t == T_VF or t == T_VH:
                    if st_v[a] != it:
                        yv[a, 0], yv[a, 1], yv[a, 2] = _apply(L, p, it, av[a])
                        st_v[a] = it
                    if t == T_VF:
                        f = _row_vf(yv[a, 0], yv[a, 1], yv[a, 2], a, b, it, R2, Dl, eps, aqv, bf_o, bf_n,
                                    bf_U, bf_hn, bf_hc, rel_pad)
                    else:
                        f = _row_vh(yv[a, 0], yv[a, 1], yv[a, 2], a, b, it, R2, Dl, eps, aqv, h_n, h_off,
                                    rel_pad, abs_pad)
                elif t == T_EE or t == T_EF:
                    if st_e[a] != it:
                        ye[a, 0], ye[a, 1], ye[a, 2] = _apply(L, p, it, ae_v0[a])
                        ye[a, 3], ye[a, 4], ye[a, 5] = _lin(L, it, ae_d[a])
                        st_e[a] = it
                    if t == T_EE:
                        f = _row_ee(ye[a, 0], ye[a, 1], ye[a, 2], ye[a, 3], ye[a, 4], ye[a, 5], a, b, R2[it],
                                    Dl[it], eps[it], ae_k, be_w0, be_e, rel_pad)
                    else:
                        f = _row_ef(ye[a, 0], ye[a, 1], ye[a, 2], ye[a, 3], ye[a, 4], ye[a, 5], b, it, eps,
                                    bf_o, bf_n, bf_U, bf_hn, bf_hc)
                else:
                    if st_f[a] != it:
                        _face_frame(a, it, L, p, R2[it], af_o, af_U, af_K, ff[a])
                        st_f[a] = it
                    f = _row_fe(ff[a], a, b, R2[it], Dl[it], eps[it], af_k0, af_kg, af_hn, af_hc, be_w0, be_e,
                                rel_pad)
                stamp[g] = it
                val[g] = f
                rows_per_item[it] += 1
                total += 1
            fired = fired or f
            if fired and short_circuit:
                break
        unit_fired[ku] = fired
    return total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _separated(i, k, L, p, R2, Dl, eps, V, qv, n, off, two, rel_pad):
    """Pre-filter of item i (pair k): the orbit's hull conv{ball(g(v), F(v))} misses a face plane of B.

    NaN anywhere makes the pad NaN, and then nothing separates (the oracle's rule).
    """
    nv = V.shape[1]
    nf = n.shape[1]
    Fmax = -math.inf
    hmax = -math.inf
    omax = -math.inf
    Y = np.empty((nv, 3))
    F = np.empty(nv)
    for v in range(nv):
        y0, y1, y2 = _apply(L, p, i, V[k, v])
        Y[v, 0], Y[v, 1], Y[v, 2] = y0, y1, y2
        F[v] = math.sqrt(R2[i] * qv[k, v] + Dl[i])
        Fmax = _mx(Fmax, F[v])
    for f in range(nf):
        omax = _mx(omax, abs(off[k, f]))
        for v in range(nv):
            h = n[k, f, 0] * Y[v, 0] + n[k, f, 1] * Y[v, 1] + n[k, f, 2] * Y[v, 2] - off[k, f]
            hmax = _mx(hmax, abs(h))
    pad = 8.0 * rel_pad * (hmax + Fmax + omax) + 4.0 * eps[i]
    if pad != pad:
        return False
    for f in range(nf):
        lo = math.inf
        hi = -math.inf
        for v in range(nv):
            h = n[k, f, 0] * Y[v, 0] + n[k, f, 1] * Y[v, 1] + n[k, f, 2] * Y[v, 2] - off[k, f]
            lo = _mn(lo, h - F[v])
            hi = _mx(hi, h + F[v])
        if lo > pad:
            return True
        if two and hi < -pad:
            return True
    return False


@njit(cache=True, no_cfunc_wrapper=True, error_model="numpy")
def traj_balls(pair, body_a, body_b, pos, rot, trans, angle, ref, mp_all, mw_all, mp_off, pad_factor,
               L_out, p_out, R_out):
    """Balls B_R(g) of a trajectory's sub-intervals (§2 metric, §5; ``toleranced._TrajectoryBalls``).

    For item n of pair k (A = body_a[k] moving, B = body_b[k] fixed side): the centre is the
    relative pose at the midpoint, g = X_WB^-1 X_WA (L = R_WB^T R_WA, p = R_WB^T (p_WA - p_WB));
    a metric point m of A moves by at most delta(m) = T_A + chord(angle_A) |m - c_A| + T_B +
    chord(angle_B) |g(m) - c_B| (the motion-bound contract applied to A at m and to B at g(m)),
    padded by ``pad_factor``; R^2 = sum_i w_i delta(m_i)^2 (the metric's definition, eq. 1-3).

    Args:
        pair: (N,) pair of each item. body_a, body_b: (P,) body indices.
        pos (N, nbody, 3), rot (N, nbody, 3, 3): world poses at the item midpoints.
        trans, angle: (N, nbody) motion bounds of the items' sub-intervals (m, rad).
        ref: (nbody, 3) reference points of the bounds (body frames).
        mp_all (M, 3), mw_all (M,): metric points and weights of every pair's A, CSR by
            mp_off (P + 1,).
        pad_factor: 1 + 8 rel_pad.
        L_out (N, 3, 3), p_out (N, 3), R_out (N,): outputs (R unpadded, as the oracle).
    """
    for n in range(pair.shape[0]):
        k = pair[n]
        a = body_a[k]
        b = body_b[k]
        for i in range(3):
            for c in range(3):
                L_out[n, i, c] = rot[n, b, 0, i] * rot[n, a, 0, c] + rot[n, b, 1, i] * rot[n, a, 1, c] \
                    + rot[n, b, 2, i] * rot[n, a, 2, c]
            p_out[n, i] = rot[n, b, 0, i] * (pos[n, a, 0] - pos[n, b, 0]) \
                + rot[n, b, 1, i] * (pos[n, a, 1] - pos[n, b, 1]) \
                + rot[n, b, 2, i] * (pos[n, a, 2] - pos[n, b, 2])
        TA, TB = trans[n, a], trans[n, b]
        chA = 2.0 * math.sin(0.5 * _mn(angle[n, a], math.pi))
        chB = 2.0 * math.sin(0.5 * _mn(angle[n, b], math.pi))
        R2 = 0.0
        for j in range(mp_off[k], mp_off[k + 1]):
            m0, m1, m2 = mp_all[j, 0], mp_all[j, 1], mp_all[j, 2]
            x0, x1, x2 = m0 - ref[a, 0], m1 - ref[a, 1], m2 - ref[a, 2]
            dA = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
            y0 = L_out[n, 0, 0] * m0 + L_out[n, 0, 1] * m1 + L_out[n, 0, 2] * m2 + p_out[n, 0] - ref[b, 0]
            y1 = L_out[n, 1, 0] * m0 + L_out[n, 1, 1] * m1 + L_out[n, 1, 2] * m2 + p_out[n, 1] - ref[b, 1]
            y2 = L_out[n, 2, 0] * m0 + L_out[n, 2, 1] * m1 + L_out[n, 2, 2] * m2 + p_out[n, 2] - ref[b, 2]
            dB = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            d = (TA + chA * dA + TB + chB * dB) * pad_factor
            R2 += mw_all[j] * d * d
        R_out[n] = math.sqrt(R2)


# ---------------------------------------------------------------------------- screw motions
# Poses and bounds of a screw BodyMotion (monitor.motion.bodymotion, module docstring: "Screw
# motion bound (derivation)"), the scalar transcription of BodyMotion._poses / _bounds /
# _screw_ref_deviation and of _kinematics (Segments.locate, QuatTrack.interp,
# vector_deviation, rotation_deviation) and _screw (screw_point, helix_span). The numpy
# methods stay the oracle (tests/test_fat_kernels.py).


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _locate(times, t):
    """Segment i, parameter s in [0, 1], at_end (``Segments.locate``)."""
    K = times.shape[0]
    i = _search_right(times, t) - 1
    i = min(max(i, 0), K - 2)
    s = (t - times[i]) / (times[i + 1] - times[i])
    s = min(max(s, 0.0), 1.0)
    return i, s, t >= times[K - 1]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _screw_b(phi):
    """(phi - sin phi) / phi^3, series below 0.1 (``_screw._b``)."""
    if phi < 0.1:
        p2 = phi * phi
        return 1 / 6 - p2 / 120 + p2**2 / 5040 - p2**3 / 362880 + p2**4 / 39916800
    return (phi - math.sin(phi)) / phi**3


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _helix_span(d, P, th, sigma):
    """Helix displacement sigma sqrt(d^2 + (sinc(th sigma / 2) P)^2), sigma in [0, 1] (``helix_span``)."""
    sigma = min(max(sigma, 0.0), 1.0)
    return sigma * math.hypot(d, np.sinc(th * sigma / (2.0 * np.pi)) * P)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _screw_pose(b, i, s, at_end, pos, quat, target, half, same, rotating, omega, v, x, q):
    """World origin x (3) and quaternion q (4) of body b at (segment i, parameter s)."""
    K = pos.shape[0]
    if at_end:
        for c in range(3):
            x[c] = pos[K - 1, b, c]
        for c in range(4):
            q[c] = quat[K - 1, b, c]
        return
    h = half[i, b]
    den = np.sinc(h / np.pi)
    c0 = (1.0 - s) * np.sinc((1.0 - s) * h / np.pi) / den
    c1 = s * np.sinc(s * h / np.pi) / den
    if same[i, b] or s == 0.0:
        for c in range(4):
            q[c] = quat[i, b, c]
    else:
        for c in range(4):
            q[c] = c0 * quat[i, b, c] + c1 * target[i, b, c]
    if rotating[b] and s != 0.0:
        w0, w1, w2 = omega[i, b, 0], omega[i, b, 1], omega[i, b, 2]
        th = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        phi = s * th
        y0, y1, y2 = pos[i, b, 0], pos[i, b, 1], pos[i, b, 2]
        v0, v1, v2 = v[i, b, 0], v[i, b, 1], v[i, b, 2]
        wy0, wy1, wy2 = _cross(w0, w1, w2, y0, y1, y2)
        wwy0, wwy1, wwy2 = _cross(w0, w1, w2, wy0, wy1, wy2)
        wv0, wv1, wv2 = _cross(w0, w1, w2, v0, v1, v2)
        wwv0, wwv1, wwv2 = _cross(w0, w1, w2, wv0, wv1, wv2)
        k1 = s * np.sinc(phi / np.pi)
        ka = s * s * (0.5 * np.sinc(phi / (2.0 * np.pi)) ** 2)
        kb = s**3 * _screw_b(phi)
        x[0] = y0 + k1 * wy0 + ka * wwy0 + s * v0 + ka * wv0 + kb * wwv0
        x[1] = y1 + k1 * wy1 + ka * wwy1 + s * v1 + ka * wv1 + kb * wwv1
        x[2] = y2 + k1 * wy2 + ka * wwy2 + s * v2 + ka * wv2 + kb * wwv2
    else:
        for c in range(3):
            x[c] = pos[i, b, c] + s * (pos[i + 1, b, c] - pos[i, b, c])


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _quat_mat(q, R):
    """Rotation matrix of q / |q| (``_kinematics.quat_to_mat``)."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    w, x, y, z = q[0] / n, q[1] / n, q[2] / n, q[3] / n
    R[0, 0] = 1 - 2 * (y * y + z * z)
    R[0, 1] = 2 * (x * y - w * z)
    R[0, 2] = 2 * (x * z + w * y)
    R[1, 0] = 2 * (x * y + w * z)
    R[1, 1] = 1 - 2 * (x * x + z * z)
    R[1, 2] = 2 * (y * z - w * x)
    R[2, 0] = 2 * (x * z - w * y)
    R[2, 1] = 2 * (y * z + w * x)
    R[2, 2] = 1 - 2 * (x * x + y * y)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy")
def _path(times, cum, phi, b, t):
    """Cumulative slerp path length of body b at time t (``QuatTrack.path`` after ``locate``)."""
    i, s, _ = _locate(times, t)
    return cum[i, b] + s * phi[i, b]


@njit(cache=True, no_cfunc_wrapper=True, error_model="numpy")
def screw_poses_bounds(times, pos, quat, target, half, phi, cum, same, moving, rotating, omega, v,
                       hx_d, hx_P, hx_th, ref, ref_W, prm, ta, tb, out_pos, out_rot, out_trans, out_angle):
    """Midpoint poses and certified bounds of a screw BodyMotion for N sub-intervals (one call).

    Args:
        times (K,), pos (K, nb, 3), quat (K, nb, 4): waypoints. target, half, phi, same
            (K-1, nb, ...), cum (K, nb): slerp tracks. moving, rotating (nb,) bool.
            omega, v (K-1, nb, 3), hx_d, hx_P, hx_th (K-1, nb): twists and helix constants.
            ref (nb, 3), ref_W (K, nb, 3): reference points (body, world at waypoints).
        prm: (rel_pad, abs_pad, scale_pad, pos_mag, scale, screw_pad).
        ta, tb: (N,) sub-intervals inside the window.
        out_pos (N, nb, 3), out_rot (N, nb, 3, 3): poses at the midpoints;
        out_trans, out_angle (N, nb): the bounds (m, rad), as ``BodyMotion.motion_bounds``.
    """
    rel, ab, scale_pad, pos_mag, scale, screw_pad = prm[0], prm[1], prm[2], prm[3], prm[4], prm[5]
    K, nb = pos.shape[0], pos.shape[1]
    xa = np.empty(3)
    xb = np.empty(3)
    qa = np.empty(4)
    qb = np.empty(4)
    qm = np.empty(4)
    Rm = np.empty((3, 3))
    for n in range(ta.shape[0]):
        t0, t1 = ta[n], tb[n]
        tm = 0.5 * (t0 + t1)
        ia, sa, ea = _locate(times, t0)
        ib, sb, eb = _locate(times, t1)
        im, sm, em = _locate(times, tm)
        lo = _search_right(times, t0)
        hi = _search_left(times, t1)
        # the segments left / right of m and their waypoints strictly before / after m (on a
        # sub-interval one ulp long m rounds to t1; t1's own segment would leave [t0, m] out)
        jl = min(max(_search_left(times, tm) - 1, 0), K - 2)
        jr = min(max(_search_right(times, tm) - 1, 0), K - 2)
        near_left = min(max(times[jl], t0), tm)
        near_right = max(min(times[jr + 1], t1), tm)
        for b in range(nb):
            xm = out_pos[n, b]
            _screw_pose(b, im, sm, em, pos, quat, target, half, same, rotating, omega, v, xm, qm)
            _quat_mat(qm, out_rot[n, b])
            out_trans[n, b] = 0.0
            out_angle[n, b] = 0.0
            if not moving[b]:
                continue
            _screw_pose(b, ia, sa, ea, pos, quat, target, half, same, rotating, omega, v, xa, qa)
            _screw_pose(b, ib, sb, eb, pos, quat, target, half, same, rotating, omega, v, xb, qb)
            # vector_deviation of the waypoint positions
            dx = max(_norm(xa[0] - xm[0], xa[1] - xm[1], xa[2] - xm[2]),
                     _norm(xb[0] - xm[0], xb[1] - xm[1], xb[2] - xm[2]))
            for w in range(lo, hi):
                dx = max(dx, _norm(pos[w, b, 0] - xm[0], pos[w, b, 1] - xm[1], pos[w, b, 2] - xm[2]))
            dx = dx + rel * pos_mag
            th = 0.0
            if rotating[b]:
                nq = math.sqrt(qm[0] * qm[0] + qm[1] * qm[1] + qm[2] * qm[2] + qm[3] * qm[3])
                s_m = cum[im, b] + sm * phi[im, b]
                dev = max(abs(s_m - _path(times, cum, phi, b, near_left)),
                          abs(_path(times, cum, phi, b, near_right) - s_m))
                for w in range(lo, hi):
                    dd = 0.0
                    ss = 0.0
                    for c in range(4):
                        u = quat[w, b, c] - qm[c] / nq
                        dd += u * u
                        u = quat[w, b, c] + qm[c] / nq
                        ss += u * u
                    dd, ss = math.sqrt(dd), math.sqrt(ss)
                    d_w = 4.0 * math.atan2(min(dd, ss), max(dd, ss))
                    t_w = times[w]
                    if t_w <= tm:
                        outer = max(times[max(w - 1, 0)], t0)
                    else:
                        outer = min(times[min(w + 1, K - 1)], t1)
                    dev = max(dev, d_w + abs(_path(times, cum, phi, b, outer) - cum[w, b]))
                dev = min(dev, math.pi)
                th = dev + rel * (cum[K - 1, b] + 1.0)
                th = min(th * (1.0 + rel) + ab, math.pi)
            if rotating[b]:
                # _screw_ref_deviation: helix pieces of the reference point's world image
                left = max(tm - near_left, 0.0) / (times[jl + 1] - times[jl])
                right = max(near_right - tm, 0.0) / (times[jr + 1] - times[jr])
                T = max(_helix_span(hx_d[jl, b], hx_P[jl, b], hx_th[jl, b], left),
                        _helix_span(hx_d[jr, b], hx_P[jr, b], hx_th[jr, b], right))
                if hi > lo:
                    _quat_mat(qm, Rm)
                    ym0 = xm[0] + Rm[0, 0] * ref[b, 0] + Rm[0, 1] * ref[b, 1] + Rm[0, 2] * ref[b, 2]
                    ym1 = xm[1] + Rm[1, 0] * ref[b, 0] + Rm[1, 1] * ref[b, 1] + Rm[1, 2] * ref[b, 2]
                    ym2 = xm[2] + Rm[2, 0] * ref[b, 0] + Rm[2, 1] * ref[b, 1] + Rm[2, 2] * ref[b, 2]
                    for w in range(lo, hi):
                        d_w = _norm(ref_W[w, b, 0] - ym0, ref_W[w, b, 1] - ym1, ref_W[w, b, 2] - ym2)
                        t_w = times[w]
                        if t_w <= tm:
                            k = min(max(w - 1, 0), K - 2)
                            outer = max(times[max(w - 1, 0)], t0)
                        else:
                            k = min(max(w, 0), K - 2)
                            outer = min(times[min(w + 1, K - 1)], t1)
                        sigma = abs(outer - t_w) / (times[k + 1] - times[k])
                        T = max(T, d_w + _helix_span(hx_d[k, b], hx_P[k, b], hx_th[k, b], sigma))
                T = T + screw_pad
            else:
                T = dx + 2.0 * math.sin(0.5 * min(th, math.pi)) * _norm(ref[b, 0], ref[b, 1], ref[b, 2])
            out_trans[n, b] = T * (1.0 + rel) + ab + scale_pad * scale
            out_angle[n, b] = th


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _norm(x, y, z):
    return math.sqrt(x * x + y * y + z * z)


__all__ = ["fat_level", "traj_balls", "screw_poses_bounds", "T_VF", "T_EE", "T_FE", "T_EF", "T_VH"]


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
