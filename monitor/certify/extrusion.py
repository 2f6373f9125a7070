"""Cameron's 4-D extrusion checker: exact space-time certification of translating bodies.

Implements S. Cameron, *Collision detection by four-dimensional intersection
testing* (IEEE T-RA 1990) for bodies whose rotation is constant over the window
and whose origin moves with piecewise-constant velocity (static bodies have
velocity zero). Section numbers below refer to the paper.

Pipeline (per time span, spans in time order):

1. **Extrusion** (§2, eqs. 3-4). A body is a union of convex geoms (the
   distribution theorem: the body's extrusion is the same union over the
   extruded leaves). A polytope leaf ``n.x <= o`` moving with ``v`` extrudes to
   ``n.x - (n.v) tau <= o``. Spans are the merged velocity breakpoints of all
   bodies (§3, §4.3.2), each bounded by the two temporal half-spaces
   ``tau >= 0`` and ``tau <= T``.
2. **S-bounds** (§4.3, App. B, §6.3). Per body pair, leaf boxes are combined by
   the Upward (join) and Downward (meet) rules and the closed-form root operator
   of Appendix B, which yields the time interval ``[t_l, t_h]`` of possible
   overlap and tightened boxes. Leaves whose bound empties are removed; spans
   whose interval is null are discarded. With many bodies (§6.3) each leaf keeps
   one bound per partner body; pairs excluded by the pair policy start with
   empty bounds. Counts of surviving primitives and passes go into the stats.
3. **Divide and conquer** (§4.1, §6.2). A 4-D region (aligned box in x, y, z,
   tau) and the list of live leaf pairs. Per region a leaf is *empty* if one of
   its extruded half-spaces excludes the whole region (dropped), *full* if the
   region lies strictly inside all of them; a pair whose two leaves are both
   full is a proved collision. Leaves are tested against the region met with
   the pair's own S-bound box. Complexity = number of live leaf pairs needing
   exact work; conquer when it is ``<= kappa(d) = 2 d + 6`` (the paper's
   threshold, with our complexity unit being a leaf pair, i.e. one LP) or at
   ``d = 12`` binary splits (= 3 levels of the paper's 16-way split), else
   bisect the longest axis (time measured in metres by the fastest speed).
   Regions are processed earliest-first (heap on ``tau_lo``). A pair reaching
   conquer is decided by one exact test over its whole S-bound box (one per
   pair and span: regions prune, prove and order, they never multiply LPs).
   Before that, each pair is region-tested once on its own S-bound region in
   its own co-moving frame (the first scheme of §6.3). Regions are measured in
   a frame moving with a per-axis body velocity (App. B, "optimal fitting");
   collision is Galilean invariant, so this only shifts velocities.
   ``division="16way"`` splits all four axes as the paper does; the default
   longest-axis bisection needed the same LPs with 3.7x fewer regions (measured,
   docs/notes/issue-14-extrusion.md).
4. **Null-set test** (§4.2), per remaining convex leaf pair, in
   :mod:`monitor.certify.extrusion_null`: the slack LP with its float64-verified
   dual bound (regularised semantics: touching is not a collision), first tried
   with the 1- and 2-row duals (:func:`~monitor.certify.extrusion_null.dual_certificate`,
   no solver call). With a radius or a margin (``r = r_a + r_b + margin > 0``)
   each leaf's half-spaces are **offset** outward by its radius + margin/2 + delta
   (sphere and capsule cores get a synthesised H-rep: 14 directions about a point,
   an octagonal prism about a segment, :func:`core_hrep`). The offset polytope
   contains the rounded shape, so an empty offset intersection (max slack <=
   ``extrusion_slack`` < delta) certifies core distance > r. The offset
   over-approximates the rounded shape by up to r(sqrt 3 - 1) at a box corner
   (less with the 14 directions), so a region it leaves open (or a "full"
   region of §4.1) goes to
5. **the exact swept test** (not in the paper): the swept least-distance test
   (Wolfe / NNLS min-norm point of the swept Minkowski difference), which decides
   exactly; also ``offset=False`` sends every rounded pair straight there. Against
   a plane the closed form is exact (counted as the null-set stage: a half-space
   offset by r is exact). Sphere and capsule geoms are exact (no circumscribed
   polytope), so ``approx_error`` is 0 for them.

   ``PairOutcome.info["stage"]`` names the stage that decided the pair (the latest
   stage any span needed): ``"sbounds"``, ``"divide_and_conquer"``, ``"null_set"`` or
   ``"exact_swept"`` (:data:`STAGES`); :func:`search_summary` counts them.
6. **Earliest witness** (§5). Spans are visited in time order, and a pair found
   colliding in a span gets the exact first-contact time in that span (LP
   ``min tau`` over the intersection polytope, or bisection of the convex core
   distance). ``witness_time`` is the earliest time at which the overlap reaches
   half its maximal depth in that span (so that an exact static test confirms it
   robustly); ``info["earliest_time"]`` is the first-contact time.

Verdicts: "violation" only with a float64-verified witness (a point strictly
inside both solids, or core distance upper bound below ``r``); "certified" only
with a dual / separating-plane certificate (max slack <= extrusion_slack, or
core distance >= r - extrusion_slack). Accuracy of ``earliest_time``: LP
feasibility tolerance 1e-10 m divided by the approach speed along the contact
normal (LP path); 2^-52 of the span plus distance pads / speed (quadratic path).
"""

from __future__ import annotations

import heapq
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from monitor.certify.common import Budget, Outcome, PairOutcome
from monitor.certify.extrusion_null import (
    Leaf,
    NullResult,
    dual_certificate,
    halfspace_null_test,
    lp_earliest,
    lp_null_test,
    min_norm,
    quadratic_first_time,
    quadratic_null_test,
    slack_lower,
)
from monitor.certify.extrusion_sbounds import RootBound, pair_sbounds, swept_box
from monitor.errors import InvalidInputError, UnsupportedGeometryError
from monitor.geometry.shapes import ConvexShape
from monitor.motion._kinematics import finite_velocities
from monitor.tolerances import DEFAULT, Tolerances

KAPPA_MAX_DEPTH = 12
"""Maximum number of binary splits of a 4-D region (3 levels of the paper's 16-way split)."""


def kappa(d: int) -> int:
    """Complexity threshold of §4.1: conquer when live leaf pairs <= 2 d + 6."""
    return 2 * d + 6


@dataclass(frozen=True)
class TranslatingPair:
    """Two convex geoms on two translating bodies.

    Body pose: ``x_W = R @ p_B + origin(t)``, origin piecewise linear between ``times``.

    Attributes:
        shape_a: geom A's shape in its body frame.
        R_a: (3, 3) constant body rotation R_WB of A.
        times_a: (k+1,) strictly increasing breakpoints (s).
        origins_a: (k+1, 3) body origin (m, world) at the breakpoints.
        shape_b, R_b, times_b, origins_b: the same for B.
        name: (geom_a, geom_b) names for reports.
        bodies: optional (body_a, body_b) names: the n-ary search (``check_pairs(...,
            nary=True)``) groups geoms into bodies by name and identical motion, and names
            its bodies (stats) after them.
    """

    shape_a: ConvexShape
    R_a: np.ndarray
    times_a: np.ndarray
    origins_a: np.ndarray
    shape_b: ConvexShape
    R_b: np.ndarray
    times_b: np.ndarray
    origins_b: np.ndarray
    name: tuple[str, str] = ("a", "b")
    bodies: tuple[str, str] = ("", "")


@dataclass(frozen=True)
class TranslatingBody:
    """A body = union of convex geoms, translating with piecewise-constant velocity.

    Attributes:
        name: body name.
        shapes: convex geoms in the body frame.
        geom_names: one unique name per shape.
        R: (3, 3) constant rotation R_WB.
        times: (k+1,) strictly increasing breakpoints (s).
        origins: (k+1, 3) world body origin at the breakpoints (m).
    """

    name: str
    shapes: tuple[ConvexShape, ...]
    geom_names: tuple[str, ...]
    R: np.ndarray
    times: np.ndarray
    origins: np.ndarray


