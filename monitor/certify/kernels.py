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

**Algorithm (§6, depth-first, earliest first).** Sub-interval lengths adapt to the
measured clearance (issue 12, item 2): the window is swept from t0 by conservative
advancement with a certified bound. The uncovered rest ``[a, e]`` is one stack entry; its
next sub-interval is the prefix ``[a, a + L]``, tested exactly like a bisection interval
(the ball of §5 about its midpoint). After an exclusion the rest ``[a + L, e]`` is pushed
with a step L chosen so that the next bound is about ``_STEP_SAFETY`` x the gap predicted
at its midpoint (distance estimate and slope from the last two tests, bound per second
from the last test; at most ``_STEP_GROW`` x, at least half the last step and a bound of
about ``epsilon``). A prefix that is not excluded is retried shorter while its bound
stays >= epsilon (a prefix that crosses a waypoint: the length at which the pair's motion
profile, its cumulative joint path length calibrated by this test's bound, predicts
``_STEP_SAFETY`` x the smaller known gap; long windows are fast at the start and slow in
their braking tail, where a bound proportional to the prefix is far off); once the step
would go below the epsilon scale (or at ``max_depth``)
the whole rest ``[a, e]`` is bisected as before (so witnesses are looked for at the
midpoints of the open region, and ``uncertain`` keeps its epsilon / depth meaning: only
an interval with bound < epsilon or at ``max_depth`` is ever unresolved). Coverage: an
entry is only dropped when excluded, confirmed-later-than-a-witness or unresolved, and
the sweep pushes exactly the uncovered rest, so the excluded intervals tile the window
(``tests/test_adaptive.py``). The step control is a heuristic only: no verdict depends
on its predictions. Bisection entries: a stack of sub-intervals, left child
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

from monitor._jit_cache import bind_caches, purge_if_changed
from monitor.errors import MonitorError as _MonitorError
from monitor.geometry._gjk import (
    OUT_SIZE,
    _compact,
    _depth_at,
    _subalgorithm,
    core_distance,
    halfspace_distance,
    pose_relative,
)
from monitor.motion import pack as _pack  # read per call (_pack.f): tests replace its functions
from monitor.motion.kernel import (
    NO_NRT,
    _bounds_core,
    _search_right,
    body_pose,
    bounds_workspace,
    mark_ancestors,
    pair_bound,
    pair_workspace,
)

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)

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
R_START_LO = 14         # window_kernel: lower bound (m) of the start-pose distance
R_SIZE = 15

_EPS_REL = 1e-14
_STEP_SAFETY = 0.85
"""Adaptive sub-intervals: aim the next interval's bound at this share of the predicted gap."""
_STEP_GROW = 4.0
"""Adaptive sub-intervals: at most this growth of the step after an exclusion."""
_PROF_RETRY_MIN = 1.0 / 32.0
"""Adaptive sub-intervals: a retry guided by the motion profile may shrink the prefix down to this share."""
_STEP_HEADROOM = 4.0
"""Adaptive sub-intervals: the early-exit GJK is asked to prove this many bounds of clearance
(a better distance estimate for the next step; exclusion still needs one bound)."""
_MAX_ITER = 200
_MAX_EDGE_PAIRS = 2_000_000


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _norm3(x, y, z):
    return math.sqrt(x * x + y * y + z * z)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _chord(angle):
    a = min(angle, math.pi)
    return 2.0 * math.sin(0.5 * a) * (1.0 + 4.0 * 2.0**-52)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
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
    # np.int64(...): int64, not Literal[int], so this is the specialisation the Python callers
    # (monitor.geometry.distance) compile too: one compile of core_distance per process
    core_distance(PA, Ra, pa, EA, NA, PB, Rb, pb, EB, NB, ka, kb, gp.dpad[ga], gp.dpad[gb], rel_pad, abs_pad,
                  _EPS_REL, np.int64(_MAX_ITER), np.int64(_MAX_EDGE_PAIRS), out)
    for r in range(3):
        w_out[r] = 0.5 * (out[4 + r] + out[7 + r]) + pa[r]
    if ka == 2 and kb == 2 and out[0] != 0.0 and not out[3] < 0.0:
        _common_point_depth(PA, Ra, NA, PB, Rb, pb, pa, NB, gp.dpad[ga], gp.dpad[gb], out)
    return out[2] - ra - rb, out[3] - ra - rb


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _curved_support(curve, cparam, cframe, ccenter, R, off, v, sign, pt):
    """Max over the exact cylinder / ellipsoid g of (sign v) . x, posed by R and origin ``off``.

    Closed-form support functions (issue 12, item 2): cylinder (radius r, half length h,
    axis z of its frame) ``h(d) = r |d_xy| + h |d_z|``, ellipsoid ``h(d) = |diag(radii) d|``,
    with d in the geom frame, plus ``d . centre``. The value is computed in closed form;
    the extreme point (for GJK's simplex only) goes into ``pt`` (3,). The geom g's rows of the
    pack are passed (``gp.curve[g], gp.cparam[g], gp.cframe[g], gp.ccenter[g]``), not the pack:
    a compiled function typed on the 22-array pack costs several times more to compile.
    """
    # (scalars, no scratch arrays: the same sums in the same order as the former loops over
    # arrays, ``acc = 0.0; acc += ...``: x + a b + c d + e f is ((x + a b) + c d) + e f, so the same
    # numbers bit for bit, -0.0 included; no helper function: one more compile; issue 12, kernel cost)
    c0 = off[0] + R[0, 0] * ccenter[0] + R[0, 1] * ccenter[1] + R[0, 2] * ccenter[2]
    c1 = off[1] + R[1, 0] * ccenter[0] + R[1, 1] * ccenter[1] + R[1, 2] * ccenter[2]
    c2 = off[2] + R[2, 0] * ccenter[0] + R[2, 1] * ccenter[1] + R[2, 2] * ccenter[2]
    g00 = 0.0 + R[0, 0] * cframe[0, 0] + R[0, 1] * cframe[1, 0] + R[0, 2] * cframe[2, 0]
    g01 = 0.0 + R[0, 0] * cframe[0, 1] + R[0, 1] * cframe[1, 1] + R[0, 2] * cframe[2, 1]
    g02 = 0.0 + R[0, 0] * cframe[0, 2] + R[0, 1] * cframe[1, 2] + R[0, 2] * cframe[2, 2]
    g10 = 0.0 + R[1, 0] * cframe[0, 0] + R[1, 1] * cframe[1, 0] + R[1, 2] * cframe[2, 0]
    g11 = 0.0 + R[1, 0] * cframe[0, 1] + R[1, 1] * cframe[1, 1] + R[1, 2] * cframe[2, 1]
    g12 = 0.0 + R[1, 0] * cframe[0, 2] + R[1, 1] * cframe[1, 2] + R[1, 2] * cframe[2, 2]
    g20 = 0.0 + R[2, 0] * cframe[0, 0] + R[2, 1] * cframe[1, 0] + R[2, 2] * cframe[2, 0]
    g21 = 0.0 + R[2, 0] * cframe[0, 1] + R[2, 1] * cframe[1, 1] + R[2, 2] * cframe[2, 1]
    g22 = 0.0 + R[2, 0] * cframe[0, 2] + R[2, 1] * cframe[1, 2] + R[2, 2] * cframe[2, 2]
    d0 = sign * (g00 * v[0] + g10 * v[1] + g20 * v[2])
    d1 = sign * (g01 * v[0] + g11 * v[1] + g21 * v[2])
    d2 = sign * (g02 * v[0] + g12 * v[1] + g22 * v[2])
    val = sign * (c0 * v[0] + c1 * v[1] + c2 * v[2])
    if curve == 1:
        rad, hh = cparam[0], cparam[1]
        rho = math.sqrt(d0 * d0 + d1 * d1)
        val += rad * rho + hh * abs(d2)
        if rho > 0.0:
            l0, l1 = rad * d0 / rho, rad * d1 / rho
        else:
            l0, l1 = rad, 0.0
        l2 = hh if d2 >= 0.0 else -hh
    else:
        e0, e1, e2 = cparam[0] * d0, cparam[1] * d1, cparam[2] * d2
        nrm = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        val += nrm
        if nrm > 0.0:
            l0 = cparam[0] * e0 / nrm
            l1 = cparam[1] * e1 / nrm
            l2 = cparam[2] * e2 / nrm
        else:
            l0, l1, l2 = cparam[0], 0.0, 0.0
    pt[0] = c0 + g00 * l0 + g01 * l1 + g02 * l2
    pt[1] = c1 + g10 * l0 + g11 * l1 + g12 * l2
    pt[2] = c2 + g20 * l0 + g21 * l1 + g22 * l2
    return val


