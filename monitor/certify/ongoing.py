"""The ongoing-contact rule: pairs already in contact when a window starts.

Plain :func:`monitor.certify` treats a pair whose start distance is below the
margin as a violation at t0 (a body starting inside another is a violation).
A gate on a real task needs a different question for such a pair: *does this
action deepen the contact beyond a set penetration?* With
``certify(..., ongoing="deepen", penetration_tol=d)``:

* A pair is **ongoing** when its exact static distance at t0 cannot be proven
  larger than the margin (``lower <= margin``). Every other pair (in particular a
  *new* contact with a hazard while another contact is ongoing) keeps the full
  rule: clearance > margin over the whole window.
* An ongoing pair that is provably apart at t0 (``0 < lower - d``, i.e. inside the
  margin but not touching) may close by at most ``d``: it is re-certified at margin 0
  with A's radius (B's when A is a half-space, whose solid has no radius)
  *inflated* by ``x = (lower - d)(1 + 1e-9)`` (exact: the signed
  distance drops by exactly x), so certified => clearance > lower - d > 0 at every
  instant; it cannot reach contact within this window. The rule is per window: over
  successive windows such a pair can close step by step, reach contact and then
  penetrate, never by more than ``d`` (the next bullet), which is what
  ``penetration_tol`` allows for contacts that belong to the task.
* Any other ongoing pair is acceptable iff its penetration never exceeds ``d`` during
  the window, certified soundly: the pair is re-certified at margin 0 with its
  shapes *shrunk* by ``s <= d``:

  - the rounded radii (sphere / capsule radius) are reduced, A's first, then B's;
  - a half-space (MuJoCo plane) is moved inwards along its normal.

  Both are exact: for a core C swept by radius r, the signed distance of
  ``C + B(r - x)`` to any convex set is the original signed distance plus x
  (distance and penetration depth of Minkowski sums add radii), and the signed
  distance of a convex set to ``{n.x <= o - x}`` is the original plus x. So a
  certificate of the shrunk pair (sd_shrunk > 0 at every instant) proves
  sd_original > -s >= -d: penetration < d at every instant of the continuous motion.
  ``s`` is ``d * (1 - 1e-9)`` when the pair has enough radius / a half-space, so
  rounding in the shrinking cannot make s exceed d.
* Polytope cores cannot be eroded exactly (the support function of an eroded
  polytope drops by more than x at its corners), so a pair with too little
  radius and no half-space (box on box, cylinder on box) is shrunk by what its
  radii allow: certified => penetration < s (a stronger statement); otherwise it
  is "uncertain" with the note ``"ongoing contact, polytope cores"``, never a
  "violation" (its witness only shows penetration > s, not > d).
* A confirmed witness of a fully shrunk pair shows penetration > s: the pair's
  result is a "violation" whose witness distance is the original distance
  (shrunk distance - s).

Every pair judged this way carries a ``PairResult.note`` starting with
``"ongoing"``; :attr:`Certificate.ongoing` lists them and
``stats["ongoing"]`` / ``stats["penetration_tol"]`` record the rule's use.
The certificate's ``clearance`` includes the ongoing pairs' (negative) bounds.

Pure: numpy only (no MuJoCo).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from monitor.certify.certificate import Certificate, PairResult, Witness, combine_verdicts
from monitor.certify.types import Verdict
from monitor.errors import InvalidInputError
from monitor.geometry.shapes import ConvexShape

DEFAULT_PENETRATION_TOL = 0.005
"""Metres of penetration an ongoing contact may reach within a window (5 mm: above
MuJoCo's typical resting penetration of soft contacts, ~1 mm, below any geometry
feature that matters for a collision)."""
MAX_PENETRATION_TOL = 1e9
"""Largest accepted ``penetration_tol`` (m), the geometry's coordinate limit. The rule shifts shapes by
it and subtracts it back from the clearance: far beyond it that subtraction's rounding (~1e-16 of it)
exceeds every pad, and clearances of 1e14 m tolerances were overstated by centimetres (red team 7)."""
ONGOING_RULES = ("violation", "deepen")
_REL = 1e-9  # relative safety factor on the shrink amount (rounding of r - x, o - x)
POLYTOPE_NOTE = "ongoing contact, polytope cores"


def check_rule(ongoing: Any, penetration_tol: Any) -> float:
    """Validate ``ongoing`` / ``penetration_tol``; returns the tolerance as a float."""
    if ongoing not in ONGOING_RULES:
        raise InvalidInputError(f"ongoing must be one of {ONGOING_RULES}, got {ongoing!r}")
    try:
        d = float(penetration_tol)
    except (TypeError, ValueError):
        raise InvalidInputError(f"penetration_tol must be a number (m), got {penetration_tol!r}") from None
    if not 0 < d <= MAX_PENETRATION_TOL:
        raise InvalidInputError(f"penetration_tol must be > 0 and <= {MAX_PENETRATION_TOL:g} (m), "
                                f"got {penetration_tol!r}")
    return d


def shrink_pair(sa: ConvexShape, sb: ConvexShape, d: float) -> tuple[ConvexShape, ConvexShape, float]:
    """Shrink a pair's shapes so that their signed distance grows by exactly ``s <= d``.

    Returns:
        (shrunk A, shrunk B, s) with s the achieved shrink (m); s < d*(1-1e-9) only when
        the radii are used up and neither shape is a half-space.
    """
    want = d * (1.0 - _REL)
    left = want
    out = []
    for s in (sa, sb):
        x = min(float(s.radius), left)
        if x > 0:
            s = replace(s, radius=0.0 if x >= s.radius else float(s.radius) - x)
            left -= x
        out.append(s)
    for k in (0, 1):
        if left > 0 and out[k].kind == "halfspace":
            n = np.asarray(out[k].normals[0], dtype=np.float64)
            out[k] = out[k].transformed(np.eye(3), -left * n / float(np.linalg.norm(n)))
            left = 0.0
    return out[0], out[1], want - max(left, 0.0)


class _PairScene:
    """A scene-like view with per-pair (shrunk) geom copies for :func:`monitor.certify`."""

    allowed_pairs: tuple = ()
    derived_geoms = True
    """Its geoms are modified copies (ids past the model's): never read their shape from the model."""

    def __init__(self, scene: Any, geoms: list[Any], pair_ids: list[tuple[int, int]],
                 names: list[tuple[str, str]]) -> None:
        self.model = scene.model
        self.geoms = tuple(geoms)
        self.pair_ids = np.asarray(pair_ids, dtype=np.int64).reshape(-1, 2)
        self.candidate_pairs = tuple(names)
        self.body_names = scene.body_names
        self.body_static = scene.body_static
        self.tolerances = getattr(scene, "tolerances", None)
        self._scene = scene

    @property
    def model_hash(self) -> str:
        return self._scene.model_hash


def deepen(certify_fn: Callable[..., Certificate], scene: Any, plan: Any, cert: Certificate, *,
           margin: float, epsilon: float, method: str, budget: Any, tolerances: Any,
           penetration_tol: float) -> Certificate:
    """Apply the ongoing-contact rule to a certificate of plain :func:`monitor.certify`.

    Args:
        certify_fn: :func:`monitor.certify.engine.certify` (passed in: no import cycle).
        scene: the scene ``cert`` was computed on.
        plan: the plan.
        cert: the plain certificate (start-inside rule).
        margin, epsilon, method, budget, tolerances: as given to ``certify``.
        penetration_tol: d (m), see module docstring.

    Returns:
        the certificate with ongoing pairs re-judged (unchanged when there are none).
    """
    if cert.verdict == Verdict.CERTIFIED:
        # every pair is certified (any other pair verdict makes the combined verdict
        # "uncertain" or "violation"): no ongoing pair; cert.pairs need not be built here
        return cert
    # read before cert.pairs (building the pairs drops the kernel's arrays)
    known = _start_lower(cert) if _START_BOUND else None
    if known is not None and all(lo > margin for lo in known.values()):
        return cert   # every pair the kernel did not cull is proven clear at t0: none is ongoing
    cand = [k for k, p in enumerate(cert.pairs) if p.verdict != Verdict.CERTIFIED]
    if not cand:
        return cert
    t0 = float(cert.window[0])
    poses = None
    geoms = list(scene.geoms)
    pair_rows: list[tuple[int, int]] = []
    names: list[tuple[str, str]] = []
    meta: list[tuple[int, float]] = []  # (index in cert.pairs, achieved shrink)
    for k in cand:
        if known is not None and known.get(k, math.nan) > margin:
            continue  # proven clear at t0 by the window kernel's start-pose test: a new contact
        p = cert.pairs[k]
        ga, gb = scene.geom(p.geoms[0]), scene.geom(p.geoms[1])
        if poses is None:
            poses = plan.body_poses(np.array([t0]))
        dist = start_distance(ga, gb, poses, tolerances)
        if dist.lower > margin:
            continue  # clear at t0: a new contact, the full rule stands
        floor = float(dist.lower) - penetration_tol
        if floor > 0.0:
            # within the margin but provably apart: it may close by at most penetration_tol,
            # never down to contact. Inflating a radius by x is exact (sd drops by exactly x),
            # so certifying the inflated pair at margin 0 proves sd > x >= floor.
            x = floor * (1.0 + _REL)
            if ga.shape.kind != "halfspace":
                sa, sb, s = replace(ga.shape, radius=float(ga.shape.radius) + x), gb.shape, -x
            else:  # a half-space's solid ignores its radius: inflate B's (the same exact drop by x)
                sa, sb, s = ga.shape, replace(gb.shape, radius=float(gb.shape.radius) + x), -x
        else:  # touching or penetrating: penetration may not exceed penetration_tol
            sa, sb, s = shrink_pair(ga.shape, gb.shape, penetration_tol)
        ia, ib = len(geoms), len(geoms) + 1
        geoms.append(replace(ga, id=ia, shape=sa))
        geoms.append(replace(gb, id=ib, shape=sb))
        pair_rows.append((ia, ib))
        names.append(p.geoms)
        meta.append((k, s))
    if not meta:
        return cert
    view = _PairScene(scene, geoms, pair_rows, names)
    sub = certify_fn(view, plan, margin=0.0, epsilon=epsilon, method=method, window=tuple(cert.window),
                     budget=budget, tolerances=tolerances)
    full = penetration_tol * (1.0 - _REL)
    pairs = list(cert.pairs)
    for (k, s), r in zip(meta, sub.pairs):
        tol_txt = f"{penetration_tol:g} m"
        clear = r.clearance - s if math.isfinite(r.clearance) else r.clearance
        if s < 0 or s >= full:  # inflated (floor is a clearance) or fully shrunk (penetration < tol)
            if s < 0:
                head, bound = "ongoing (within margin): clearance", f"{-s:.3g} m"
                texts = ("> {b} certified", "falls below {b}", "> {b} not proven")
            else:
                head, bound = "ongoing contact: penetration", tol_txt
                texts = ("< {b} certified", "exceeds {b}", "< {b} not proven")
            which = {Verdict.CERTIFIED: 0, Verdict.VIOLATION: 1}.get(r.verdict, 2)
            note = f"{head} {texts[which].format(b=bound)}"
            w = r.witness
            if w is not None:
                w = Witness(w.time, w.geoms, w.point, float(w.distance) - s)
            pairs[k] = replace(r, clearance=clear, witness=w, note=note)
        elif r.verdict == Verdict.CERTIFIED:
            pairs[k] = replace(r, clearance=clear,
                               note=f"ongoing contact: penetration < {s:g} m certified (polytope cores)")
        else:
            pairs[k] = replace(r, verdict=Verdict.UNCERTAIN, witness=None, clearance=-math.inf,
                               intervals=r.intervals or ((t0, float(cert.window[1])),),
                               note=f"{POLYTOPE_NOTE}: penetration < {tol_txt} cannot be certified "
                                    f"(only {s:g} m of radius to shrink)")
    return _recombine(cert, pairs, len(meta), penetration_tol)


def start_distance(ga: Any, gb: Any, poses: tuple[np.ndarray, np.ndarray], tolerances: Any) -> Any:
    """Exact static distance of geoms ``ga``, ``gb`` (``GeomInfo``) at the first time of ``poses``.

    ``poses`` = ``plan.body_poses(times)``: ((T, nbody, 3) positions, (T, nbody, 3, 3) rotations);
    row 0 is used. The test by which :func:`deepen` calls a pair ongoing (``lower <= margin``);
    :meth:`monitor.gate.Gate._tail_refuted` asks the same question of a tail's start.
    """
    from monitor.geometry.distance import shape_distance

    pos, rot = poses
    return shape_distance(ga.shape, (rot[0, ga.body_id], pos[0, ga.body_id]),
                          gb.shape, (rot[0, gb.body_id], pos[0, gb.body_id]), tolerances=tolerances)


_START_BOUND = True
"""Let :func:`deepen` take the window kernel's start-pose bound where it proves a pair clear
(:func:`_start_lower`); tests switch it off to compare with ``shape_distance`` alone."""


def _start_lower(cert: Certificate) -> dict[int, float] | None:
    """{position in ``cert.pairs``: lower bound (m) of the pair's distance at t0}, or None.

    From the engine's compiled path, whose window kernel tests every surviving pair's start
    pose exactly (float-verified ``posed_distance``, the test the engine certifies start
    poses with): the certificate's unbuilt pairs object answers
    (:meth:`monitor.certify.engine._WindowPairs.start_lower`), one entry per pair the kernel
    did not cull (NaN where the test did not run); every other pair is "certified" (culled).
    None for a certificate whose pairs are a tuple (the Python pipeline, ``replace``, pairs
    already read): then every pair is measured.
    """
    store = cert.__dict__.get("_pairs_store")
    f = getattr(store, "start_lower", None)
    return None if f is None else f()


def _recombine(cert: Certificate, pairs: list[PairResult], n_ongoing: int, tol: float) -> Certificate:
    verdict = combine_verdicts([p.verdict for p in pairs])
    wits = [p.witness for p in pairs if p.verdict == Verdict.VIOLATION and p.witness is not None]
    witness = min(wits, key=lambda w: w.time) if wits else None
    earliest = None
    if verdict != Verdict.CERTIFIED:
        starts = [p.intervals[0][0] for p in pairs if p.verdict != Verdict.CERTIFIED and p.intervals]
        starts += [w.time for w in wits]
        earliest = float(min(starts)) if starts else float(cert.window[0])
    clears = [p.clearance for p in pairs if p.method != "culled" or math.isfinite(p.clearance)]
    clearance = float(min(clears)) if clears else math.inf
    stats = dict(cert.stats)
    stats["ongoing"] = n_ongoing
    stats["penetration_tol"] = tol
    return replace(cert, verdict=verdict, witness=witness, earliest_time=earliest, clearance=clearance,
                   pairs=tuple(pairs), stats=stats)


__all__ = ["deepen", "shrink_pair", "check_rule", "DEFAULT_PENETRATION_TOL", "MAX_PENETRATION_TOL",
           "ONGOING_RULES", "POLYTOPE_NOTE"]
