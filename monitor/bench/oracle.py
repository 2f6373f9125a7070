"""Independent oracle for the pair-window cases of :mod:`monitor.bench.cases`.

Two oracles, neither of which uses the checkers' motion bounds:

* :func:`label`: adaptive dense time sampling of the exact static distance with an
  **analytic** Lipschitz margin. On a sub-interval with midpoint m and half width h,
  every point of body b moves at most ``speed_b * h`` from its pose at m
  (:meth:`PairCase.speed_bounds`: |v| + |omega| max|p| for a lerp/slerp segment), so
  ``d(t) >= lower(m) - (speed_A + speed_B) h``. Intervals are split (earliest first)
  until they are proved clear, a sample is confirmed colliding (``upper < margin``),
  or they fall below the resolution (then the case is ``"near"``).
* :func:`lp_overlap`: for translating polytope pairs, the exact space-time LP
  ``max s`` s.t. ``x`` lies ``s`` deep inside both extruded bodies at some
  ``t in [0, T]``; interior overlap iff ``s > slack`` (touching is not a collision).

The static distance is ``monitor.geometry.distance.shape_distance`` (rigorous
lower/upper bounds) when it is importable; otherwise MuJoCo's ``mj_geomDistance``
with its GJK tolerance padded by :data:`MUJOCO_DISTANCE_PAD` (the backend is
recorded in the results).
"""

from __future__ import annotations

import functools
import heapq
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog
from scipy.spatial import ConvexHull

from monitor.bench.cases import PairCase

MUJOCO_DISTANCE_PAD = 1e-6
"""Metres added on both sides of a MuJoCo ``mj_geomDistance`` value (its ccd tolerance
is 1e-6 by default); only used when ``monitor.geometry.distance`` is unavailable."""

LP_SLACK = 1e-9
"""Interior depth (m) the LP must find to call a translating case colliding."""


def backend_name() -> str:
    """``"monitor"`` if ``shape_distance`` is importable, else ``"mujoco"``."""
    try:
        from monitor.geometry.distance import shape_distance  # noqa: F401
        from monitor.geometry.polytope import box_polytope  # noqa: F401
    except ImportError:
        return "mujoco"
    return "monitor"


@functools.lru_cache(maxsize=1024)
def _convex_shapes(case: PairCase):
    return tuple(s.convex_shape() for s in case.shapes)


_MJ_DATA: dict[int, tuple[object, object]] = {}


def _mj_data(case: PairCase):
    import mujoco

    m = case.model
    hit = _MJ_DATA.get(id(m))
    if hit is None or hit[0] is not m:
        if len(_MJ_DATA) > 256:
            _MJ_DATA.clear()
        hit = _MJ_DATA[id(m)] = (m, mujoco.MjData(m))
    return hit[1]


def distance_bounds(case: PairCase, t: float, backend: str | None = None) -> tuple[float, float]:
    """Rigorous (lower, upper) bounds (m) on the signed distance of A and B at time ``t``."""
    backend = backend or backend_name()
    P, R = case.poses(np.array([t]))
    if backend == "monitor":
        from monitor.geometry.distance import shape_distance

        sa, sb = _convex_shapes(case)
        r = shape_distance(sa, (R[0, 0], P[0, 0]), sb, (R[0, 1], P[0, 1]))
        return float(r.lower), float(r.upper)
    import mujoco

    m, d = case.model, _mj_data(case)
    d.qpos[:] = case.qpos(np.array([t]))[0]
    mujoco.mj_kinematics(m, d)
    v = mujoco.mj_geomDistance(m, d, 0, 1, 10.0, None)
    return v - MUJOCO_DISTANCE_PAD, v + MUJOCO_DISTANCE_PAD


def mujoco_distance(case: PairCase, t: float) -> float:
    """MuJoCo ``mj_geomDistance`` (m) at ``t``: fast, approximate; used to place near-misses."""
    lo, up = distance_bounds(case, t, "mujoco")
    return 0.5 * (lo + up)


def approx_distance(case: PairCase, t: float) -> float:
    """Best estimate (m) of the signed distance at ``t`` (midpoint of the bounds)."""
    lo, up = distance_bounds(case, t)
    return 0.5 * (lo + up)


@dataclass
class OracleLabel:
    """Oracle verdict for one case.

    Attributes:
        label: ``"collide" | "clear" | "near"``.
        clearance_lower: proved lower bound (m) on the min distance (clear cases), else -inf.
        distance_upper: smallest sampled distance upper bound (m).
        hit_time: time (s) of a confirmed collision sample, or None.
        evals: static distance evaluations used.
        lp: exact LP verdict for translating polytope pairs (True = collide), or None.
    """

    label: str
    clearance_lower: float
    distance_upper: float
    hit_time: float | None
    evals: int
    lp: bool | None = None

    def to_dict(self) -> dict:
        """JSON form."""
        return {
            "label": self.label,
            "clearance_lower": _jf(self.clearance_lower),
            "distance_upper": _jf(self.distance_upper),
            "hit_time": self.hit_time,
            "evals": self.evals,
            "lp": self.lp,
        }