@njit(cache=True, no_cfunc_wrapper=True, **NO_NRT)
def separated_beyond(gp, ga, Ra, pa, gb, Rb, pb, target, floor, rel_pad, abs_pad, VA, VB, W, IA, IB, lam, v,
                     vn, X):
    """The best separating-axis lower bound on ``dist(core_a, core_b)`` found (early-exit GJK), or -inf.

    The lean exclusion test of the whole-shape stage (§4): GJK on the posed cores in the
    frame shifted by ``pa`` (as :func:`monitor.geometry._gjk.core_distance`), returning as
    soon as the separating-axis bound of the current direction v,
    ``(min_a v.a - max_b v.b) / |v| - pad``, exceeds ``target``. Any direction gives a
    valid lower bound, so the bound does not depend on GJK's convergence; the pad
    ``2 rel_pad S + abs_pad`` (S = largest coordinate) is core_distance's. The result is
    > ``target`` when that excluded the pair; otherwise (touching, overlapping, closer
    than target, or no progress) it is the largest bound of the directions tried (any
    of them is a valid lower bound), -inf when none was computed. The caller then runs
    the full :func:`posed_distance` unless that bound already rules out a witness: once a
    point of A - B closer than ``target`` is found (no exclusion possible), GJK goes on
    only while that point is farther than ``floor`` (< target) and no bound above
    ``floor`` has been found, to tighten the bound the caller compares with ``floor``.
    Work arrays: VA, VB (>= vertex counts, 3), W (4, 3), IA, IB (4,) int64, lam (4,),
    v, vn (3,), X (4, 3) or (5, 3).

    Resuming (X with 5 rows; issue 12, kernel cost): the caller's second call on the SAME
    poses (exclusion first, then the witness floor; :func:`pair_window`) continues where the
    first one returned instead of replaying its GJK iterations from the first vertices. Each
    iteration starts by storing (k, best) in ``X[4, :2]`` and ``X[4, 2] = 1``; a return
    before the simplex is changed leaves W, IA, IB, lam, v as they were at that iteration's
    start, so a call with ``X[4, 2] == 1`` restarts exactly that iteration (returns after the
    simplex changed set ``X[4, 2] = 0``: the next call starts afresh). This gives the same
    result, bit for bit, as a fresh call: GJK's iterates do not depend on target / floor, and
    when the second call's target is at most the first call's target and equal to its floor
    (pair_window: (hi, target) then (target, floor)), a fresh second call cannot return at an
    iterate the first one passed: it returns there only if lb > target2 (then the first
    call's best exceeds target2, and the caller makes no second call) or if sv < target2 - pad
    (then sv < target1 - pad and sv <= floor1, where the first call returned). The caller
    clears ``X[4, 2]`` before a call on new poses.

    Both geoms must be cores (no half-spaces). A circumscribed
    cylinder / ellipsoid (``gp.curve > 0``) is replaced by
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
    zero = X[0]
    off_b = X[1]
    for r in range(3):
        zero[r] = 0.0
        off_b[r] = pb[r] - pa[r]
    xa = X[2]
    xb = X[3]
    keep = X.shape[0] >= 5          # X[4]: (k, best, resumable) at the start of the last iteration
    if keep and X[4, 2] == 1.0:
        # resume the caller's previous call on these poses (see the docstring)
        k = int(X[4, 0])
        best = X[4, 1]
    else:
        best = -np.inf
        k = 1
        IA[0] = 0
        IB[0] = 0
        lam[0] = 1.0
        for r in range(3):
            W[0, r] = VA[0, r] - VB[0, r]
            v[r] = W[0, r]
    vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    for _it in range(64):
        if keep:
            X[4, 0] = k
            X[4, 1] = best
            X[4, 2] = 1.0
        if not vv > tiny * tiny:
            return best
        sv = math.sqrt(vv)
        if curved_a:
            ia, sa = -1, -_curved_support(gp.curve[ga], gp.cparam[ga], gp.cframe[ga], gp.ccenter[ga], Ra,
                                          zero, v, -1.0, xa)
        else:
            ia, sa = 0, np.inf
            for i in range(na):
                d = VA[i, 0] * v[0] + VA[i, 1] * v[1] + VA[i, 2] * v[2]
                if d < sa:
                    ia, sa = i, d
            for r in range(3):
                xa[r] = VA[ia, r]
        if curved_b:
            ib, sb = -1, _curved_support(gp.curve[gb], gp.cparam[gb], gp.cframe[gb], gp.ccenter[gb], Rb,
                                         off_b, v, 1.0, xb)
        else:
            ib, sb = 0, -np.inf
            for i in range(nb):
                d = VB[i, 0] * v[0] + VB[i, 1] * v[1] + VB[i, 2] * v[2]
                if d > sb:
                    ib, sb = i, d
            for r in range(3):
                xb[r] = VB[ib, r]
        lb = (sa - sb) / sv - pad
        if lb > best:
            best = lb
        if lb > target:
            return lb
        if sv < target - pad:     # a point of A - B closer than target: cannot be proven
            if best > floor or not (sv > floor):
                return best       # a witness is ruled out already, or cannot be ruled out
        vw = 0.0
        for r in range(3):
            vw += v[r] * (xa[r] - xb[r])
        if vv - vw <= 1e-13 * vv:  # converged below target
            return best
        if not (curved_a or curved_b):
            for q in range(k):
                if IA[q] == ia and IB[q] == ib:
                    return best
        for r in range(3):
            W[k, r] = xa[r] - xb[r]
        IA[k] = ia
        IB[k] = ib
        k += 1
        if keep:
            X[4, 2] = 0.0           # the simplex changes from here on: not resumable
        mask, inside = _subalgorithm(W, k, lam, vn, tiny_len2, tiny_area2)
        if inside:
            return best
        vnn = vn[0] * vn[0] + vn[1] * vn[1] + vn[2] * vn[2]
        if not vnn < vv:
            return best
        k = _compact(mask, k, W, IA, IB, lam)
        for r in range(3):
            v[r] = vn[r]
        vv = vnn
    return best


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _lever(P, ref, dist_out):
    """Max over the points P (n, 3) of a geom of |v - ref| (body frame), padded; dist_out[i] = |P_i - ref|.

    Takes the geom's rows ``gp.verts[gp.vstart[g]:gp.vstart[g + 1]]`` (or its mass points), not the
    pack (compile cost). ``dist_out`` (n,) is :func:`_rel_terms`'s ``dP`` (issue 12, kernel cost).
    """
    lv = 0.0
    for i in range(P.shape[0]):
        d = _norm3(P[i, 0] - ref[0], P[i, 1] - ref[1], P[i, 2] - ref[2])
        dist_out[i] = d
        lv = max(lv, d)
    return lv * (1.0 + 4.0 * 2.0**-52)


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _rel_terms(P, dP, TA, chA, RA, pA, TB, chB, cB, RB, pB, w, weighted):
    """Relative displacement bound delta_rel over the rows of P (points of A, body frame).

    ``dP`` (n,): |P_i - c_A| from :func:`_lever`, fixed for a pair and computed once per search
    (the same expression as before, so the same numbers; it was one of the two square roots per
    point and test: issue 12, kernel cost).

    Returns max_i delta_rel(P_i) if ``weighted == 0.0``, else sqrt(sum_i w_i delta_rel(P_i)^2) (= R).
    ``weighted`` is a float, not a bool: numba compiles a separate copy for each literal
    ``True`` / ``False`` argument, not for float constants.
    B's reference point c_B is taken to world by (RB, pB), A's points by (RA, pA); only the
    difference pA - pB of the translations enters.
    """
    # X_WB(m) c_B - pA (world, relative to A's origin)
    qb0 = RB[0, 0] * cB[0] + RB[0, 1] * cB[1] + RB[0, 2] * cB[2] + (pB[0] - pA[0])
    qb1 = RB[1, 0] * cB[0] + RB[1, 1] * cB[1] + RB[1, 2] * cB[2] + (pB[1] - pA[1])
    qb2 = RB[2, 0] * cB[0] + RB[2, 1] * cB[1] + RB[2, 2] * cB[2] + (pB[2] - pA[2])
    acc = 0.0
    for i in range(P.shape[0]):
        x0, x1, x2 = P[i, 0], P[i, 1], P[i, 2]
        dA = dP[i]
        y0 = RA[0, 0] * x0 + RA[0, 1] * x1 + RA[0, 2] * x2 - qb0
        y1 = RA[1, 0] * x0 + RA[1, 1] * x1 + RA[1, 2] * x2 - qb1
        y2 = RA[2, 0] * x0 + RA[2, 1] * x1 + RA[2, 2] * x2 - qb2
        d = TA + chA * dA + TB + chB * _norm3(y0, y1, y2)
        if weighted != 0.0:
            acc += w[i] * d * d
        else:
            acc = max(acc, d)
    if weighted != 0.0:
        return math.sqrt(acc)
    return acc


# Compile structure (issue 12 item 7, docs/notes/issue-12-coldstart.md): pair_window has one
# compiled caller on the certify path, so numba inlines it there (inline="always"): a separate
# compile re-optimises and re-emits its whole linked callee tree once more. interval_bound is NOT
# inlined: it is called per test, and inlined numba re-counted the references of every array it
# borrows (gp, mp, the workspaces) on each call; as a plain call compiled without reference counting
# (_nrt=False, like separated_beyond and the motion bound: monitor/motion/kernel.py, "Reference
# counting") it borrows them for free (docs/notes/issue-12-pairwindow-5.md: the window kernel 0.52x
# with the motion bound's change, bit-identical, and ~1.5 s less cold compile CPU). Python callers
# still get a compiled pair_window. Small helpers stay separate functions (inlining them per call
# site costs more compile time), and nothing Python never calls gets a CPython wrapper.
@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **NO_NRT)
def interval_bound(gp, mp, ga, gb, ta, tb, pA, RA, pB, RB, levers, stats, rel_pad, pws, dref):
    """Bound (m) on how far the cores of ga, gb can come closer on [ta, tb] than at its midpoint.

    Poses at the midpoint are written into (pA, RA), (pB, RB). ``levers`` (2,) are the
    precomputed max |v - ref| of A and B. ``stats[0]`` is incremented when a paper
    ball (§5, R rho_max) gives the smallest bound. Returns inf when nothing applies.
    ``pws``: :func:`monitor.motion.kernel.pair_workspace` scratch (allocated once per search).
    ``dref``: (|v - c_A| over A's vertices, over A's mass points, the same for B) from
    :func:`_lever` (once per search).

    Both bodies' motion bounds come from ONE :func:`monitor.motion.kernel.pair_bound` pass
    (the same numbers as two ``body_bound`` calls, without the second FK of their common
    ancestors and without per-call allocations; issue 12, long windows).

    A body the motion does not move (``mp.body_moving[b] == 0``: no coordinate on its
    chain changes anywhere in the trajectory) has bound (0, 0) and the same pose at
    every time (lerp of equal values and slerp of bit-identical quaternions return them
    exactly), which is what ``body_bound`` would return; its pose is then not recomputed:
    the caller must have written it into (pA, RA) / (pB, RB) (:func:`pair_window` does).

    Compiled without numba's reference counting and not inlined (issue 12, pair-window floor;
    :mod:`monitor.motion.kernel`, "Reference counting"): it allocates, returns and keeps no
    array, and a plain call borrows ``gp``, ``mp`` and the workspaces, where ``inline="always"``
    re-counted every array of them per call.
    """
    ba, bb = gp.body[ga], gp.body[gb]
    TA, angA, TB, angB = 0.0, 0.0, 0.0, 0.0
    mva, mvb = mp.body_moving[ba] != 0, mp.body_moving[bb] != 0
    if mva or mvb:
        TA, angA, TB, angB = pair_bound(mp, ba if mva else -1, bb if mvb else -1, ta, tb, pA, RA, pB, RB, pws,
                                            1)
    chA, chB = _chord(angA), _chord(angB)
    cA, cB = mp.ref_points[ba], mp.ref_points[bb]
    hsA, hsB = gp.kind[ga] == -1, gp.kind[gb] == -1
    best = np.inf
    paper = False
    if not hsA and not hsB:
        best = TA + chA * levers[0] + TB + chB * levers[1]
    if not hsA:
        PA = gp.verts[gp.vstart[ga]:gp.vstart[ga + 1]]
        d = _rel_terms(PA, dref[0], TA, chA, RA, pA, TB, chB, cB, RB, pB, gp.mw, 0.0)
        if d < best:
            best = d
        M = gp.mpts[gp.mstart[ga]:gp.mstart[ga + 1]]
        W = gp.mw[gp.mstart[ga]:gp.mstart[ga + 1]]
        d = _rel_terms(M, dref[1], TA, chA, RA, pA, TB, chB, cB, RB, pB, W, 1.0) * gp.rho_max[ga]
        if d < best:
            best = d
            paper = True
    if not hsB:
        PB = gp.verts[gp.vstart[gb]:gp.vstart[gb + 1]]
        d = _rel_terms(PB, dref[2], TB, chB, RB, pB, TA, chA, cA, RA, pA, gp.mw, 0.0)
        if d < best:
            best = d
            paper = False
        M = gp.mpts[gp.mstart[gb]:gp.mstart[gb + 1]]
        W = gp.mw[gp.mstart[gb]:gp.mstart[gb + 1]]
        d = _rel_terms(M, dref[3], TB, chB, RB, pB, TA, chA, cA, RA, pA, W, 1.0) * gp.rho_max[gb]
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


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _path_profile(body_parent, body_moving, body_jntadr, body_jntnum, jnt_type, jnt_qposadr, jnt_track, qpos,
                  qt_phi, ba, bb, cum):
    """Step-control profile of a pair: cum (K,) = joint path length up to waypoint k (heuristic only).

    The sum over the joints on the chains root -> ba and root -> bb (moving bodies only) of
    the path length of their coordinates from the first waypoint to waypoint k: hinge and
    slide |dq| (rad and m, unweighted), free-joint positions |dp| (m), ball / free rotations
    the slerp angle of each segment (rad). Piecewise linear in t between waypoints, like the
    interpolated motion; its increase over an interval is a rough, uncalibrated measure of
    how much the pair moves there. Takes the pack's arrays, not the pack (compile cost).
    """
    K = qpos.shape[0]
    for k in range(K):
        cum[k] = 0.0
    seen = np.zeros(body_parent.shape[0], np.int64)
    for body in (ba, bb):
        c = body
        while c != 0 and seen[c] == 0:
            seen[c] = 1
            if body_moving[c] != 0:
                for j in range(body_jntadr[c], body_jntadr[c] + body_jntnum[c]):
                    typ = jnt_type[j]
                    adr = jnt_qposadr[j]
                    if typ == 0 or typ == 1:
                        tr = jnt_track[j]
                        for i in range(K - 1):
                            cum[i + 1] += qt_phi[tr, i]
                    if typ == 0:
                        for i in range(K - 1):
                            cum[i + 1] += _norm3(qpos[i + 1, adr] - qpos[i, adr],
                                                 qpos[i + 1, adr + 1] - qpos[i, adr + 1],
                                                 qpos[i + 1, adr + 2] - qpos[i, adr + 2])
                    elif typ >= 2:
                        for i in range(K - 1):
                            cum[i + 1] += abs(qpos[i + 1, adr] - qpos[i, adr])
            c = body_parent[c]
    for k in range(1, K):
        cum[k] += cum[k - 1]


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _profile_at(times, cum, t):
    """The profile of :func:`_path_profile` at time t (linear between waypoints, clamped)."""
    K = times.shape[0]
    if not t > times[0]:
        return cum[0]
    if not t < times[K - 1]:
        return cum[K - 1]
    lo, hi = 0, K - 1        # times[lo] < t < times[hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
    s = (t - times[lo]) / (times[hi] - times[lo])
    return cum[lo] + s * (cum[hi] - cum[lo])


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _profile_inv(times, cum, v):
    """The first time at which the profile reaches v (times[-1] when it never does)."""
    K = times.shape[0]
    if not v > cum[0]:
        return times[0]
    if not v < cum[K - 1]:
        return times[K - 1]
    lo, hi = 0, K - 1        # cum[lo] < v <= cum[hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if cum[mid] < v:
            lo = mid
        else:
            hi = mid
    s = (v - cum[lo]) / (cum[hi] - cum[lo])
    return times[lo] + s * (times[hi] - times[lo])


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _push(stack, sp, a, b, depth):
    stack[sp, 0] = a
    stack[sp, 1] = b
    stack[sp, 2] = depth
    return sp + 1


@njit(cache=True, no_cfunc_wrapper=True, inline="always")
def pair_window(gp, mp, ga, gb, t0, t1, margin, epsilon, max_depth, max_tests, mode, rel_pad, abs_pad,
                stack, res):
    """Decide geom pair (ga, gb) of ``gp`` over [t0, t1] of motion ``mp`` (see module docstring).

    :func:`_pair_search` with its scratch allocated for this call (arguments and result there).
    """
    return _pair_search(gp, mp, ga, gb, t0, t1, margin, epsilon, max_depth, max_tests, mode, rel_pad, abs_pad,
                        stack, res, _search_workspace(gp, mp))


@njit(cache=True, no_cfunc_wrapper=True, inline="always")
def _search_workspace(gp, mp):
    """Scratch of :func:`_pair_search` for any pair of ``gp`` under ``mp`` (a tuple; see there).

    (pws, cum, out, w, pA, pB, RA, RB, stats, levers, W4, IA, IB, lam, v, vn, X, VA, VB, dref):
    :func:`monitor.motion.kernel.pair_workspace`, (K,) profile, the posed-distance and GJK work
    arrays, and VA, VB (n, 3), dref (4, n) with n the largest vertex / mass-point count of a geom
    (each search takes the leading rows of its geoms' sizes: the same shapes as its own arrays).
    """
    n = 1
    for g in range(gp.kind.shape[0]):
        n = max(n, gp.vstart[g + 1] - gp.vstart[g], gp.mstart[g + 1] - gp.mstart[g])
    return (pair_workspace(mp), np.empty(mp.times.shape[0]), np.empty(OUT_SIZE), np.empty(3), np.empty(3),
            np.empty(3), np.empty((3, 3)), np.empty((3, 3)), np.zeros(1), np.zeros(2), np.zeros((4, 3)),
            np.zeros(4, np.int64), np.zeros(4, np.int64), np.zeros(4), np.empty(3), np.empty(3),
            np.empty((5, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((4, n)))


# Not inlined (issue 12, cold compile; docs/notes/issue-12-coldtrim.md): compiled once and called
# by window_kernel and pair_window. Inlined, its whole body (with the ~20-array workspace tuple)
# was re-typed and re-lowered inside window_kernel. Reference counting stays on: numba hands a
# caller's "no reference counting" down to callees compiled first from it, and several callees
# here allocate (body_pose, core_distance, _path_profile).
@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _pair_search(gp, mp, ga, gb, t0, t1, margin, epsilon, max_depth, max_tests, mode, rel_pad, abs_pad,
                 stack, res, sw):
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
        stack: (max_depth + 2, 3) float64 work array; keep it between calls to resume a
            PAUSED search. Rows (ta, tb, depth) are bisection intervals, rows (a, e, -L) the
            uncovered rest [a, e] of the adaptive sweep with its next step L; the last row is the
            step controller's memory (midpoint, gap estimate, valid flag).
        res: (R_SIZE,) float64 result row; set ``res[R_STARTED] = 0`` for a fresh search
            (:func:`new_result`), or 2 for a fresh search whose start pose the caller has
            already tested (no start test here; used by :func:`window_kernel`). Holds verdict,
            witness time / point / upper bound,
            clearance lower bound, tests, max depth, unresolved count, first unresolved
            time, paper-ball wins, and the resumable state.
        sw: :func:`_search_workspace` (contents on entry do not matter: what must start at
            zero is zeroed here), so that :func:`window_kernel` allocates it once for all its
            pairs. Its (K,) profile array for the step control (:func:`_path_profile`) is
            filled on its first use in this call only (most searches never retry a prefix).

    Returns:
        The verdict code (also in ``res[R_VERDICT]``).
    """
    pws, cum, out, w, pA, pB, RA, RB, stats, levers, W4, IA, IB, lam, v, vn, X, VAbuf, VBbuf, dbuf = sw
    stats[0] = 0.0
    levers[0] = 0.0
    levers[1] = 0.0
    for i in range(4):                 # (the GJK work arrays start at zero, as fresh np.zeros)
        IA[i] = 0
        IB[i] = 0
        lam[i] = 0.0
        for r in range(3):
            W4[i, r] = 0.0
    if gp.kind[ga] < -1 or gp.kind[gb] < -1 or (gp.kind[ga] == -1 and gp.kind[gb] == -1):
        res[R_VERDICT] = UNSUPPORTED
        return UNSUPPORTED
    times = mp.times
    cum_ready = False                   # cum: step control only (see _path_profile), filled when first read
    approx = gp.approx[ga] + gp.approx[gb]
    # |v - ref| of every vertex / mass point of A and B (interval_bound's lever arms), once per search
    refA, refB = mp.ref_points[gp.body[ga]], mp.ref_points[gp.body[gb]]
    PvA = gp.verts[gp.vstart[ga]:gp.vstart[ga + 1]]
    PmA = gp.mpts[gp.mstart[ga]:gp.mstart[ga + 1]]
    PvB = gp.verts[gp.vstart[gb]:gp.vstart[gb + 1]]
    PmB = gp.mpts[gp.mstart[gb]:gp.mstart[gb + 1]]
    dref = (dbuf[0, :PvA.shape[0]], dbuf[1, :PmA.shape[0]], dbuf[2, :PvB.shape[0]], dbuf[3, :PmB.shape[0]])
    lv_a = _lever(PvA, refA, dref[0])
    _lever(PmA, refA, dref[1])
    lv_b = _lever(PvB, refB, dref[2])
    _lever(PmB, refB, dref[3])
    if gp.kind[ga] != -1:
        levers[0] = lv_a
    if gp.kind[gb] != -1:
        levers[1] = lv_b
    lean = gp.kind[ga] >= 0 and gp.kind[gb] >= 0
    rsum = gp.radius[ga] + gp.radius[gb]
    VA = VAbuf[:max(gp.vstart[ga + 1] - gp.vstart[ga], 1)]
    VB = VBbuf[:max(gp.vstart[gb + 1] - gp.vstart[gb], 1)]
    # X: row 4 is separated_beyond's resumable state
    spent = 0
    sp = int(res[R_SP])
    mem = stack.shape[0] - 1       # last stack row: the step controller's memory (m, gap, valid)
    W = t1 - t0
    Lmin = W * 2.0**-max_depth
    # poses of bodies the motion does not move: constant, set once (see interval_bound)
    if mp.body_moving[gp.body[ga]] == 0:
        body_pose(mp, gp.body[ga], t0, pA, RA)
    if mp.body_moving[gp.body[gb]] == 0:
        body_pose(mp, gp.body[gb], t0, pB, RB)
    if res[R_STARTED] == 0.0 or res[R_STARTED] == 2.0:
        start_done = res[R_STARTED] == 2.0     # the caller ran the start-pose test already
        res[R_STARTED] = 1.0
        res[R_WTIME] = np.nan
        res[R_CLEAR] = np.inf
        res[R_FIRST_UNRES] = np.nan
        res[R_TESTS] = 0.0
        res[R_DEPTH] = 0.0
        res[R_UNRES] = 0.0
        res[R_PAPER] = 0.0
        if not start_done:
            # start pose: exact static test at t0
            body_pose(mp, gp.body[ga], t0, pA, RA)
            body_pose(mp, gp.body[gb], t0, pB, RB)
            lo, up = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)
            spent += 1
            res[R_TESTS] += 1.0
            res[R_START_LO] = lo        # (the step control's gap at t0, as window_kernel's row)
            if up + approx < margin:
                res[R_WTIME] = t0
                for r in range(3):
                    res[R_WPOINT + r] = w[r]
                res[R_WUPPER] = up + approx
                res[R_VERDICT] = VIOLATION
                res[R_SP] = 0.0
                return VIOLATION
        stack[mem, 2] = 0.0
        sp = _push(stack, 0, t0, t1, -W)      # a sweep entry: [t0, t1], first step W
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
        sweep = depth < 0.0
        e = b
        if sweep:
            # adaptive sub-interval (see _STEP_*): the prefix [a, a + L] of the uncovered [a, e]
            b = a + (-depth)
            if not b < e - 0.05 * (-depth):
                b = e
            depth = 0.0
            if b > a:
                depth = max(0.0, math.ceil(math.log2(W / (b - a)) - 1e-9))
        m = 0.5 * (a + b)
        bound = interval_bound(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad, pws, dref)
        spent += 1
        res[R_TESTS] += 1.0
        if depth > res[R_DEPTH]:
            res[R_DEPTH] = depth
        excluded = False
        gap = np.nan                   # estimate of the solid distance at m minus margin (step control)
        if lean:
            # core distance > margin + radii + bound (+ the subtraction pad) excludes I
            target = margin + rsum + bound
            target += rel_pad * (abs(target) + bound + margin) + abs_pad
            # (no witness possible at m when the cores' lower bound exceeds floor: see below)
            floor = margin + rsum + approx
            floor += 2.0 * rel_pad * (abs(floor) + margin) + abs_pad
            lb = -np.inf
            X[4, 2] = 0.0              # new poses: no separated_beyond state to resume
            if sweep:
                # ask for _STEP_HEADROOM x the bound (a distance estimate for the step control);
                # with floor = target, GJK returns a value > target whenever it can prove one
                hi = max(margin + rsum + _STEP_HEADROOM * bound, target)
                lb = separated_beyond(gp, ga, RA, pA, gb, RB, pB, hi, target, rel_pad, abs_pad, VA, VB, W4,
                                      IA, IB, lam, v, vn, X)
                if lb > target:
                    sv = _norm3(v[0], v[1], v[2])
                    gap = (lb if lb > hi else 0.5 * (lb + max(lb, sv))) - rsum - margin
            if not lb > target and not lb > floor:
                # (a bound above floor from the first call already rules out a witness: no second call)
                lb = separated_beyond(gp, ga, RA, pA, gb, RB, pB, target, floor, rel_pad, abs_pad, VA, VB, W4,
                                      IA, IB, lam, v, vn, X)
            if not gap == gap:
                sv = _norm3(v[0], v[1], v[2])
                gap = 0.5 * (lb + max(lb, sv)) - rsum - margin
            if lb > target:
                slack = lb - (target - margin)      # > margin: proven clearance over I
                if slack < res[R_CLEAR]:
                    res[R_CLEAR] = slack
                excluded = True
            # No witness at m when the cores' lower bound already clears margin + radii +
            # the polytope error (+ rounding pads): posed_distance's upper bound ``up`` (of
            # the polytope cores, which lie within ``approx`` of the exact geoms) is
            # >= lb - rsum - approx, so ``up + approx < margin`` cannot hold, and its
            # exclusion test ``lo - bound > margin`` needs lo >~ target, which lb <= target
            # (GJK found a point closer than target) leaves to rounding. The full distance
            # is skipped: the interval is split (this never certifies anything).
            no_witness = excluded or lb > floor
        else:
            no_witness = False
        if not no_witness:
            lo, up = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)
            gap = up - margin
            if up + approx < margin:
                res[R_WTIME] = m
                for r in range(3):
                    res[R_WPOINT + r] = w[r]
                res[R_WUPPER] = up + approx
                # everything on the stack is later than m: search [a, m] only (a sweep again)
                sp = 0
                if depth < max_depth and a < m and bound >= epsilon:
                    sp = _push(stack, 0, a, m, -0.5 * (m - a))
                stack[mem, 2] = 0.0
                continue
            slack = lo - bound - (rel_pad * (abs(lo) + bound + margin) + abs_pad)
            if slack > margin:
                if slack < res[R_CLEAR]:
                    res[R_CLEAR] = slack
                excluded = True
        # -- step control (heuristic only: coverage and soundness never depend on it) -------
        slope = 0.0
        gap_a = res[R_START_LO] - margin if a == t0 else np.nan   # gap at a, when known (> 0 only)
        if stack[mem, 2] == 1.0 and m != stack[mem, 0]:
            slope = (gap - stack[mem, 1]) / (m - stack[mem, 0])
            if not gap_a == gap_a:
                gap_a = stack[mem, 1]          # the last test's (its midpoint is before a)
        if gap == gap and abs(gap) < np.inf:
            stack[mem, 0] = m
            stack[mem, 1] = gap
            stack[mem, 2] = 1.0
        else:
            stack[mem, 2] = 0.0
        if not (abs(slope) < np.inf):
            slope = 0.0
        L_old = b - a
        rate = bound / L_old if L_old > 0.0 else np.inf     # bound per second of interval
        den = rate - 0.5 * _STEP_SAFETY * slope
        if excluded:
            if sweep and b < e:
                # largest L with rate L <= safety * (predicted gap at b + L / 2)
                gb_pred = gap + slope * (b - m)
                L_new = _STEP_GROW * L_old
                if den > 0.0:
                    L_new = _STEP_SAFETY * gb_pred / den
                if not L_new >= 0.5 * L_old:
                    L_new = 0.5 * L_old
                L_new = min(L_new, _STEP_GROW * L_old)
                if rate > 0.0:
                    L_new = max(L_new, epsilon / rate)      # keep the bound at about epsilon or more
                L_new = max(L_new, Lmin)
                sp = _push(stack, sp, b, e, -L_new)
            continue
        if sweep:
            if bound >= epsilon and depth < max_depth and a < m < b:
                # Retry with the motion profile (_path_profile): bound ~ ratio x (profile increase),
                # calibrated on this test. A long window whose motion is fast at its start (the
                # window, the start of a braking tail) and slow after it has a bound that does not
                # shrink in proportion to the prefix; the linear model (rate) then retries prefixes
                # that still fail.
                # Only across waypoints: inside one segment the motion is one smooth piece and the
                # linear model is kept (same steps as before on single-segment motions).
                ia = _search_right(times, a)
                prof = False
                Aa, ratio = 0.0, np.nan
                if ia < times.shape[0] and times[ia] < b:
                    if not cum_ready:
                        _path_profile(mp.body_parent, mp.body_moving, mp.body_jntadr, mp.body_jntnum,
                                      mp.jnt_type, mp.jnt_qposadr, mp.jnt_track, mp.qpos, mp.qt_phi,
                                      gp.body[ga], gp.body[gb], cum)
                        cum_ready = True
                    Aa = _profile_at(times, cum, a)
                    Ab = _profile_at(times, cum, b)
                    ratio = bound / (Ab - Aa) if Ab > Aa else np.nan
                    prof = ratio > 0.0 and ratio < np.inf
                L_new = 0.5 * L_old
                # a shorter prefix's midpoint lies between a and m: the smaller known gap
                g_pre = min(gap, gap_a) if gap_a > 0.0 else gap
                if prof and g_pre > 0.0:
                    L_new = _profile_inv(times, cum, Aa + _STEP_SAFETY * g_pre / ratio) - a
                elif den > 0.0 and gap > 0.0:
                    L_new = _STEP_SAFETY * gap / den
                L_new = min(max(L_new, (_PROF_RETRY_MIN if prof else 0.125) * L_old), 0.5 * L_old)
                if rate * L_new >= epsilon and L_new >= Lmin:
                    sp = _push(stack, sp, a, e, -L_new)     # retry a shorter prefix of [a, e]
                    continue
            if b < e:
                # at the epsilon scale: plain bisection of everything left, [a, e]
                sp = _push(stack, sp, a, e, max(0.0, math.floor(math.log2(W / (e - a)))))
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