@dataclass
class SearchResult:
    """Outcomes of one n-ary search plus its statistics.

    Attributes:
        outcomes: one :class:`PairOutcome` per requested geom pair, in request order.
        pairs: the (geom_a, geom_b) names, same order.
        stats: JSON-serialisable counters (spans, per-span S-bound survivors,
            regions, LPs, full-region proofs, wall seconds).
    """

    outcomes: list[PairOutcome]
    pairs: list[tuple[str, str]]
    stats: dict[str, Any] = field(default_factory=dict)


# ----------------------------------------------------------------------------- validation

_EYE3 = np.eye(3)
_EYE3_BYTES = _EYE3.tobytes()


def _check_body(name: str, R: Any, times: Any, origins: Any, window: tuple[float, float]
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate and convert one body's motion; raises InvalidInputError naming ``name``."""
    R = np.asarray(R, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64).reshape(-1)
    origins = np.asarray(origins, dtype=np.float64)
    if R.shape != (3, 3):
        raise InvalidInputError(f"{name}: R must be a finite (3, 3) rotation, got shape {R.shape}")
    # the identity (bit for bit; the common case of static and translating bodies) is a
    # proper rotation: only other matrices need the finiteness / orthonormality / det test
    if R.tobytes() != _EYE3_BYTES:
        if not np.all(np.isfinite(R)):
            raise InvalidInputError(f"{name}: R must be a finite (3, 3) rotation, got shape {R.shape}")
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R.tolist()
        det = r00 * (r11 * r22 - r12 * r21) - r01 * (r10 * r22 - r12 * r20) + r02 * (r10 * r21 - r11 * r20)
        if float(np.abs(R.T @ R - _EYE3).max()) > 1e-9 or det < 0:
            raise InvalidInputError(f"{name}: R is not a proper rotation (|R^T R - I| > 1e-9 or det < 0)")
    if times.ndim != 1 or len(times) < 2 or origins.shape != (len(times), 3):
        raise InvalidInputError(f"{name}: need times (k+1,) with k >= 1 and origins (k+1, 3); "
                                f"got {times.shape} and {origins.shape}")
    if not (np.isfinite(times).all() and np.isfinite(origins).all()):
        raise InvalidInputError(f"{name}: times/origins contain NaN or inf")
    if (times[1:] <= times[:-1]).any():
        raise InvalidInputError(f"{name}: times must be strictly increasing")
    if not finite_velocities(times.tolist(), origins):
        raise InvalidInputError(f"{name}: a segment's velocity (origin change / duration) overflows float64")
    if times[0] > window[0] or times[-1] < window[1]:
        raise InvalidInputError(f"{name}: motion covers [{times[0]}, {times[-1]}] s, "
                                f"not the window {window}")
    return R, times, origins


def _check_shape(name: str, s: ConvexShape) -> None:
    """Reject shapes the checker cannot represent."""
    if not isinstance(s, ConvexShape):
        raise InvalidInputError(f"geom {name}: expected a ConvexShape, got {type(s).__name__}")
    if s.kind not in ("polytope", "sphere", "capsule", "halfspace"):
        raise UnsupportedGeometryError(f"geom {name}: unknown shape kind {s.kind!r}")
    if s.kind in ("polytope", "halfspace") and (len(s.normals) == 0 or len(s.normals) != len(s.offsets)):
        raise InvalidInputError(f"geom {name}: {s.kind} without a matching H-representation")
    if not (np.all(np.isfinite(s.points)) and np.isfinite(s.radius) and s.radius >= 0):
        raise InvalidInputError(f"geom {name}: non-finite points or negative radius")


def _check_window(window: Any, margin: float) -> tuple[float, float]:
    """Validate window and margin."""
    try:
        w0, w1 = (float(window[0]), float(window[1]))
    except (TypeError, IndexError, ValueError) as exc:
        raise InvalidInputError(f"window must be (t0, t1), got {window!r}") from exc
    if not (np.isfinite(w0) and np.isfinite(w1)) or not w0 < w1:
        raise InvalidInputError(f"window must be finite with t0 < t1, got {window!r}")
    if not np.isfinite(margin) or margin < 0:
        raise InvalidInputError(f"margin must be finite and >= 0, got {margin!r}")
    return w0, w1


# ----------------------------------------------------------------------------- the search

@dataclass
class _Body:
    name: str
    shapes: tuple[ConvexShape, ...]
    geoms: tuple[str, ...]
    R: np.ndarray
    times: np.ndarray
    origins: np.ndarray

    def state(self, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray]:
        """Origin (3,) at ``t0`` and velocity (3,) on the span [t0, t1] (inside one segment).

        The segment is the one starting at or before ``t0`` (a span's midpoint rounds to an end
        on a span one ulp long, and would pick a neighbouring segment's velocity).
        """
        i = min(max(int(np.searchsorted(self.times, t0, side="right")) - 1, 0), len(self.times) - 2)
        ta, tb = self.times[i], self.times[i + 1]
        v = (self.origins[i + 1] - self.origins[i]) / (tb - ta)
        return self.origins[i] + v * (t0 - ta), v


_DIAG = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float) / np.sqrt(3.0)
_POINT_NORMALS = np.vstack([np.eye(3), -np.eye(3), _DIAG])
"""(14, 3) unit normals of the polytope circumscribing a ball about a point core (cube + octahedron)."""


def core_hrep(shape: ConvexShape) -> tuple[np.ndarray, np.ndarray]:
    """H-representation ``N x <= h`` (body frame) of a shape's core, unit normals.

    Polytopes and half-spaces use their own. Point and segment cores (sphere,
    capsule) get a synthesised one with ``h`` the core's exact support values: 14
    directions (cube + octahedron) about a point; about a segment with axis ``a``
    the two end caps ``+-a`` and 8 directions 45 degrees apart around it (an
    octagonal prism). Offsetting these rows by the radius gives a polytope that
    contains the rounded shape (the construction of the offset null-set test).

    Returns:
        ``(N (f, 3), h (f,))``.
    """
    if shape.kind in ("polytope", "halfspace"):
        return shape.normals, shape.offsets
    P = shape.points
    if shape.kind == "capsule" and len(P) >= 2 and np.linalg.norm(P[1] - P[0]) > 0:
        a = (P[1] - P[0]) / np.linalg.norm(P[1] - P[0])
        u = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])
        u /= np.linalg.norm(u)
        w = np.cross(a, u)
        ang = np.arange(8) * (np.pi / 4)
        ring = np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * w
        N = np.vstack([a, -a, ring])
    else:
        N = _POINT_NORMALS
    return N, (N @ P.T).max(axis=1)


def _leaf(shape: ConvexShape, R: np.ndarray, o: np.ndarray, v: np.ndarray, c: np.ndarray,
          offset: float = 0.0) -> Leaf:
    """Leaf data centred at ``c`` (world) for a geom of a body at origin ``o`` (span start).

    ``offset`` (m) moves every half-space of the core's H-rep outwards (``h + offset``,
    unit normals): the offset polytope of §4.2's null-set test on rounded shapes.
    ``V`` and ``radius`` stay the exact core (the exact swept test uses them).
    """
    d = o - c
    Nb, hb = core_hrep(shape)
    N = Nb @ R.T if len(Nb) else np.zeros((0, 3))
    h = hb + offset + N @ d if len(hb) else np.zeros(0)
    V = shape.points @ R.T + d
    return Leaf(shape.kind, N, h, V, v, float(shape.radius))


