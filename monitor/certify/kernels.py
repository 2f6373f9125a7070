r"""Compiled pair-window narrow phase: whole-shape exclusion, bisection, exact witnesses (issue 12).

One call decides one geom pair over one window ``[t0, t1]`` of a packed motion, with no
Python per sub-interval. It is the whole-shape stage of the toleranced checker of
Schröcker & Weber (seed 003; §2 metric, §3 orbits, §4 tests, §5 balls, §6 algorithm):

**Ball of a sub-interval (§5).** On ``I = [a, b]`` with midpoint ``m`` the motion-bound
contract (:mod:`monitor.motion.base`) gives, per body, ``(trans, angle)`` with
``|X(t) p - X(m) p| <= trans + chord(angle) |p - ref|`` for all t in I and every point p.
For the relative motion of A in B's frame (design.md, "Both bodies moving"), every point
p of A stays within

    delta_rel(p) = T_A + ch_A |p - c_A| + T_B + ch_B |X_WA(m) p - X_WB(m) c_B|

of its pose at m. The R^12 ball ``B_R(g)`` of §5 (g = relative pose at m, metric of §2
on A's feature points m_i with weights w_i) has ``R^2 = sum_i w_i delta_rel(m_i)^2``.

**Whole-shape test (§3 orbits, §4).** By eq. 4 the orbit of a point x of A under
``B_R(g)`` is the ball of radius ``R rho(x)`` about ``g(x)``, and rho is convex, so the
orbit of the core A lies in ``g(A) ⊕ ball(R rho_max)`` (rho_max over A's vertices).
Hence ``dist(g(A), B) - R rho_max > r`` (r = radii + margin + pad) excludes the whole
sub-interval with ONE exact static distance call. The plain displacement bounds give
the same kind of statement with other radii, all sound, and we take the smallest:

* ``R_A rho_max_A`` (the paper's ball for A moving relative to B) and ``R_B rho_max_B``;
* ``max_{p in A} delta_rel(p)`` (A in B's frame) and the same for B in A's frame
  (a convex function of p: the max is at a vertex of the core);
* ``max_A (T_A + ch_A |p - c_A|) + max_B (T_B + ch_B |q - c_B|)`` (each body about
  its own pose at m; not for half-spaces).

Only sub-intervals left open go on (bisection here; the fat vertex/edge/face tests of
§4 remain in :mod:`monitor.certify.toleranced`, which the engine runs on what this
stage does not certify).

**Distance.** :func:`monitor.geometry._gjk.core_distance` (GJK/EPA, rigorous bounds)
or the closed-form half-space distance, minus the radii: ``lower <= dist <= upper``.

**Algorithm (§6, depth-first, earliest first).** A stack of sub-intervals, left child
popped first. For each: the exact static distance at ``m``; ``upper + approx < margin``
confirms a violation at m (``approx`` = over-approximation of circumscribed geoms), after
which only ``[a, m]`` is searched further for an earlier confirmed time (everything
still on the stack is later); ``lower - bound - pad > margin`` excludes I and
contributes ``lower - bound - pad`` to the clearance lower bound; otherwise, when the
bound is below ``epsilon`` (the role of eq. 11's ``R rho_max < epsilon``) or the depth
reaches ``max_depth``, I is *unresolved*, else it is split. Before the first
sub-interval the start pose t0 gets the exact static test (a body starting inside or
within margin of another is a violation at t0). The exclusion test is a whole-solid
signed-distance test, so containment is excluded or not like any other contact: no
boundary argument is needed and no start pose must be proven.

Verdicts: ``CERTIFIED`` (every sub-interval excluded), ``VIOLATION`` (a confirmed time;
the earliest one found), ``UNRESOLVED`` (some sub-interval neither excluded nor
confirmed; the caller falls back or reports uncertain), ``PAUSED`` (the test budget of
this call ran out; call again with the same state to continue), ``UNSUPPORTED`` (two
half-spaces, or a geom without a shape).

Rounding: every bound used is padded upward (motion bounds by the motion kernels,
distances by ``core_distance``); the exclusion threshold adds
``rel_pad (|lower| + bound + margin) + abs_pad`` for the subtraction, the bound is
multiplied by ``1 + 8 rel_pad`` and gets ``8 rel_pad (ch_A + ch_B) S`` for the world
coordinates of magnitude S that enter the lever arms. NaN anywhere never excludes
(every exclusion is written as a comparison that NaN fails).
"""

from __future__ import annotations

import math
import weakref

import numpy as np
from numba import njit

from monitor.geometry._gjk import (
    OUT_SIZE,
    _compact,
    _depth_at,
    _subalgorithm,
    core_distance,
    halfspace_distance,
    pose_relative,
)
from monitor.motion.kernel import body_bound, body_pose

# ---------------------------------------------------------------------------- codes

CERTIFIED = 0
VIOLATION = 1
UNRESOLVED = 2
PAUSED = 3
UNSUPPORTED = 4