def _jf(x: float) -> float | None:
    return None if not np.isfinite(x) else float(x)


def label(
    case: PairCase,
    margin: float = 0.0,
    *,
    resolution: float = 1e-10,
    max_evals: int = 200_000,
    backend: str | None = None,
) -> OracleLabel:
    """Label ``case`` by adaptive sampling with the analytic Lipschitz margin.

    Args:
        case: the pair window.
        margin: clearance (m) that counts as safe.
        resolution: smallest sub-interval (fraction of the window) before giving up ("near").
        max_evals: cap on static distance evaluations (then "near" if unresolved).
        backend: distance backend (see :func:`backend_name`).

    Returns:
        :class:`OracleLabel`; translating polytope pairs also carry the LP verdict,
        which decides collide/not-collide when it is available.
    """
    backend = backend or backend_name()
    L = float(case.speed_bounds().sum())
    T = case.duration
    heap = [(0.0, T)]  # earliest first
    evals, lower, upper, unresolved, hit = 0, np.inf, np.inf, False, None
    while heap:
        a, b = heapq.heappop(heap)
        m, h = 0.5 * (a + b), 0.5 * (b - a)
        lo, up = distance_bounds(case, m, backend)
        evals += 1
        upper = min(upper, up)
        if up < margin:
            hit = m
            break
        bound = lo - L * h
        if bound > margin:
            lower = min(lower, bound)
            continue
        if (b - a) < resolution * T or evals >= max_evals:
            unresolved = True
            lower = min(lower, bound)
            continue
        heapq.heappush(heap, (a, m))
        heapq.heappush(heap, (m, b))
    lp = lp_overlap(case, margin) if _lp_applies(case) else None
    low = -np.inf if hit is not None else lower
    return OracleLabel(_label(hit, unresolved, lp), low, upper, hit, evals, lp)


def _label(hit: object, unresolved: bool, lp: bool | None) -> str:
    """The oracle's label from sampling (``hit``, ``unresolved``) and the exact LP (``lp``, or None).

    "collide" (a sampled hit, or the LP says overlap), "near" (unresolved, or sampling and the
    LP disagree: never scored as clear) or "clear".
    """
    label = "collide" if hit is not None else "near" if unresolved else "clear"
    if lp is True:
        return "collide"
    if lp is False and label == "collide":
        return "near"
    return label


def _lp_applies(case: PairCase) -> bool:
    return case.group == "translating" and all(s.is_polytope for s in case.shapes) and not case.angles().any()


def lp_overlap(case: PairCase, margin: float = 0.0) -> bool:
    """Exact LP: do the translating polytopes overlap (interior, margin-inflated) at some t?

    Variables (x (3), t, s); maximise s subject to, for each body b and facet
    (n, d) of its hull (n.y + d <= 0 inside, body frame), with constant rotation R_b
    and origin p_b(t) = p_b0 + v_b t:

        (R_b n) . x - (R_b n) . v_b t + s <= (R_b n) . p_b0 - d + margin / 2,

    0 <= t <= T, s <= 1. Inflating both bodies by margin/2 over-approximates the
    margin band (their Minkowski sums with balls lie inside), so a "no overlap"
    answer is sound; with margin 0 it is exact. Returns True iff s* > LP_SLACK.
    """
    A_rows, b_rows = [], []
    V = case.velocities()
    for b in range(2):
        eq = ConvexHull(case.shapes[b].vertices).equations
        n, d = eq[:, :3], eq[:, 3]
        R = case.poses(np.array([0.0]))[1][0, b]
        nw = n @ R.T
        A_rows.append(np.column_stack([nw, -(nw @ V[b]), np.ones(len(nw))]))
        b_rows.append(nw @ case.pos[b, 0] - d + 0.5 * margin)
    res = linprog(
        c=[0, 0, 0, 0, -1],
        A_ub=np.vstack(A_rows),
        b_ub=np.concatenate(b_rows),
        bounds=[(None, None)] * 3 + [(0.0, case.duration), (None, 1.0)],
        method="highs",
    )
    if res.status != 0:
        return False
    return bool(-res.fun > LP_SLACK)


# ------------------------------------------------------------------------------ translating cases
@dataclass
class TranslatingLabel:
    """Oracle verdict for one :class:`monitor.bench.cases.TranslatingCase`.

    Attributes:
        label: ``"collide" | "clear" | "near"`` (relative to the case's margin).
        clearance_lower: proved lower bound (m) on the minimum signed distance (-inf on collide).
        distance_upper: smallest sampled upper bound (m) on the signed distance.
        hit_time: time (s) of a sample with ``upper < margin``, or None.
        lp: exact LP verdict (True = the margin band is entered) for polytope/half-space pairs
            at margin 0, else None.
        evals: static distance evaluations.
    """

    label: str
    clearance_lower: float
    distance_upper: float
    hit_time: float | None
    lp: bool | None
    evals: int

    def to_dict(self) -> dict:
        """JSON form."""
        return {"label": self.label, "clearance_lower": _jf(self.clearance_lower),
                "distance_upper": _jf(self.distance_upper), "hit_time": self.hit_time, "lp": self.lp,
                "evals": self.evals}