@njit(cache=True, no_cfunc_wrapper=True)
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


# ------------------------------------------------------------------ the whole window (issue 12, item 1)

WK_SS = 1
"""Both bodies welded to the world and not moved by the plan: culled, clearance +inf."""
WK_CULLED = 2
"""Swept spheres further apart than the margin: culled; ``gap`` (NaN: not computed, see below)."""
WK_PYTHON = 3
"""Left to the Python pipeline (start-pose stage on): two half-spaces, a geom without a shape,
or a static pair whose start pose is not proven clear."""
WK_OPEN = 4
"""Survived the broad phase, start pose clear, not narrowed here (extrusion route, or stage 1 not run)."""
WK_STATIC_VIOL = 5
"""Start-pose violation (``upper + approx < margin`` at t0): witness in the result row."""
WK_STATIC_CERT = 6
"""Neither body moves and the start pose is clear beyond the margin (``R_CLEAR`` = lower bound)."""
WK_CERT = 7
"""Certified by the whole-shape stage (``R_CLEAR``)."""
WK_VIOL = 8
"""Violation confirmed by the whole-shape stage (witness in the result row)."""
WK_UNRES = 9
"""The whole-shape stage left a sub-interval open: the fat-feature toleranced checker decides."""

WP_T0, WP_T1, WP_MARGIN, WP_EPS, WP_REL, WP_ABS, WP_SCALE_PAD, WP_MAX_DEPTH, WP_MAX_TESTS = range(9)
WP_SIZE = 9
"""Layout of the float parameter vector of :func:`window_kernel`."""
WI_PAD, WI_BEST, WI_TESTS, WI_SURV, WI_DEPTH, WI_DONE = range(6)
WI_SIZE = 6
"""Layout of the info vector of :func:`window_kernel`: sphere-gap pad (m), smallest culled gap
computed (m), tests spent, survivors, deepest level, end of the survivor slots processed."""
_REL_SLOTS = 4
"""Common ancestors whose relative bounds stage 0 keeps at a time (see window_kernel)."""
CALL_TESTS = 64
"""Whole-shape tests after which one stage-1 :func:`window_kernel` call stops (after the pair
that reached them; ``info[WI_DONE]`` says where), so the engine checks its budget clock at least
every CALL_TESTS tests plus one pair's search, however many survivor slots it asked for."""


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **NO_NRT)
def _moving_base(body_parent, body_moving, ba, bb, mark, stamp):
    """The deepest common ancestor of bodies ba and bb if it is not the world and moves, else 0.

    (Each body is its own ancestor.) The frame :func:`monitor.motion.kernel.pair_bound` freezes
    with ``relative=1``. ``mark``: (nbody,) int64 scratch; ``stamp``: a value that no entry of
    ``mark`` holds unless written for the same pair before.
    """
    mark_ancestors(body_parent, ba, mark, stamp)
    c = bb
    while mark[c] != stamp:
        c = body_parent[c]
    if c != 0 and body_moving[c] != 0:
        return c
    return 0


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def sphere_gap(sc, sr, ga, gb, pad):
    """Min over sub-intervals of |c_a - c_b| - r_a - r_b, minus ``pad`` (-inf if not all finite)."""
    g = np.inf
    for t in range(sc.shape[0]):
        d = (_norm3(sc[t, ga, 0] - sc[t, gb, 0], sc[t, ga, 1] - sc[t, gb, 1], sc[t, ga, 2] - sc[t, gb, 2])
             - sr[t, ga] - sr[t, gb])
        if not (d > -np.inf and d < np.inf):
            return -np.inf
        if d < g:
            g = d
    return g - pad


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _halfspace_gap(n, q, bh, c, sc, sr, trans, ang, rot, pos, pad):
    """Certified gap of geom c's swept spheres from a half-space (unit normal n, point q, body bh).

    -inf when the plane's body moves (no cull), as :func:`broadphase.halfspace_gaps`.
    """
    T = sc.shape[0]
    for t in range(T):
        if trans[t, bh] > 0.0 or ang[t, bh] > 0.0:
            return -np.inf     # a moving plane: no cull
    g = np.inf
    for t in range(T):
        # as broadphase.halfspace_gaps: (c - X(m) q) . R n - r, q the plane's point, n its unit normal
        R = rot[t, bh]
        nx = R[0, 0] * n[0] + R[0, 1] * n[1] + R[0, 2] * n[2]
        ny = R[1, 0] * n[0] + R[1, 1] * n[1] + R[1, 2] * n[2]
        nz = R[2, 0] * n[0] + R[2, 1] * n[1] + R[2, 2] * n[2]
        qx = R[0, 0] * q[0] + R[0, 1] * q[1] + R[0, 2] * q[2] + pos[t, bh, 0]
        qy = R[1, 0] * q[0] + R[1, 1] * q[1] + R[1, 2] * q[2] + pos[t, bh, 1]
        qz = R[2, 0] * q[0] + R[2, 1] * q[1] + R[2, 2] * q[2] + pos[t, bh, 2]
        d = (sc[t, c, 0] - qx) * nx + (sc[t, c, 1] - qy) * ny + (sc[t, c, 2] - qz) * nz - sr[t, c]
        if not (d > -np.inf and d < np.inf):
            return -np.inf
        if d < g:
            g = d
    return g - pad