MODE_FULL = 0
"""Search the whole window: earliest confirmed violation, every unresolved interval counted."""
MODE_CERTIFY_ONLY = 1
"""Stop at the first unresolved sub-interval met before any confirmed violation (pre-filter use).

A confirmed violation is refined as in MODE_FULL (earliest confirmed time, and
``R_FIRST_UNRES`` = start of the earliest sub-interval before it that could be neither
excluded nor confirmed: the first contact is not earlier than min(that, witness time))."""

# layout of the result row (float64)
R_VERDICT = 0
R_WTIME = 1
R_WPOINT = 2            # 3 entries
R_WUPPER = 5
R_CLEAR = 6
R_TESTS = 7
R_DEPTH = 8
R_UNRES = 9
R_FIRST_UNRES = 10
R_PAPER = 11            # sub-intervals where a paper ball (R rho_max) was the smallest bound
R_SP = 12               # stack pointer (resumable state)
R_STARTED = 13
R_SIZE = 14

_EPS_REL = 1e-14
_MAX_ITER = 200
_MAX_EDGE_PAIRS = 2_000_000


@njit(cache=True)
def _norm3(x, y, z):
    return math.sqrt(x * x + y * y + z * z)


@njit(cache=True)
def _chord(angle):
    a = min(angle, math.pi)
    return 2.0 * math.sin(0.5 * a) * (1.0 + 4.0 * 2.0**-52)


@njit(cache=True)
def posed_distance(gp, ga, Ra, pa, gb, Rb, pb, rel_pad, abs_pad, out, w_out):
    """Rigorous signed distance bounds of geoms ga, gb of ``gp`` posed by (R, p) (world).

    Returns ``(lower, upper)`` of the solid distance (cores minus radii, m) and writes a
    world point between the closest / common points into ``w_out`` (3,). Both geoms
    must have shapes and not both be half-spaces (checked by the caller).
    """
    ka, kb = gp.kind[ga], gp.kind[gb]
    ra, rb = gp.radius[ga], gp.radius[gb]
    if kb == -1 or ka == -1:
        if kb == -1:
            h, c, Rh, ph, Rc, pc = gb, ga, Rb, pb, Ra, pa
        else:
            h, c, Rh, ph, Rc, pc = ga, gb, Ra, pa, Rb, pb
        n0 = gp.nstart[h]
        PC = gp.verts[gp.vstart[c]:gp.vstart[c + 1]]
        halfspace_distance(gp.normals[n0], gp.offset[h], Rh, ph, PC, Rc, pc, rel_pad, abs_pad, out)
        for r in range(3):
            w_out[r] = 0.5 * (out[4 + r] + out[7 + r]) + pc[r]
        rc = gp.radius[c]
        return out[2] - rc, out[3] - rc
    PA = gp.verts[gp.vstart[ga]:gp.vstart[ga + 1]]
    PB = gp.verts[gp.vstart[gb]:gp.vstart[gb + 1]]
    EA = gp.edges[gp.estart[ga]:gp.estart[ga + 1]]
    EB = gp.edges[gp.estart[gb]:gp.estart[gb + 1]]
    NA = gp.normals[gp.nstart[ga]:gp.nstart[ga + 1]]
    NB = gp.normals[gp.nstart[gb]:gp.nstart[gb + 1]]
    core_distance(PA, Ra, pa, EA, NA, PB, Rb, pb, EB, NB, ka, kb, gp.dpad[ga], gp.dpad[gb], rel_pad, abs_pad,
                  _EPS_REL, _MAX_ITER, _MAX_EDGE_PAIRS, out)
    for r in range(3):
        w_out[r] = 0.5 * (out[4 + r] + out[7 + r]) + pa[r]
    if ka == 2 and kb == 2 and out[0] != 0.0 and not out[3] < 0.0:
        _common_point_depth(PA, Ra, NA, PB, Rb, pb, pa, NB, gp.dpad[ga], gp.dpad[gb], out)
    return out[2] - ra - rb, out[3] - ra - rb


@njit(cache=True)
def _common_point_depth(PA, Ra, NA, PB, Rb, pb, pa, NB, dpad_a, dpad_b, out):
    """Overlapping polytopes whose GJK/EPA gave no negative upper bound (e.g. containment).

    Candidate common points x (GJK's point ``out[4:7]`` in the frame shifted by pa, and
    the vertex centroids of A and of B): with certified depths
    d_A >= 0, d_B >= 0 of x in both cores (face normals, minus the normals' depth pad
    and 2 pads of rounding), B(x, d_A) lies in A and B(x, d_B) in B, so separating them
    needs a translation of at least d_A + d_B: ``upper = -(d_A + d_B)`` (the same
    certificate as ``distance._depth_lp``, at GJK's point instead of the LP optimum).
    """
    VA, VB, WNA, WNB = pose_relative(PA, Ra, pa, NA, PB, Rb, pb, NB)
    pad = out[10]
    x = np.empty(3)
    for k in range(3):      # candidates: GJK's point, the vertex centroids of A and of B
        for r in range(3):
            if k == 0:
                x[r] = out[4 + r]
            else:
                acc = 0.0
                V = VA if k == 1 else VB
                for i in range(V.shape[0]):
                    acc += V[i, r]
                x[r] = acc / V.shape[0]
        da = _depth_at(VA, WNA, x) - 2.0 * pad - dpad_a
        db = _depth_at(VB, WNB, x) - 2.0 * pad - dpad_b
        if da >= 0.0 and db >= 0.0 and -(da + db) < out[3]:
            out[3] = -(da + db)
            for r in range(3):
                out[4 + r] = x[r]
                out[7 + r] = x[r]