@dataclass
class _PairState:
    ia: int
    ga: int
    ib: int
    gb: int
    r: float
    mode: str  # "lp" | "offset" | "quadratic" | "halfspace"
    off_a: float = 0.0  # outward offset (m) of A's half-spaces (offset mode)
    off_b: float = 0.0
    stage: int = 0  # index into STAGES of the deciding stage so far
    verdict: Outcome = Outcome.CERTIFIED
    tests: int = 0
    max_depth: int = 0
    unresolved: list[tuple[float, float]] = field(default_factory=list)
    clearance: float = np.inf
    witness_time: float | None = None
    witness_point: np.ndarray | None = None
    info: dict[str, Any] = field(default_factory=dict)
    done: bool = False


def _pair_box(rb: Any, va: np.ndarray, vb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Static box (3,) lo, hi holding both tightened moving boxes' overlap over [t_l, t_h]."""
    sa_lo, sa_hi = swept_box(rb.a_lo, rb.a_hi, va, rb.t_lo, rb.t_hi)
    sb_lo, sb_hi = swept_box(rb.b_lo, rb.b_hi, vb, rb.t_lo, rb.t_hi)
    return np.maximum(sa_lo, sb_lo), np.minimum(sa_hi, sb_hi)


def _own_frame_velocity(rb: Any, va: np.ndarray, vb: np.ndarray) -> np.ndarray:
    """(3,) per axis k the velocity va[k] or vb[k] whose co-moving frame gives the narrower overlap box.

    Ties go to A. Each axis of :func:`_pair_box` depends only on that axis' velocities,
    so one call per candidate gives all three axes (the same per-axis operations as
    measuring axis by axis).
    """
    lo_a, hi_a = _pair_box(rb, va - va, vb - va)
    lo_b, hi_b = _pair_box(rb, va - vb, vb - vb)
    return np.where((hi_a - lo_a) <= (hi_b - lo_b), va, vb)


def _empty_in_own_frames(rb: Any, va: np.ndarray, vb: np.ndarray) -> bool:
    """True if the pair's overlap box is empty along some axis measured in A's or B's frame.

    Every frame gives a valid bound (App. B, optimal fitting); the n-ary search uses
    one common frame per span for its regions, so each pair is first culled in its own
    two candidate frames, as the pairwise search would.
    """
    for w in (va, vb):
        lo, hi = _pair_box(rb, va - w, vb - w)
        if np.any(lo > hi):
            return True
    return False


STAGES = ("sbounds", "divide_and_conquer", "null_set", "exact_swept")
"""Deciding stages, in pipeline order (``PairOutcome.info["stage"]``): S-bounds (§4.3,
App. B), divide and conquer (§4.1 region tests), the null-set LP (§4.2; also the closed
form against a half-space), the exact swept least-distance test (fallback, not in the paper).
A pair's stage is the latest stage any of its spans needed."""


def _mode(sa: ConvexShape, sb: ConvexShape, r: float, name: tuple[str, str], offset: bool = True) -> str:
    """Which exact test decides a leaf pair.

    ``"lp"``: two sharp polytopes at zero margin (§4.2 as in the paper); ``"offset"``:
    r > 0, the null-set LP on the offset half-spaces first, the exact swept test only
    where it leaves the region open; ``"quadratic"``: the exact swept test alone
    (``offset=False``); ``"halfspace"``: closed form against a plane.
    """
    if sa.kind == "halfspace" and sb.kind == "halfspace":
        raise UnsupportedGeometryError(f"pair {name}: two half-spaces (planes) cannot be collided")
    if sa.kind == "halfspace" or sb.kind == "halfspace":
        return "halfspace"
    if r > 0.0:
        return "offset" if offset else "quadratic"
    return "lp"


class _Search:
    """One §6 n-ary search over translating bodies (a single pair is the case n = 2)."""

    def __init__(self, bodies: Sequence[_Body], pairs: Sequence[tuple[int, int, int, int]],
                 window: tuple[float, float], margin: float, tol: Tolerances,
                 budget: Budget | None, earliest: bool, clearance: bool,
                 divide: bool = True, offset: bool = True, division: str = "bisect") -> None:
        if division not in ("bisect", "16way"):
            raise InvalidInputError(f"division must be 'bisect' or '16way', got {division!r}")
        self.division = division
        self.bodies = bodies
        self.window = window
        self.margin = margin
        self.tol = tol
        self.budget = budget
        self.earliest = earliest
        self.want_clearance = clearance
        self.divide = divide
        coords = [np.abs(b.origins).max() + max(float(np.abs(s.points).max()) for s in b.shapes)
                  for b in bodies]
        self.scale = float(max(coords)) if coords else 0.0
        self.box_pad = self.tol.pad(self.scale) + self.tol.scale_pad * self.scale
        # rounding made when leaves are placed in the world and centred (|o - c| from
        # coordinates of size `scale`): widens every exact-test bound (rel_pad = 64 ulp)
        self.data_pad = self.tol.rel_pad * self.scale + self.tol.abs_pad
        # offset null-set test: each side's half-spaces move out by its radius + margin/2
        # + delta. If the rounded shapes came within the margin at some instant, the
        # midpoint of the closest points would lie in both offset polytopes with slack
        # >= delta; the LP certifies max slack <= extrusion_slack < delta, so an offset
        # certificate proves core distance > r_a + r_b + margin over the region.
        self.delta = 2.0 * self.tol.extrusion_slack + self.data_pad + 1e-12
        self.states: list[_PairState] = []
        for ia, ga, ib, gb in pairs:
            sa, sb = bodies[ia].shapes[ga], bodies[ib].shapes[gb]
            r = sa.radius + sb.radius + margin
            nm = (bodies[ia].geoms[ga], bodies[ib].geoms[gb])
            st = _PairState(ia, ga, ib, gb, r, _mode(sa, sb, r, nm, offset))
            if st.mode == "offset":
                st.off_a = sa.radius + 0.5 * margin + self.delta
                st.off_b = sb.radius + 0.5 * margin + self.delta
            self.states.append(st)
        self._w = np.zeros(3)
        self.stats: dict[str, Any] = {"spans": [], "lps": 0, "nnls": 0, "regions": 0,
                                      "full_region_proofs": 0, "leaf_pairs": len(pairs),
                                      "offset_lps": 0, "offset_certified": 0, "offset_open": 0,
                                      "exact_swept": 0, "dual_shortcut": 0}

    @staticmethod
    def _stage(p: _PairState, name: str) -> None:
        """Record that ``name`` was needed for ``p`` (the latest stage wins)."""
        p.stage = max(p.stage, STAGES.index(name))

    def _leaves(self, p: _PairState, st: dict, c: np.ndarray) -> tuple[Leaf, Leaf]:
        """Both leaves of a pair centred at ``c`` (offset H-reps in offset mode)."""
        A, B = self.bodies[p.ia], self.bodies[p.ib]
        (oa, va), (ob, vb) = st[p.ia], st[p.ib]
        return (_leaf(A.shapes[p.ga], A.R, oa, va, c, p.off_a),
                _leaf(B.shapes[p.gb], B.R, ob, vb, c, p.off_b))

    # -- spans
    def spans(self) -> list[tuple[float, float]]:
        """Merged velocity breakpoints of all bodies inside the window (§3)."""
        w0, w1 = self.window
        bps = {w0, w1}
        for b in self.bodies:
            bps.update(float(t) for t in b.times if w0 < t < w1)
        ts = sorted(bps)
        return list(zip(ts[:-1], ts[1:]))

    def _charge(self, n: int = 1) -> None:
        if self.budget is not None:
            self.budget.charge(n)

    def _exhausted(self) -> bool:
        return self.budget is not None and self.budget.exhausted

    # -- main loop
    def run(self) -> None:
        """Process spans in time order until every pair is decided."""
        t_start = time.perf_counter()
        for s0, s1 in self.spans():
            live = [p for p in self.states if not p.done]
            if not live:
                break
            if self._exhausted():
                for p in live:
                    p.unresolved.append((s0, self.window[1]))
                    p.done = True
                    p.info["budget_exhausted"] = True
                break
            self._span(s0, s1, live)
        self.stats["wall_seconds"] = time.perf_counter() - t_start

    def _leaf_box(self, body: _Body, g: int, o: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World AABB of a leaf at the span start (inflated by radius, margin/2, pad)."""
        s = body.shapes[g]
        if s.kind == "halfspace":
            lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
            n = (s.normals @ body.R.T)[0]
            off = float(s.offsets[0] + n @ o)
            nz = np.flatnonzero(n != 0.0)
            if len(nz) == 1:
                k = int(nz[0])
                bound = off / n[k]
                if n[k] > 0:
                    hi[k] = bound + self.box_pad + 0.5 * self.margin
                else:
                    lo[k] = bound - self.box_pad - 0.5 * self.margin
            return lo, hi
        P = s.points @ body.R.T + o
        infl = s.radius + 0.5 * self.margin + self.box_pad
        return P.min(axis=0) - infl, P.max(axis=0) + infl

    def _span(self, s0: float, s1: float, live: list[_PairState]) -> None:
        """S-bounds, divide and conquer and exact tests for one span."""
        T = s1 - s0
        st = {o: self.bodies[o].state(s0, s1) for o in {p.ia for p in live} | {p.ib for p in live}}
        span_stats: dict[str, Any] = {"span": [s0, s1], "body_pairs": 0, "body_pairs_pruned": 0,
                                      "passes": 0, "leaves_in": 0, "leaves_out": 0}
        # group leaf pairs by body pair; each leaf keeps one bound per partner body (§6.3)
        groups: dict[tuple[int, int], list[_PairState]] = {}
        for p in live:
            groups.setdefault((p.ia, p.ib), []).append(p)
        items: list[tuple[_PairState, Any]] = []
        for (ia, ib), plist in groups.items():
            A, B = self.bodies[ia], self.bodies[ib]
            (oa, va), (ob, vb) = st[ia], st[ib]
            ga = sorted({p.ga for p in plist})
            gb = sorted({p.gb for p in plist})
            boxa = [self._leaf_box(A, g, oa) for g in ga]
            boxb = [self._leaf_box(B, g, ob) for g in gb]
            a_lo = np.array([b[0] for b in boxa])
            a_hi = np.array([b[1] for b in boxa])
            b_lo = np.array([b[0] for b in boxb])
            b_hi = np.array([b[1] for b in boxb])
            span_stats["body_pairs"] += 1
            span_stats["leaves_in"] += len(ga) + len(gb)
            sb = pair_sbounds(a_lo, a_hi, np.ones(len(ga), bool), va, b_lo, b_hi,
                              np.ones(len(gb), bool), vb, 0.0, T)
            bp = {"bodies": [A.name, B.name], "leaves_in": len(ga) + len(gb), "leaves_out": 0}
            span_stats.setdefault("body_pair_sbounds", []).append(bp)
            if sb is None:
                span_stats["body_pairs_pruned"] += 1
                continue
            bp["leaves_out"] = int(sb.a_alive.sum() + sb.b_alive.sum())
            bp["survivors"] = [A.geoms[g] for g, a in zip(ga, sb.a_alive) if a] + \
                [B.geoms[g] for g, b in zip(gb, sb.b_alive) if b]
            bp["time_bounds"] = [s0 + sb.t_lo, s0 + sb.t_hi]
            bp["passes"] = sb.passes
            span_stats["passes"] = max(span_stats["passes"], sb.passes)
            span_stats["leaves_out"] += int(sb.a_alive.sum() + sb.b_alive.sum())
            span_stats.setdefault("time_bounds", []).append([s0 + sb.t_lo, s0 + sb.t_hi])
            ia_idx = {g: k for k, g in enumerate(ga)}
            ib_idx = {g: k for k, g in enumerate(gb)}
            for p in plist:
                ka, kb = ia_idx[p.ga], ib_idx[p.gb]
                if not (sb.a_alive[ka] and sb.b_alive[kb]):
                    continue
                # leaf-pair S-bound (the implicit subtree E_i meet E_j of §6.3)
                # iterated to convergence like the body-level bound
                one = np.ones(1, bool)
                lb = pair_sbounds(sb.a_lo[ka:ka + 1], sb.a_hi[ka:ka + 1], one, va,
                                  sb.b_lo[kb:kb + 1], sb.b_hi[kb:kb + 1], one, vb, sb.t_lo, sb.t_hi)
                rb = None if lb is None else RootBound(lb.t_lo, lb.t_hi, lb.a_lo[0], lb.a_hi[0],
                                                       lb.b_lo[0], lb.b_hi[0])
                if rb is None or _empty_in_own_frames(rb, va, vb):
                    continue
                if self._pruned_in_own_frame(p, rb, st):
                    span_stats["leaf_pairs_pruned_own_region"] = span_stats.get(
                        "leaf_pairs_pruned_own_region", 0) + 1
                    self._stage(p, "divide_and_conquer")
                    continue
                items.append((p, rb))
        # optimal fitting of the final region (App. B): measure space in a frame moving with
        # w, per axis one of the bodies' velocities; collision is Galilean invariant, so the
        # rest of the span runs with velocities v - w and points are mapped back with + w tau
        w = self._frame_velocity(items, st)
        self._w = w
        stw = {k: (o, v - w) for k, (o, v) in st.items()}
        work = []
        for p, rb in items:
            x_lo, x_hi = _pair_box(rb, stw[p.ia][1], stw[p.ib][1])
            if np.any(x_lo > x_hi):
                continue
            work.append((p, rb.t_lo, rb.t_hi, x_lo, x_hi, stw[p.ia][1], stw[p.ib][1]))
            span_stats.setdefault("sbound_regions", []).append(
                [*(x_hi - x_lo).tolist(), rb.t_hi - rb.t_lo])
        span_stats["frame_velocity"] = w.tolist()
        span_stats["leaf_pairs_after_sbounds"] = len(work)
        self.stats["spans"].append(span_stats)
        self._exact_stage(s0, s1, stw, work, span_stats)
        for p in live:
            self._clearance(p, s0, s1, st)

    def _pruned_in_own_frame(self, p: _PairState, rb: RootBound, st: dict) -> bool:
        """§4.1 region test of a leaf pair on its own S-bound region (scheme 1 of §6.3).

        The region is the pair's overlap box in its best co-moving frame (per axis A's
        or B's velocity); a leaf with one extruded half-space excluding the whole
        region cannot meet the other there.
        """
        if p.mode not in ("lp", "offset"):
            return False
        va, vb = st[p.ia][1], st[p.ib][1]
        w = _own_frame_velocity(rb, va, vb)
        lo, hi = _pair_box(rb, va - w, vb - w)
        rlo, rhi = np.r_[lo, rb.t_lo], np.r_[hi, rb.t_hi]
        la, lb = self._leaves(p, {p.ia: (st[p.ia][0], va - w), p.ib: (st[p.ib][0], vb - w)}, np.zeros(3))
        return self._classify(la, rlo, rhi)[0] == "empty" or self._classify(lb, rlo, rhi)[0] == "empty"

    def _frame_velocity(self, items: list, st: dict) -> np.ndarray:
        """Per axis, the body velocity whose co-moving frame gives the narrowest region (App. B)."""
        w = np.zeros(3)
        if not items:
            return w
        for k in range(3):
            cands = sorted({float(st[p.ia][1][k]) for p, _ in items}
                           | {float(st[p.ib][1][k]) for p, _ in items})
            best = (np.inf, 0.0)
            for c in cands:
                lo, hi = np.inf, -np.inf
                dv = np.zeros(3)
                dv[k] = c
                for p, rb in items:
                    xl, xh = _pair_box(rb, st[p.ia][1] - dv, st[p.ib][1] - dv)
                    if xl[k] <= xh[k]:
                        lo, hi = min(lo, xl[k]), max(hi, xh[k])
                width = hi - lo if hi >= lo else 0.0
                if not np.isfinite(width):
                    width = np.inf
                if width < best[0] or (width == best[0] and c == 0.0):
                    best = (width, c)
            w[k] = best[1]
        return w

    def _exact_stage(self, s0: float, s1: float, st: dict, work: list, span_stats: dict) -> None:
        """Divide and conquer for LP and offset pairs, direct exact tests for the others."""
        # quadratic / half-space pairs: exact tests over their S-bound time interval directly
        lp_work = []
        for item in work:
            p = item[0]
            if p.mode in ("lp", "offset"):
                lp_work.append(item)
            else:
                self._round_pair(p, s0, s1, st, item[1], item[2])
        if lp_work:
            self._divide_and_conquer(s0, s1, st, lp_work, span_stats)

    # -- clearance
    def _clearance(self, p: _PairState, s0: float, s1: float, st: dict | None = None) -> None:
        """Exact lower bound of the core distance minus radii over the span (when wanted).

        ``st`` (body index -> (origin at s0, velocity)) is the span's state when the caller
        has it (the same ``_Body.state(s0, s1)`` values).
        """
        if not self.want_clearance or p.done:
            return
        A, B = self.bodies[p.ia], self.bodies[p.ib]
        if st is not None and p.ia in st and p.ib in st:
            (oa, va), (ob, vb) = st[p.ia], st[p.ib]
        else:
            (oa, va), (ob, vb) = A.state(s0, s1), B.state(s0, s1)
        c = 0.5 * (oa + ob)
        sa, sb = A.shapes[p.ga], B.shapes[p.gb]
        rr = float(sa.radius) + float(sb.radius)
        if p.mode == "halfspace":
            la = _leaf(sa, A.R, oa, va, c)
            lb = _leaf(sb, B.R, ob, vb, c)
            plane, other = (la, lb) if la.kind == "halfspace" else (lb, la)
            res, _ = halfspace_null_test(plane, other, 0.0, 0.0, s1 - s0, self.tol, self.data_pad)
            low = res.lower - rr
        else:
            # the leaves' core vertices (as _leaf builds them; no H-rep needed here)
            Va = sa.points @ A.R.T + (oa - c)
            Vb = sb.points @ B.R.T + (ob - c)
            D = (Va[:, None, :] - Vb[None, :, :]).reshape(-1, 3)
            w = va - vb
            low, _, _ = min_norm(np.vstack([D, D + w * (s1 - s0)]), self.tol)
            self.stats["nnls"] += 1
            low -= rr + self.data_pad
        p.clearance = min(p.clearance, low)

    # -- quadratic / half-space pairs
    def _round_pair(self, p: _PairState, s0: float, s1: float, st: dict, tl: float, th: float) -> None:
        A, B = self.bodies[p.ia], self.bodies[p.ib]
        (oa, va), (ob, vb) = st[p.ia], st[p.ib]
        c = 0.5 * (oa + ob)
        la = _leaf(A.shapes[p.ga], A.R, oa, va, c)
        lb = _leaf(B.shapes[p.gb], B.R, ob, vb, c)
        self._charge()
        p.tests += 1
        self._stage(p, "null_set" if p.mode == "halfspace" else "exact_swept")
        if p.mode == "halfspace":
            plane, other = (la, lb) if la.kind == "halfspace" else (lb, la)
            res, first = halfspace_null_test(plane, other, p.r, tl, th, self.tol, self.data_pad)
            if res.verdict == Outcome.VIOLATION:
                # witness: earliest time at which d <= (r + min d) / 2 (half the depth)
                dmin = 0.5 * (res.lower + res.upper) + p.r
                _, wt = halfspace_null_test(plane, other, 0.5 * (p.r + dmin), tl, th, self.tol)
                tau_w = float(np.clip(res.tau if wt is None else wt, tl, th))
                n = plane.N[0]
                dv = other.V @ n + ((other.v - plane.v) @ n) * tau_w - plane.h[0]
                k = int(np.argmin(dv))
                point = other.V[k] + other.v * tau_w - 0.5 * dv[k] * n
                fpoint = other.V[k] + other.v * first
                self._violation(p, s0, s1, c, first, fpoint, tau_w, point, res, "halfspace")
            else:
                self._settle(p, res, s0, tl, th)
            return
        res = quadratic_null_test(la, lb, p.r, tl, th, self.tol, self.data_pad)
        self.stats["nnls"] += 1
        self.stats["exact_swept"] += 1
        if res.verdict == Outcome.VIOLATION:
            first, fpoint, n1 = quadratic_first_time(la, lb, p.r, tl, res.tau, p.r, self.tol)
            dmin = res.upper + p.r
            tw, wpoint, n2 = quadratic_first_time(la, lb, p.r, tl, res.tau, 0.5 * (p.r + dmin), self.tol)
            self.stats["nnls"] += n1 + n2
            self._violation(p, s0, s1, c, first, fpoint, tw, wpoint, res, "quadratic")
        else:
            self._settle(p, res, s0, tl, th)

    def _settle(self, p: _PairState, res: NullResult, s0: float, tl: float, th: float) -> None:
        if res.verdict == Outcome.UNRESOLVED:
            p.verdict = Outcome.UNRESOLVED
            p.unresolved.append((s0 + tl, s0 + th))

    def _violation(self, p: _PairState, s0: float, s1: float, c: np.ndarray, first: float,
                   fpoint: np.ndarray, tw: float, wpoint: np.ndarray, res: NullResult, how: str) -> None:
        p.verdict = Outcome.VIOLATION
        p.done = True
        p.stage = STAGES.index("exact_swept" if how == "quadratic" else "null_set")
        p.clearance = -np.inf
        p.witness_time = float(s0 + tw)
        p.witness_point = np.asarray(wpoint, float) + c + self._w * tw
        p.info.update({
            "earliest_time": float(s0 + first),
            "earliest_point": (np.asarray(fpoint) + c + self._w * first).tolist(),
            "test": how, "span": [s0, s1],
            "depth": float(-res.upper) if how == "lp" else float(-res.upper),
        })
        p.unresolved = [(float(s0 + first), float(s0 + tw))]

    # -- divide and conquer (LP pairs)
    def _divide_and_conquer(self, s0: float, s1: float, st: dict, work: list, span_stats: dict) -> None:
        speeds = [float(np.linalg.norm(st[k][1])) for k in st]
        vmax = max(speeds + [0.0])
        lo = np.min([np.r_[w[3], w[1]] for w in work], axis=0)
        hi = np.max([np.r_[w[4], w[2]] for w in work], axis=0)
        heap: list[tuple[float, int, int, np.ndarray, np.ndarray, list[int]]] = []
        counter = 0
        heapq.heappush(heap, (float(lo[3]), counter, 0, lo, hi, list(range(len(work)))))
        regions = 0
        tested: set[int] = set()
        leaves = {}  # (pair idx) -> (world leaves at span start, uncentred) for region tests
        for k, (p, *_r) in enumerate(work):
            leaves[k] = self._leaves(p, st, np.zeros(3))
        while heap:
            if self._exhausted():
                for _, _, _, rlo, rhi, idx in heap:
                    for k in idx:
                        p = work[k][0]
                        if not p.done:
                            p.verdict = Outcome.UNRESOLVED
                            p.info["budget_exhausted"] = True
                            p.unresolved.append((s0 + float(rlo[3]), s0 + float(rhi[3])))
                return
            t_key, _, d, rlo, rhi, idx = heapq.heappop(heap)
            regions += 1
            live_idx = []
            for k in idx:
                p, tl, th, x_lo, x_hi, _, _ = work[k]
                if p.done or k in tested:
                    continue
                # S-bound of the pair against the region
                if tl > rhi[3] or th < rlo[3] or np.any(x_lo > rhi[:3]) or np.any(x_hi < rlo[:3]):
                    continue
                # classify against the region met with the pair's own S-bound box (its
                # intersection lies there), which is tighter than the region alone
                blo = np.maximum(rlo, np.r_[x_lo, tl])
                bhi = np.minimum(rhi, np.r_[x_hi, th])
                la, lb = leaves[k]
                ca, _ = self._classify(la, blo, bhi)
                if ca == "empty":
                    continue
                cb, _ = self._classify(lb, blo, bhi)
                if cb == "empty":
                    continue
                if ca == "full" and cb == "full":
                    if p.mode == "lp":
                        self.stats["full_region_proofs"] += 1
                        self._stage(p, "divide_and_conquer")
                        self._lp_collision(p, s0, s1, st, tl, th, x_lo, x_hi, proof="full region")
                    else:  # offset polytopes over-approximate: the exact swept test decides
                        tested.add(k)
                        self.stats["offset_open"] += 1
                        self._round_pair(p, s0, s1, st, tl, th)
                    continue
                live_idx.append(k)
            if not live_idx:
                continue
            max_d = KAPPA_MAX_DEPTH // 4 if self.division == "16way" else KAPPA_MAX_DEPTH
            if not self.divide or len(live_idx) <= kappa(d) or d >= max_d:
                # conquer: one LP per leaf pair and span, over its whole S-bound box (the
                # regions prune, prove full collisions and order by time; re-testing a
                # pair per region would only multiply LPs)
                for k in live_idx:
                    p, tl, th, x_lo, x_hi, _, _ = work[k]
                    if p.done or k in tested:
                        continue
                    tested.add(k)
                    p.max_depth = max(p.max_depth, d)
                    self._lp_region(p, s0, s1, st, np.r_[x_lo, tl], np.r_[x_hi, th], tl, th, x_lo, x_hi)
                continue
            if self.division == "16way":  # the paper's rule: halve all four axes
                mid4 = 0.5 * (rlo + rhi)
                for code in range(16):
                    bits = np.array([(code >> j) & 1 for j in range(4)], bool)
                    nlo = np.where(bits, mid4, rlo)
                    nhi = np.where(bits, rhi, mid4)
                    counter += 1
                    heapq.heappush(heap, (float(nlo[3]), counter, d + 1, nlo, nhi, live_idx))
                continue
            # divide: bisect the longest axis (time in metres via the fastest speed)
            ext = rhi - rlo
            ext_m = np.r_[ext[:3], ext[3] * vmax]
            ext_m = np.where(np.isfinite(ext_m), ext_m, 0.0)
            ax = int(np.argmax(ext_m))
            mid = 0.5 * (rlo[ax] + rhi[ax])
            for half in (0, 1):
                nlo, nhi = rlo.copy(), rhi.copy()
                if half == 0:
                    nhi[ax] = mid
                else:
                    nlo[ax] = mid
                counter += 1
                heapq.heappush(heap, (float(nlo[3]), counter, d + 1, nlo, nhi, live_idx))
        for k, (p, *_r) in enumerate(work):
            if k not in tested and p.stage < 1 and not (p.done and p.verdict == Outcome.VIOLATION):
                self._stage(p, "divide_and_conquer")  # every region excluded it (§4.1)
        self.stats["regions"] += regions
        span_stats["regions"] = regions

    def _classify(self, leaf: Leaf, rlo: np.ndarray, rhi: np.ndarray) -> tuple[str, None]:
        """Region test of §4.1 for an H-rep leaf (uncentred world coordinates)."""
        if len(leaf.N) == 0:  # no half-spaces (sphere / capsule core): undecided
            return "crossing", None
        G = leaf.G
        Glo, Ghi = G * rlo, G * rhi
        gmax = np.maximum(Glo, Ghi).sum(axis=1) - leaf.h
        gmin = np.minimum(Glo, Ghi).sum(axis=1) - leaf.h
        zmax = np.maximum(np.abs(rlo), np.abs(rhi))
        pad = 8 * self.tol.rel_pad * (np.abs(leaf.h) + np.abs(G) @ zmax) + self.box_pad
        if np.any(gmin > pad):
            return "empty", None
        if np.all(gmax < -pad):
            return "full", None
        return "crossing", None

    def _centred(self, p: _PairState, st: dict, c: np.ndarray) -> tuple[Leaf, Leaf]:
        return self._leaves(p, st, c)

    def _lp_region(self, p: _PairState, s0: float, s1: float, st: dict, blo: np.ndarray,
                   bhi: np.ndarray, tl: float, th: float, x_lo: np.ndarray, x_hi: np.ndarray) -> None:
        c = 0.5 * (blo[:3] + bhi[:3])
        la, lb = self._centred(p, st, c)
        cz = np.r_[c, 0.0]
        self._charge()
        p.tests += 1
        if dual_certificate(la, lb, blo - cz, bhi - cz, self.tol, self.data_pad) <= self.tol.extrusion_slack:
            # the LP's own weak-duality certificate, found among 1- and 2-row duals (§4.2)
            self.stats["dual_shortcut"] += 1
            if p.mode == "offset":
                self.stats["offset_certified"] += 1
            self._stage(p, "null_set")
            return
        self.stats["lps"] += 1
        res = lp_null_test(la, lb, blo - cz, bhi - cz, self.tol, self.data_pad)
        if p.mode == "offset":
            self.stats["offset_lps"] += 1
            if res.verdict == Outcome.CERTIFIED:
                self.stats["offset_certified"] += 1
                self._stage(p, "null_set")
            else:  # the offset polytopes meet: not a collision proof, the exact test decides
                self.stats["offset_open"] += 1
                self._round_pair(p, s0, s1, st, tl, th)
            return
        self._stage(p, "null_set")
        if res.verdict == Outcome.VIOLATION:
            self._lp_collision(p, s0, s1, st, tl, th, x_lo, x_hi, proof="lp", found=res, found_c=c)
        elif res.verdict == Outcome.UNRESOLVED:
            p.verdict = Outcome.UNRESOLVED
            p.unresolved.append((s0 + float(blo[3]), s0 + float(bhi[3])))

    def _lp_collision(self, p: _PairState, s0: float, s1: float, st: dict, tl: float, th: float,
                      x_lo: np.ndarray, x_hi: np.ndarray, proof: str, found: NullResult | None = None,
                      found_c: np.ndarray | None = None) -> None:
        """A proved collision of an LP pair in this span: exact first contact and witness."""
        c = 0.5 * (x_lo + x_hi)
        la, lb = self._centred(p, st, c)
        lo = np.r_[x_lo - c, tl]
        hi = np.r_[x_hi - c, th]
        G = np.vstack([la.G, lb.G])
        h = np.concatenate([la.h, lb.h])
        if found is None:  # full-region proof: find the deepest point once
            found = lp_null_test(la, lb, lo, hi, self.tol, self.data_pad)
            self.stats["lps"] += 1
            p.tests += 1
            found_x = found.point
        else:  # the region LP's witness, re-expressed about this centre
            found_x = found.point + found_c - c
        smax = -found.upper
        first_tau, first_x = found.tau, found_x
        w_tau, w_x = found.tau, found_x
        if self.earliest:
            e = lp_earliest(la, lb, lo, hi, 0.0, self.tol)
            self.stats["lps"] += 1
            p.tests += 1
            if e is not None:
                first_tau, first_x = e
            wz = lp_earliest(la, lb, lo, hi, 0.5 * smax, self.tol)
            self.stats["lps"] += 1
            p.tests += 1
            if wz is not None:
                if slack_lower(G, h, np.r_[wz[1], wz[0]], self.tol) > self.data_pad:
                    w_tau, w_x = wz
        res = NullResult(Outcome.VIOLATION, -np.inf, -smax, w_tau, w_x)
        self._violation(p, s0, s1, c, first_tau, first_x, w_tau, w_x, res, "lp")
        p.info["earliest_exact"] = bool(self.earliest)  # False: earliest_time is just a violating time
        p.info["proof"] = proof
        if proof == "full region":
            p.stage = STAGES.index("divide_and_conquer")
        p.info["max_slack"] = float(smax)

    # -- results
    def outcomes(self) -> list[PairOutcome]:
        out = []
        for p in self.states:
            A, B = self.bodies[p.ia], self.bodies[p.ib]
            info = dict(p.info)
            info["geoms"] = [A.geoms[p.ga], B.geoms[p.gb]]
            info["test"] = info.get("test", p.mode)
            info["stage"] = STAGES[p.stage]
            if p.verdict == Outcome.VIOLATION:
                out.append(PairOutcome(Outcome.VIOLATION, p.tests, p.max_depth, list(p.unresolved),
                                       float("-inf"), p.witness_time, p.witness_point, info))
            elif p.verdict == Outcome.UNRESOLVED or info.get("budget_exhausted"):
                out.append(PairOutcome(Outcome.UNRESOLVED, p.tests, p.max_depth, sorted(p.unresolved),
                                       float("-inf"), None, None, info))
            else:
                clr = float(p.clearance) if self.want_clearance else float("-inf")
                if not np.isfinite(clr) and self.want_clearance:
                    clr = float("inf")  # no span reached the pair at all
                out.append(PairOutcome(Outcome.CERTIFIED, p.tests, p.max_depth, [], clr, None, None, info))
        return out


# ----------------------------------------------------------------------------- public API

def _bodies_from_pair(p: TranslatingPair, window: tuple[float, float]) -> list[_Body]:
    na, nb = p.name
    _check_shape(na, p.shape_a)
    _check_shape(nb, p.shape_b)
    Ra, ta, oa = _check_body(f"pair {p.name} body a", p.R_a, p.times_a, p.origins_a, window)
    Rb, tb, ob = _check_body(f"pair {p.name} body b", p.R_b, p.times_b, p.origins_b, window)
    return [_Body(f"{na}.body", (p.shape_a,), (na,), Ra, ta, oa),
            _Body(f"{nb}.body", (p.shape_b,), (nb,), Rb, tb, ob)]


def check_pairs(pairs: Sequence[TranslatingPair], window: tuple[float, float], margin: float = 0.0,
                tolerances: Tolerances = DEFAULT, budget: Budget | None = None, earliest: bool = True,
                clearance: bool = True, nary: bool = False, offset: bool = True) -> list[PairOutcome]:
    """Decide each translating geom pair exactly over ``window``.

    Args:
        pairs: the pairs; both bodies of each translate with piecewise-constant velocity.
        window: (t0, t1) seconds, covered by every pair's motion.
        margin: clearance (m); distance < margin is a violation, distance == margin is not.
        tolerances: numerical tolerances (``extrusion_slack`` is the exactness band).
        budget: optional work limit; exhaustion gives "unresolved", never "certified".
        earliest: compute the exact first-contact time of violations (``info["earliest_time"]``).
        clearance: compute an exact lower bound of the min distance for certified pairs.
        nary: decide all pairs in one §6 n-ary search: pairs are grouped into bodies by
            identical motion (R, times, origins) and geoms by name; same verdicts and
            first-contact times as the pairwise loop (tested), usually much faster.
            Pairs whose two geoms fall into one group are decided one by one.
        offset: pairs with radii or a margin go through the null-set LP on offset
            half-spaces first (§4.2); False: straight to the exact swept test.

    Returns:
        One :class:`PairOutcome` per pair. "violation" carries ``witness_time`` (s),
        ``witness_point`` (3,) world m, ``info["earliest_time"]``, ``info["geoms"]``.

    Raises:
        InvalidInputError: bad window, margin, rotation, times or shapes.
        UnsupportedGeometryError: plane against plane.
    """
    w = _check_window(window, margin)
    if nary:
        return _check_pairs_nary(list(pairs), w, float(margin), tolerances, budget, earliest, clearance,
                                 offset)
    out = []
    for p in pairs:
        bodies = _bodies_from_pair(p, w)
        s = _Search(bodies, [(0, 0, 1, 0)], w, float(margin), tolerances, budget, earliest, clearance,
                    offset=offset)
        s.run()
        o = s.outcomes()[0]
        o.info["stats"] = _compact_stats(s.stats)
        out.append(o)
    return out


def _check_pairs_nary(pairs: list[TranslatingPair], w: tuple[float, float], margin: float,
                      tol: Tolerances, budget: Budget | None, earliest: bool, clearance: bool,
                      offset: bool = True) -> list[PairOutcome]:
    """check_pairs through one n-ary search (bodies grouped by name and identical motion)."""
    groups: dict[bytes, int] = {}
    members: list[dict[str, ConvexShape]] = []
    motion: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    gnames: list[str] = []
    ends: list[tuple[int, int] | None] = []
    for p in pairs:
        bodies = _bodies_from_pair(p, w)  # validates
        gi = []
        for b, nm, bn in zip(bodies, p.name, p.bodies):
            key = str(bn).encode() + b"\0" + b.R.tobytes() + b.times.tobytes() + b.origins.tobytes()
            if key not in groups:
                groups[key] = len(members)
                members.append({})
                motion.append((b.R, b.times, b.origins))
                gnames.append(str(bn) if bn else f"group{len(gnames)}")
            k = groups[key]
            if members[k].get(nm, b.shapes[0]) is not b.shapes[0]:
                gi = None  # two different shapes under one name: decide alone
                break
            members[k][nm] = b.shapes[0]
            gi.append(k)
        ends.append(None if gi is None or gi[0] == gi[1] else (gi[0], gi[1]))
    tb = [TranslatingBody(gnames[k], tuple(m.values()), tuple(m.keys()), *motion[k])
          for k, m in enumerate(members)]
    names = [p.name for p, e in zip(pairs, ends) if e is not None]
    seen_names = [n for m in members for n in m]
    out: list[PairOutcome | None] = [None] * len(pairs)
    if names and len(seen_names) == len(set(seen_names)):
        # the pairs were validated above (_bodies_from_pair) and the groups hold the validated
        # arrays, unique geom names and >= 1 shape each: no second validation pass
        bl = [_Body(b.name, b.shapes, b.geom_names, b.R, b.times, b.origins) for b in tb]
        res = _search_validated(bl, names, w, margin, tol, budget, earliest, clearance, offset=offset)
        it = iter(res.outcomes)
        for i, e in enumerate(ends):
            if e is not None:
                out[i] = next(it)
                # one shared dict per search (not copied per pair): summarise with search_summary
                out[i].info["stats"] = res.stats
                out[i].info["nary"] = True
    for i, o in enumerate(out):
        if o is None:
            out[i] = check_pairs([pairs[i]], w, margin, tol, budget, earliest, clearance, offset=offset)[0]
    return out  # type: ignore[return-value]


def _compact_stats(stats: dict[str, Any]) -> dict[str, Any]:
    """JSON-friendly copy of search stats."""
    return {k: (float(v) if isinstance(v, np.floating) else v) for k, v in stats.items()}


def _bodies_many(bodies: Sequence[TranslatingBody], window: tuple[float, float]) -> list[_Body]:
    out = []
    seen: set[str] = set()
    for b in bodies:
        if len(b.shapes) != len(b.geom_names) or not b.shapes:
            raise InvalidInputError(f"body {b.name}: need one geom name per shape (and >= 1 shape)")
        for g, s in zip(b.geom_names, b.shapes):
            if g in seen:
                raise InvalidInputError(f"geom name {g!r} is not unique")
            seen.add(g)
            _check_shape(g, s)
        R, t, o = _check_body(f"body {b.name}", b.R, b.times, b.origins, window)
        out.append(_Body(b.name, tuple(b.shapes), tuple(b.geom_names), R, t, o))
    return out


def _resolve_pairs(bodies: list[_Body], allowed: Iterable[tuple[str, str]] | None
                   ) -> list[tuple[int, int, int, int]]:
    where = {g: (i, k) for i, b in enumerate(bodies) for k, g in enumerate(b.geoms)}
    out = []
    if allowed is None:
        for i in range(len(bodies)):
            for j in range(i + 1, len(bodies)):
                for ga in range(len(bodies[i].geoms)):
                    for gb in range(len(bodies[j].geoms)):
                        out.append((i, ga, j, gb))
        return out
    for a, b in allowed:
        if a not in where or b not in where:
            raise InvalidInputError(f"allowed pair ({a!r}, {b!r}) names an unknown geom")
        (i, ga), (j, gb) = where[a], where[b]
        if i == j:
            raise InvalidInputError(f"allowed pair ({a!r}, {b!r}) is inside one body")
        out.append((i, ga, j, gb))
    return out


def search_many(bodies: Sequence[TranslatingBody], allowed_pairs: Iterable[tuple[str, str]] | None,
                window: tuple[float, float], margin: float = 0.0, tolerances: Tolerances = DEFAULT,
                budget: Budget | None = None, earliest: bool = True, clearance: bool = True,
                divide: bool = True, offset: bool = True, division: str = "bisect") -> SearchResult:
    """The n-ary operator of §6 over all translating bodies in one search, with statistics.

    Args:
        bodies: translating bodies (unions of convex geoms).
        allowed_pairs: (geom_a, geom_b) names to check (the scene's pair policy);
            every other leaf pair has an empty S-bound. None = all cross-body pairs.
        window, margin, tolerances, budget, earliest, clearance: as :func:`check_pairs`.
        divide: run the divide-and-conquer stage (False: conquer every region at once).
        offset: null-set LP on offset half-spaces for pairs with radii / margin (see
            :func:`check_pairs`).
        division: ``"bisect"`` (longest axis, time in metres by the fastest speed; the
            default, see docs/notes/issue-14-extrusion.md) or ``"16way"`` (the paper's
            split of all four axes, at most 3 levels).

    Returns:
        :class:`SearchResult` with one outcome per pair (request order) and stats.
    """
    w = _check_window(window, margin)
    return _search_validated(_bodies_many(bodies, w), allowed_pairs, w, margin, tolerances, budget,
                             earliest, clearance, divide, offset, division)


def _search_validated(bl: list[_Body], allowed_pairs: Iterable[tuple[str, str]] | None,
                      w: tuple[float, float], margin: float, tolerances: Tolerances,
                      budget: Budget | None, earliest: bool, clearance: bool, divide: bool = True,
                      offset: bool = True, division: str = "bisect") -> SearchResult:
    """:func:`search_many` on bodies already checked by ``_bodies_many`` / ``_check_body``."""
    idx = _resolve_pairs(bl, allowed_pairs)
    s = _Search(bl, idx, w, float(margin), tolerances, budget, earliest, clearance, divide, offset, division)
    s.run()
    names = [(bl[i].geoms[ga], bl[j].geoms[gb]) for i, ga, j, gb in idx]
    return SearchResult(s.outcomes(), names, _compact_stats(s.stats))


def check_many(bodies: Sequence[TranslatingBody], allowed_pairs: Iterable[tuple[str, str]] | None,
               window: tuple[float, float], margin: float = 0.0, tolerances: Tolerances = DEFAULT,
               budget: Budget | None = None, earliest: bool = True, clearance: bool = True
               ) -> list[PairOutcome]:
    """Outcomes of :func:`search_many` (one per allowed geom pair, in request order)."""
    return search_many(bodies, allowed_pairs, window, margin, tolerances, budget, earliest,
                       clearance).outcomes


def search_summary(outcomes: Sequence[PairOutcome]) -> dict[str, Any]:
    """Aggregate stage counts and S-bound figures over outcomes of one or more searches.

    Returns:
        dict with ``stages`` ({stage: pairs}, the deciding stage of each outcome, see
        :data:`STAGES`), ``lps``, ``offset_lps``, ``offset_certified``, ``offset_open``
        (offset LPs that left the region to the exact swept test), ``exact_swept``,
        ``regions``, ``searches`` and ``sbounds``: per span and body pair the primitives
        in, the survivors and the time bounds (§4.3); ``swept_kernel`` (only when > 0):
        outcomes decided by the compiled first pass
        (:mod:`monitor.certify.extrusion_swept`, stage ``exact_swept``).
    """
    stages: dict[str, int] = {}
    compiled = 0
    for o in outcomes:
        st = o.info.get("stage")
        if st is not None:
            stages[st] = stages.get(st, 0) + 1
        if o.info.get("test") == "swept_kernel":
            compiled += 1
    out: dict[str, Any] = {"stages": stages, "searches": 0, "sbounds": []}
    if compiled:
        out["swept_kernel"] = compiled
    keys = ("lps", "dual_shortcut", "nnls", "offset_lps", "offset_certified", "offset_open", "exact_swept",
            "regions")
    for k in keys:
        out[k] = 0
    seen: set[int] = set()
    for s in [o.info.get(k) for o in outcomes for k in ("stats", "first_pass_stats")]:
        if not isinstance(s, dict) or id(s) in seen or "spans" not in s:
            continue
        seen.add(id(s))
        out["searches"] += 1
        for k in keys:
            out[k] += int(s.get(k, 0))
        for sp in s["spans"]:
            for bp in sp.get("body_pair_sbounds", []):
                out["sbounds"].append({"span": sp["span"], **bp})
    return out


def earliest_violation(outcomes: Sequence[PairOutcome]) -> PairOutcome | None:
    """The violating outcome with the smallest ``info["earliest_time"]``, or None."""
    v = [o for o in outcomes if o.verdict == Outcome.VIOLATION]
    return min(v, key=lambda o: o.info["earliest_time"]) if v else None


def compare_pairwise_nary(bodies: Sequence[TranslatingBody], allowed_pairs: Iterable[tuple[str, str]] | None,
                          window: tuple[float, float], margin: float = 0.0,
                          tolerances: Tolerances = DEFAULT) -> dict[str, Any]:
    """Benchmark helper: the pairwise loop (one search per geom pair) against one n-ary search.

    Returns:
        dict with ``pairs``, ``pairwise_seconds``, ``nary_seconds``, ``pairwise_lps``,
        ``nary_lps``, ``pairwise_nnls``, ``nary_nnls``, ``agree`` (all verdicts equal and
        earliest times within 1e-9 of the window) and ``verdicts`` ({verdict: count}).
    """
    allowed = list(allowed_pairs) if allowed_pairs is not None else None
    w = _check_window(window, margin)
    bl = _bodies_many(bodies, w)
    idx = _resolve_pairs(bl, allowed)
    t0 = time.perf_counter()
    nary = _Search(bl, idx, w, float(margin), tolerances, None, True, False)
    nary.run()
    n_out = nary.outcomes()
    t1 = time.perf_counter()
    p_out, lps, nn = [], 0, 0
    for q in idx:
        s = _Search(bl, [q], w, float(margin), tolerances, None, True, False)
        s.run()
        p_out.append(s.outcomes()[0])
        lps += s.stats["lps"]
        nn += s.stats["nnls"]
    t2 = time.perf_counter()
    tol_t = 1e-9 * (w[1] - w[0])
    agree = all(a.verdict == b.verdict
                and abs(a.info.get("earliest_time", 0.0) - b.info.get("earliest_time", 0.0)) <= tol_t
                for a, b in zip(n_out, p_out))
    verdicts: dict[str, int] = {}
    for o in n_out:
        verdicts[o.verdict] = verdicts.get(o.verdict, 0) + 1
    return {"pairs": len(idx), "pairwise_seconds": t2 - t1, "nary_seconds": t1 - t0,
            "pairwise_lps": lps, "nary_lps": nary.stats["lps"], "pairwise_nnls": nn,
            "nary_nnls": nary.stats["nnls"], "agree": bool(agree), "verdicts": verdicts}


__all__ = ["TranslatingPair", "TranslatingBody", "SearchResult", "check_pairs", "check_many",
           "search_many", "earliest_violation", "compare_pairwise_nary", "kappa", "KAPPA_MAX_DEPTH",
           "STAGES", "core_hrep", "search_summary"]