WK_UNVISITED = 0
"""Not produced by the sort-and-sweep broad phase (``rows`` given to :func:`window_kernel`): culled,
gap not computed (``code`` is allocated zeroed; read as ``WK_CULLED`` with gap NaN)."""


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **NO_NRT)
def _pair_row(pairs, rows, a, b):
    """Row k of ``pairs`` equal to (a, b) (a < b), or -1 (binary search in rows[a]:rows[a + 1])."""
    lo_k, hi_k = rows[a], rows[a + 1]
    while lo_k < hi_k:
        mid = (lo_k + hi_k) // 2
        v = pairs[mid, 1]
        if v < b:
            lo_k = mid + 1
        elif v > b:
            hi_k = mid
        else:
            return mid
    return -1


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **NO_NRT)
def sweep_rows(lo, hi, order, nb, unb, thr, thr_old, pairs, rows, out, n0, sep_min):
    """Sort-and-sweep over swept AABBs: the rows of ``pairs`` whose boxes are within ``thr`` on every axis.

    Args:
        lo, hi: (G, 3) box corners (world frame, m); a geom with a non-finite coordinate is
            unbounded (``unb[g] == 1``) and pairs with every geom.
        order: (>= nb,) int64 the bounded geoms sorted by ``lo[:, 0]``.
        unb: (G,) int64 1 for unbounded geoms.
        thr: the separation threshold (m, >= 0).
        thr_old: < 0 on the first sweep; else only pairs NOT produced at ``thr_old`` are written
            (some computed separation > thr_old), and pairs with an unbounded geom are skipped (the
            first sweep produced them all).
        pairs: (P, 2) int64 selected pairs, a < b per row, rows strictly increasing (lexicographic).
        rows: (G + 1,) int64: the rows with ``pairs[k, 0] == a`` are ``rows[a]:rows[a + 1]``.
        out: (>= n0 + produced,) int64 output rows, written from ``n0``.
        sep_min: (1,) output: a lower bound (m) on the largest computed separation of every pair
            of bounded geoms NOT produced (inf if none), selected or not.

    A pair is produced iff each of its six computed separations ``lo_b - hi_a``, ``lo_a - hi_b``
    (per axis) is ``<= thr``: the very subtractions of :func:`window_kernel`'s AABB test, so a
    pair left out has ``sep > thr`` there (rounding is monotone). Along x the scan of ``a``
    stops at the first later geom with ``lo_b - hi_a > thr`` (``lo`` sorted, so every later one
    too, with an x separation at least as large: that one bounds ``sep_min`` for the rest of the
    scan); ``lo_a - hi_b <= 0`` for a later ``b``. Each unordered pair is met once.

    Returns:
        The new end of ``out`` (n0 + rows written).
    """
    n = n0
    m = np.inf
    for i in range(nb):
        a = order[i]
        hx, hy, hz = hi[a, 0], hi[a, 1], hi[a, 2]
        lx, ly, lz = lo[a, 0], lo[a, 1], lo[a, 2]
        for j in range(i + 1, nb):
            b = order[j]
            sx = lo[b, 0] - hx
            if sx > thr:
                if sx < m:
                    m = sx
                break
            s1 = lo[b, 1] - hy
            s2 = ly - hi[b, 1]
            s3 = lo[b, 2] - hz
            s4 = lz - hi[b, 2]
            if s1 > thr or s2 > thr or s3 > thr or s4 > thr:
                sep = max(sx, s1, s2, s3, s4)
                if sep < m:
                    m = sep
                continue
            if thr_old >= 0.0:
                s0 = lx - hi[b, 0]
                if not (sx > thr_old or s0 > thr_old or s1 > thr_old or s2 > thr_old or s3 > thr_old
                        or s4 > thr_old):
                    continue
            k = _pair_row(pairs, rows, a, b) if a < b else _pair_row(pairs, rows, b, a)
            if k >= 0:
                out[n] = k
                n += 1
    if thr_old < 0.0:
        G = unb.shape[0]
        for u in range(G):
            if unb[u] == 0:
                continue
            for g in range(G):
                if g == u or (unb[g] != 0 and g < u):   # a pair of two unbounded geoms once
                    continue
                k = _pair_row(pairs, rows, u, g) if u < g else _pair_row(pairs, rows, g, u)
                if k >= 0:
                    out[n] = k
                    n += 1
    sep_min[0] = m
    return n