@njit(cache=True)
def _curved_support(gp, g, R, off, v, sign, pt):
    """Max over the exact cylinder / ellipsoid g of (sign v) . x, posed by R and origin ``off``.

    Closed-form support functions (issue 12, item 2): cylinder (radius r, half length h,
    axis z of its frame) ``h(d) = r |d_xy| + h |d_z|``, ellipsoid ``h(d) = |diag(radii) d|``,
    with d in the geom frame, plus ``d . centre``. The value is computed in closed form;
    the extreme point (for GJK's simplex only) goes into ``pt`` (3,).
    """
    Rg = np.empty((3, 3))
    c = np.empty(3)
    for r in range(3):
        c[r] = off[r]
        for q in range(3):
            c[r] += R[r, q] * gp.ccenter[g, q]
            acc = 0.0
            for j in range(3):
                acc += R[r, j] * gp.cframe[g, j, q]
            Rg[r, q] = acc
    dl = np.empty(3)
    for q in range(3):
        dl[q] = sign * (Rg[0, q] * v[0] + Rg[1, q] * v[1] + Rg[2, q] * v[2])
    val = sign * (c[0] * v[0] + c[1] * v[1] + c[2] * v[2])
    loc = np.empty(3)
    if gp.curve[g] == 1:
        rad, hh = gp.cparam[g, 0], gp.cparam[g, 1]
        rho = math.sqrt(dl[0] * dl[0] + dl[1] * dl[1])
        val += rad * rho + hh * abs(dl[2])
        if rho > 0.0:
            loc[0], loc[1] = rad * dl[0] / rho, rad * dl[1] / rho
        else:
            loc[0], loc[1] = rad, 0.0
        loc[2] = hh if dl[2] >= 0.0 else -hh
    else:
        e0, e1, e2 = gp.cparam[g, 0] * dl[0], gp.cparam[g, 1] * dl[1], gp.cparam[g, 2] * dl[2]
        nrm = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        val += nrm
        if nrm > 0.0:
            loc[0] = gp.cparam[g, 0] * e0 / nrm
            loc[1] = gp.cparam[g, 1] * e1 / nrm
            loc[2] = gp.cparam[g, 2] * e2 / nrm
        else:
            loc[0], loc[1], loc[2] = gp.cparam[g, 0], 0.0, 0.0
    for r in range(3):
        pt[r] = c[r] + Rg[r, 0] * loc[0] + Rg[r, 1] * loc[1] + Rg[r, 2] * loc[2]
    return val


