"""Compiled first pass of the extrusion checker for one translating convex pair (issue 12 items 1, 4).

The extrusion checker (:mod:`monitor.certify.extrusion`, Cameron 1990) decides a pair of
translating convex geoms with S-bounds (§4.3, App. B), divide and conquer (§4.1), the
null-set LP (§4.2) and, where those leave a region open, the exact swept least-distance
test (stage ``"exact_swept"``, not in the paper). Every step of that pipeline is Python. For
the common case this module decides the pair in **one compiled call** with the exact swept
test alone, applied per span of the whole window, and hands back to the Python checker
(unchanged) every pair it cannot settle.

The test (the ``"exact_swept"`` stage of the checker, per span)
    Spans are the merged velocity breakpoints of the two bodies inside the window (§3,
    §4.3.2: on a span both origins move linearly). On a span ``[s0, s1]`` of length ``T``,
    with the cores' vertex differences ``D`` (core A minus core B at ``s0``) and the relative
    velocity ``w``, the core difference at ``s0 + tau`` is ``conv(D) + w tau``; its union over
    ``tau in [0, T]`` is ``conv(D) + [0, T] w = conv(D u (D + w T))`` (the extrusion of the
    configuration-space obstacle, §2 eqs. 3-4, projected on space). So the least core
    distance over the span is the distance from the origin to ``conv(D u (D + w T))``: ONE
    min-norm problem (Wolfe's method, :func:`~monitor.certify.extrusion_kernels.min_norm_kernel`,
    float64-verified lower and upper bounds), exactly what the checker's ``quadratic_null_test``
    solves on a leaf pair's S-bound interval. The S-bounds are not needed for the answer: they
    only shrink the interval, and outside it the distance is above the level anyway.

Decision per span, spans in time order (the §6 earliest-first order):
    * certified span: ``lower - data_pad >= r + margin_ext - extrusion_slack`` (the checker's
      own rule at the engine's stronger margin ``margin_ext``; ``r`` the radii);
    * violating span: ``upper + data_pad < r + margin`` (the checker's rule at the true
      margin); every earlier span was certified at the stronger margin, so the earliest
      contact at the true margin is in this span. Its exact first-contact time (§5/§6 earliest
      witness) and the witness time (the first instant at which the distance falls half way
      from the level to the span's minimum) come from
      :func:`~monitor.certify.extrusion_kernels.first_time_kernel` (conservative advancement
      with proved steps, then the bisection rule), as in the Python checker;
    * a half-space against a core: the checker's closed form per span
      (:func:`halfspace_pair_kernel`, the null-set stage of §4.2 for a plane), same rules;
    * anything else (the exactness band, a penetration at zero level, two half-spaces, bad
      input, too many vertices): **undecided**, and the whole pair goes to the Python checker, which then
      decides it exactly as before. So completeness is never below the Python checker's, and
      every pair this pass decides gets the verdict the Python checker's exact test would.

Pads: every coordinate handled is of size at most ``scale = max |origin| + 2 max |core
vertex|`` (world-rotated), and ``data_pad = rel_pad scale + abs_pad`` widens both bounds (the
Python checker's ``data_pad`` for the same pair; the factor 2 covers the rotation's rounding
and the rotated vertices' norm, <= sqrt(3) x their largest component).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from monitor._jit_cache import bind_caches, purge_if_changed
from monitor.certify.common import Outcome, PairOutcome
from monitor.certify.extrusion_kernels import first_time_kernel, min_norm_kernel
from monitor.motion._kinematics import finite_velocities
from monitor.tolerances import Tolerances

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)

SWEPT_MAX_POINTS = 1 << 15
"""At most this many swept difference points (``2 n_a n_b``) per span; larger pairs go to Python."""

CODE_UNDECIDED, CODE_CERTIFIED, CODE_VIOLATION = 0, 1, 2
"""Return codes of :func:`swept_pair_kernel`."""

# out[] slots of swept_pair_kernel
O_CLEAR, O_FIRST, O_WTIME, O_WP, O_FP = 0, 1, 2, 3, 6
O_S0, O_S1, O_DEPTH, O_SPANS, O_SOLVES = 9, 10, 11, 12, 13
OUT_SIZE = 14


@njit(cache=True)
def _body_state(times, origins, s0, s1, o_out, v_out):
    """Origin at ``s0`` and velocity on the span ``[s0, s1]`` (the checker's ``_Body.state``).

    The span lies in the segment that starts at or before ``s0`` (``searchsorted(side="right")``):
    its midpoint would round to ``s0`` or ``s1`` on a span one ulp long and pick a neighbour.
    """
    n = times.shape[0]
    i = np.searchsorted(times, s0, side="right") - 1
    i = min(max(i, 0), n - 2)
    ta = times[i]
    tb = times[i + 1]
    for c in range(3):
        v = (origins[i + 1, c] - origins[i, c]) / (tb - ta)
        v_out[c] = v
        o_out[c] = origins[i, c] + v * (s0 - ta)


@njit(cache=True)
def _valid_motion(times, origins, w0, w1):
    """Strictly increasing finite times covering ``[w0, w1]`` and finite origins (else: undecided)."""
    n = times.shape[0]
    if n < 2 or origins.shape[0] != n:
        return False
    for i in range(n):
        if not np.isfinite(times[i]):
            return False
        for c in range(3):
            if not np.isfinite(origins[i, c]):
                return False
        if i > 0 and not times[i] > times[i - 1]:
            return False
    return times[0] <= w0 and times[n - 1] >= w1


@njit(cache=True)
def _max_abs(rows):
    """Largest |entry| of an (n, 3) array (0.0 when empty): the data scale of the rounding pad."""
    m = 0.0
    for i in range(rows.shape[0]):
        for c in range(3):
            m = max(m, abs(rows[i, c]))
    return m


@njit(cache=True)
def _spans(ta, tb, w0, w1):
    """Sorted breakpoints of the window: w0, every waypoint time of either body inside (w0, w1), w1 (§3)."""
    bps = np.empty(ta.shape[0] + tb.shape[0] + 2)
    nbp = 0
    bps[nbp] = w0
    nbp += 1
    for t in ta:
        if w0 < t < w1:
            bps[nbp] = t
            nbp += 1
    for t in tb:
        if w0 < t < w1:
            bps[nbp] = t
            nbp += 1
    bps[nbp] = w1
    nbp += 1
    return np.sort(bps[:nbp])


@njit(cache=True)
def swept_pair_kernel(Pa, Ra, ta, oa, Pb, Rb, tb, ob, w0, w1, thr_cert, level, rr, rel_pad, abs_pad, out):
    """Decide one translating pair over ``[w0, w1]`` with the exact swept test per span, or leave it.

    Args:
        Pa, Pb: (na, 3), (nb, 3) core vertices in the body frames (m).
        Ra, Rb: (3, 3) constant rotations R_WB.
        ta, oa, tb, ob: (ka,), (ka, 3), (kb,), (kb, 3) breakpoints (s) and world origins (m).
        w0, w1: the window (s).
        thr_cert: a span is certified when its verified lower core distance is ``>= thr_cert``
            (m): ``r_a + r_b + margin_ext - extrusion_slack``.
        level: a span violates when its verified upper core distance is ``< level`` (m):
            ``r_a + r_b + margin`` (``0 <= level <= thr_cert``; at ``level == 0``, two sharp
            cores at margin 0, no upper bound is below it: only certificates are decided,
            penetration is left to the Python checker's LP).
        rr: ``r_a + r_b`` (m), for the clearance.
        rel_pad, abs_pad: rounding pads.
        out: (OUT_SIZE,) output: clearance lower bound (certified), first-contact time,
            witness time, witness point (3,), first-contact point (3,), the violating span,
            its depth (m below the level), spans tested, min-norm solves.

    Returns:
        ``CODE_CERTIFIED``, ``CODE_VIOLATION`` or ``CODE_UNDECIDED`` (the caller runs the
        Python checker on the pair).
    """
    for k in range(OUT_SIZE):
        out[k] = 0.0
    na = Pa.shape[0]
    nb = Pb.shape[0]
    if na < 1 or nb < 1 or 2 * na * nb > SWEPT_MAX_POINTS or not (level >= 0.0) or not (thr_cert >= level):
        return CODE_UNDECIDED
    if not (np.isfinite(w0) and np.isfinite(w1) and w0 < w1):
        return CODE_UNDECIDED
    if not (_valid_motion(ta, oa, w0, w1) and _valid_motion(tb, ob, w0, w1)):
        return CODE_UNDECIDED
    # world-rotated core vertices and the coordinate scale of everything handled below
    A0 = np.empty((na, 3))
    B0 = np.empty((nb, 3))
    ma = 0.0
    for i in range(na):
        for r in range(3):
            A0[i, r] = Ra[r, 0] * Pa[i, 0] + Ra[r, 1] * Pa[i, 1] + Ra[r, 2] * Pa[i, 2]
            ma = max(ma, abs(A0[i, r]), abs(Pa[i, r]))
    mb = 0.0
    for i in range(nb):
        for r in range(3):
            B0[i, r] = Rb[r, 0] * Pb[i, 0] + Rb[r, 1] * Pb[i, 1] + Rb[r, 2] * Pb[i, 2]
            mb = max(mb, abs(B0[i, r]), abs(Pb[i, r]))
    if not (np.isfinite(ma) and np.isfinite(mb)):
        return CODE_UNDECIDED
    scale = max(_max_abs(oa) + 2.0 * ma, _max_abs(ob) + 2.0 * mb)
    data_pad = rel_pad * scale + abs_pad
    bps = _spans(ta, tb, w0, w1)  # spans: merged breakpoints inside the window (§3)
    nbp = bps.shape[0]
    m = na * nb
    P = np.empty((2 * m, 3))
    lam = np.empty(2 * m)
    nrm = np.empty(3)
    Ac = np.empty((na, 3))
    Bc = np.empty((nb, 3))
    o_a = np.empty(3)
    v_a = np.empty(3)
    o_b = np.empty(3)
    v_b = np.empty(3)
    pt = np.empty(3)
    clear = np.inf
    spans = 0
    solves = 0
    for j in range(nbp - 1):
        s0 = bps[j]
        s1 = bps[j + 1]
        if not (s1 > s0):
            continue
        T = s1 - s0
        _body_state(ta, oa, s0, s1, o_a, v_a)
        _body_state(tb, ob, s0, s1, o_b, v_b)
        for c in range(3):   # centre between the two origins (as the checker's leaves)
            cc = 0.5 * (o_a[c] + o_b[c])
            for i in range(na):
                Ac[i, c] = A0[i, c] + (o_a[c] - cc)
            for i in range(nb):
                Bc[i, c] = B0[i, c] + (o_b[c] - cc)
        for i in range(na):
            for k in range(nb):
                for c in range(3):
                    d = Ac[i, c] - Bc[k, c]
                    wv = v_a[c] - v_b[c]
                    P[i * nb + k, c] = d
                    P[m + i * nb + k, c] = d + wv * T
        lower, upper = min_norm_kernel(P, rel_pad, abs_pad, lam, nrm)
        spans += 1
        solves += 1
        lo = lower - data_pad
        up = upper + data_pad
        if lo >= thr_cert:
            clear = min(clear, lower - (rr + data_pad))
            continue
        if not (up < level):
            return CODE_UNDECIDED   # the exactness band (or worse): the Python checker decides
        # violation in this span; every earlier span is clear at thr_cert >= level
        mu = 0.0
        for i in range(m, 2 * m):
            mu += lam[i]
        tau = min(max(T * mu, 0.0), T)
        first, n1, _ = first_time_kernel(Ac, v_a, Bc, v_b, 0.0, tau, level, rel_pad, abs_pad, pt)
        for c in range(3):
            out[O_FP + c] = pt[c] + 0.5 * (o_a[c] + o_b[c])
        tw, n2, _ = first_time_kernel(Ac, v_a, Bc, v_b, 0.0, tau, 0.5 * (level + up), rel_pad, abs_pad, pt)
        for c in range(3):
            out[O_WP + c] = pt[c] + 0.5 * (o_a[c] + o_b[c])
        out[O_FIRST] = s0 + first
        out[O_WTIME] = s0 + tw
        out[O_S0] = s0
        out[O_S1] = s1
        out[O_DEPTH] = level - up
        out[O_CLEAR] = -np.inf
        out[O_SPANS] = spans
        out[O_SOLVES] = solves + n1 + n2
        return CODE_VIOLATION
    out[O_CLEAR] = clear
    out[O_SPANS] = spans
    out[O_SOLVES] = solves
    return CODE_CERTIFIED


_KINDS = ("polytope", "sphere", "capsule")
"""Core kinds of :func:`swept_pair_kernel`; a half-space against one of them takes
:func:`halfspace_pair_kernel`."""


@njit(cache=True)
def halfspace_pair_kernel(n_p, h_p, Pp, Rp, tp, op, Po, Ro, to, oo, w0, w1, thr_cert, level, rr, rel_pad,
                          abs_pad, out):
    """A convex core against a (translating) half-space: the checker's closed form per span.

    The half-space is ``{x : n . x <= h}`` in its body frame (``n_p`` (3,) unit, ``h_p``), on a
    body with rotation ``Rp``, motion ``tp, op``; the core has vertices ``Po`` (body frame),
    rotation ``Ro``, motion ``to, oo``. On a span the signed distance of the core to the plane
    is ``d(tau) = min_i n.(p_i + w tau) - h``, concave and piecewise linear: its minimum over
    the span is at an end, and its first crossing of a level is the smallest per-vertex
    crossing time (the closed form of ``extrusion_null.halfspace_null_test``, counted as the
    null-set stage §4.2: a half-space offset by r is exact). Same rules, levels, pads,
    first-contact and witness times as the Python checker (``_round_pair``).

    Args and returns: as :func:`swept_pair_kernel` (``Pp``: the plane's points, only for the
    coordinate scale).
    """
    for k in range(OUT_SIZE):
        out[k] = 0.0
    no = Po.shape[0]
    if no < 1 or not (level >= 0.0) or not (thr_cert >= level):
        return CODE_UNDECIDED
    if not (np.isfinite(w0) and np.isfinite(w1) and w0 < w1):
        return CODE_UNDECIDED
    if not (_valid_motion(tp, op, w0, w1) and _valid_motion(to, oo, w0, w1)):
        return CODE_UNDECIDED
    nw0 = np.empty(3)
    for r in range(3):
        nw0[r] = Rp[r, 0] * n_p[0] + Rp[r, 1] * n_p[1] + Rp[r, 2] * n_p[2]
    V0 = np.empty((no, 3))
    mo = 0.0
    for i in range(no):
        for r in range(3):
            V0[i, r] = Ro[r, 0] * Po[i, 0] + Ro[r, 1] * Po[i, 1] + Ro[r, 2] * Po[i, 2]
            mo = max(mo, abs(V0[i, r]), abs(Po[i, r]))
    mp = abs(h_p)
    for i in range(Pp.shape[0]):
        for r in range(3):
            mp = max(mp, abs(Pp[i, r]))
    if not (np.isfinite(mo) and np.isfinite(mp) and np.isfinite(nw0[0] + nw0[1] + nw0[2])):
        return CODE_UNDECIDED
    scale = max(_max_abs(op) + 2.0 * mp, _max_abs(oo) + 2.0 * mo)
    data_pad = rel_pad * scale + abs_pad
    bps = _spans(tp, to, w0, w1)
    nbp = bps.shape[0]
    o_p = np.empty(3)
    v_p = np.empty(3)
    o_o = np.empty(3)
    v_o = np.empty(3)
    cc = np.empty(3)
    V = np.empty((no, 3))
    d0 = np.empty(no)
    clear = np.inf
    spans = 0
    for j in range(nbp - 1):
        s0 = bps[j]
        s1 = bps[j + 1]
        if not (s1 > s0):
            continue
        T = s1 - s0
        _body_state(tp, op, s0, s1, o_p, v_p)
        _body_state(to, oo, s0, s1, o_o, v_o)
        for c in range(3):
            cc[c] = 0.5 * (o_p[c] + o_o[c])
        # the plane centred at cc: n . x <= h + n . (o_p - cc); the core V + v_o tau
        h = h_p + (nw0[0] * (o_p[0] - cc[0]) + nw0[1] * (o_p[1] - cc[1]) + nw0[2] * (o_p[2] - cc[2]))
        nw = 0.0
        for c in range(3):
            nw += nw0[c] * (v_o[c] - v_p[c])
        mag = 0.0
        for i in range(no):
            s = 0.0
            m = 0.0
            for c in range(3):
                V[i, c] = V0[i, c] + (o_o[c] - cc[c])
                s += V[i, c] * nw0[c]
                m += abs(V[i, c]) * abs(nw0[c])
            d0[i] = s - h
            mag = max(mag, m + abs(h) + abs(nw) * T)
        # the minimum over both ends, the span start first on ties (the checker's argmin order)
        dmin = np.inf
        tmin = 0.0
        for i in range(no):
            if d0[i] < dmin:
                dmin = d0[i]
        for i in range(no):
            e1 = d0[i] + nw * T
            if e1 < dmin:
                dmin, tmin = e1, T
        pad_w = 8 * rel_pad * mag + abs_pad   # the checker's witness-level call has no data pad
        pad = pad_w + data_pad
        spans += 1
        if dmin - pad >= thr_cert:
            clear = min(clear, dmin - pad - rr)
            continue
        if not (dmin + pad < level):
            return CODE_UNDECIDED
        # first crossing of the level, and of the witness level half way to the minimum
        first = np.inf
        lw = 0.5 * (level + dmin)
        wt = np.inf
        for i in range(no):
            if d0[i] < level:
                first = 0.0
            elif nw < 0:
                first = min(first, min(max((level - d0[i]) / nw, 0.0), T))
            if d0[i] < lw:
                wt = 0.0
            elif nw < 0:
                wt = min(wt, min(max((lw - d0[i]) / nw, 0.0), T))
        if not (dmin + pad_w < lw) or not np.isfinite(wt):
            wt = tmin   # the checker: no proved crossing of the witness level -> the minimum's end
        if not np.isfinite(first):
            return CODE_UNDECIDED
        kw = 0
        dw = np.inf
        for i in range(no):
            dv = d0[i] + nw * wt
            if dv < dw:
                dw, kw = dv, i
        for c in range(3):
            out[O_WP + c] = V[kw, c] + v_o[c] * wt - 0.5 * dw * nw0[c] + cc[c]
            out[O_FP + c] = V[kw, c] + v_o[c] * first + cc[c]
        out[O_FIRST] = s0 + first
        out[O_WTIME] = s0 + wt
        out[O_S0] = s0
        out[O_S1] = s1
        out[O_DEPTH] = level - (dmin + pad)
        out[O_CLEAR] = -np.inf
        out[O_SPANS] = spans
        out[O_SOLVES] = 0
        return CODE_VIOLATION
    out[O_CLEAR] = clear
    out[O_SPANS] = spans
    return CODE_CERTIFIED


def _f(x: Any) -> np.ndarray:
    """``x`` as a writable C-contiguous float64 array (one kernel specialisation; a copy if needed)."""
    if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable:
        return x
    return np.array(x, dtype=np.float64, order="C")


def decide_pair(shape_a: Any, R_a: np.ndarray, times_a: np.ndarray, origins_a: np.ndarray,
                shape_b: Any, R_b: np.ndarray, times_b: np.ndarray, origins_b: np.ndarray,
                window: tuple[float, float], margin: float, margin_ext: float, tol: Tolerances,
                names: tuple[str, str] = ("a", "b")) -> PairOutcome | None:
    """The compiled exact swept test on one translating pair, or None (run the Python checker).

    Args:
        shape_a, shape_b: :class:`~monitor.geometry.shapes.ConvexShape` geoms (body frame);
            half-spaces are never decided here.
        R_a, R_b: (3, 3) constant rotations R_WB.
        times_a, origins_a, times_b, origins_b: (k+1,), (k+1, 3) piecewise-linear motion.
        window: (t0, t1) seconds.
        margin: the true margin (m): violations are decided at it.
        margin_ext: the stronger margin (m) certificates are decided at (the engine's
            ``margin + extrusion_slack + pad(margin)``; ``>= margin``).
        tol: tolerances (pads, ``extrusion_slack``).
        names: (geom_a, geom_b) for ``info["geoms"]``.

    Returns:
        A :class:`PairOutcome` with ``info["stage"] == "exact_swept"`` and
        ``info["test"] == "swept_kernel"`` ("certified": ``clearance`` a verified lower
        bound of the distance over the window; "violation": ``witness_time``,
        ``witness_point``, ``info["earliest_time"]`` the exact first contact at ``margin``,
        ``intervals == [(earliest, witness)]``), or None when the pass cannot decide.
    """
    if not (finite_velocities(times_a.tolist(), origins_a)
            and finite_velocities(times_b.tolist(), origins_b)):
        return None   # a segment velocity overflows: bad input, which the Python checker refuses (red team 7)
    ka, kb = shape_a.kind, shape_b.kind
    plane = ka == "halfspace" or kb == "halfspace"
    if plane and (ka == kb or (ka if kb == "halfspace" else kb) not in _KINDS):
        return None   # two planes (the checker raises) or an unknown kind
    if not plane and (ka not in _KINDS or kb not in _KINDS):
        return None
    ra, rb = float(shape_a.radius), float(shape_b.radius)
    rr = ra + rb
    # the Python checker's thresholds: r = radii + margin; certified iff lower >= r - slack
    thr_cert = ra + rb + margin_ext - tol.extrusion_slack
    level = ra + rb + margin
    out = np.empty(OUT_SIZE)
    if plane:
        sides = [(shape_a, R_a, times_a, origins_a), (shape_b, R_b, times_b, origins_b)]
        if ka != "halfspace":
            sides.reverse()
        (sp, Rp, tp, op), (so, Ro, to, oo) = sides
        if len(sp.normals) != 1:
            return None
        code = halfspace_pair_kernel(_f(sp.normals[0]), float(sp.offsets[0]), _f(sp.points), _f(Rp), _f(tp),
                                     _f(op), _f(so.points), _f(Ro), _f(to), _f(oo), float(window[0]),
                                     float(window[1]), float(thr_cert), float(level), float(rr),
                                     float(tol.rel_pad), float(tol.abs_pad), out)
    else:
        code = swept_pair_kernel(_f(shape_a.points), _f(R_a), _f(times_a), _f(origins_a),
                                 _f(shape_b.points), _f(R_b), _f(times_b), _f(origins_b),
                                 float(window[0]), float(window[1]), float(thr_cert), float(level), float(rr),
                                 float(tol.rel_pad), float(tol.abs_pad), out)
    if code == CODE_UNDECIDED:
        return None
    o = out.tolist()
    # the stage names follow the checker's: the half-space closed form is its null-set stage
    info: dict[str, Any] = {"geoms": [names[0], names[1]], "test": "swept_kernel",
                            "stage": "null_set" if plane else "exact_swept",
                            "spans": int(o[O_SPANS]), "solves": int(o[O_SOLVES])}
    if plane:
        info["closed_form"] = "halfspace"
    if code == CODE_CERTIFIED:
        clr = o[O_CLEAR]
        return PairOutcome(Outcome.CERTIFIED, int(o[O_SPANS]), 0, [], clr if clr < np.inf else float("inf"),
                           None, None, info)
    first, tw = o[O_FIRST], o[O_WTIME]
    info.update({"earliest_time": first, "earliest_point": o[O_FP:O_FP + 3], "span": [o[O_S0], o[O_S1]],
                 "depth": o[O_DEPTH], "earliest_exact": True})
    return PairOutcome(Outcome.VIOLATION, int(o[O_SPANS]), 0, [(first, tw)], float("-inf"), tw,
                       np.array(o[O_WP:O_WP + 3]), info)


def warm() -> None:
    """Compile (or load from the numba cache) :func:`swept_pair_kernel` (both outcomes)."""
    P = np.array([[0.0, 0.0, 0.0]])
    eye = np.eye(3)
    t = np.array([0.0, 1.0])
    oa = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    ob = np.array([[3.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    out = np.empty(OUT_SIZE)
    swept_pair_kernel(P, eye, t, oa, P, eye, t, ob, 0.0, 1.0, 0.5, 0.5, 0.5, 64 * 2.0**-52, 1e-12, out)
    halfspace_pair_kernel(np.array([0.0, 0.0, 1.0]), 0.0, P, eye, t, oa, P, eye, t, ob, 0.0, 1.0, 0.5, 0.5,
                          0.5, 64 * 2.0**-52, 1e-12, out)


__all__ = ["swept_pair_kernel", "halfspace_pair_kernel", "decide_pair", "warm", "SWEPT_MAX_POINTS"]


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