_SWEEP_MAX_COORD = 1e150
"""Largest finite box coordinate (m) for which :func:`_sweep_first` sweeps: below it no squared
centre difference of :func:`sphere_gap` (|d|^2 <= 3 (2 smax)^2) overflows, so a left-out pair's
sphere gap is finite and > margin as the pair loop computes it; above it, the pair loop."""


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _sweep_first(lo, hi, margin, pad, pairs, rows, surv, sep_min):
    """The first sweep of :func:`window_kernel`'s stage 0 (its docstring, "Sweep"): rows into ``surv``.

    Returns (swept, nrows, thr, lk, smax, order, nb, unb): ``swept`` False (nrows = P) when the
    threshold is not numerically sound or a box coordinate reaches ``_SWEEP_MAX_COORD`` (then the
    pair loop visits every pair); else the sorted produced rows are ``surv[:nrows]``, every pair
    left out has ``sep >= lk > margin``;
    ``order[:nb]`` the bounded geoms by ``lo[:, 0]``, ``unb`` (G,) the unbounded flags.
    """
    G = lo.shape[0]
    unb = np.zeros(G, np.int64)
    keyx = np.empty(G)
    idx = np.empty(G, np.int64)
    nb = 0
    smax = 1.0
    for g in range(G):
        fin = True
        for r in range(3):
            if not (abs(lo[g, r]) < np.inf and abs(hi[g, r]) < np.inf):
                fin = False
        if not fin:
            unb[g] = 1
            continue
        idx[nb] = g
        keyx[nb] = lo[g, 0]
        nb += 1
        for r in range(3):
            smax = max(smax, abs(lo[g, r]), abs(hi[g, r]))
    perm = np.argsort(keyx[:nb])
    order = np.empty(nb, np.int64)
    for i in range(nb):
        order[i] = idx[perm[i]]
    thr = (margin + pad + 1e-12 * smax) * (1.0 + 1e-9) + 1e-12
    lk = thr - pad - 1e-12 * smax
    # smax < 1e150: no squared centre difference in sphere_gap overflows (it would return -inf, a
    # survivor of the pair loop, for a pair the sweep leaves out; red team 8)
    if not (thr >= 0.0 and thr < np.inf and lk > margin and smax < _SWEEP_MAX_COORD):
        return False, pairs.shape[0], thr, lk, smax, order, nb, unb
    n = sweep_rows(lo, hi, order, nb, unb, thr, -1.0, pairs, rows, surv, 0, sep_min)
    surv[:n].sort()
    m = sep_min[0]
    if m > thr:     # (always: every pair left out has a separation > thr) the tighter bound
        lk = m - pad - 1e-12 * smax
    return True, n, thr, lk, smax, order, nb, unb


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **NO_NRT)
def _sweep_best(lo, hi, order, nb, unb, thr, lk, smax, margin, pad, best, pairs, rows, fixed, gbody, code,
                sc, sr, surv, S, sep_min):
    """The smallest sphere gap over ALL culled pairs, from ``best`` over the first sweep's (window_kernel).

    Every pair not produced so far has ``sep >= lk`` (``lk`` from ``sep_min``, the kernel's own
    expression ``sep - pad - 1e-12 scale`` with scale <= smax), hence sphere gap >= lk. While
    ``best > lk``, sweep at a larger threshold -- the one that makes ``lk >= best`` when ``best``
    is finite, else one for twice the last target, at least the largest box extent -- and
    take the sphere gaps of the pairs produced now and not before (``surv[S:]`` as scratch: at
    most P - S of them; they are culled: their ``sep`` exceeds the first sweep's ``lk``). If a
    threshold is not numerically sound, or after 64 rounds, the sphere gaps of every unvisited
    pair decide instead.
    """
    ext = 0.0        # the largest box extent: the first widening's scale while nothing is found
    for i in range(nb):
        g = order[i]
        for r in range(3):
            ext = max(ext, hi[g, r] - lo[g, r])
    target = margin
    thr_old = thr
    rounds = 0
    sound = True
    while not best <= lk:
        rounds += 1
        target = best if best < np.inf else max(2.0 * target, ext, 1e-9)
        thr = (target + pad + 1e-12 * smax) * (1.0 + 1e-9) + 1e-12
        if not thr - pad - 1e-12 * smax >= target:
            sound = False
        if rounds > 64 or not (thr > thr_old and thr < np.inf):
            sound = False
        if not sound:
            break
        n = sweep_rows(lo, hi, order, nb, unb, thr, thr_old, pairs, rows, surv, S, sep_min)
        for kk in range(S, n):
            k = surv[kk]
            ga, gb = pairs[k, 0], pairs[k, 1]
            if fixed[gbody[ga]] != 0 and fixed[gbody[gb]] != 0:
                continue
            g = sphere_gap(sc, sr, ga, gb, pad)
            if g < best:
                best = g
        thr_old = thr
        m = sep_min[0]
        lk = m - pad - 1e-12 * smax if m > thr else -np.inf   # (m > thr always; else one more round)
    if not sound:
        for k in range(pairs.shape[0]):
            if code[k] == WK_UNVISITED:
                g = sphere_gap(sc, sr, pairs[k, 0], pairs[k, 1], pad)
                if g < best:
                    best = g
    return best