@njit(cache=True)
def separated_beyond(gp, ga, Ra, pa, gb, Rb, pb, target, rel_pad, abs_pad, VA, VB, W, IA, IB, lam, v, vn):
    """A separating-axis lower bound > ``target`` on ``dist(core_a, core_b)``, else -inf (early-exit GJK).

    The lean exclusion test of the whole-shape stage (§4): GJK on the posed cores in the
    frame shifted by ``pa`` (as :func:`monitor.geometry._gjk.core_distance`), returning as
    soon as the separating-axis bound of the current direction v,
    ``(min_a v.a - max_b v.b) / |v| - pad``, exceeds ``target``. Any direction gives a
    valid lower bound, so the bound does not depend on GJK's convergence; the pad
    ``2 rel_pad S + abs_pad`` (S = largest coordinate) is core_distance's. -inf means
    "not proven" (touching, overlapping, closer than target, or no progress): the caller
    then runs the full :func:`posed_distance`. Work arrays: VA, VB (>= vertex counts, 3),
    W (4, 3), IA, IB (4,) int64, lam (4,), v, vn (3,). Both geoms must be cores (no
    half-spaces). A circumscribed cylinder / ellipsoid (``gp.curve > 0``) is replaced by
    its exact geom through :func:`_curved_support`: the exact geom lies inside the polytope
    (checked when packing), so S (from the polytope's vertices) still bounds its
    coordinates, and a lower bound on the distance of the exact geoms is what a
    certificate needs (the polytope only over-approximates them).
    """
    sa0, na = gp.vstart[ga], gp.vstart[ga + 1] - gp.vstart[ga]
    sb0, nb = gp.vstart[gb], gp.vstart[gb + 1] - gp.vstart[gb]
    S = 0.0
    for i in range(na):
        for r in range(3):
            x = (Ra[r, 0] * gp.verts[sa0 + i, 0] + Ra[r, 1] * gp.verts[sa0 + i, 1]
                 + Ra[r, 2] * gp.verts[sa0 + i, 2])
            VA[i, r] = x
            S = max(S, abs(x))
    for i in range(nb):
        for r in range(3):
            x = (Rb[r, 0] * gp.verts[sb0 + i, 0] + Rb[r, 1] * gp.verts[sb0 + i, 1]
                 + Rb[r, 2] * gp.verts[sb0 + i, 2] + (pb[r] - pa[r]))
            VB[i, r] = x
            S = max(S, abs(x))
    pad = 2.0 * rel_pad * S + abs_pad
    tiny = 8.0 * 2.0**-53 * S
    tiny_len2 = (1e-14 * S) ** 2
    tiny_area2 = (1e-14 * S * S) ** 2
    curved_a = gp.curve[ga] > 0
    curved_b = gp.curve[gb] > 0
    zero = np.zeros(3)
    off_b = np.empty(3)
    for r in range(3):
        off_b[r] = pb[r] - pa[r]
    xa = np.empty(3)
    xb = np.empty(3)
    k = 1
    IA[0] = 0
    IB[0] = 0
    lam[0] = 1.0
    for r in range(3):
        W[0, r] = VA[0, r] - VB[0, r]
        v[r] = W[0, r]
    vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    for _it in range(64):
        if not vv > tiny * tiny:
            return -np.inf
        sv = math.sqrt(vv)
        if curved_a:
            ia, sa = -1, -_curved_support(gp, ga, Ra, zero, v, -1.0, xa)
        else:
            ia, sa = 0, np.inf
            for i in range(na):
                d = VA[i, 0] * v[0] + VA[i, 1] * v[1] + VA[i, 2] * v[2]
                if d < sa:
                    ia, sa = i, d
            for r in range(3):
                xa[r] = VA[ia, r]
        if curved_b:
            ib, sb = -1, _curved_support(gp, gb, Rb, off_b, v, 1.0, xb)
        else:
            ib, sb = 0, -np.inf
            for i in range(nb):
                d = VB[i, 0] * v[0] + VB[i, 1] * v[1] + VB[i, 2] * v[2]
                if d > sb:
                    ib, sb = i, d
            for r in range(3):
                xb[r] = VB[ib, r]
        lb = (sa - sb) / sv - pad
        if lb > target:
            return lb
        if sv < target - pad:     # a point of A - B closer than target: cannot be proven
            return -np.inf
        vw = 0.0
        for r in range(3):
            vw += v[r] * (xa[r] - xb[r])
        if vv - vw <= 1e-13 * vv:  # converged below target
            return -np.inf
        if not (curved_a or curved_b):
            for q in range(k):
                if IA[q] == ia and IB[q] == ib:
                    return -np.inf
        for r in range(3):
            W[k, r] = xa[r] - xb[r]
        IA[k] = ia
        IB[k] = ib
        k += 1
        mask, inside = _subalgorithm(W, k, lam, vn, tiny_len2, tiny_area2)
        if inside:
            return -np.inf
        vnn = vn[0] * vn[0] + vn[1] * vn[1] + vn[2] * vn[2]
        if not vnn < vv:
            return -np.inf
        k = _compact(mask, k, W, IA, IB, lam)
        for r in range(3):
            v[r] = vn[r]
        vv = vnn
    return -np.inf


@njit(cache=True)
def _lever(gp, g, ref):
    """Max over g's core vertices of |v - ref| (body frame), padded."""
    lv = 0.0
    for i in range(gp.vstart[g], gp.vstart[g + 1]):
        lv = max(lv, _norm3(gp.verts[i, 0] - ref[0], gp.verts[i, 1] - ref[1], gp.verts[i, 2] - ref[2]))
    return lv * (1.0 + 4.0 * 2.0**-52)


@njit(cache=True)
def _rel_terms(P, TA, chA, cA, RA, pA, TB, chB, cB, RB, pB, w, weighted):
    """Relative displacement bound delta_rel over the rows of P (points of A, body frame).

    Returns max_i delta_rel(P_i) if not ``weighted``, else sqrt(sum_i w_i delta_rel(P_i)^2) (= R).
    B's reference point c_B is taken to world by (RB, pB), A's points by (RA, pA); only the
    difference pA - pB of the translations enters.
    """
    # X_WB(m) c_B - pA (world, relative to A's origin)
    qb = np.empty(3)
    for r in range(3):
        qb[r] = RB[r, 0] * cB[0] + RB[r, 1] * cB[1] + RB[r, 2] * cB[2] + (pB[r] - pA[r])
    acc = 0.0
    for i in range(P.shape[0]):
        x0, x1, x2 = P[i, 0], P[i, 1], P[i, 2]
        dA = _norm3(x0 - cA[0], x1 - cA[1], x2 - cA[2])
        y0 = RA[0, 0] * x0 + RA[0, 1] * x1 + RA[0, 2] * x2 - qb[0]
        y1 = RA[1, 0] * x0 + RA[1, 1] * x1 + RA[1, 2] * x2 - qb[1]
        y2 = RA[2, 0] * x0 + RA[2, 1] * x1 + RA[2, 2] * x2 - qb[2]
        d = TA + chA * dA + TB + chB * _norm3(y0, y1, y2)
        if weighted:
            acc += w[i] * d * d
        else:
            acc = max(acc, d)
    if weighted:
        return math.sqrt(acc)
    return acc