def translating_label(case, *, resolution: float = 1e-7, cap: int = 20_000) -> TranslatingLabel:
    """Label a translating case by dense sampling with the exact Lipschitz margin (+ the LP).

    The waypoint times are sampled first. On segment k the signed distance changes at
    most at the relative speed
    ``|v_A - v_B|`` (:meth:`TranslatingCase.relative_speeds`), so on a sub-interval with
    midpoint m and half width h, ``d(t) >= lower(m) - speed h``. Sub-intervals are split
    until each is proved clear of the margin, a sample has ``upper < margin`` (collide),
    or they are shorter than ``resolution`` of the window or ``cap`` are open ("near").
    Polytope and half-space pairs at margin 0 also get the exact space-time LP
    (:func:`translating_lp`), which decides collide / not collide when available.
    """
    margin = case.margin
    a_l, b_l, L_l = [], [], []
    for k, (t0, t1) in enumerate(zip(case.times[:-1], case.times[1:])):
        e = np.linspace(t0, t1, 33)
        a_l.append(e[:-1])
        b_l.append(e[1:])
        L_l.append(np.full(32, case.relative_speeds()[k]))
    a, b, L = np.concatenate(a_l), np.concatenate(b_l), np.concatenate(L_l)
    T = float(case.times[-1] - case.times[0])
    evals, best_up, lower, hit, unresolved = 0, np.inf, np.inf, None, False
    # the waypoints first: on each segment the distance is convex in time, so its minimum is
    # often at a waypoint, which the midpoints of the subdivision never hit exactly
    lo_w, up_w = case.distance_bounds(case.times)
    evals += len(case.times)
    best_up = float(up_w.min())
    if (up_w < margin).any():
        hit = float(case.times[int(np.argmax(up_w < margin))])
        a = a[:0]
    while len(a):
        m = 0.5 * (a + b)
        lo, up = case.distance_bounds(m)
        evals += len(m)
        best_up = min(best_up, float(up.min()))
        if (up < margin).any():
            hit = float(m[int(np.argmax(up < margin))])
            break
        bound = lo - L * 0.5 * (b - a)
        bad = bound <= margin
        if (~bad).any():
            lower = min(lower, float(bound[~bad].min()))
        if not bad.any():
            break
        if (b - a)[bad].max() < resolution * T or 2 * bad.sum() > cap:
            unresolved = True
            lower = min(lower, float(bound[bad].min()))
            break
        a, b, L, m = a[bad], b[bad], L[bad], m[bad]
        a, b, L = np.concatenate([a, m]), np.concatenate([m, b]), np.concatenate([L, L])
    lp = translating_lp(case) if case.margin == 0.0 and _translating_lp_applies(case) else None
    low = -np.inf if hit is not None else lower
    return TranslatingLabel(_label(hit, unresolved, lp), low, best_up, hit, lp, evals)


def _translating_lp_applies(case) -> bool:
    return all(s.kind in ("polytope", "halfspace") for s in case.shapes) and not all(
        s.kind == "halfspace" for s in case.shapes)


def translating_lp(case) -> bool:
    """Exact LP at margin 0: do the translating polytopes / half-space overlap (interior) at some t?

    Per segment k (duration h, origins p_b(tau) = P_b + V_b tau, tau in [0, h]), with each
    body's H-rep ``n.y <= o`` (body frame, unit n) and rotation R_b, maximise s subject to

        (R_b n) . x - ((R_b n) . V_b) tau + s <= o + (R_b n) . P_b,   0 <= tau <= h,  s <= 1.

    Interior overlap on the segment iff s* > LP_SLACK; touching is not a collision.
    """
    V = case.velocities()
    for k in range(len(case.times) - 1):
        h = float(case.times[k + 1] - case.times[k])
        A_rows, b_rows = [], []
        for b in range(2):
            s = case.shapes[b]
            nrm = np.asarray(s.normals, float)
            scale = np.linalg.norm(nrm, axis=1)
            n, o = nrm / scale[:, None], np.asarray(s.offsets, float) / scale
            nw = n @ case.rotations[b].T
            A_rows.append(np.column_stack([nw, -(nw @ V[k, b]), np.ones(len(nw))]))
            b_rows.append(o + nw @ case.origins[k, b])
        res = linprog(c=[0, 0, 0, 0, -1], A_ub=np.vstack(A_rows), b_ub=np.concatenate(b_rows),
                      bounds=[(None, None)] * 3 + [(0.0, h), (None, 1.0)], method="highs")
        if res.status == 0 and -res.fun > LP_SLACK:
            return True
    return False


__all__ = [
    "OracleLabel",
    "label",
    "lp_overlap",
    "distance_bounds",
    "approx_distance",
    "mujoco_distance",
    "backend_name",
    "MUJOCO_DISTANCE_PAD",
    "LP_SLACK",
    "TranslatingLabel",
    "translating_label",
    "translating_lp",
]