@njit(cache=True, no_cfunc_wrapper=True)
def window_kernel(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr,
                  rows, info):
    """One window of a packed scene and motion: cull, start pose, whole-shape stage (no Python per pair).

    Args:
        gp: :class:`monitor.certify.packed.GeomPack` (index = geom id).
        mp: :class:`monitor.motion.pack.MotionPack`.
        pairs: (P, 2) int64 geom ids of the selected candidate pairs.
        fixed: (nbody,) int64, 1 where the body is welded to the world and not moved by the plan.
        moving: (nbody,) int64, the plan's ``moving_bodies()``.
        route: (S,) int64 per survivor slot, 1 = whole-shape stage, 0 = leave to Python
            (extrusion route); an empty array means 1 for every slot.
        stage: 0 = broad phase over all P pairs (fills code, gap, surv, sc, sr, info), then
            stage 1 on survivor slots [0, min(k1, S)); 1 = stage 1 on survivor slots [k0, k1).
        prm: (WP_SIZE,) float parameters (window, margin, epsilon, pads, max depth, tests per pair).
        code: (P,) int64 outcome per pair (``WK_*``).
        gap: (P,) certified sphere gap (m) of culled pairs; NaN where not computed because the
            pair's swept AABBs are further apart than the margin AND than a culled gap already
            computed (then its gap is not the window's minimum; :func:`sphere_gap` gives it).
        surv: (P,) int64: surviving pair indices in slots [0, S).
        res: (>= S, R_SIZE) result rows per survivor slot (see :func:`pair_window`).
        sc, sr: (T, G, 3), (T, G) swept spheres (stage 0 output, kept for :func:`sphere_gap`).
        rows: None or empty (the pair loop below visits every pair; None compiles a
            specialisation without the sweep), or (G + 1,) int64 row starts of
            ``pairs`` (``pairs[k, 0] == a`` for k in ``rows[a]:rows[a + 1]``; ``pairs`` sorted
            lexicographically, a < b per row): stage 0 then visits only the pairs a
            sort-and-sweep of the boxes produces (see "Sweep" below); ``code`` must come zeroed
            (``WK_UNVISITED`` marks the rest).
        info: (WI_SIZE,) pad, smallest culled gap, tests, S, max depth, and ``WI_DONE``: the
            end of the survivor slots this call processed (``k1``, or less when the whole-shape
            searches of this call spent :data:`CALL_TESTS` tests first: the caller continues
            from there; start-pose tests do not count).

    Broad phase (stage 0, O(G T + P)): per geom the swept spheres and their AABB (one
    ``tree_bounds`` per sub-interval for all bodies). Per pair: static-static -> ``WK_SS``;
    a half-space pair gets its exact plane gap; otherwise the AABB separation
    ``max_axis (lo_b - hi_a, lo_a - hi_b)`` minus the pads is a lower bound on every
    sub-interval's sphere gap (a ball lies in its box), so when it exceeds the margin
    the pair is culled without the O(T) sphere test, unless it could still be the
    smallest culled gap (then the exact gap is computed, so ``info[WI_BEST]`` is the
    same minimum as the pairwise sphere test gives). Pairs not culled are survivors. The middle
    sub-range is bounded first: when it alone shows every selected pair of cores within the
    margin, none can be culled and the other sub-ranges are skipped (early survival; the
    argument is in stage 0's comment; not for long windows, which read every sub-range).

    Relative spheres (issue 12, hand30): a pair of cores the world spheres leave within the
    margin whose bodies have a common ancestor C that moves (not the world; C may be one of the
    two bodies) gets a second test: each geom's sphere over the whole window [t0, t1] (the same
    expressions as the sub-range spheres) from the bounds of
    :func:`monitor.motion.kernel.pair_bound` with ``relative=1``, i.e. of the motion
    X_WC(m) X_WC(t)^-1 X_Wb(t) (m = the window's middle; one ``_bounds_core`` pass per C for
    all of C's descendants, the last ``_REL_SLOTS`` kept: the same numbers, as a body's bound
    reads only its own ancestors). That map moves both geoms by the same rigid transform at
    each t, so their distance is the real one; when these spheres are apart by more than the
    margin (after the rounding pad, the larger of ``pad`` and the same formula on these
    centres' magnitude) the pair is culled
    with that certified gap (``gap[k]``, and ``info[WI_BEST]`` if smallest). Two fingers of one
    moving hand: the hand's own motion no longer keeps them. The early survival below is not
    taken when a selected pair has such an ancestor.

    Sweep (issue 12, sparse scaling; ``rows`` given): :func:`sweep_rows` produces the pairs
    whose boxes are within ``thr = (margin + pad + 1e-12 smax)(1 + 1e-9) + 1e-12`` on every
    axis (``smax`` >= 1 and >= every finite box coordinate, so >= each pair's ``scale``);
    pairs with an unbounded box (half-spaces, no shape, NaN) are always produced. A pair left
    out has a computed separation ``sep_raw > thr``, so its ``sep = sep_raw - pad - 1e-12 scale
    >= thr - pad - 1e-12 smax > margin`` (the same expressions, monotone rounding; checked):
    the pair loop would cull it too (``WK_UNVISITED``, gap NaN as for an AABB-culled pair). The
    produced pairs get the pair loop's decisions, in row order (so the survivors and their
    order are the pair loop's). Static-static pairs are marked from the rows of fixed geoms.
    ``info[WI_BEST]`` stays the minimum sphere gap over ALL culled pairs: the sweep also
    returns the smallest ``sep_raw`` left out (``m``), so every pair left out has a sphere gap
    ``>= lk = m - pad - 1e-12 smax``; while the best found exceeds ``lk``, sweep again at a
    larger threshold (the one giving ``lk >= best``; while nothing is found, doubling from the
    largest box extent) and take
    the sphere gaps of the newly produced pairs (:func:`_sweep_best`); any numerical doubt
    falls back to the sphere gaps of every unvisited pair.

    Stage 1 (per survivor): the exact start-pose test at t0 (``posed_distance``:
    ``upper + approx < margin`` is a violation at t0); pairs of two bodies the plan does
    not move are decided by it (certified if ``lower > margin``, else left to Python);
    the rest run :func:`pair_window` (MODE_CERTIFY_ONLY) unless routed to Python.
    Long windows (the window and its braking tail in one call; at least T waypoints inside
    the window, so single-segment motions keep the whole-window search): a pair of two cores runs
    :func:`pair_window` only over ``[ta_f, tb_l]``, from the first to the last of the T
    sub-ranges where its swept spheres are NOT further apart than the margin. Every other
    sub-range ``[ta_j, tb_j]`` (the same edges as stage 0, bit for bit) is clear: geom g's
    swept sphere of sub-range j (centre at the sub-range midpoint pose, radius = bounding
    radius + the motion bound ``trans + chord(angle) (|c_g - ref| + r_g)``, padded) contains
    every posture of the geom on ``[ta_j, tb_j]`` (the motion-bound contract), so a sphere
    gap > margin (after the rounding pad, as the broad phase culls) proves the distance
    > margin there. The narrow phase's exclusion test is a whole-solid test, so a sub-window
    that starts after t0 needs no start-pose argument (module docstring). A certificate's
    clearance is the smaller of the narrow phase's and the cleared sub-ranges' sphere gaps;
    a witness (earliest in ``[ta_f, tb_l]``) is the earliest one, as everything before
    ``ta_f`` is clear.

    Returns:
        S (stage 0) or the number of survivor slots processed (stage 1); ``info[WI_DONE]`` is
        the end of the slots processed in both cases.
    """
    # (one function body, no helper taking the packs: each function typed on the two packs
    # costs about a second of cold compile)
    t0, t1 = prm[WP_T0], prm[WP_T1]
    margin, epsilon = prm[WP_MARGIN], prm[WP_EPS]
    rel_pad, abs_pad = prm[WP_REL], prm[WP_ABS]
    max_depth = int(prm[WP_MAX_DEPTH])
    max_tests = int(prm[WP_MAX_TESTS])
    # a long window: at least as many waypoints inside [t0, t1] as sub-ranges (a window and its
    # braking tail); single-segment motions keep the whole-window search
    n_in = 0
    for i in range(mp.times.shape[0]):
        if t0 < mp.times[i] < t1:
            n_in += 1
    long_window = n_in >= sc.shape[0]
    S = 0
    if stage == 0:
        # -- swept spheres and AABBs per geom (the argument of broadphase.swept_geom_spheres) --
        T = sc.shape[0]
        nbody = mp.body_parent.shape[0]
        G = gp.kind.shape[0]
        pos = np.empty((T, nbody, 3))
        rot = np.empty((T, nbody, 3, 3))
        trans = np.empty((T, nbody))
        ang = np.empty((T, nbody))
        step = (t1 - t0) / T      # the edges of np.linspace(t0, t1, T + 1), bit for bit
        # tree_bounds per sub-range, with its scratch allocated once for the T calls (the same
        # numbers: _bounds_core's result does not depend on the scratch's contents on entry)
        need_all = np.ones(nbody, np.int64)
        ws = bounds_workspace(mp)
        # Early survival (issue 12, pair-window median): the middle sub-range first. When every
        # selected pair is a pair of cores (not both static) whose swept spheres on that one sub-range
        # are within the margin, no pair can be culled: the full path's sphere gap is the minimum over
        # the T sub-ranges minus pad, so at most this sub-range's (pad grows with the positions of all
        # T sub-ranges, and rounding is monotone: computed with the same expressions, this pad is a
        # lower bound of the full one), and the AABB pre-test never culls a pair whose sphere gap is
        # <= margin (its separation is a lower bound on every sub-range's sphere gap). Then every pair
        # is WK_OPEN with gap NaN, S = P and no best culled gap: the full path's outputs. The other
        # outputs (sc, sr, info[WI_PAD]) are read only for culled pairs and by long windows (excluded
        # here); they are set to "unbounded" (never culls, never clears). Otherwise the full path runs
        # (reusing this sub-range's bounds: _bounds_core's results do not depend on the order).
        tq = T // 2
        ta = tq * step + t0
        tb = t1 if tq == T - 1 else (tq + 1) * step + t0
        _bounds_core(mp, ta, tb, need_all, pos[tq], rot[tq], trans[tq], ang[tq], ws)
        grow_f = 1.0 + 8.0 * rel_pad
        mark = np.zeros(nbody, np.int64)     # _moving_base's scratch (stamps: pair index + 1)
        all_open = pairs.shape[0] > 0 and not long_window
        if all_open:
            # this sub-range's share of the full path's ``mag`` (NaN propagates: then nothing is proven)
            magq = np.abs(pos[tq]).max() + 1.0
            padq = rel_pad * magq + abs_pad + prm[WP_SCALE_PAD] * magq
            cq = np.empty((2, 3))
            rq = np.empty(2)
            for k in range(pairs.shape[0]):
                ga, gb = pairs[k, 0], pairs[k, 1]
                both_fixed = fixed[gp.body[ga]] != 0 and fixed[gp.body[gb]] != 0
                if both_fixed or gp.kind[ga] < 0 or gp.kind[gb] < 0 or _moving_base(
                        mp.body_parent, mp.body_moving, gp.body[ga], gp.body[gb], mark, k + 1) != 0:
                    all_open = False     # (a pair the relative sphere below may cull)
                    break
                for j in range(2):
                    g = ga if j == 0 else gb
                    b = gp.body[g]
                    rad = gp.brad[g]
                    cg = gp.bcenter[g]
                    ref = mp.ref_points[b]
                    # the geom loop's sphere of sub-range tq, the same expressions
                    lever = _norm3(cg[0] - ref[0], cg[1] - ref[1], cg[2] - ref[2]) + rad
                    R = rot[tq, b]
                    rr = rad + (trans[tq, b] + 2.0 * math.sin(0.5 * min(ang[tq, b], math.pi)) * lever
                                ) * grow_f
                    if not rr >= 0.0:
                        rr = np.inf
                    rq[j] = rr
                    for r in range(3):
                        cq[j, r] = R[r, 0] * cg[0] + R[r, 1] * cg[1] + R[r, 2] * cg[2] + pos[tq, b, r]
                d = (_norm3(cq[0, 0] - cq[1, 0], cq[0, 1] - cq[1, 1], cq[0, 2] - cq[1, 2]) - rq[0] - rq[1])
                if not (gp.brad[ga] < np.inf and gp.brad[gb] < np.inf and d > -np.inf and d - padq <= margin):
                    all_open = False
                    break
        if all_open:
            for t in range(T):
                for g in range(G):
                    sr[t, g] = np.inf
                    for r in range(3):
                        sc[t, g, r] = 0.0
            for k in range(pairs.shape[0]):
                code[k] = WK_OPEN
                gap[k] = np.nan
                surv[S] = k
                S += 1
            info[WI_PAD] = np.nan
            info[WI_BEST] = np.inf
            info[WI_SURV] = S
            k0 = 0
            k1 = min(k1, S)
        else:
            for t in range(T):
                if t == tq:
                    continue      # computed above
                ta = t * step + t0
                tb = t1 if t == T - 1 else (t + 1) * step + t0
                _bounds_core(mp, ta, tb, need_all, pos[t], rot[t], trans[t], ang[t], ws)
            mag = 0.0
            for t in range(T):
                for b in range(nbody):
                    for r in range(3):
                        mag = max(mag, abs(pos[t, b, r]))
            mag += 1.0
            pad = rel_pad * mag + abs_pad + prm[WP_SCALE_PAD] * mag
            lo = np.empty((G, 3))
            hi = np.empty((G, 3))
            for g in range(G):
                b = gp.body[g]
                rad = gp.brad[g]
                if gp.kind[g] < 0 or not rad < np.inf:
                    for t in range(T):
                        sr[t, g] = np.inf
                        for r in range(3):
                            sc[t, g, r] = 0.0
                    for r in range(3):
                        lo[g, r] = -np.inf
                        hi[g, r] = np.inf
                    continue
                cg = gp.bcenter[g]
                ref = mp.ref_points[b]
                lever = _norm3(cg[0] - ref[0], cg[1] - ref[1], cg[2] - ref[2]) + rad
                for r in range(3):
                    lo[g, r] = np.inf
                    hi[g, r] = -np.inf
                for t in range(T):
                    R = rot[t, b]
                    rr = rad + (trans[t, b] + 2.0 * math.sin(0.5 * min(ang[t, b], math.pi)) * lever) * grow_f
                    if not rr >= 0.0:
                        rr = np.inf
                    sr[t, g] = rr
                    for r in range(3):
                        x = R[r, 0] * cg[0] + R[r, 1] * cg[1] + R[r, 2] * cg[2] + pos[t, b, r]
                        sc[t, g, r] = x
                        if not x - rr >= lo[g, r]:
                            lo[g, r] = x - rr
                        if not x + rr <= hi[g, r]:
                            hi[g, r] = x + rr
                for r in range(3):    # NaN anywhere: an unbounded box (never culls)
                    if not (lo[g, r] == lo[g, r] and hi[g, r] == hi[g, r]):
                        lo[g, r] = -np.inf
                        hi[g, r] = np.inf
            info[WI_PAD] = pad
            # relative spheres (see the docstring): scratch allocated on first use
            # (the bounds relative to one common ancestor, for all its descendants at once, kept
            # for the last _REL_SLOTS ancestors: pairs come sorted, so the same few recur)
            rneed = np.empty(0, np.int64)
            rpos = np.empty((0, 0, 3))
            rrot = np.empty((0, 0, 3, 3))
            rtrans = np.empty((0, 0))
            rang = np.empty((0, 0))
            rbase = np.full(_REL_SLOTS, -1, np.int64)
            rnext = 0
            rc = np.empty((2, 3))
            # -- which pairs: all of them, or the sweep's (sorted rows in surv[:nrows]) -----------
            nrows = pairs.shape[0]
            swept = False
            thr, lk, smax, nb = 0.0, 0.0, 1.0, 0
            order = np.empty(0, np.int64)
            unb = order
            sep_min = np.full(1, np.inf)
            # ``rows is None``: numba prunes this branch and the one after the pair loop, so the
            # sweep's kernels are not compiled into a window_kernel that never sweeps (the small
            # scenes' specialisation; the engine passes None below SWEEP_MIN_GEOMS geoms)
            if rows is not None:
                if rows.shape[0] == G + 1 and nrows > 0:
                    swept, nrows, thr, lk, smax, order, nb, unb = _sweep_first(lo, hi, margin, pad, pairs,
                                                                               rows, surv, sep_min)
                if swept:
                    for a in range(G):        # static-static pairs among the rows left out
                        if fixed[gp.body[a]] != 0:
                            for k in range(rows[a], rows[a + 1]):
                                if fixed[gp.body[pairs[k, 1]]] != 0:
                                    code[k] = WK_SS
                                    gap[k] = np.inf
            # -- per pair: static-static, half-space gap, AABB pre-test, sphere gap ---------------
            best = np.inf
            for kk in range(nrows):
                # the sweep's rows are read before slot S <= kk is written: in place
                k = surv[kk] if swept else kk
                ga, gb = pairs[k, 0], pairs[k, 1]
                if fixed[gp.body[ga]] != 0 and fixed[gp.body[gb]] != 0:
                    code[k] = WK_SS
                    gap[k] = np.inf
                    continue
                ka, kb = gp.kind[ga], gp.kind[gb]
                gap[k] = np.nan
                if ka < -1 or kb < -1 or (ka == -1 and kb == -1):
                    code[k] = WK_PYTHON
                    surv[S] = k
                    S += 1
                    continue
                if ka == -1 or kb == -1:
                    h, c = (ga, gb) if ka == -1 else (gb, ga)
                    g = _halfspace_gap(gp.normals[gp.nstart[h]], gp.verts[gp.vstart[h]], gp.body[h], c, sc,
                                       sr, trans, ang, rot, pos, pad)
                else:
                    sep = -np.inf
                    scale = 1.0
                    for r in range(3):
                        s1 = lo[gb, r] - hi[ga, r]
                        s2 = lo[ga, r] - hi[gb, r]
                        if s1 > sep:
                            sep = s1
                        if s2 > sep:
                            sep = s2
                        scale = max(scale, abs(lo[ga, r]), abs(hi[ga, r]), abs(lo[gb, r]), abs(hi[gb, r]))
                    # rounding of c +- r and of the separation: 1e-12 relative covers it many times over
                    sep = sep - pad - 1e-12 * scale
                    if sep > margin and sep >= best:
                        code[k] = WK_CULLED
                        continue
                    g = sphere_gap(sc, sr, ga, gb, pad)
                    if not g > margin:
                        ba, bb = gp.body[ga], gp.body[gb]
                        cb = _moving_base(mp.body_parent, mp.body_moving, ba, bb, mark, k + 1)
                        if cb != 0:
                            if rneed.shape[0] == 0:
                                rneed = np.empty(nbody, np.int64)
                                rpos = np.empty((_REL_SLOTS, nbody, 3))
                                rrot = np.empty((_REL_SLOTS, nbody, 3, 3))
                                rtrans = np.zeros((_REL_SLOTS, nbody))
                                rang = np.zeros((_REL_SLOTS, nbody))
                            sl = -1
                            for j in range(_REL_SLOTS):
                                if rbase[j] == cb:
                                    sl = j
                            if sl < 0:
                                # pair_bound(relative=1)'s numbers for every descendant of cb in one
                                # pass: a body's bound and pose read only its own ancestors' need
                                sl = rnext
                                rnext = (rnext + 1) % _REL_SLOTS
                                rbase[sl] = cb
                                for b in range(nbody):
                                    c = b
                                    while c != 0 and c != cb:
                                        c = mp.body_parent[c]
                                    rneed[b] = 1 if c == cb and b != cb else 0
                                mark_ancestors(mp.body_parent, cb, rneed, 2)
                                _bounds_core(mp, t0, t1, rneed, rpos[sl], rrot[sl], rtrans[sl], rang[sl], ws)
                            TA, aA, TB, aB = rtrans[sl, ba], rang[sl, ba], rtrans[sl, bb], rang[sl, bb]
                            for r in range(3):
                                rc[0, r] = rpos[sl, ba, r]
                                rc[1, r] = rpos[sl, bb, r]
                            # the broad phase's sphere of each geom over [t0, t1], in the common
                            # ancestor's frame at the window's middle (same expressions)
                            d = 0.0
                            magr = 1.0
                            for j in range(2):
                                gg = ga if j == 0 else gb
                                b = ba if j == 0 else bb
                                tr, an = (TA, aA) if j == 0 else (TB, aB)
                                rad = gp.brad[gg]
                                cg = gp.bcenter[gg]
                                ref = mp.ref_points[b]
                                lever = _norm3(cg[0] - ref[0], cg[1] - ref[1], cg[2] - ref[2]) + rad
                                rr = rad + (tr + 2.0 * math.sin(0.5 * min(an, math.pi)) * lever) * grow_f
                                if not rr >= 0.0:
                                    rr = np.inf
                                d -= rr
                                R = rrot[sl, b]
                                for r in range(3):
                                    magr = max(magr, abs(rc[j, r]) + 1.0)
                                    x = R[r, 0] * cg[0] + R[r, 1] * cg[1] + R[r, 2] * cg[2] + rc[j, r]
                                    rc[j, r] = x       # (the origin is not read again)
                            padr = max(pad, rel_pad * magr + abs_pad + prm[WP_SCALE_PAD] * magr)
                            gr = _norm3(rc[0, 0] - rc[1, 0], rc[0, 1] - rc[1, 1], rc[0, 2] - rc[1, 2])
                            gr = gr + d - padr
                            if gr > margin:
                                g = gr
                if g > margin:
                    code[k] = WK_CULLED
                    gap[k] = g
                    if g < best:
                        best = g
                else:
                    code[k] = WK_OPEN
                    surv[S] = k
                    S += 1
            if rows is not None:
                if swept:
                    best = _sweep_best(lo, hi, order, nb, unb, thr, lk, smax, margin, pad, best, pairs, rows,
                                       fixed, gp.body, code, sc, sr, surv, S, sep_min)
            info[WI_BEST] = best
            info[WI_SURV] = S
            k0 = 0
            k1 = min(k1, S)
    # -- stage 1: start pose and whole-shape stage on survivor slots [k0, k1) ----------------
    done = k1
    if k1 > k0:   # (nothing allocated for a window every pair of which was culled)
        call_tests = 0.0               # whole-shape tests of this call (see CALL_TESTS)
        stack = np.empty((max_depth + 2, 3))
        sw = _search_workspace(gp, mp)     # the searches' scratch, once per call (see _pair_search)
        out = np.empty(OUT_SIZE)
        w = np.empty(3)
        pA = np.empty(3)
        pB = np.empty(3)
        RA = np.empty((3, 3))
        RB = np.empty((3, 3))
        nbody = mp.body_parent.shape[0]
        have0 = np.zeros(nbody, np.int64)      # body poses at t0 computed in this call (pos0, rot0)
        pos0 = np.empty((nbody, 3))
        rot0 = np.empty((nbody, 3, 3))
        for s in range(k0, k1):
            k = surv[s]
            if code[k] != WK_OPEN:
                continue
            ga, gb = pairs[k, 0], pairs[k, 1]
            ba, bb = gp.body[ga], gp.body[gb]
            row = res[s]
            for j in range(R_SIZE):
                row[j] = 0.0
            row[R_WTIME] = np.nan
            row[R_FIRST_UNRES] = np.nan
            # start poses, each body's computed once per call (body_pose's numbers: a body's
            # FK reads only its own ancestors, so the pose does not depend on the pair)
            for b in (ba, bb):
                if have0[b] == 0:
                    body_pose(mp, b, t0, pos0[b], rot0[b])
                    have0[b] = 1
            for r in range(3):
                pA[r] = pos0[ba, r]
                pB[r] = pos0[bb, r]
                for c in range(3):
                    RA[r, c] = rot0[ba, r, c]
                    RB[r, c] = rot0[bb, r, c]
            lo_d, up_d = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)
            info[WI_TESTS] += 1.0
            row[R_START_LO] = lo_d
            approx = gp.approx[ga] + gp.approx[gb]
            if up_d + approx < margin:
                code[k] = WK_STATIC_VIOL
                row[R_VERDICT] = VIOLATION
                row[R_WTIME] = t0
                for r in range(3):
                    row[R_WPOINT + r] = w[r]
                row[R_WUPPER] = up_d + approx
                row[R_CLEAR] = -np.inf
                continue
            if moving[ba] == 0 and moving[bb] == 0:
                if lo_d > margin:
                    code[k] = WK_STATIC_CERT
                    row[R_VERDICT] = CERTIFIED
                    row[R_CLEAR] = lo_d
                else:
                    code[k] = WK_PYTHON    # "uncertain" unless the Python start test (depth LP) confirms
                continue
            if route.shape[0] > 0 and route[s] == 0:
                continue                   # extrusion route: the Python pipeline
            row[R_STARTED] = 2.0
            # Sub-ranges of the window where the pair's swept spheres are apart (issue 12, long
            # windows): only the span from the first to the last sub-range where they are not goes
            # to the narrow phase (see the docstring: "Stage 1").
            ta_s, tb_s, sph = t0, t1, np.inf
            if long_window and gp.kind[ga] >= 0 and gp.kind[gb] >= 0:
                T = sc.shape[0]
                step = (t1 - t0) / T      # the sub-range edges of stage 0, bit for bit
                jf, jl = -1, -1
                gaps = np.empty(T)
                for t in range(T):
                    d = (_norm3(sc[t, ga, 0] - sc[t, gb, 0], sc[t, ga, 1] - sc[t, gb, 1],
                                sc[t, ga, 2] - sc[t, gb, 2]) - sr[t, ga] - sr[t, gb]) - info[WI_PAD]
                    gaps[t] = d
                    if not (d > margin and d < np.inf):
                        if jf < 0:
                            jf = t
                        jl = t
                if jf >= 0:
                    ta_s = t0 if jf == 0 else jf * step + t0
                    tb_s = t1 if jl == T - 1 else (jl + 1) * step + t0
                    for t in range(T):
                        if (t < jf or t > jl) and gaps[t] < sph:
                            sph = gaps[t]
            v = _pair_search(gp, mp, ga, gb, ta_s, tb_s, margin, epsilon, max_depth, max_tests,
                             MODE_CERTIFY_ONLY, rel_pad, abs_pad, stack, row, sw)
            if v == CERTIFIED and sph < row[R_CLEAR]:
                row[R_CLEAR] = sph        # the sub-ranges the spheres cleared: their gap bounds the clearance
            info[WI_TESTS] += row[R_TESTS]
            call_tests += row[R_TESTS]
            row[R_TESTS] += 1.0            # the start-pose test, counted as the pair's (as pair_window does)
            if row[R_DEPTH] > info[WI_DEPTH]:
                info[WI_DEPTH] = row[R_DEPTH]
            if v == CERTIFIED:
                code[k] = WK_CERT
            elif v == VIOLATION:
                code[k] = WK_VIOL
                fu = row[R_FIRST_UNRES]
                if not (fu <= row[R_WTIME]):
                    row[R_FIRST_UNRES] = row[R_WTIME]
            else:
                code[k] = WK_UNRES
            if call_tests >= CALL_TESTS and s + 1 < k1:
                done = s + 1               # the budget clock is the caller's: it continues from here
                break
    info[WI_DONE] = done
    if stage == 0:
        return S
    return done - k0


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