@njit(cache=True)
def interval_bound(gp, mp, ga, gb, ta, tb, pA, RA, pB, RB, levers, stats, rel_pad):
    """Bound (m) on how far the cores of ga, gb can come closer on [ta, tb] than at its midpoint.

    Poses at the midpoint are written into (pA, RA), (pB, RB). ``levers`` (2,) are the
    precomputed max |v - ref| of A and B. ``stats[0]`` is incremented when a paper
    ball (§5, R rho_max) gives the smallest bound. Returns inf when nothing applies.
    """
    ba, bb = gp.body[ga], gp.body[gb]
    TA, angA = body_bound(mp, ba, ta, tb, pA, RA)
    TB, angB = body_bound(mp, bb, ta, tb, pB, RB)
    chA, chB = _chord(angA), _chord(angB)
    cA, cB = mp.ref_points[ba], mp.ref_points[bb]
    hsA, hsB = gp.kind[ga] == -1, gp.kind[gb] == -1
    best = np.inf
    paper = False
    if not hsA and not hsB:
        best = TA + chA * levers[0] + TB + chB * levers[1]
    if not hsA:
        PA = gp.verts[gp.vstart[ga]:gp.vstart[ga + 1]]
        d = _rel_terms(PA, TA, chA, cA, RA, pA, TB, chB, cB, RB, pB, gp.mw, False)
        if d < best:
            best = d
        M = gp.mpts[gp.mstart[ga]:gp.mstart[ga + 1]]
        W = gp.mw[gp.mstart[ga]:gp.mstart[ga + 1]]
        d = _rel_terms(M, TA, chA, cA, RA, pA, TB, chB, cB, RB, pB, W, True) * gp.rho_max[ga]
        if d < best:
            best = d
            paper = True
    if not hsB:
        PB = gp.verts[gp.vstart[gb]:gp.vstart[gb + 1]]
        d = _rel_terms(PB, TB, chB, cB, RB, pB, TA, chA, cA, RA, pA, gp.mw, False)
        if d < best:
            best = d
            paper = False
        M = gp.mpts[gp.mstart[gb]:gp.mstart[gb + 1]]
        W = gp.mw[gp.mstart[gb]:gp.mstart[gb + 1]]
        d = _rel_terms(M, TB, chB, cB, RB, pB, TA, chA, cA, RA, pA, W, True) * gp.rho_max[gb]
        if d < best:
            best = d
            paper = True
    if paper:
        stats[0] += 1.0
    # coordinates of magnitude S enter the lever arms: pad their rounding
    S = levers[0] + levers[1] + _norm3(pA[0] - pB[0], pA[1] - pB[1], pA[2] - pB[2])
    S += _norm3(cA[0], cA[1], cA[2]) + _norm3(cB[0], cB[1], cB[2])
    pad = 8.0 * rel_pad * (best + (chA + chB) * S)
    return best * (1.0 + 8.0 * rel_pad) + pad


@njit(cache=True)
def _push(stack, sp, a, b, depth):
    stack[sp, 0] = a
    stack[sp, 1] = b
    stack[sp, 2] = depth
    return sp + 1