_SCENE_PACKS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

def scene_pack(scene):
    """The scene's :class:`~monitor.certify.packed.ScenePack`, packed once and cached per scene.

    Keyed on the scene object AND its current ``geoms`` tuple and ``pair_ids`` array:
    :meth:`monitor.Scene.sync` replaces both when it rebuilds the shapes after an in-place
    model edit, so a stale pack is never used.
    """
    cached = _SCENE_PACKS.get(scene)
    if cached is not None and cached[0] is scene.geoms and len(cached) == 3 and cached[1] is scene.pair_ids:
        return cached[2]
    from monitor.certify.packed import pack_scene
    sp = pack_scene(scene)
    _SCENE_PACKS[scene] = (scene.geoms, scene.pair_ids, sp)
    return sp


_MOTION_PACKS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _poses_match(traj, mp) -> bool:
    """Packed poses == the trajectory's own ``body_poses`` at every waypoint and segment midpoint.

    Tolerance: 1e-9 relative (positions), 1e-9 absolute (rotation entries). Costs one FK of
    the trajectory (``mj_kinematics`` for a Plan) and one packed FK per point.
    """
    from monitor.motion.pack import body_poses

    wp = np.asarray(mp.times, np.float64)
    times = np.sort(np.concatenate([wp, 0.5 * (wp[:-1] + wp[1:])]))
    P_W, R_WB = traj.body_poses(times)
    p_k, R_k = body_poses(mp, times)
    P_W = np.asarray(P_W, np.float64)
    R_WB = np.asarray(R_WB, np.float64)
    return bool((np.abs(p_k - P_W) <= 1e-9 * (1.0 + np.abs(P_W))).all()
                and (np.abs(R_k - R_WB) <= 1e-9).all())


_VERIFIED_TREES: dict = {}
"""(model structure key, :func:`monitor.motion.pack.static_key`) -> True (the packed tree was
checked against the model's own FK at random configurations), False (it failed: refuse), or
"full" (the tree passed but a plan's own full pose check failed: check every plan in full)."""
_VERIFIED_TREES_MAX = 64
PROBE_SEED = 20261124
PROBE_WAYPOINTS = 4


def _tree_verified(traj, mp, key) -> bool:
    """Check the pack's kinematic tree once against the model's own FK (see :func:`_pack_agrees`)."""
    from monitor.motion.pack import pack_trajectory, probe_plan, static_key

    hit = _VERIFIED_TREES.get(key)
    if hit is not None:
        return hit is not False
    probe = probe_plan(traj, PROBE_SEED, PROBE_WAYPOINTS)
    if getattr(probe._st, "key", None) != key[0]:
        return False    # the live model is no longer the one the plan was built on: no verdict to keep
    pm = pack_trajectory(probe)
    ok = static_key(pm, _pack_static(probe)) == key[1] and _poses_match(probe, pm)
    if len(_VERIFIED_TREES) >= _VERIFIED_TREES_MAX:
        _VERIFIED_TREES.pop(next(iter(_VERIFIED_TREES)))
    _VERIFIED_TREES[key] = ok
    return ok


def _pack_static(traj):
    """The packer's cached model part of ``traj``'s structure (a hint for ``static_key``), or None."""
    return getattr(getattr(traj, "_st", None), "_motion_pack_static", None)


def _pack_agrees(traj, mp) -> bool:
    """The packed motion reproduces the trajectory's own poses (checked once per pack).

    A :class:`monitor.BodyMotion` (or any trajectory without a model structure snapshot):
    packed poses == ``traj.body_poses`` at every waypoint and segment midpoint
    (:func:`_poses_match`), for every new object.

    A :class:`monitor.Plan` is a pack of two parts: the **tree** (model-only arrays:
    parents, joint types, qpos columns, anchors, axes, body offsets, mocap flags, reference
    points; :func:`monitor.motion.pack.static_key`) and the plan's **data** (times, qpos,
    quaternion tracks, held mocap poses, moving flags). Instead of a double FK per plan
    (0.7 ms per gate window on Pusher), the check is split:

    1. **Tree, once per (model structure, tree bytes).** A probe Plan of the same model
       (:func:`monitor.motion.pack.probe_plan`: 4 seeded random configurations covering
       every joint, hinge angles in [-pi, pi], random ball / free / mocap orientations,
       random mocap positions; layout read from the plan's model snapshot, not from the
       pack) is packed by the same packer; its tree must be byte-equal to this pack's, and
       its packed poses must equal ``mj_kinematics`` at its waypoints and midpoints
       (:func:`_poses_match`, 1e-9). The result is remembered by key; the key contains the
       tree's bytes, so a new or an in-place edited tree is checked again on first use.
    2. **The first plan of each key** also gets the full :func:`_poses_match` on its own
       motion (as before this split).
    3. **Every plan**: :func:`monitor.motion.pack.plan_data_agrees`: the pack's times,
       qpos, quaternion tracks and mocap rows are the plan's own arrays bit for bit, and the
       moving / rotating flags equal the plan's own (derived independently). Microseconds.

    Soundness argument. The compiled FK of a pack is a fixed function of (tree, joint
    positions, mocap poses), and its interpolation a fixed function of (times, qpos,
    tracks). (3) makes the data the plan's own; (1) makes FK(tree, .) equal to MuJoCo's FK
    at 4 random configurations with every joint away from zero. A packing error in the tree
    (wrong joint axis, anchor, parent, body offset, joint type or qpos column, mocap flag)
    changes the pose of a body by a nonzero analytic function of the configuration; to pass
    it would have to vanish (below 1e-9) at all 4 random probes, i.e. lie on a measure-zero
    set or be below the 1e-9 tolerance everywhere (the old per-plan check had the same
    tolerance). An error in the interpolation would have to differ from the plan's own
    interpolation only on data other than the probe's random waypoints and the first plan's
    (branch decisions, e.g. which arc of a half turn, are the plan's own copied track
    arrays, checked in (3)). An error in the per-plan data would have to leave the arrays
    bit-identical, i.e. not be an error. Tests: tests/test_window_kernel.py (a corrupted
    joint axis or parent is refused on its first use, also after a good pack of the same
    model was verified, and after an in-place edit of the shared tree arrays).
    """
    if _is_plain_body_motion(traj):
        return _body_motion_agrees(traj, mp)
    st = getattr(traj, "_st", None)
    skey = getattr(st, "key", None)
    if skey is None or not hasattr(traj, "_quat_tracks"):
        return _poses_match(traj, mp)
    key = (skey, _pack.static_key(mp, _pack_static(traj)))
    state = _VERIFIED_TREES.get(key)
    if state is not True and not _tree_verified(traj, mp, key):   # True: verified (a dict hit)
        return False
    if not _pack.plan_data_agrees(traj, mp):
        return False
    if state is None or state == "full":     # the key's first plan, or a key already caught once
        if not _poses_match(traj, mp):
            # the tree passed its probes but this plan's own poses disagree: every later plan
            # of this key gets its own full check (the former per-plan behaviour)
            _VERIFIED_TREES[key] = "full"
            return False
    return True


_BODY_MOTION_PROBE: list = []
"""[True] / [False] once the compiled FK of BodyMotion packs was checked against
``BodyMotion.body_poses`` on the seeded probe motions (:func:`_body_motion_probe_ok`)."""


def _is_plain_body_motion(traj) -> bool:
    """``traj`` is exactly a lerp/slerp :class:`monitor.BodyMotion`.

    Not a subclass, which may override ``body_poses``.
    """
    cls = type(traj)
    if cls.__name__ != "BodyMotion":  # cheap pre-test; the identity test below decides
        return False
    from monitor.motion.bodymotion import BodyMotion

    return cls is BodyMotion and traj.interpolation == "lerp_slerp"


def _probe_body_motions() -> list:
    """Seeded BodyMotions covering what the compiled lerp/slerp FK branches on.

    Uneven waypoint times (K = 2 and K = 5), a non-identity constant world pose, random
    positions and orientations, a body that only translates, one that holds its orientation
    on one segment (``same``), one with a tiny turn, one with a turn near a half turn on
    either side of pi (sign-flipped targets) and one antipodal quaternion pair (the same
    rotation, opposite sign).
    """
    from monitor.motion._kinematics import quat_mul
    from monitor.motion.bodymotion import BodyMotion

    def turn(rotvec):
        ang = float(np.linalg.norm(rotvec))
        return np.concatenate([[np.cos(0.5 * ang)], np.sin(0.5 * ang) * np.asarray(rotvec) / ang])

    rng = np.random.default_rng(PROBE_SEED)
    out = []
    for K in (2, 5):
        nbody = 9
        times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.2, K - 1))]) + 0.3
        pos = rng.uniform(-2.0, 2.0, (K, nbody, 3))
        quat = rng.normal(size=(K, nbody, 4))
        quat /= np.linalg.norm(quat, axis=-1, keepdims=True)
        pos[:, 0] = pos[0, 0]
        quat[:, 0] = quat[0, 0]
        quat[:, 1] = quat[0, 1]                                   # translates only
        quat[1, 2] = quat[0, 2]                                   # holds orientation on segment 0
        quat[1, 3] = quat_mul(turn([1e-9, 2e-9, -1e-9]), quat[0, 3])   # tiny turn
        for b, ang in ((4, np.pi - 1e-6), (5, np.pi + 1e-6), (6, np.pi)):
            ax = rng.normal(size=3)
            quat[1, b] = quat_mul(turn(ang * ax / np.linalg.norm(ax)), quat[0, b])
        quat[1, 7] = -quat[0, 7]                                  # antipodal: no rotation
        out.append(BodyMotion(times, pos, quat, ref_points=rng.uniform(-0.3, 0.3, (nbody, 3))))
    return out


def _body_motion_probe_ok() -> bool:
    """The compiled FK of BodyMotion packs equals ``BodyMotion.body_poses`` on the probes (once)."""
    if not _BODY_MOTION_PROBE:
        from monitor.motion.pack import pack_trajectory

        ok = True
        for bm in _probe_body_motions():
            mp = pack_trajectory(bm)
            ok = (ok and _body_motion_layout_ok(bm, mp) and _body_motion_data_ok(bm, mp)
                  and _poses_match(bm, mp))
        _BODY_MOTION_PROBE.append(bool(ok))
    return _BODY_MOTION_PROBE[0]


def _body_motion_layout_ok(bm, mp) -> bool:
    """The pack's tree is the fixed BodyMotion layout.

    One free joint per non-world body, child of the world, qpos columns 7 (b - 1) .. 7 b,
    zero anchors and offsets, the world's row the motion's constant world pose, the motion's
    reference points. Every body's rows are the same function of its own qpos block and
    quaternion track.
    """
    nbody = bm.nbody
    nj = nbody - 1
    ar = np.arange(nj)
    eq = np.array_equal
    one = np.concatenate([[0], np.ones(nj, dtype=np.int64)])
    ident = np.zeros((nj, 4))
    ident[:, 0] = 1.0
    return bool(
        mp.jnt_type.shape == (nj,) and (mp.jnt_type == 0).all() and eq(mp.jnt_qposadr, 7 * ar)
        and eq(mp.qpos0, np.zeros(7 * nj)) and eq(mp.jnt_pos, np.zeros((nj, 3))) and eq(mp.jnt_track, ar)
        and eq(mp.jnt_axis_norm, np.ones(nj)) and eq(mp.body_parent, np.zeros(nbody, dtype=np.int64))
        and eq(mp.body_jntadr, np.concatenate([[0], ar])) and eq(mp.body_jntnum, one)
        and eq(mp.body_mocap, 1 - one) and eq(mp.body_pos[1:], np.zeros((nj, 3)))
        and eq(mp.body_quat[1:], ident)
        and eq(mp.body_pos[0], bm.pos[0, 0]) and eq(mp.body_quat[0], bm.quat[0, 0])
        and eq(mp.ref_points, bm.ref_points) and eq(mp.qt_adr, 7 * ar + 3))


def _body_motion_data_ok(bm, mp) -> bool:
    """The pack's motion data is the BodyMotion's own, bit for bit.

    Times, the position and
    quaternion columns of qpos, every quaternion track (target, half, phi, cum, same; the
    motion's own ``QuatTrack`` objects, whose waypoints are the motion's quaternions), and
    the moving / rotating flags against the motion's own (derived independently).
    """
    times = bm.times
    K, nbody = bm.pos.shape[0], bm.nbody
    nj = nbody - 1
    if not (mp.times.tobytes() == times.tobytes() and mp.qpos.shape == (K, 7 * nj)):
        return False
    q = mp.qpos.reshape(K, nj, 7)
    if not (np.array_equal(q[:, :, :3], bm.pos[:, 1:]) and np.array_equal(q[:, :, 3:], bm.quat[:, 1:])):
        return False
    if not (np.array_equal(mp.body_moving[1:] != 0, bm._moving[1:])
            and np.array_equal(mp.body_rotating[1:] != 0, bm._rotating[1:])):
        return False
    tracks = bm._tracks[1:]
    if len(tracks) != nj or mp.qt_target.shape != (nj, K - 1, 4):
        return False
    if nj == 0:
        return True
    return bool(np.array_equal(np.stack([tr.q for tr in tracks], axis=1), bm.quat[:, 1:])
                and np.array_equal(mp.qt_target, np.stack([tr.target for tr in tracks]))
                and np.array_equal(mp.qt_half, np.stack([tr.half for tr in tracks]))
                and np.array_equal(mp.qt_phi, np.stack([tr.phi for tr in tracks]))
                and np.array_equal(mp.qt_cum, np.stack([tr.cum for tr in tracks]))
                and np.array_equal(mp.qt_same != 0, np.stack([tr.same for tr in tracks])))


def _body_motion_agrees(bm, mp) -> bool:
    """The pack check for a plain lerp/slerp :class:`monitor.BodyMotion` (no per-motion FK).

    The former check evaluated ``bm.body_poses`` (a Python slerp per body: ~45 ms at 1000
    bodies) at every waypoint and midpoint, per motion. Split as for a Plan
    (:func:`_pack_agrees`):

    1. **Once per process**: the compiled FK of BodyMotion packs must equal
       ``BodyMotion.body_poses`` (1e-9, :func:`_poses_match`) on seeded probe motions
       (:func:`_probe_body_motions`: random poses, a constant non-identity world pose, and
       the slerp's edge cases) whose packs also pass (2) and (3).
    2. **Every motion, layout** (:func:`_body_motion_layout_ok`): the tree is the fixed
       BodyMotion layout, in which every body is an independent free joint on the world,
       computed by the same compiled code from its own qpos block and track only.
    3. **Every motion, data** (:func:`_body_motion_data_ok`): times, qpos, tracks and flags
       are the motion's own arrays, bit for bit.

    Soundness argument. With (2) the compiled pose of body b at time t is one fixed function
    F(times, qpos block of b, track of b, t) (plus the world's constant pose); ``body_poses``
    of a plain BodyMotion is one fixed function G of the same data (lerp of ``pos[:, b]``,
    ``QuatTrack.interp`` of the motion's own track). (3) makes the data the motion's own.
    F = G on the probes' bodies and times, which exercise every branch either function takes
    (segment location, translation only, held orientation, tiny turn, half turn on both
    sides, sign-flipped target); a disagreement elsewhere would need F - G to vanish on
    the probes yet not on this motion's data, i.e. a packing error that depends on data
    values the probes do not take. Subclasses and screw motions keep the full per-motion
    check. Tests: tests/test_pack_check_bodymotion.py.
    """
    return _body_motion_probe_ok() and _body_motion_layout_ok(bm, mp) and _body_motion_data_ok(bm, mp)


def trajectory_pack(traj):
    """The trajectory's :class:`~monitor.motion.pack.MotionPack` for the compiled window, or None.

    None when the motion packer does not support the trajectory (screw / Bézier motions,
    other Trajectory classes) or when the packed poses differ from the trajectory's own
    (:func:`_pack_agrees`). Cached per trajectory object (weakly): a :class:`monitor.Plan`
    or :class:`monitor.BodyMotion` never changes after construction (its waypoint arrays
    are read-only copies, held mocap poses are copies); a plan whose model was edited in
    place is replaced by a new object (``Plan.refreshed``, see ``engine._check_model``)
    before it gets here, so it gets its own pack.
    """
    return trajectory_pack_memo(traj)[0]


def trajectory_pack_memo(traj) -> tuple:
    """(:func:`trajectory_pack` of ``traj``, a dict cached with it) or (None, None).

    The dict lives as long as the cached pack (per trajectory object, weakly keyed) and is
    empty at first: the engine keeps there what it derives from the (immutable) trajectory
    alone, e.g. ``moving_bodies()``, so a window certified again costs no re-derivation.
    Not cached (a fresh empty dict) for objects that cannot be weakly referenced.
    """
    try:
        hit = _MOTION_PACKS.get(traj)
    except TypeError:          # not weak-referenceable / hashable: no cache
        hit = None
    if hit is not None:
        return hit if hit[0] is not None else (None, None)
    try:
        mp = _pack.pack_trajectory(traj)
        if not _pack_agrees(traj, mp):
            mp = None
    except (_MonitorError, TypeError, AttributeError, ValueError):
        mp = None
    entry = (mp, {})
    try:
        _MOTION_PACKS[traj] = entry
    except TypeError:
        pass
    return entry if mp is not None else (None, None)


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
        ``body_poses`` at a waypoint or a segment midpoint (:func:`trajectory_pack`), makes
        every entry None.
    """
    out: list[dict | None] = [None] * len(geom_pairs)
    if not geom_pairs or (budget is not None and budget.exhausted):
        return out
    mp = trajectory_pack(plan)     # None: not packable, or packed poses differ from the plan's own
    if mp is None:
        return out
    gp = scene_pack(scene).geoms
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


whole_shape_stage._compiled_stage = True  # the engine's window kernel runs this stage itself (see engine)


__all__ = ["CERTIFIED", "VIOLATION", "UNRESOLVED", "PAUSED", "UNSUPPORTED", "MODE_FULL", "MODE_CERTIFY_ONLY",
           "posed_distance", "interval_bound", "pair_window", "pairs_window", "new_result", "R_SIZE",
           "check_pair_window", "whole_shape_stage", "window_kernel", "sphere_gap", "scene_pack",
           "trajectory_pack", "trajectory_pack_memo"]


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