@njit(cache=True)
def pair_window(gp, mp, ga, gb, t0, t1, margin, epsilon, max_depth, max_tests, mode, rel_pad, abs_pad,
                stack, res):
    """Decide geom pair (ga, gb) of ``gp`` over [t0, t1] of motion ``mp`` (see module docstring).

    Args:
        gp: :class:`monitor.certify.packed.GeomPack`.
        mp: :class:`monitor.motion.pack.MotionPack` (poses and bounds: :mod:`monitor.motion.kernel`).
        ga, gb: geom indices.
        t0, t1: window (s).
        margin: clearance (m) below which the pair is in violation.
        epsilon: stop splitting a sub-interval once its motion bound is below this (m).
        max_depth: maximum bisection depth.
        max_tests: distance tests this call may spend (PAUSED when reached).
        mode: MODE_FULL or MODE_CERTIFY_ONLY.
        rel_pad, abs_pad: rounding pads.
        stack: (max_depth + 2, 3) float64 work array (ta, tb, depth); keep it between
            calls to resume a PAUSED search.
        res: (R_SIZE,) float64 result row; set ``res[R_STARTED] = 0`` for a fresh search
            (:func:`new_result`). Holds verdict, witness time / point / upper bound,
            clearance lower bound, tests, max depth, unresolved count, first unresolved
            time, paper-ball wins, and the resumable state.

    Returns:
        The verdict code (also in ``res[R_VERDICT]``).
    """
    out = np.empty(OUT_SIZE)
    w = np.empty(3)
    pA = np.empty(3)
    pB = np.empty(3)
    RA = np.empty((3, 3))
    RB = np.empty((3, 3))
    stats = np.zeros(1)
    if gp.kind[ga] < -1 or gp.kind[gb] < -1 or (gp.kind[ga] == -1 and gp.kind[gb] == -1):
        res[R_VERDICT] = UNSUPPORTED
        return UNSUPPORTED
    approx = gp.approx[ga] + gp.approx[gb]
    levers = np.zeros(2)
    if gp.kind[ga] != -1:
        levers[0] = _lever(gp, ga, mp.ref_points[gp.body[ga]])
    if gp.kind[gb] != -1:
        levers[1] = _lever(gp, gb, mp.ref_points[gp.body[gb]])
    lean = gp.kind[ga] >= 0 and gp.kind[gb] >= 0
    rsum = gp.radius[ga] + gp.radius[gb]
    VA = np.empty((max(gp.vstart[ga + 1] - gp.vstart[ga], 1), 3))
    VB = np.empty((max(gp.vstart[gb + 1] - gp.vstart[gb], 1), 3))
    W = np.zeros((4, 3))
    IA = np.zeros(4, np.int64)
    IB = np.zeros(4, np.int64)
    lam = np.zeros(4)
    v = np.empty(3)
    vn = np.empty(3)
    spent = 0
    sp = int(res[R_SP])
    if res[R_STARTED] == 0.0:
        res[R_STARTED] = 1.0
        res[R_WTIME] = np.nan
        res[R_CLEAR] = np.inf
        res[R_FIRST_UNRES] = np.nan
        res[R_TESTS] = 0.0
        res[R_DEPTH] = 0.0
        res[R_UNRES] = 0.0
        res[R_PAPER] = 0.0
        # start pose: exact static test at t0
        body_pose(mp, gp.body[ga], t0, pA, RA)
        body_pose(mp, gp.body[gb], t0, pB, RB)
        lo, up = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)
        spent += 1
        res[R_TESTS] += 1.0
        if up + approx < margin:
            res[R_WTIME] = t0
            for r in range(3):
                res[R_WPOINT + r] = w[r]
            res[R_WUPPER] = up + approx
            res[R_VERDICT] = VIOLATION
            res[R_SP] = 0.0
            return VIOLATION
        sp = _push(stack, 0, t0, t1, 0.0)
    while sp > 0:
        if spent >= max_tests:
            res[R_SP] = sp
            res[R_PAPER] += stats[0]
            res[R_VERDICT] = PAUSED
            return PAUSED
        sp -= 1
        a, b, depth = stack[sp, 0], stack[sp, 1], stack[sp, 2]
        wt = res[R_WTIME]
        if wt == wt and a >= wt:      # a confirmed violation earlier than this interval
            continue
        m = 0.5 * (a + b)
        bound = interval_bound(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad)
        spent += 1
        res[R_TESTS] += 1.0
        if depth > res[R_DEPTH]:
            res[R_DEPTH] = depth
        if lean:
            # core distance > margin + radii + bound (+ the subtraction pad) excludes I
            target = margin + rsum + bound
            target += rel_pad * (abs(target) + bound + margin) + abs_pad
            lb = separated_beyond(gp, ga, RA, pA, gb, RB, pB, target, rel_pad, abs_pad, VA, VB, W, IA, IB,
                                  lam, v, vn)
            if lb > target:
                slack = lb - (target - margin)      # > margin: proven clearance over I
                if slack < res[R_CLEAR]:
                    res[R_CLEAR] = slack
                continue
        lo, up = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)
        if up + approx < margin:
            res[R_WTIME] = m
            for r in range(3):
                res[R_WPOINT + r] = w[r]
            res[R_WUPPER] = up + approx
            # everything on the stack is later than m: search [a, m] only
            sp = 0
            if depth < max_depth and a < m and bound >= epsilon:
                sp = _push(stack, 0, a, m, depth + 1.0)
            continue
        slack = lo - bound - (rel_pad * (abs(lo) + bound + margin) + abs_pad)
        if slack > margin:
            if slack < res[R_CLEAR]:
                res[R_CLEAR] = slack
            continue
        if not (bound >= epsilon) or depth >= max_depth or not (a < m < b):
            if wt == wt:               # refining an earlier witness: contact may start here
                if not (res[R_FIRST_UNRES] <= a):
                    res[R_FIRST_UNRES] = a
                continue
            res[R_UNRES] += 1.0
            if not (res[R_FIRST_UNRES] == res[R_FIRST_UNRES]):
                res[R_FIRST_UNRES] = a
            if mode == MODE_CERTIFY_ONLY:
                sp = 0
                break
            continue
        sp = _push(stack, sp, m, b, depth + 1.0)
        sp = _push(stack, sp, a, m, depth + 1.0)
    res[R_SP] = 0.0
    res[R_PAPER] += stats[0]
    if res[R_WTIME] == res[R_WTIME]:
        res[R_VERDICT] = VIOLATION
        return VIOLATION
    if res[R_UNRES] > 0.0:
        res[R_VERDICT] = UNRESOLVED
        return UNRESOLVED
    res[R_VERDICT] = CERTIFIED
    return CERTIFIED


@njit(cache=True)
def pairs_window(gp, mp, pairs, t0, t1, margin, epsilon, max_depth, max_tests, mode, rel_pad, abs_pad, res):
    """:func:`pair_window` for every row of ``pairs`` (P, 2) int64; results into ``res`` (P, R_SIZE).

    Each pair gets a fresh search with at most ``max_tests`` tests (PAUSED beyond).
    """
    stack = np.empty((max_depth + 2, 3))
    for k in range(pairs.shape[0]):
        for j in range(R_SIZE):
            res[k, j] = 0.0
        pair_window(gp, mp, pairs[k, 0], pairs[k, 1], t0, t1, margin, epsilon, max_depth, max_tests, mode,
                    rel_pad, abs_pad, stack, res[k])


def new_result() -> np.ndarray:
    """A fresh (R_SIZE,) result row for :func:`pair_window`."""
    return np.zeros(R_SIZE)





_NAMES = {CERTIFIED: "certified", VIOLATION: "violation", UNRESOLVED: "unresolved", PAUSED: "unresolved",
          UNSUPPORTED: "unsupported"}


def check_pair_window(gp, mp, ga: int, gb: int, window: tuple[float, float], margin: float, epsilon: float, *,
                      max_depth: int = 40, max_tests: int | None = None, deadline: float | None = None,
                      certify_only: bool = False, rel_pad: float = 64 * 2.0**-52, abs_pad: float = 1e-12,
                      batch: int = 64) -> dict:
    """Python driver of :func:`pair_window` with a test budget and an optional wall-clock deadline.

    numba has no clock, so with a ``deadline`` (a ``time.perf_counter()`` value) the kernel
    runs in batches of ``batch`` tests and the clock is checked between batches; a run
    stopped by the budget or the deadline is ``"unresolved"`` (or ``"violation"`` if a
    violation was already confirmed), never ``"certified"``.

    Returns:
        dict with ``verdict`` ("certified" | "violation" | "unresolved" | "unsupported"),
        ``witness_time``, ``witness_point`` (3,) world, ``witness_upper``, ``clearance``
        (lower bound, m; meaningful when certified), ``tests``, ``max_depth``,
        ``unresolved`` (count), ``first_unresolved`` (s), ``paper_ball_wins``, ``stopped``
        ("" | "budget" | "deadline").
    """
    import time

    stack = np.empty((int(max_depth) + 2, 3))
    res = new_result()
    left = np.iinfo(np.int64).max if max_tests is None else int(max_tests)
    mode = MODE_CERTIFY_ONLY if certify_only else MODE_FULL
    stopped = ""
    while True:
        n = left if deadline is None else min(left, int(batch))
        before = res[R_TESTS]
        v = pair_window(gp, mp, int(ga), int(gb), float(window[0]), float(window[1]), float(margin),
                        float(epsilon), int(max_depth), n, mode, float(rel_pad), float(abs_pad), stack, res)
        left -= int(res[R_TESTS] - before)
        if v != PAUSED:
            break
        if left <= 0:
            stopped = "budget"
            break
        if deadline is not None and time.perf_counter() >= deadline:
            stopped = "deadline"
            break
    if v == PAUSED:
        v = VIOLATION if res[R_WTIME] == res[R_WTIME] else UNRESOLVED
    wt = float(res[R_WTIME])
    return {"verdict": _NAMES[int(v)], "witness_time": None if wt != wt else wt,
            "witness_point": res[R_WPOINT:R_WPOINT + 3].copy(), "witness_upper": float(res[R_WUPPER]),
            "clearance": float(res[R_CLEAR]) if v == CERTIFIED else float("-inf"),
            "tests": int(res[R_TESTS]), "max_depth": int(res[R_DEPTH]), "unresolved": int(res[R_UNRES]),
            "first_unresolved": float(res[R_FIRST_UNRES]), "paper_ball_wins": int(res[R_PAPER]),
            "stopped": stopped}



@njit(cache=True)
def _poses_agree(mp, bodies, times, P_W, R_WB):
    """True if the packed motion reproduces the trajectory's own poses (T, nbody, 3 / 3, 3) at ``times``.

    A guard of the engine hook: the certificate is about the trajectory's motion, so a
    packed motion that interpolates differently (e.g. the other arc of an exact
    half-turn slerp, where the sign test of the quaternion dot product is decided by
    rounding) must not be used. Tolerance 1e-9 relative (rotation entries: absolute).
    """
    p = np.empty(3)
    R = np.empty((3, 3))
    for k in range(times.shape[0]):
        for b in bodies:
            body_pose(mp, b, times[k], p, R)
            for r in range(3):
                if not abs(p[r] - P_W[k, b, r]) <= 1e-9 * (1.0 + abs(P_W[k, b, r])):
                    return False
                for c in range(3):
                    if not abs(R[r, c] - R_WB[k, b, r, c]) <= 1e-9:
                        return False
    return True


_SCENE_PACKS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

WHOLE_SHAPE_MAX_TESTS = 4096
"""Distance tests one pair may spend in the engine's whole-shape stage before it falls through."""


def whole_shape_stage(scene, plan, geom_pairs, window: tuple[float, float], margin: float, epsilon: float,
                      tolerances, budget=None) -> list[dict | None]:
    """Engine hook: try to certify toleranced-path pairs with the compiled whole-shape stage.

    Args:
        scene: the :class:`monitor.Scene` (packed once, cached per scene object).
        plan: the trajectory (packed by :func:`monitor.motion.pack.pack_trajectory`).
        geom_pairs: list of (GeomInfo a, GeomInfo b).
        window: (t0, t1) s.
        margin, epsilon: as in ``certify``.
        tolerances: rounding pads and ``max_depth``.
        budget: optional :class:`monitor.certify.common.Budget`; tests are charged to it and
            the stage stops (returning None for the rest) once it is exhausted.

    Returns:
        Per pair a dict (``verdict`` "certified" with ``clearance``, or "violation" with
        ``witness_time`` and ``first_unresolved``: the first contact is not earlier than it),
        else None (the pair falls through to the existing checker unchanged). A trajectory the
        motion packer does not support, or whose packed poses differ from its own
        ``body_poses`` at the window's start, midpoint, end or a waypoint segment's midpoint
        inside the window, makes every entry None.
    """
    from monitor.errors import MonitorError
    from monitor.motion.pack import pack_trajectory

    out: list[dict | None] = [None] * len(geom_pairs)
    if not geom_pairs or (budget is not None and budget.exhausted):
        return out
    try:
        mp = pack_trajectory(plan)
    except (MonitorError, TypeError, AttributeError):
        return out
    bodies = np.unique(np.array([[ga.body_id, gb.body_id] for ga, gb in geom_pairs], np.int64))
    t0, t1 = float(window[0]), float(window[1])
    wp = np.asarray(getattr(plan, "times", [t0, t1]), np.float64)
    mids = 0.5 * (wp[:-1] + wp[1:])
    times = np.concatenate([[t0, 0.5 * (t0 + t1), t1], mids[(mids > t0) & (mids < t1)]])
    P_W, R_WB = plan.body_poses(times)
    if not _poses_agree(mp, bodies, times, np.ascontiguousarray(P_W, np.float64),
                        np.ascontiguousarray(R_WB, np.float64)):
        return out
    # keyed on the scene's current geoms tuple too: Scene.sync() replaces it when it rebuilds the
    # shapes after an in-place model edit, so a stale pack is never used
    cached = _SCENE_PACKS.get(scene)
    if cached is not None and cached[0] is scene.geoms:
        gp = cached[1]
    else:
        from monitor.certify.packed import pack_scene
        gp = pack_scene(scene).geoms
        _SCENE_PACKS[scene] = (scene.geoms, gp)
    stack = np.empty((int(tolerances.max_depth) + 2, 3))
    for k, (ga, gb) in enumerate(geom_pairs):
        if budget is not None and budget.exhausted:
            break
        res = new_result()
        v = pair_window(gp, mp, int(ga.id), int(gb.id), float(window[0]), float(window[1]), float(margin),
                        float(epsilon), int(tolerances.max_depth), WHOLE_SHAPE_MAX_TESTS, MODE_CERTIFY_ONLY,
                        float(tolerances.rel_pad), float(tolerances.abs_pad), stack, res)
        if budget is not None:
            budget.charge(int(res[R_TESTS]))
        if v == CERTIFIED or v == VIOLATION:
            wt = float(res[R_WTIME])
            fu = float(res[R_FIRST_UNRES])
            out[k] = {"verdict": "certified" if v == CERTIFIED else "violation",
                      "clearance": float(res[R_CLEAR]) if v == CERTIFIED else float("-inf"),
                      "tests": int(res[R_TESTS]), "max_depth": int(res[R_DEPTH]),
                      "paper_ball_wins": int(res[R_PAPER]), "witness_time": wt,
                      "first_unresolved": min(fu, wt) if fu == fu else wt}
    return out


__all__ = ["CERTIFIED", "VIOLATION", "UNRESOLVED", "PAUSED", "UNSUPPORTED", "MODE_FULL", "MODE_CERTIFY_ONLY",
           "posed_distance", "interval_bound", "pair_window", "pairs_window", "new_result", "R_SIZE",
           "check_pair_window", "whole_shape_stage"]
