"""The public entry point :func:`certify`: cull, check, confirm, combine.

Pipeline for one window [t0, t1] and the scene's candidate geom pairs:

1. **Validation** (typed errors): margin finite and >= 0, epsilon finite and > 0, a
   non-empty finite window inside the plan, a known method, a plan of the scene's model
   (``plan.model is scene.model`` or equal model hashes; otherwise the body count must
   match), known pair names.
2. **Cull.** Pairs of two scene-static bodies (welded to the world) that the plan does
   not move either are ``"culled"`` (MuJoCo never collides them either; a
   :class:`monitor.BodyMotion` may move a welded body, and then the pair is checked).
   Pairs whose swept bounding spheres (:mod:`monitor.certify.broadphase`, 8
   sub-intervals, all pairs at once in numpy) stay further apart than the margin are
   ``"culled"`` and certified, with the sphere gap as clearance bound.
3. **Start pose.** Every remaining pair gets the exact static distance at t0
   (:func:`monitor.geometry.distance.shape_distance`): ``upper + approx < margin`` is a violation
   at t0 (method ``"static"``). If neither that nor clear cores can be proven, the pair can
   at best be "uncertain" (boundary tests cannot see containment). Pairs whose bodies do
   not move relative to the world in the window are decided by this test alone.
4. **Checkers.** ``method="auto"``: pairs whose two bodies both translate with
   piecewise-constant velocity (``Trajectory.translation_segments``) go to the exact
   extrusion checker, the rest to the toleranced checker; ``"toleranced"`` / ``"extrusion"``
   force one (extrusion raises InvalidInputError on a non-translating pair).
5. **Witnesses.** For every interval a checker could not exclude, exact static tests at
   ``Tolerances.witness_candidates`` times (in time order, stopping at the first hit):
   ``upper + approx < margin`` confirms a violation with a :class:`Witness` (``approx``:
   the over-approximation of circumscribed cylinders/ellipsoids); otherwise the pair is
   "uncertain". An extrusion "violation" is re-confirmed the same way at its witness time.
6. **Combine.** Any violation wins (earliest witness), else any uncertain, else certified.
   ``clearance`` is the minimum of the per-pair certified lower bounds (toleranced
   certified pairs contribute ``margin``: the checker proves ``distance > margin``; -inf for
   uncertain / violating pairs; culled static-static pairs do not contribute).

MuJoCo's per-geom ``margin`` is not added: ``margin`` here is the caller's clearance.
"""

from __future__ import annotations

import gc
import math
import sys
import time
from typing import Any

import numpy as np

from monitor.certify.broadphase import halfspace_gaps, sphere_pair_gaps, swept_geom_spheres
from monitor.certify.certificate import (
    Certificate,
    PairResult,
    Verdict,
    Witness,
    combine_verdicts,
    nothing_checked_stats,
)
from monitor.certify.common import (
    DEFAULT_BUDGET_SECONDS,
    Budget,
    BudgetExhausted,
    Outcome,
    PairOutcome,
    active_budget,
)
from monitor.certify.ongoing import DEFAULT_PENETRATION_TOL, deepen
from monitor.certify.packed import lex_sorted_pairs
from monitor.certify.request import DEFAULT_EPSILON, BudgetLimits, CertifyRequest
from monitor.certify.types import Method
from monitor.errors import InvalidInputError, ModelMismatchError, MonitorError
from monitor.tolerances import DEFAULT, Tolerances

_METHODS = tuple(m.value for m in Method)  # ("auto", "toleranced", "extrusion")
_MAX_WITNESS_INTERVALS = 64
"""Intervals per pair searched for a witness (in time order); the rest stay uncertain."""
_FINALISE_SECONDS_PER_PAIR = [8e-6]
"""Cost (s) per selected pair of assembling the certificate (one PairResult each, plus the
garbage collector's first pass over them): 2-8 us measured on a loaded 2-core machine.
Reserved from a seconds budget (at most half of it) so the stages stop early enough; the
value tracks the largest cost measured in this process (one-element list: mutable)."""
_NSUB = 8
"""Sub-intervals of the broad phase's swept spheres (one pose / bound call for all geoms)."""


_KS: list = []


def _kernels() -> Any:
    """The :mod:`monitor.certify.kernels` module (imported on first use: it imports numba)."""
    if not _KS:
        from monitor.certify import kernels
        _FINGERPRINT[0] = _fingerprint_function()
        _KS.append(kernels)
    return _KS[0]


def _finite(name: str, x: Any) -> float:
    if type(x) is float and x - x == 0.0:  # a finite float (inf - inf and nan - nan are nan)
        return x
    try:
        v = float(x)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be a real number, got {x!r}") from exc
    if math.isnan(v) or math.isinf(v):
        raise InvalidInputError(f"{name} must be finite, got {v}")
    return v


def _check_model(scene: Any, plan: Any) -> Any:
    """The plan to certify, on a scene the caller has just synced with its (possibly edited) model.

    ``scene.sync()`` (run by :func:`certify` on every call) rebuilds shapes and pairs after an
    in-place model edit. A plan whose
    frozen joint frames no longer match its live model (built before the edit) is
    replaced by the same waypoints rebuilt on the live model: the certificate is about
    the motion the simulation will now produce. The ``plan.model is scene.model`` fast
    path skips only the hash comparison, never these checks.
    """
    hot = _hot(scene)
    if hot is not None and type(plan) is _plan_class():
        memo = hot.get("plan_current")
        st = getattr(plan, "_st", None)
        if (memo is not None and memo[0] is getattr(scene, "_snapshot", None) and st is not None
                and plan.model is scene.model and memo[1].get(id(st)) is st):
            return plan        # see _remember_current: the same checks, already passed
    pm = getattr(plan, "model", None)
    if pm is not None and pm is not scene.model:
        try:
            from monitor.scene import model_hash
            same = model_hash(pm) == scene.model_hash
        except Exception:  # noqa: BLE001 - any failure to hash means we cannot prove equality
            same = False
        if not same:
            raise ModelMismatchError("the plan was built for a different MjModel than the scene "
                                     "(model objects differ and their hashes differ)")
    if int(plan.nbody) != len(scene.body_names):
        raise ModelMismatchError(f"plan has {plan.nbody} bodies, scene has {len(scene.body_names)}")
    current = getattr(plan, "is_current", None)
    if current is not None:
        if not current():
            plan = plan.refreshed()
        elif hot is not None and pm is scene.model and type(plan) is _plan_class():
            _remember_current(scene, hot, plan)
    return plan


def _plan_class() -> type | None:
    """:class:`monitor.motion.plan.Plan` if that module is loaded, else None.

    Never imports it (it imports mujoco; ``monitor.certify`` must not): a plan that is a
    ``Plan`` means the module is loaded already.
    """
    mod = sys.modules.get("monitor.motion.plan")
    return None if mod is None else getattr(mod, "Plan", None)


def _hot(scene: Any) -> dict | None:
    """The scene's engine cache (``Scene._hot``, emptied by ``Scene.sync``), or None (duck-typed scenes)."""
    hot = getattr(scene, "_hot", None)
    if hot is None and getattr(scene, "_snapshot", None) is not None:
        try:   # a Scene unpickled from an older version
            hot = scene._hot = {}
        except AttributeError:
            return None
    return hot


def _remember_current(scene: Any, hot: dict, plan: Any) -> None:
    """Record that ``plan`` passed ``is_current`` against the model as the scene's snapshot holds it.

    ``Plan.is_current()`` is ``_structure_key(plan.model) == plan._st.key``: it depends only on
    the plan's (cached, shared) structure object ``_st`` and the model's bytes of
    ``plan._STRUCT_FIELDS`` plus array sizes. Every one of those fields is watched by the
    scene's snapshot (``monitor.scene.SYNC_FIELDS``; asserted by
    ``tests/test_engine_entry.py``) and sizes cannot change in place. So while ``scene.sync()``
    finds the model equal to the same snapshot object (every watched byte unchanged), any
    plan with the same ``_st`` object on the same model object is still current: the next
    call skips the ``is_current`` bytes join. ``Scene.sync`` empties ``_hot`` when it
    rebuilds, and the memo also holds the snapshot it was made under. Only exact
    :class:`~monitor.motion.plan.Plan` objects (no subclass overriding ``is_current``).
    The memo holds the ``_st`` objects themselves, so their ``id`` is not reused.
    """
    snap = getattr(scene, "_snapshot", None)
    st = getattr(plan, "_st", None)
    if snap is None or st is None or not snap.unchanged():
        return
    memo = hot.get("plan_current")
    if memo is None or memo[0] is not snap:
        memo = hot["plan_current"] = (snap, {})
    if len(memo[1]) >= 16:
        memo[1].clear()
    memo[1][id(st)] = st


def _select(scene: Any, pairs: Any) -> np.ndarray:
    """Sorted (S,) int64 indices of the selected candidate pairs (all of them when ``pairs`` is None)."""
    if pairs is None:
        pid = scene.pair_ids
        hot = _hot(scene)
        if hot is not None:
            hit = hot.get("sel_all")
            if hit is not None and hit[0] is pid:
                return hit[1]
        sel = np.arange(len(pid), dtype=np.int64)
        if hot is not None:
            sel.setflags(write=False)
            hot["sel_all"] = (pid, sel)
        return sel
    index = {}
    for i, (a, b) in enumerate(scene.candidate_pairs):
        index[(a, b)] = i
        index[(b, a)] = i
    out = []
    for k, pr in enumerate(pairs):
        try:
            a, b = pr
        except (TypeError, ValueError) as exc:
            raise InvalidInputError(f"pairs[{k}] must be a (geom_a, geom_b) name pair, got {pr!r}") from exc
        if (a, b) not in index:
            raise InvalidInputError(f"pairs[{k}] = ({a!r}, {b!r}) is not a candidate pair of the scene")
        out.append(index[(a, b)])
    return np.array(sorted(set(out)), dtype=np.int64)


def _stage_budget(bud: Budget, npairs: int) -> Budget:
    """The budget the stages work against: ``bud`` minus the time to assemble the certificate.

    After the stages, one :class:`PairResult` per selected pair is built (about
    :data:`_FINALISE_SECONDS_PER_PAIR` each); for 500 000 pairs that is a second or more,
    which would otherwise come on top of an exhausted budget. Same clock as ``bud``.
    """
    if bud.seconds is None:
        return bud
    if npairs == 0 and bud.tests is None:
        # nothing to reserve and no test count to keep apart from ``bud``: the same clock and
        # the same seconds limit, so ``bud`` itself (the compiled path; saves a Budget per call)
        return bud
    reserve = min(0.5 * bud.seconds, _FINALISE_SECONDS_PER_PAIR[0] * npairs)
    stage = Budget(seconds=bud.seconds - reserve, tests=bud.tests)
    stage.share_clock(bud)
    return stage


def _make_budget(budget: Any) -> Budget:
    """The call's budget: ``None`` -> :data:`DEFAULT_BUDGET_SECONDS`; a dict is validated.

    No budget's clock counts numba compile time (:class:`Budget`): a kernel compiled on first
    use inside this call does not make the window "uncertain", and the call compiles only
    the kernels it uses (``python -m monitor warmup`` compiles every path ahead of time).
    """
    if budget is None:
        return Budget.default(DEFAULT_BUDGET_SECONDS)
    if isinstance(budget, Budget):
        return budget
    if isinstance(budget, dict):
        unknown = sorted(set(budget) - {"seconds", "tests"}, key=str)
        if unknown:
            raise InvalidInputError(f"budget has unknown field(s) {unknown}; expected 'seconds', 'tests'")
        return Budget(seconds=budget.get("seconds"), tests=budget.get("tests"))
    raise InvalidInputError(f"budget must be None, a Budget or a dict, got {type(budget).__name__}")


_REQUESTS: dict[tuple, CertifyRequest] = {}
"""Memo of the requests :func:`_request_of` built from plain keyword values (bounded; see there)."""
_NO_KEY = object()
_LAST_REQUEST: list[tuple | None] = [None]
"""The argument objects of the last memoised keyword call, its budget key and its request."""


def _request_of(margin: Any, epsilon: Any, method: Any, window: Any, budget: Any, tolerances: Any,
                pairs: Any, ongoing: Any, penetration_tol: Any) -> CertifyRequest:
    """The :class:`CertifyRequest` of ``certify``'s keyword arguments.

    Validation happens in ONE place, ``CertifyRequest.__post_init__``; its messages name the
    field as ``CertifyRequest.<field>`` and here they name the keyword instead (the prefix
    is dropped: ``margin must be >= 0, got -0.1``), as ``certify`` always said.

    Requests are memoised for plain values only (``margin``, ``epsilon``, ``penetration_tol``
    exact floats, ``window`` None or a tuple of two floats, ``pairs`` None, ``budget`` None or
    a :class:`Budget` (keyed by its limits), ``tolerances`` by identity): such a key decides
    the validated request completely, so a hit is the request validation would build, and
    a loop certifying many windows with the same settings validates them once.
    """
    last = _LAST_REQUEST[0]
    if (last is not None and last[0] is margin and last[1] is epsilon
            and last[2] is method and last[3] is window and last[4] is tolerances and last[5] is pairs
            and last[6] is ongoing and last[7] is penetration_tol
            and (last[8] == DEFAULT_BUDGET_SECONDS if budget is None
                 else type(budget) is Budget and last[8] == (budget.seconds, budget.tests))):
        # the very objects of the previous call (a loop certifying window after window): immutable
        # values (floats, strings, a frozen Tolerances, a tuple of floats or None) that were
        # validated into last[9], and the budget key (the engine's default seconds read now, or
        # a Budget's limits read now: a Budget object is mutable) that keyed it in _REQUESTS
        return last[9]
    if budget is None:  # the engine's default seconds, read now (tests patch it)
        bkey: Any = DEFAULT_BUDGET_SECONDS
    elif type(budget) is Budget:
        bkey = (budget.seconds, budget.tests)
    else:
        bkey = _NO_KEY
    key = None
    if (bkey is not _NO_KEY and pairs is None and type(margin) is float and type(epsilon) is float
            and type(penetration_tol) is float
            and (window is None or (type(window) is tuple and len(window) == 2
                                    and type(window[0]) is float and type(window[1]) is float))):
        key = (margin, epsilon, method, window, bkey, id(tolerances), ongoing, penetration_tol)
        try:
            hit = _REQUESTS.get(key)
        except TypeError:  # an unhashable method / ongoing: validation names it below
            hit, key = None, None
        if hit is not None and hit.tolerances is tolerances:
            _LAST_REQUEST[0] = (margin, epsilon, method, window, tolerances, pairs, ongoing,
                                penetration_tol, bkey, hit)
            return hit
    try:
        req = CertifyRequest(margin=margin, epsilon=epsilon, method=method, window=window,
                             budget=BudgetLimits(seconds=bkey) if budget is None else budget,
                             pairs=pairs, tolerances=tolerances, ongoing=ongoing,
                             penetration_tol=penetration_tol)
    except InvalidInputError as exc:
        msg = str(exc)
        raise InvalidInputError(msg[len("CertifyRequest."):] if msg.startswith("CertifyRequest.")
                                else msg) from None
    if key is not None:
        _LAST_REQUEST[0] = (margin, epsilon, method, window, tolerances, pairs, ongoing, penetration_tol,
                            bkey, req)
        if len(_REQUESTS) >= 64:
            _REQUESTS.clear()
        _REQUESTS[key] = req
    return req


def _check_no_clash(request: Any, given: tuple) -> CertifyRequest:
    """``request`` itself, after checking that no keyword setting was given alongside it."""
    if not isinstance(request, CertifyRequest):
        raise InvalidInputError(f"request must be a CertifyRequest or None, got {type(request).__name__}")
    clash = []
    for (name, default), value in zip(_KW_DEFAULTS, given):
        if value is default:
            continue
        try:
            same = type(value) is type(default) and bool(value == default)
        except Exception:  # noqa: BLE001 - an array or odd object is not the default
            same = False
        if not same:
            clash.append(name)
    if clash:
        raise InvalidInputError(f"certify got request= together with {', '.join(clash)}=: pass the "
                                f"setting(s) in the request (request.replace({clash[0]}=...)) or as "
                                "keywords, not both")
    return request


def certify(scene: Any, plan: Any, margin: float = 0.0, epsilon: float = DEFAULT_EPSILON,
            method: Method | str = "auto", *,
            window: tuple[float, float] | None = None, budget: Budget | dict | None = None,
            tolerances: Tolerances = DEFAULT, pairs: list[tuple[str, str]] | None = None,
            ongoing: str = "violation", penetration_tol: float = DEFAULT_PENETRATION_TOL,
            request: CertifyRequest | None = None) -> Certificate:
    """Certify that the planned motion keeps every candidate pair at least ``margin`` apart.

    Args:
        scene: :class:`monitor.Scene`.
        plan: a Trajectory (:class:`monitor.Plan` or :class:`monitor.BodyMotion`) of the scene's model.
        margin: clearance (m) that counts as safe; distance below it is a violation.
        epsilon: termination tolerance (m of body motion), R * max rho < epsilon.
        method: a :class:`~monitor.certify.types.Method` or its string: "auto" | "toleranced" | "extrusion".
        window: (t0, t1) sub-window (s); default the plan's span.
        budget: None (a default :class:`Budget` of
            :data:`~monitor.certify.common.DEFAULT_BUDGET_SECONDS` wall seconds), a
            :class:`Budget`, or {"seconds": .., "tests": ..}. Checked inside every stage
            (motion bounds, broad phase, start pose, checkers, witness search); pairs
            left unfinished are "uncertain" (method ``"budget"`` when no checker ran).
            A :class:`Budget` object is used as it is (its clock keeps running across
            calls); a dict or None starts a fresh clock per call.
        tolerances: numerical tolerances.
        pairs: optional subset of candidate pairs (geom-name pairs) to certify.
        ongoing: ``"violation"`` (default: a pair closer than ``margin`` at t0 is a
            violation) or ``"deepen"`` (such a pair is an ongoing contact and only has to
            stay within ``penetration_tol`` of penetration; :mod:`monitor.certify.ongoing`).
        penetration_tol: metres of penetration an ongoing contact may reach (``"deepen"``).
        request: a :class:`~monitor.certify.request.CertifyRequest` holding all of the
            settings above (validated once, when it was made; its budget limits start a
            fresh clock per call). With it, every keyword setting must be left at its
            default. Without it, ``certify`` builds one from the keywords.

    Returns:
        The :class:`Certificate`; ``cert.request`` is the request it answers (the given
        one, or the one built from the keywords; ``window`` None there means the plan's
        span, which ``cert.window`` holds). ``stats["pairs"] == 0`` together with
        ``stats["nothing_checked"] is True`` means the scene has no candidate pair:
        the verdict is "certified" only because there is nothing to check.

    Raises:
        InvalidInputError: bad margin / epsilon / window / method / pairs / budget
            (NaN, ranges, field types), a ``request`` that is not a CertifyRequest, or a
            keyword setting given together with ``request`` (the message names it).
        ModelMismatchError: the plan belongs to a different model, or the scene's model
            was edited in place in a way the scene cannot be rebuilt for.

    The scene is synced with its model first (:meth:`monitor.Scene.sync`), and a
    :class:`monitor.Plan` built before an in-place model edit is rebuilt on the live
    model, so the certificate is about the model as it is now. MuJoCo's per-geom
    ``margin`` is not added (see :mod:`monitor.scene`): pass ``margin`` explicitly.
    """
    wall0 = time.perf_counter()
    if request is None:
        req = _request_of(margin, epsilon, method, window, budget, tolerances, pairs, ongoing,
                          penetration_tol)
    else:
        d = _KW_DEFAULT_OBJECTS
        if (type(request) is CertifyRequest and margin is d[0] and epsilon is d[1] and method is d[2]
                and window is None and budget is None and tolerances is d[5] and pairs is None
                and ongoing is d[7] and penetration_tol is d[8]):
            req = request  # every keyword setting left at its default object (the common case)
        else:
            req = _check_no_clash(request, (margin, epsilon, method, window, budget, tolerances, pairs,
                                            ongoing, penetration_tol))
    # a live Budget keeps its clock (and test count); otherwise the request's limits, fresh clock
    lim = req.budget
    if isinstance(budget, Budget):
        bud = budget
    elif lim.tests is None:
        bud = Budget.default(lim.seconds)  # = req.new_budget(), inlined (per call)
    else:
        bud = req.new_budget()
    margin, epsilon, method, tol = req.margin, req.epsilon, req.method.value, req.tolerances
    ongoing, pen_tol = req.ongoing, req.penetration_tol
    sync = getattr(scene, "sync", None)
    if sync is not None:
        sync()      # every call: it guards in-place model edits (the memo below is valid only after it)
    allowed = getattr(scene, "allowed_pairs", ())
    if type(allowed) is not tuple:
        allowed = tuple(allowed)
    hit = _call_memo(scene, plan, req)
    if hit is not None:   # the same scene state, plan and request as the call that stored it
        plan, t0, t1, sel, fast, prep = hit
    else:
        plan_given = plan
        plan = _check_model(scene, plan)
        pt0, pt1 = _finite("plan.t0", plan.t0), _finite("plan.t1", plan.t1)
        if req.window is None:
            t0, t1 = pt0, pt1
        else:
            t0, t1 = req.window
            if t0 < pt0 or t1 > pt1:
                raise InvalidInputError(f"window ({t0}, {t1}) is not inside the plan span ({pt0}, {pt1})")
        if not t1 > t0:
            raise InvalidInputError(f"empty window: t1 = {t1} must be > t0 = {t0}")
        sel = _select(scene, req.pairs)
        if len(sel) == 0:  # nothing to check (e.g. Reacher's pairs="mujoco"): the gate's hot path
            cert = Certificate(Verdict.CERTIFIED, (t0, t1), margin, epsilon, method, None, None, float("inf"),
                               (), nothing_checked_stats(time.perf_counter() - wall0), allowed)
            cert.__dict__["request"] = req
            return cert
        fast = _fast_inputs(scene, plan)
        prep = None
        if fast is not None:
            prep = _fast_prep(scene, plan, sel, fast, t0, t1, margin, epsilon, method, tol)
            _remember_call(scene, plan_given, plan, req, t0, t1, sel, fast, prep)
    # the compiled path builds no PairResult objects (cert.pairs is built on first read)
    stage = _stage_budget(bud, len(sel) if fast is None else 0)
    with active_budget(stage):
        if fast is not None and not stage.exhausted:
            cert = _certify_fast(scene, plan, margin, epsilon, method, t0, t1, stage, tol, sel, wall0,
                                 allowed, fast, prep)
        else:
            cert = _certify(scene, plan, margin, epsilon, method, t0, t1, stage, tol, sel, wall0, allowed)
    # issue 13: contacts present at t0 (monitor/certify/ongoing.py); deepen returns a
    # "certified" certificate unchanged (no pair can be an ongoing contact), so it is not called
    if ongoing == "deepen" and cert.verdict != "certified":
        cert = deepen(certify, scene, plan, cert, margin=margin, epsilon=epsilon, method=method,
                      budget=bud, tolerances=tol, penetration_tol=pen_tol)
    cert.__dict__["request"] = req  # not a compared field: certificates stay equal, to_dict unchanged
    return cert


_KW_DEFAULTS = (tuple(zip(("margin", "epsilon", "method"), certify.__defaults__))
                + tuple(kv for kv in certify.__kwdefaults__.items() if kv[0] != "request"))
"""``certify``'s keyword settings and their default objects (the ones a ``request=`` replaces)."""
_KW_DEFAULT_OBJECTS = tuple(d for _, d in _KW_DEFAULTS)


def _certify(scene: Any, plan: Any, margin: float, epsilon: float, method: str, t0: float, t1: float,
             bud: Budget, tol: Tolerances, sel: np.ndarray, wall0: float, allowed: tuple) -> Certificate:
    """The pipeline of :func:`certify` on validated arguments (``bud`` is the active budget).

    Every stage may end early with :class:`BudgetExhausted` (raised by the motion, polled
    between pairs): the pairs it had not decided become "uncertain".
    """
    moving = np.asarray(plan.moving_bodies(), bool)
    static = np.asarray(scene.body_static, bool)
    results: dict[int, PairResult] = {}
    mix: dict[str, int] = {}

    # -- 1./2. cull (vectorised over all selected pairs; no Python per culled pair) ---------
    sel_a = np.asarray(sel, np.int64)
    pid = np.asarray(scene.pair_ids, np.int64).reshape(-1, 2)[sel_a]
    geom_body = np.array([g.body_id for g in scene.geoms], np.int64)
    # welded to the world AND not moved by the plan (a BodyMotion may move any body)
    fixed = static & ~moving
    ss = fixed[geom_body[pid[:, 0]]] & fixed[geom_body[pid[:, 1]]]
    cull_clear = np.full(len(sel_a), np.nan)          # clearance of culled pairs (inf: static-static)
    cull_clear[ss] = np.inf
    live = np.nonzero(~ss)[0]
    todo: list[tuple[int, Any, Any]] = []
    # Pairs a stage could not decide within the budget ("uncertain", method "budget"), as a
    # mask over the selected pairs: hundreds of thousands of them cost no Python per pair.
    unfin = np.zeros(len(sel_a), bool)

    def unfinished(items: list) -> None:
        ks = np.searchsorted(sel_a, np.fromiter((it[0] for it in items if it[0] not in results),
                                                np.int64))
        unfin[ks] = True

    try:
        bud.check()
        todo = _broad_phase(scene, plan, margin, tol, t0, t1, sel_a, pid, geom_body, live, cull_clear)
    except BudgetExhausted:
        cull_clear[live] = np.nan
        unfin[live] = True
    n_culled = int(np.count_nonzero(~np.isnan(cull_clear)))
    if n_culled:
        mix["culled"] = n_culled
    tests_total, depth_max, ext_stats = _python_stages(
        scene, plan, margin, epsilon, method, t0, t1, bud, tol, todo, moving, results, mix, unfinished,
        whole_shape=True)
    n_unfin = int(np.count_nonzero(unfin))
    if n_unfin:
        mix["budget"] = n_unfin
    # -- 6. combine -------------------------------------------------------------------------
    names = [g.name for g in scene.geoms]
    bnames = [g.body for g in scene.geoms]
    fin0 = time.perf_counter()
    ordered = _build_ordered(sel_a.tolist(), cull_clear.tolist(), unfin.tolist(), (t0, t1),
                             pid[:, 0].tolist(), pid[:, 1].tolist(),
                             results, names, bnames)
    checked_r = [results[i] for i in sorted(results)]
    verdict = combine_verdicts([r.verdict for r in checked_r] + ([Verdict.UNCERTAIN] if n_unfin else []))
    witnesses = [r.witness for r in checked_r if r.verdict == Verdict.VIOLATION and r.witness is not None]
    witness = min(witnesses, key=lambda w: w.time) if witnesses else None
    earliest = None
    if verdict != Verdict.CERTIFIED:
        starts = _open_starts(checked_r)
        starts += [w.time for w in witnesses] + ([t0] if n_unfin else [])
        earliest = float(min(starts)) if starts else t0
    finite_cull = cull_clear[np.isfinite(cull_clear)]
    clears = [r.clearance for r in checked_r] + ([float(finite_cull.min())] if len(finite_cull) else [])
    if n_unfin:
        clears.append(float("-inf"))
    clearance = float(min(clears)) if clears else float("inf")
    stats = {"pairs": len(ordered), "pairs_culled": n_culled,
             "tests": tests_total, "max_depth": depth_max,
             "wall_seconds": time.perf_counter() - wall0, "checker_mix": mix,
             "budget_exhausted": bool(bud.exhausted), "nothing_checked": False, **ext_stats}
    cert = Certificate(verdict, (t0, t1), margin, epsilon, method, witness, earliest, clearance,
                       ordered, stats, allowed)
    if len(ordered) >= 10_000:  # learn the assembly cost on big scenes (small ones are noise)
        per_pair = (time.perf_counter() - fin0) / len(ordered)
        _FINALISE_SECONDS_PER_PAIR[0] = max(_FINALISE_SECONDS_PER_PAIR[0], min(per_pair, 1e-4))
    return cert


SWEEP_MIN_GEOMS = 400
"""Geoms from which stage 0 of the window kernel sweeps (sort-and-sweep on the swept boxes) instead of
visiting every selected pair: on the scaling scenes the sweep wins from ~60 geoms when sparse, from
~400 on the dense grid (x-slabs); docs/notes/issue-12-sweep-2.md. Tests set it to 0 to force it."""


def _pack_of_pairs(sp: Any, pair_ids: np.ndarray) -> bool:
    """The pack's pair array is ``pair_ids``' own memory (same address, shape, strides, int64; no copy)."""
    a = sp.pair_ids
    return (a.dtype == np.int64 and pair_ids.dtype == np.int64 and a.shape == pair_ids.shape
            and a.strides == pair_ids.strides and a.ctypes.data == pair_ids.ctypes.data)


def _sweep_rows(scene: Any, sp: Any, pid: np.ndarray) -> np.ndarray:
    """(G + 1,) int64 row starts of ``pid`` per first geom for the kernel's sweep, or empty (the pair loop).

    Empty below :data:`SWEEP_MIN_GEOMS` geoms, or when ``pid`` is not strictly increasing in
    (a, b) with a < b per row (the sweep finds a produced pair's row by binary search). The
    check and the starts are cached in ``Scene._hot`` per pair array (the pack's ``pair_ids`` for a full
    selection, whatever view of it ``pid`` is); a subset selection's fresh ``pid`` is checked per call (O(S)).
    """
    G = sp.geoms.kind.shape[0]
    if G < SWEEP_MIN_GEOMS or G < 2 or len(pid) == 0:
        return _NONE
    # a full selection's pid is the pack's array or a read-only view of it (a new view per request)
    key = sp.pair_ids if len(pid) == len(sp.pair_ids) else pid
    hot = _hot(scene)
    hit = None if hot is None else hot.get("sweep_rows")
    if hit is not None and hit[0] is key and hit[1] == G:
        return hit[2]
    if key is sp.pair_ids and getattr(scene, "_sorted_pairs", None) is not None \
            and scene._sorted_pairs is scene.pair_ids and _pack_of_pairs(sp, scene.pair_ids):
        ok = True                # checked by the Scene when it was built (lex_sorted_pairs)
    else:
        ok = lex_sorted_pairs(pid, G)
    rows = np.searchsorted(pid[:, 0], np.arange(G + 1, dtype=np.int64)).astype(np.int64) if ok else _NONE
    if hot is not None:
        hot["sweep_rows"] = (key, G, rows)
    return rows


_FAST_MAX_COORD = 1e9
"""The compiled window path takes trajectories whose rounding scale (m) is below this: the
geometry's coordinate limit (``monitor.geometry.distance._MAX_COORD``; not imported here, the
engine's import stays light; ``tests/test_redteam_10.py`` checks the two agree)."""
_PACK_TOL_SCALE = 3
"""Index of the rounding scale in ``MotionPack.tol`` (``monitor.motion.kernel.TOL_SCALE``): an upper
bound (m) of every body origin and reference point over the window plus the window's motion bound
(from the midpoint poses and the whole-window bounds; ``Plan._scale``), 0 when nothing moves."""
_PACK_TOL_QMAG = 4
"""Index of max |qpos| + max |qpos0| in ``MotionPack.tol`` (``monitor.motion.kernel.TOL_QMAG``): a
slide / free joint (or a BodyMotion body) beyond 1e9 m when nothing moves."""


def _fast_inputs(scene: Any, plan: Any) -> tuple | None:
    """(ScenePack, MotionPack, memo) for the compiled window path, or None (then the Python pipeline runs).

    Both packs are cached (:func:`monitor.certify.kernels.scene_pack` per scene and geoms,
    :func:`~monitor.certify.kernels.trajectory_pack_memo` per trajectory object, checked once
    against the trajectory's own poses); ``memo`` is the dict cached with the motion pack
    (see :func:`_plan_inputs`).
    """
    KS = _kernels()
    mp, memo = KS.trajectory_pack_memo(plan)
    if mp is None:
        return None
    tol = mp.tol
    if not (tol[_PACK_TOL_SCALE] < _FAST_MAX_COORD and tol[_PACK_TOL_QMAG] < _FAST_MAX_COORD):
        # coordinates beyond the geometry's 1e9 m limit: the general path's static tests raise
        # its typed error there, where the kernel's start test (no such guard) certified with a
        # useless clearance (-2e187 m at 1e200 m; red team 7 / 10)
        return None
    hot = _hot(scene)
    hit = None if hot is None else hot.get("scene_pack")
    if hit is not None and hit[0] is scene.geoms and hit[1] is scene.pair_ids and hit[2] is KS.scene_pack:
        sp = hit[3]         # what KS.scene_pack returned for these geoms / pair_ids objects
    else:
        try:
            sp = KS.scene_pack(scene)
        except (MonitorError, TypeError, AttributeError, ValueError):
            return None
        if sp.geoms.body.shape[0] != len(scene.geoms):
            return None
        if hot is not None:
            hot["scene_pack"] = (scene.geoms, scene.pair_ids, KS.scene_pack, sp)
    if int(plan.nbody) != mp.nbody:
        return None
    return sp, mp, memo


def _fast_prep(scene: Any, plan: Any, sel: np.ndarray, fast: tuple, t0: float, t1: float, margin: float,
               epsilon: float, method: str, tol: Tolerances) -> tuple:
    """(pid, moving, fixed, mov, prm, narrow): the inputs :func:`_certify_fast` derives per call.

    ``pid`` (S, 2) int64 read-only geom pairs of the selection, ``moving`` / ``fixed`` / ``mov`` /
    ``prm`` from :func:`_plan_inputs`, ``narrow`` whether the compiled whole-shape stage runs.
    Read-only for the kernel; kept by :func:`_remember_call` for the next identical call.
    """
    KS = _kernels()
    sp, _mp, memo = fast
    pid = sp.pair_ids if len(sel) == len(sp.pair_ids) else np.ascontiguousarray(sp.pair_ids[sel])
    if pid.flags.writeable:
        # always a read-only array (a subset copy, a pack built writable): window_kernel keeps
        # ONE specialisation (numba types the readonly flag: a second ~20 s compile otherwise)
        pid = pid.view()
        pid.flags.writeable = False
    moving, fixed, mov, prm = _plan_inputs(scene, plan, memo, t0, t1, margin, epsilon, tol, KS)
    # the compiled stage can be switched off (tests monkeypatch kernels.whole_shape_stage): then
    # every surviving pair takes the Python route, which calls the replacement
    narrow = bool(getattr(KS.whole_shape_stage, "_compiled_stage", False)) and method != "extrusion"
    return pid, moving, fixed, mov, prm, narrow


def _call_memo(scene: Any, plan: Any, req: CertifyRequest) -> tuple | None:
    """(plan, t0, t1, sel, fast, prep) kept by :func:`_remember_call` for this scene, plan, request; or None.

    Call right after ``scene.sync()``. A hit needs the very plan and request objects of the
    stored call (both immutable: an exact Plan / BodyMotion, a frozen CertifyRequest), the
    scene's snapshot, geoms, pair_ids and body_static objects of that call (``Scene.sync``
    replaces them, and empties ``Scene._hot``, when the model was edited) and the same
    replaceable engine functions (tests monkeypatch them). Everything stored was derived
    from those alone, so a hit holds what the validation and packing would recompute:
    the checks ran on the stored call and their inputs are unchanged.
    """
    hot = getattr(scene, "_hot", None)
    if not hot:
        return None
    m = hot.get("call")
    if m is None or m[0] is not plan or m[1] is not req:
        return None
    KS = _KS[0]
    if (m[2] is not scene._snapshot or m[3] is not scene.geoms or m[4] is not scene.pair_ids
            or m[5] is not scene.body_static or m[6] is not _fast_inputs or m[7] is not KS.scene_pack
            or m[8] is not KS.trajectory_pack_memo or m[9] is not KS.whole_shape_stage):
        return None
    return m[10]


def _remember_call(scene: Any, plan_given: Any, plan: Any, req: CertifyRequest, t0: float, t1: float,
                   sel: np.ndarray, fast: tuple, prep: tuple) -> None:
    """Keep this call's validated inputs in ``Scene._hot["call"]`` for :func:`_call_memo` (one entry).

    Only when they depend on nothing but the objects :func:`_call_memo` compares: a
    :class:`monitor.Scene` (snapshot and cache), an exact Plan / BodyMotion used as given
    (not refreshed) whose model is none or the scene's own (a plan of another, equal-hash
    model is re-hashed on every call: that model may be edited in place). A Plan of the
    scene's model stays current while ``sync`` finds the model unchanged (see
    :func:`_remember_current`).
    """
    hot = getattr(scene, "_hot", None)
    snap = getattr(scene, "_snapshot", None)
    if hot is None or snap is None or plan is not plan_given or type(plan) not in _known_trajectories():
        return
    pm = getattr(plan, "model", None)
    if pm is not None and pm is not scene.model:
        return
    KS = _kernels()
    hot["call"] = (plan, req, snap, scene.geoms, scene.pair_ids, scene.body_static, _fast_inputs,
                   KS.scene_pack, KS.trajectory_pack_memo, KS.whole_shape_stage,
                   (plan, t0, t1, sel, fast, prep))


_new = object.__new__
_NAMES: dict[int, tuple] = {}
_NAMES_MAX = 16


def _geom_names(geoms: tuple) -> tuple[list[str], list[str]]:
    """(geom names, body names) of a scene's geoms tuple, cached per tuple object.

    ``Scene.sync`` replaces the tuple (never edits it) and GeomInfo is frozen, so the
    names of one tuple object never change; the cache holds the tuple itself, so its
    ``id`` is not reused while cached. The lists are shared: callers do not modify them.
    """
    hit = _NAMES.get(id(geoms))
    if hit is not None and hit[0] is geoms:
        return hit[1], hit[2]
    names = [g.name for g in geoms]
    bnames = [g.body for g in geoms]
    if len(_NAMES) >= _NAMES_MAX:
        _NAMES.pop(next(iter(_NAMES)))
    _NAMES[id(geoms)] = (geoms, names, bnames)
    return names, bnames


_M_CULLED, _M_STATIC, _M_TOLERANCED, _M_BUDGET = (np.array(m, dtype=object)
                                                  for m in ("culled", "static", "toleranced", "budget"))


class _WindowPairs:
    """Per-pair results of the compiled window as arrays; :meth:`build_pairs` makes the PairResults.

    Read by :class:`monitor.certify.certificate.Certificate` the first time ``cert.pairs``
    is read (then kept there). Same objects, content and order as the eager assembly
    (:func:`_build_ordered`): culled / static-static / budget pairs, the kernel's
    decisions (start-pose violations and certificates, whole-shape certificates and
    violations with their witnesses), and the Python pipeline's PairResults.
    """

    def __init__(self, sel: np.ndarray, pid: np.ndarray, code: np.ndarray, gap: np.ndarray, surv: np.ndarray,
                 res: np.ndarray, unfin: np.ndarray, results: dict, geoms: tuple,
                 window: tuple[float, float], sc: np.ndarray, sr: np.ndarray, pad: float) -> None:
        self.sel, self.pid, self.code, self.gap, self.surv, self.res = sel, pid, code, gap, surv, res
        self.unfin, self.results = unfin, results
        self.geoms = geoms          # the scene's geoms tuple of this window (sync() replaces, never edits it)
        self.names: list | None = None
        self.bnames: list | None = None
        self.window, self.sc, self.sr, self.pad = window, sc, sr, pad

    def _names(self) -> None:
        if self.names is None:
            self.names, self.bnames = _geom_names(self.geoms)

    def kernel_witness(self, k: int, s: int) -> Witness:
        """The Witness of pair k, a violation decided by the kernel (survivor slot s)."""
        KS = _kernels()
        self._names()
        a, b = self.pid[k].tolist()
        row = self.res[s]
        # = Witness(time, geoms, point, distance): a frozen dataclass without __post_init__,
        # built field for field without its per-field object.__setattr__
        w = _new(Witness)
        w.__dict__.update(time=row.item(KS.R_WTIME), geoms=(self.names[a], self.names[b]),
                          point=row[KS.R_WPOINT:KS.R_WPOINT + 3].copy(), distance=row.item(KS.R_WUPPER))
        return w

    def kernel_result(self, k: int, s: int) -> PairResult:
        """PairResult of pair k decided by the kernel (survivor slot s)."""
        KS = _kernels()
        self._names()
        a, b = int(self.pid[k, 0]), int(self.pid[k, 1])
        geoms, bodies = (self.names[a], self.names[b]), (self.bnames[a], self.bnames[b])
        row = self.res[s]
        c = int(self.code[k])
        if c == KS.WK_STATIC_CERT:
            return PairResult(geoms, bodies, Verdict.CERTIFIED, "static", clearance=float(row[KS.R_CLEAR]))
        if c == KS.WK_CERT:
            return PairResult(geoms, bodies, Verdict.CERTIFIED, "toleranced", int(row[KS.R_TESTS]),
                              int(row[KS.R_DEPTH]), (), float(row[KS.R_CLEAR]))
        w = self.kernel_witness(k, s)
        if c == KS.WK_STATIC_VIOL:
            t0 = float(self.window[0])
            return PairResult(geoms, bodies, Verdict.VIOLATION, "static", intervals=((t0, t0),), witness=w)
        return PairResult(geoms, bodies, Verdict.VIOLATION, "toleranced", int(row[KS.R_TESTS]),
                          int(row[KS.R_DEPTH]), ((float(row[KS.R_FIRST_UNRES]), w.time),), float("-inf"), w)

    def methods(self) -> np.ndarray:
        """(P,) object array: ``str(p.method)`` of each pair :meth:`build_pairs` would make, in order.

        Without building a PairResult: the same precedence as :meth:`build_pairs` /
        :func:`_build_ordered` (budget-unfinished first; then culled / static-static pairs;
        then the kernel's decisions, which win over the Python pipeline's results).
        """
        KS = _kernels()
        code = self.code
        # (the names as 0-d object arrays: numpy stores the one str object, where a str is first
        # made a '<U' array and then a new str per element: ~4x slower; equal values)
        out = np.full(len(self.sel), _M_CULLED, dtype=object)   # WK_CULLED and WK_SS
        if self.results:
            pos = np.searchsorted(self.sel, np.fromiter(self.results, np.int64, len(self.results)))
            for k, r in zip(pos.tolist(), self.results.values()):
                out[k] = str(r.method)
        if self.surv.size:
            c = code[self.surv]
            st = self.surv[(c == KS.WK_STATIC_VIOL) | (c == KS.WK_STATIC_CERT)]
            tl = self.surv[(c == KS.WK_CERT) | (c == KS.WK_VIOL)]
            out[st] = _M_STATIC
            out[tl] = _M_TOLERANCED
        if self.unfin.any():
            out[self.unfin] = _M_BUDGET
        return out

    def start_lower(self) -> dict[int, float]:
        """{k: lower bound (m) of pair k's distance at t0} for every pair the kernel did not cull.

        ``k`` is the pair's position in :meth:`build_pairs`' tuple; the pairs not in the dict
        were culled (``WK_CULLED`` / ``WK_SS``: "certified"). The bound is the window kernel's
        start-pose test (``R_START_LO``: ``posed_distance`` of the motion pack's poses at t0,
        float-verified; the test that certifies static pairs and start poses for the engine),
        NaN where that test did not write the row (``WK_PYTHON``: left to the Python pipeline
        in stage 0; a static pair the test left there is not proven clear anyway).
        """
        KS = _kernels()
        code = self.code
        py = KS.WK_PYTHON
        out: dict[int, float] = {}
        for s, k in enumerate(self.surv.tolist()):
            out[k] = math.nan if int(code[k]) == py else self.res.item(s, KS.R_START_LO)
        return out

    def build_pairs(self) -> tuple:
        KS = _kernels()

        code, gap = self.code, self.gap
        unvisited = code == KS.WK_UNVISITED     # left out by the sweep: culled, gap not computed
        if unvisited.any():
            code = np.where(unvisited, KS.WK_CULLED, code)
            gap = np.where(unvisited, np.nan, gap)
        miss = np.flatnonzero((code == KS.WK_CULLED) & np.isnan(gap))
        if miss.size:
            gap = gap.copy()
        for s in range(0, len(miss), 1 << 15):  # their exact sphere gaps (skipped by the AABB test)
            k = miss[s:s + (1 << 15)]
            ab = self.pid.take(k, axis=0)       # (m, 2) geoms of each pair: one gather per array
            c = self.sc.take(ab, axis=1)        # (T, m, 2, 3) sphere centres
            r = self.sr.take(ab, axis=1)        # (T, m, 2) radii
            dv = c[:, :, 0] - c[:, :, 1]
            # = np.linalg.norm(dv, axis=2) - r_a - r_b (same arithmetic, same order), fewer calls
            d = np.sqrt(np.add.reduce(dv * dv, axis=2)) - r[:, :, 0] - r[:, :, 1]
            g = d.min(axis=0) - self.pad
            fin = np.isfinite(d).all(axis=0)
            if not fin.all():
                g[~fin] = -np.inf
            gap[k] = g
        results = dict(self.results)
        if self.surv.size:
            decided = (KS.WK_STATIC_VIOL, KS.WK_STATIC_CERT, KS.WK_CERT, KS.WK_VIOL)
            slot = {int(k): s for s, k in enumerate(self.surv.tolist())}
            for k, s in slot.items():
                if int(code[k]) in decided:
                    results[int(self.sel[k])] = self.kernel_result(k, s)
        cull = np.where((code == KS.WK_CULLED) | (code == KS.WK_SS), gap, np.nan)
        self._names()
        return _build_ordered(self.sel.tolist(), cull.tolist(), self.unfin.tolist(), self.window,
                              self.pid[:, 0].tolist(), self.pid[:, 1].tolist(), results, self.names,
                              self.bnames)


_WK_DIRECT: list = [None, None]
"""Per ``rows`` kind (slot 0: None, slot 1: an array): (dispatcher, number of its overloads, entry
point, gp, mp, pairs, fixed, moving, type(mp), :func:`_pack_fingerprint` of mp) of the last
:func:`_window_kernel` call of that kind that went through numba's dispatcher (see there)."""

_WK_ROWS = 16
"""Position of ``rows`` among :func:`monitor.certify.kernels.window_kernel`'s arguments."""


def _window_kernel(KS: Any, gp: Any, mp: Any, pairs: np.ndarray, fixed: np.ndarray, moving: np.ndarray,
                   *rest: Any) -> Any:
    """``KS.window_kernel(gp, mp, pairs, fixed, moving, *rest)``, skipping numba's argument typing if known.

    numba's dispatcher types every argument on every call; for the two packs (47 arrays) that
    costs ~9 us per call (issue 12, pair-window floor: a trivial njit function taking them
    costs 12-15 us, its compiled entry point 3-6 us). The caller builds every other argument
    afresh with fixed types (int64 / float64 C-contiguous writable arrays, Python ints), but
    for ``rows``: None (no sweep: a specialisation without the sweep's code) or an int64 array.
    So the argument types are decided by these five objects and by ``rows is None``: when they
    are the very objects of the last call of that kind that went through the dispatcher, and
    that dispatcher still has the overloads it had then -- one, or two that differ in nothing but
    the type of ``rows`` (so the one that ran is the one of this kind) -- the overload's entry
    point is called directly: what the dispatcher itself calls after typing. The motion pack may
    also be another one of the same class whose fields have numba's type fingerprint of that
    call's pack (:func:`_pack_fingerprint`: the key under which the dispatcher itself would find
    its type; the gate's new pack per window). Anything else (another scene pack, pair or flag
    array, a pack of another type, a monkeypatched or non-numba ``window_kernel``, other
    overloads) goes through the dispatcher. The packs and flag arrays are never modified in
    place (the kernels only read them).
    """
    wk = KS.window_kernel
    slot = 0 if rest[-2] is None else 1
    d = _WK_DIRECT[slot]
    if (d is not None and d[0] is wk and d[3] is gp and d[5] is pairs and d[6] is fixed
            and d[7] is moving and len(wk.overloads) == d[1]
            and (d[4] is mp or (type(mp) is d[8] and d[9] is not None and _pack_fingerprint(mp) == d[9]))):
        return d[2](gp, mp, pairs, fixed, moving, *rest)
    out = wk(gp, mp, pairs, fixed, moving, *rest)
    if type(wk).__name__ == "CPUDispatcher":
        ovl = getattr(wk, "overloads", None)
        if ovl is not None and 1 <= len(ovl) <= 2:
            ep = _ENTRY_POINTS.get(id(wk))
            if ep is None or ep[0] is not wk or ep[1] != len(ovl):
                # (reading the overloads costs ~50-100 us: once per dispatcher, overload count and
                # process; a numba without these attributes keeps the dispatcher path)
                ep = _ENTRY_POINTS[id(wk)] = (wk, len(ovl), _entry_points_by_rows(ovl))
            if ep[2][slot] is not None:
                _WK_DIRECT[slot] = (wk, len(ovl), ep[2][slot], gp, mp, pairs, fixed, moving, type(mp),
                                    _pack_fingerprint(mp))
    return out


def _pack_fingerprint(mp: Any) -> bytes | None:
    """Numba's type fingerprint of the motion pack's fields (a plain tuple of its arrays), or None.

    ``numba._dispatcher.compute_fingerprint`` is what numba's dispatcher computes for a tuple
    argument (the motion pack) before it looks its type up: equal fingerprints get the same numba
    type there (the fingerprint is the key of its type cache; for an array it encodes ndim, layout
    C / F / A, writeable and dtype, not alignment, which numba's lookup does not tell apart either;
    a value it cannot encode, e.g. an object array, raises and the dispatcher types it the slow way).
    A named tuple's type is its class and its fields' types, so a pack of the very same class whose
    fields' fingerprint equals that of the pack the dispatcher typed has that pack's type, and
    the overload the dispatcher chose for it is the one it would choose again (issue 12, gate:
    the gate's packs are new per window, of one type per model structure; typing the arguments
    cost ~5 us per window). None (no shortcut) when numba lacks the function or cannot encode a field.

    The fingerprint is not ``numba.typeof``: it encodes neither an array's byte order nor its class
    (an ndarray subclass), so a field in non-native byte order or a masked array fingerprints as the
    native plain array although ``typeof`` refuses it (red team 19; once the native pack's fingerprint
    is in numba's dispatcher cache, which types the pack through it, the dispatcher runs such a pack
    too, on the raw bytes, as the shortcut does). The packer
    (:mod:`monitor.motion.pack`) gives every field as a native-order plain ndarray whatever the
    Plan's / BodyMotion's inputs, so such a pack never reaches the kernels.
    """
    fp = _FINGERPRINT[0]
    if fp is None:
        return None
    try:
        return fp(tuple(mp))
    except Exception:  # noqa: BLE001 - not encodable: the dispatcher types it
        return None


def _fingerprint_function() -> Any:
    """``numba._dispatcher.compute_fingerprint`` when this numba has it (a private API), else None."""
    try:
        from numba import _dispatcher
    except ImportError:
        return None
    fp = getattr(_dispatcher, "compute_fingerprint", None)
    return fp if callable(fp) else None


_FINGERPRINT: list = [None]
"""[``numba._dispatcher.compute_fingerprint`` or None], set when :func:`_kernels` first loads the kernels."""


def _entry_points_by_rows(ovl: Any) -> tuple:
    """(entry point of the overload whose ``rows`` is None, of the one whose ``rows`` is not), or None each.

    Both None unless ``ovl`` (numba's ``overloads``: argument types -> compile result) holds one
    overload, or two whose argument types differ only at ``rows`` (one None, one array).
    """
    from numba.core import types

    sigs = list(ovl)
    if len(sigs) == 2:
        a, b = sigs
        if len(a) != len(b) or len(a) <= _WK_ROWS or any(
                x != y for i, (x, y) in enumerate(zip(a, b)) if i != _WK_ROWS):
            return (None, None)
    out = [None, None]
    for sig, cres in ovl.items():
        if len(sig) <= _WK_ROWS:
            return (None, None)
        slot = 0 if isinstance(sig[_WK_ROWS], types.NoneType) else 1
        if out[slot] is not None:
            return (None, None)
        out[slot] = getattr(cres, "entry_point", None)
    return tuple(out)


_ENTRY_POINTS: dict[int, tuple] = {}
"""id(dispatcher) -> (the dispatcher, its overload count, :func:`_entry_points_by_rows`), read once per
process and overload count."""


def _certify_fast(scene: Any, plan: Any, margin: float, epsilon: float, method: str, t0: float, t1: float,
                  bud: Budget, tol: Tolerances, sel: np.ndarray, wall0: float, allowed: tuple,
                  fast: tuple, prep: tuple) -> Certificate:
    """The pipeline of :func:`certify` with stages 1-4 in :func:`monitor.certify.kernels.window_kernel`.

    One compiled call culls every selected pair (static-static, swept spheres), tests the
    survivors' start poses and runs the whole-shape stage on the pairs of the toleranced
    route (``method="toleranced"``, or ``"auto"`` for pairs that do not both translate);
    further compiled calls follow when one stopped after ``kernels.CALL_TESTS`` whole-shape
    tests (under a test budget: one survivor per call; the budget is checked between calls:
    numba has no clock). Pairs the kernel leaves open (whole-shape
    unresolved, the extrusion route, static pairs not proven clear, unsupported kinds) go
    through the Python stages 3-5 exactly as in :func:`_certify`. Results stay arrays;
    ``cert.pairs`` is built on first read (:class:`_WindowPairs`).
    """
    KS = _kernels()

    sp, mp, memo = fast
    P = len(sel)
    pid, moving, fixed, mov, prm, narrow = prep
    route_all = narrow and method == "toleranced"
    # "auto" when no moving body translates (the Arm's hinges): every survivor takes the
    # whole-shape stage as under "toleranced" (see _no_extrusion_route), so stage 0 runs the
    # first chunk too and no route is computed
    whole = route_all or (narrow and method == "auto" and _no_extrusion_route(mp, mov))
    rows = _sweep_rows(scene, sp, pid)
    # the sweep leaves the pairs it does not produce untouched: zeroed (WK_UNVISITED), which for
    # a large array costs no pass over it (fresh zero pages)
    code = np.zeros(P, np.int64) if rows.size else np.empty(P, np.int64)
    gap = np.empty(P)
    surv = np.empty(P, np.int64)
    res = np.empty((P, KS.R_SIZE))
    G = sp.geoms.kind.shape[0]
    sc = np.empty((_NSUB, G, 3))
    sr = np.empty((_NSUB, G))
    info = np.zeros(KS.WI_SIZE)
    none = _NONE
    # without a test budget, each call stops by itself after kernels.CALL_TESTS whole-shape tests
    # (the budget is polled between calls); with "whole", stage 0 runs stage 1 too
    chunk = 1 if bud.tests is not None else P
    # every survivor on the extrusion route (the tunnel's windows; see _all_translate): stage 0
    # runs stage 1 too, which then only tests the start poses, as the second call below would
    ext_only = (_ONE_CALL and not whole and bud.tests is None
                and (not narrow or _all_translate(plan, mp, memo)))
    first = chunk if (whole or ext_only) else 0
    if not rows.size:
        rows = None  # window_kernel's specialisation without the sweep (see its "rows")
    route0 = np.zeros(P, np.int64) if ext_only else none
    S = int(_window_kernel(KS, sp.geoms, mp, pid, fixed, mov, route0, 0, 0, first, prm, code, gap, surv, res,
                           sc, sr, rows, info))
    done_to = int(info[KS.WI_DONE])
    charged = info.item(KS.WI_TESTS)
    if charged:
        bud.charge(int(charged))
    if S == 0:   # every selected pair culled (the gate's common window): nothing for the stages below
        return _all_culled(sel, pid, code, gap, surv, res, info, scene.geoms, t0, t1, margin, epsilon, method,
                           bud, wall0, allowed, sc, sr, KS)
    route = none if whole else np.zeros(S, np.int64)   # empty: every slot takes the whole-shape stage
    stopped = False
    if ext_only:
        # the budget poll the routing below makes (a clock only: no test budget here); the start
        # tests it would run after it ran in the call above (done_to == S)
        stopped = bud.exhausted
    elif narrow and not whole and S:   # "auto": both bodies translating -> extrusion route
        route = np.ones(S, np.int64)
        trans: dict[int, bool] = {}
        # a budget checkpoint where the plan's waypoint FK (first translation_segments) used to
        # poll it: a budget spent by now stops here, as before (see _translates)
        stopped = bud.exhausted
        try:
            if not stopped:
                # Python ints of the survivors' codes and bodies (one gather each: per-element
                # numpy indexing costs more than the loop on a few survivors)
                sv_all = surv[:S]
                gbody = sp.geoms.body
                ba = gbody.take(pid[sv_all, 0]).tolist()
                bb = gbody.take(pid[sv_all, 1]).tolist()
                wk_open = KS.WK_OPEN
                for s, c in enumerate(code.take(sv_all).tolist()):
                    if c != wk_open:
                        continue
                    for b in (ba[s], bb[s]):
                        if b not in trans:
                            trans[b] = _translates(plan, mp, b)
                    if trans[ba[s]] and trans[bb[s]]:
                        route[s] = 0
        except BudgetExhausted:
            stopped = True
    while done_to < S and not stopped:
        if bud.exhausted:
            stopped = True
            break
        k1 = min(S, done_to + chunk)
        _window_kernel(KS, sp.geoms, mp, pid, fixed, mov, route, 1, done_to, k1, prm, code, gap, surv, res,
                       sc, sr, rows, info)
        bud.charge(int(info[KS.WI_TESTS] - charged))
        charged = info[KS.WI_TESTS]
        done_to = int(info[KS.WI_DONE])
    if done_to < S and stopped:
        # budget spent: the rest get their start-pose test only (the Python pipeline tests every
        # start pose before any checker runs; start tests are not charged), then go on to the
        # checkers, which leave them undecided on the exhausted budget
        _window_kernel(KS, sp.geoms, mp, pid, fixed, mov, np.zeros(S, np.int64), 1, done_to, S, prm, code,
                       gap, surv, res, sc, sr, rows, info)
        done_to = S
    if whole and done_to == S and not stopped:
        # stage 1 ran on every survivor (whole-shape route): when the kernel decided them all,
        # the certificate is the general tail's (see _kernel_decided; no survivor is left
        # WK_OPEN then, so _extrusion_decided below would return None)
        cert = _kernel_decided(sel, pid, code, gap, surv, res, info, S, scene.geoms, t0, t1, margin, epsilon,
                               method, bud, wall0, allowed, sc, sr, KS)
        if cert is not None:
            return cert
    if _EXTRUSION_DIRECT and method != "toleranced" and done_to == S and not stopped:
        # every survivor on the extrusion route (the tunnel's window): its certificate without the
        # general stages and tail (see _extrusion_decided); None leaves it to them
        cert = _extrusion_decided(scene, plan, sel, pid, code, gap, surv, res, info, S, mp=mp,
                                  all_translate=ext_only and narrow, t0=t0, t1=t1,
                                  margin=margin, epsilon=epsilon, method=method, bud=bud, tol=tol,
                                  wall0=wall0, allowed=allowed, sc=sc, sr=sr, KS=KS)
        if cert is not None:
            return cert
    # -- colliding pairs the whole-shape stage left open: its full search for a witness -------
    full_tests = 0
    sv = surv[:done_to]
    svl = sv.tolist()
    codes = code[sv].tolist() if done_to else []
    if narrow and done_to and not stopped and KS.WK_UNRES in codes:
        full_tests = _full_search(KS, sp.geoms, mp, pid, surv, code, res, done_to, t0, t1, margin, epsilon,
                                  tol, bud)
        codes = code[sv].tolist()           # convicted pairs are WK_VIOL now
    rows = res[:done_to].tolist() if done_to else []   # the result rows as Python floats (read below)
    # -- the Python stages on what the kernel left open -------------------------------------
    # (plain Python over the S survivors: a handful of numpy calls cost more than the kernel)
    results: dict[int, PairResult] = {}
    mix: dict[str, int] = {}
    unfin = np.zeros(P, bool)
    geoms = scene.geoms
    if done_to < S:                       # budget: survivors the kernel never reached
        unfin[surv[done_to:S]] = True
    todo = []
    start_known: dict[int, bool] = {}   # i -> start pose NOT proven clear (the kernel's exact test)
    vslots, cslots, wslots = [], [], []
    n_static = 0
    for s, (k, c) in enumerate(zip(svl, codes)):
        if c == KS.WK_PYTHON or c == KS.WK_OPEN or c == KS.WK_UNRES:
            i, ga, gb = int(sel[k]), geoms[int(pid[k, 0])], geoms[int(pid[k, 1])]
            todo.append((i, ga, gb))
            if c != KS.WK_PYTHON:
                lo = rows[s][KS.R_START_LO]
                start_known[i] = not (lo > margin or lo + ga.shape.radius + gb.shape.radius > 0)
            continue
        if c == KS.WK_STATIC_VIOL or c == KS.WK_VIOL:
            vslots.append(s)
        else:
            cslots.append(s)
        if c == KS.WK_STATIC_VIOL or c == KS.WK_STATIC_CERT:
            n_static += 1
        else:
            wslots.append(s)

    def unfinished(items: list) -> None:
        ks = np.searchsorted(sel, np.fromiter((it[0] for it in items if it[0] not in results), np.int64))
        unfin[ks] = True

    n_culled = P - S                      # every pair that did not survive stage 0 was culled
    if n_culled:
        mix["culled"] = n_culled
    if n_static:
        mix["static"] = n_static
    if wslots:
        mix["toleranced/whole-shape"] = len(wslots)
    tests_total, depth_max, ext_stats = full_tests, 0, {}
    if todo:
        tests_py, depth_max, ext_stats = _python_stages(
            scene, plan, margin, epsilon, method, t0, t1, bud, tol, todo, moving, results, mix, unfinished,
            whole_shape=not narrow, start_known=start_known, mp=mp)
        tests_total += tests_py
    n_unfin = int(np.count_nonzero(unfin)) if (todo or done_to < S) else 0
    if n_unfin:
        mix["budget"] = n_unfin
    # -- 6. combine (arrays for the kernel's pairs, PairResults for the Python ones) ------------
    for s in wslots:
        tests_total += int(rows[s][KS.R_TESTS])
        depth_max = max(depth_max, int(rows[s][KS.R_DEPTH]))
    checked_r, has_viol, has_unc, cand = _python_decided(results)
    has_viol = has_viol or bool(vslots)
    has_unc = has_unc or n_unfin > 0
    verdict = Verdict.VIOLATION if has_viol else Verdict.UNCERTAIN if has_unc else Verdict.CERTIFIED
    # views, not copies: code / gap / surv / res are this call's own arrays, not written after here
    lazy = _WindowPairs(sel, pid, code, gap, surv[:done_to], res[:done_to], unfin, results,
                        geoms, (t0, t1), sc, sr, info.item(KS.WI_PAD))
    # earliest witness: ties go to the first pair in selection order (as min() over pairs does)
    for s in vslots:
        k = svl[s]
        cand.append((rows[s][KS.R_WTIME], int(sel[k]), None, k, s))
    witness = None
    if cand:
        best = cand[0] if len(cand) == 1 else min(cand, key=lambda c: (c[0], c[1]))
        witness = best[2] if best[2] is not None else lazy.kernel_witness(best[3], best[4])
    earliest = None
    if verdict != Verdict.CERTIFIED:
        starts = _open_starts(checked_r)
        starts += [c[0] for c in cand] + ([t0] if n_unfin else [])
        for s in vslots:
            starts.append(t0 if codes[s] == KS.WK_STATIC_VIOL else rows[s][KS.R_FIRST_UNRES])
        earliest = float(min(starts)) if starts else t0
    clears = [r.clearance for r in checked_r]
    clears += [rows[s][KS.R_CLEAR] for s in cslots]
    if vslots or n_unfin:
        clears.append(float("-inf"))
    best_cull = info.item(KS.WI_BEST)
    if best_cull < float("inf"):
        clears.append(best_cull)
    clearance = float(min(clears)) if clears else float("inf")
    stats = {"pairs": P, "pairs_culled": n_culled,
             "tests": tests_total, "max_depth": depth_max,
             "wall_seconds": time.perf_counter() - wall0, "checker_mix": mix,
             "budget_exhausted": bool(bud.exhausted), "nothing_checked": False, **ext_stats}
    return Certificate._trusted(_VERDICT_OF[verdict], (t0, t1), margin, epsilon, _METHOD_OF[method], witness,
                                earliest, clearance, lazy, stats, allowed)


_ONE_CALL = True
"""Let :func:`_certify_fast` run stage 0 and the start-pose tests of an all-extrusion-route window in one
``window_kernel`` call (:func:`_all_translate`); tests switch it off to compare with the two calls."""


def _all_translate(plan: Any, mp: Any, memo: dict) -> bool:
    """Whether :func:`_translates` holds for every body of a Plan / BodyMotion (False for other trajectories).

    Then ``"auto"`` routes every survivor of the window kernel that it leaves ``WK_OPEN`` to the
    extrusion route (``route`` 0 per slot), so the route is known before stage 0 and one
    ``window_kernel`` call does stage 0 and the start-pose tests (issue 12, tunnel gate: the
    second call cost ~20 us per window). Kept in ``memo`` (the dict cached with the trajectory's
    motion pack; the trajectory is immutable). The same flags as :func:`_translates`: a body
    translates unless it moves and rotates (the pack's ``body_rotating`` or the trajectory's own
    ``_rotating``).
    """
    hit = memo.get("all_translate")
    if hit is None:
        if type(plan) not in _known_trajectories():
            return False       # translation_segments may be asked (and poll the budget): the routing loop
        bm, br, pr = mp.body_moving, mp.body_rotating, plan._rotating
        if not (type(pr) is np.ndarray and bm.shape == br.shape == pr.shape and bm.ndim == 1):
            hit = False
        elif bm.shape[0] > 64:
            hit = not ((bm != 0) & ((br != 0) | np.asarray(pr, bool))).any()
        else:   # (Python ints of a few bodies: the numpy calls above cost ~5 us)
            hit = not any(m and (r or q) for m, r, q in zip(bm.tolist(), br.tolist(), pr.tolist()))
        memo["all_translate"] = hit
    return hit


def _no_extrusion_route(mp: Any, mov: np.ndarray) -> bool:
    """Whether ``"auto"`` routes every survivor of this motion to the whole-shape stage.

    Args:
        mp: the motion pack (``body_moving`` / ``body_rotating`` (nbody,) flags).
        mov: (nbody,) int64, the window kernel's ``moving`` flags (the plan's ``moving_bodies()``).

    True when the two moving flags agree and every moving body also rotates. Then the route
    :func:`_certify_fast` would compute after stage 0 is 1 (whole-shape) for every survivor the
    kernel routes at all: a survivor slot gets 0 only when both bodies translate
    (:func:`_translates`), and :func:`_translates` is False for a body the pack flags as moving
    and rotating, True only for one it flags as not moving; a survivor whose two bodies do not
    move is decided by its start-pose test before the kernel reads ``route`` (kernels.py,
    stage 1: ``moving[ba] == 0 and moving[bb] == 0``), so its route is never read. Every
    slot thus runs exactly what ``route`` all ones (or empty, as under ``"toleranced"``) runs.
    """
    bm, br = mp.body_moving, mp.body_rotating
    if bm.shape != mov.shape or br.shape != mov.shape:
        return False
    if bm.dtype == br.dtype == mov.dtype:   # the common case: the three flag arrays are equal
        b = bm.tobytes()
        if b == br.tobytes() and b == mov.tobytes():
            return True
    if bm.shape[0] > 64:
        m = bm != 0
        return not ((m != (mov != 0)) | (m & (br == 0))).any()
    # (Python ints of a few bodies: a handful of numpy calls on them cost ~10 us)
    for m, r, k in zip(bm.tolist(), br.tolist(), mov.tolist()):
        if (m != 0) != (k != 0) or (m != 0 and r == 0):
            return False
    return True


def _python_decided(results: dict[int, PairResult]) -> tuple[list[PairResult], bool, bool, list[tuple]]:
    """The pairs of a window decided as :class:`PairResult` objects, in selection order.

    Returns (checked (R,), any violation, any uncertain, witness candidates): a candidate is
    ``(witness time, pair index, Witness)`` per violation with a witness, in pair order (so a
    ``min`` over ``(time, pair)`` gives ties to the first pair, as ``min`` over pairs does).
    """
    if not results:
        return [], False, False, []
    if len(results) == 1:    # (the tunnel's window: one pair, without the list passes below)
        (i, r), = results.items()
        v = r.verdict
        cand1 = [(r.witness.time, i, r.witness)] if v == Verdict.VIOLATION and r.witness is not None else []
        return [r], v == Verdict.VIOLATION, v == Verdict.UNCERTAIN, cand1
    ids = sorted(results)
    checked = [results[i] for i in ids]
    cand = [(r.witness.time, i, r.witness) for i, r in zip(ids, checked)
            if r.verdict == Verdict.VIOLATION and r.witness is not None]
    has_viol = any(r.verdict == Verdict.VIOLATION for r in checked)
    has_unc = any(r.verdict == Verdict.UNCERTAIN for r in checked)
    return checked, has_viol, has_unc, cand


def _open_starts(checked: list[PairResult]) -> list[float]:
    """Start (s) of the first interval left open by each pair of ``checked`` not certified."""
    return [r.intervals[0][0] for r in checked if r.verdict != Verdict.CERTIFIED and r.intervals]


def _all_culled(sel: np.ndarray, pid: np.ndarray, code: np.ndarray, gap: np.ndarray, surv: np.ndarray,
                res: np.ndarray, info: np.ndarray, geoms: tuple, t0: float, t1: float, margin: float,
                epsilon: float, method: str, bud: Budget, wall0: float, allowed: tuple, sc: np.ndarray,
                sr: np.ndarray, KS: Any) -> Certificate:
    """The certificate :func:`_certify_fast` builds when stage 0 culled every selected pair.

    The same values as its general tail with no survivor (no stage runs, no result, nothing
    unfinished): "certified", no witness or earliest time, clearance the best culled gap
    (``info[WI_BEST]``, inf if none is finite), ``checker_mix == {"culled": P}``, 0 tests;
    the pairs stay arrays (:class:`_WindowPairs`).
    """
    P = len(sel)
    lazy = _WindowPairs(sel, pid, code, gap, surv[:0], res[:0], _none_unfinished(P), {}, geoms, (t0, t1),
                        sc, sr, info.item(KS.WI_PAD))
    best_cull = info.item(KS.WI_BEST)
    clearance = float(best_cull) if best_cull < float("inf") else float("inf")
    stats = {"pairs": P, "pairs_culled": P, "tests": 0, "max_depth": 0,
             "wall_seconds": time.perf_counter() - wall0, "checker_mix": {"culled": P} if P else {},
             "budget_exhausted": bool(bud.exhausted), "nothing_checked": False}
    return Certificate._trusted(Verdict.CERTIFIED, (t0, t1), margin, epsilon, _METHOD_OF[method], None, None,
                                clearance, lazy, stats, allowed)


_NONE_UNFINISHED: dict[int, np.ndarray] = {}


def _none_unfinished(P: int) -> np.ndarray:
    """(P,) read-only all-False bool mask: no pair left unfinished (shared per P; bounded cache).

    :class:`_WindowPairs` only reads its ``unfin`` mask; the read-only flag makes a write raise.
    """
    hit = _NONE_UNFINISHED.get(P)
    if hit is None:
        hit = np.zeros(P, bool)
        hit.setflags(write=False)
        if len(_NONE_UNFINISHED) >= 16:
            _NONE_UNFINISHED.clear()
        _NONE_UNFINISHED[P] = hit
    return hit


def _kernel_decided(sel: np.ndarray, pid: np.ndarray, code: np.ndarray, gap: np.ndarray, surv: np.ndarray,
                    res: np.ndarray, info: np.ndarray, S: int, geoms: tuple, t0: float, t1: float,
                    margin: float, epsilon: float, method: str, bud: Budget, wall0: float, allowed: tuple,
                    sc: np.ndarray, sr: np.ndarray, KS: Any) -> Certificate | None:
    """The certificate :func:`_certify_fast` builds when the kernel decided every one of the S survivors.

    None when a survivor is left to the stages after the kernel (``WK_PYTHON``, ``WK_OPEN``,
    ``WK_UNRES``: the general tail runs). Called only when the ``window_kernel`` calls ran stage 1
    on all S survivors, every one on the whole-shape route (``method="toleranced"``, or ``"auto"``
    under :func:`_no_extrusion_route`) and the budget stopped none, so nothing is unfinished, no
    Python stage and no full search runs, and the general tail's values reduce to these (same
    order of survivors, same float values read from ``res``, same dict insertion order):
    violation if any survivor is ``WK_STATIC_VIOL`` / ``WK_VIOL``, else certified; the witness
    of the smallest (time, pair index); the earliest time the smallest of the witness times and
    first unresolved times (t0 for a start-pose violation); the clearance the smallest of the
    certified survivors' clearances, -inf with a violation, and the best culled gap.
    Issue 12 (pair-window floor): the general tail's survivor lists cost ~20 us per call.
    """
    if S == 1:      # the bench's and a lone pair's case, without the lists below
        k = surv.item(0)
        c = code.item(k)
        if c == KS.WK_PYTHON or c == KS.WK_OPEN or c == KS.WK_UNRES:
            return None
        ks, cs = (k,), (c,)
    else:
        ks = surv[:S].tolist()
        cs = code.take(surv[:S]).tolist()
        if KS.WK_PYTHON in cs or KS.WK_OPEN in cs or KS.WK_UNRES in cs:
            return None
    P = len(sel)
    rows = res[:S].tolist()
    mix: dict[str, int] = {}
    if P - S:
        mix["culled"] = P - S
    tests, depth = 0, 0
    n_static = 0
    clears: list[float] = []
    best_v = None                     # (witness time, pair index, k, slot) of the earliest witness
    starts: list[float] = []          # the witness times, then the first unresolved times (the tail's order)
    firsts: list[float] = []
    for s, (k, c) in enumerate(zip(ks, cs)):
        row = rows[s]
        static = c == KS.WK_STATIC_VIOL or c == KS.WK_STATIC_CERT
        if static:
            n_static += 1
        else:
            tests += int(row[KS.R_TESTS])
            if int(row[KS.R_DEPTH]) > depth:
                depth = int(row[KS.R_DEPTH])
        if c == KS.WK_STATIC_VIOL or c == KS.WK_VIOL:
            key = (row[KS.R_WTIME], sel.item(k))
            if best_v is None or key < best_v[:2]:
                best_v = (key[0], key[1], k, s)
            starts.append(row[KS.R_WTIME])
            firsts.append(t0 if static else row[KS.R_FIRST_UNRES])
        else:
            clears.append(row[KS.R_CLEAR])
    if n_static:
        mix["static"] = n_static
    if S - n_static:
        mix["toleranced/whole-shape"] = S - n_static
    lazy = _WindowPairs(sel, pid, code, gap, surv[:S], res[:S], _none_unfinished(P), {}, geoms, (t0, t1),
                        sc, sr, info.item(KS.WI_PAD))
    witness = earliest = None
    if best_v is not None:
        witness = lazy.kernel_witness(best_v[2], best_v[3])
        earliest = float(min(starts + firsts))
        clears.append(float("-inf"))
    verdict = Verdict.VIOLATION if best_v is not None else Verdict.CERTIFIED
    return _window_certificate(verdict, witness, earliest, clears, lazy, info, P, S, tests, depth, mix, {},
                               t0, t1, margin, epsilon, method, bud, wall0, allowed, KS)


def _window_certificate(verdict: Verdict, witness: Witness | None, earliest: float | None,
                        clears: list[float], lazy: _WindowPairs, info: np.ndarray, P: int, S: int, tests: int,
                        depth: int, mix: dict, extra: dict, t0: float, t1: float, margin: float,
                        epsilon: float, method: str, bud: Budget, wall0: float, allowed: tuple,
                        KS: Any) -> Certificate:
    """The certificate of a window whose S survivors were all decided, the general tail's values.

    For :func:`_kernel_decided` and :func:`_extrusion_decided`: clearance the smallest of
    ``clears`` (the pairs') and the best culled gap (``info[WI_BEST]``, when finite), inf if
    none; the general tail's stats (``extra``: the extrusion stats) with ``P - S`` pairs culled.
    """
    best_cull = info.item(KS.WI_BEST)
    if best_cull < float("inf"):
        clears.append(best_cull)
    clearance = float(min(clears)) if clears else float("inf")
    stats = {"pairs": P, "pairs_culled": P - S, "tests": tests, "max_depth": depth,
             "wall_seconds": time.perf_counter() - wall0, "checker_mix": mix,
             "budget_exhausted": bool(bud.exhausted), "nothing_checked": False, **extra}
    return Certificate._trusted(verdict, (t0, t1), margin, epsilon, _METHOD_OF[method], witness, earliest,
                                clearance, lazy, stats, allowed)



_EXTRUSION_DIRECT = True
"""Let :func:`_certify_fast` build the certificate of an all-extrusion-route window itself
(:func:`_extrusion_decided`); tests switch it off to compare with the general stages."""


def _extrusion_decided(scene: Any, plan: Any, sel: np.ndarray, pid: np.ndarray, code: np.ndarray,
                       gap: np.ndarray, surv: np.ndarray, res: np.ndarray, info: np.ndarray, S: int, *,
                       mp: Any, all_translate: bool, t0: float,
                       t1: float, margin: float, epsilon: float, method: str, bud: Budget, tol: Tolerances,
                       wall0: float, allowed: tuple, sc: np.ndarray, sr: np.ndarray,
                       KS: Any) -> Certificate | None:
    """The certificate :func:`_certify_fast` builds when all S survivors take the extrusion route.

    None unless every survivor is ``WK_OPEN`` (start pose tested clear by the window kernel,
    not narrowed) and both of its bodies translate (:func:`_translates`, then
    ``translation_segments``); then the general stages and tail run (a survivor for the
    toleranced checker, ``method="extrusion"`` on a rotating pair: its InvalidInputError, a
    budget spent while posing the waypoints). Otherwise the same calls as the general path
    (:func:`_python_stages`' dispatch, :func:`_run_extrusion`: the compiled swept pass, the
    Python checker for what it leaves; :func:`extrusion_stats`; :func:`_checked_result` with
    its witness confirmation), in the same order with the same budget, and the general
    tail's values with no kernel-decided survivor and nothing unfinished: violation if a
    pair is, else uncertain if one is, else certified; the witness of the smallest
    (time, pair index); the earliest time the smallest interval start / witness time;
    clearance the smallest pair clearance and the best culled gap; ``checker_mix``
    {"culled", "extrusion"}; the extrusion stats. Issue 12 (tunnel gate).

    Args:
        sel, pid, code, gap, surv, res, info, sc, sr: the window kernel's arrays
            (:func:`_certify_fast`); S: survivors, all run by the kernel.
        mp: the motion pack (its body flags route the pairs).
        all_translate: :func:`_all_translate` holds (every body translates: no per-body check).
        others: as in :func:`_certify_fast`.
    """
    sv = surv[:S]
    wk_open = KS.WK_OPEN
    if S == 1:
        if int(code[int(sv[0])]) != wk_open:
            return None
    elif any(c != wk_open for c in code.take(sv).tolist()):
        return None
    geoms = scene.geoms
    items = []
    trans: dict[int, bool] = {}
    try:
        for k, a, b in zip(sv.tolist(), pid[sv, 0].tolist(), pid[sv, 1].tolist()):
            ga, gb = geoms[a], geoms[b]
            if not all_translate:
                for body in (ga.body_id, gb.body_id):
                    if body not in trans:
                        trans[body] = _translates(plan, mp, body)
                    if not trans[body]:
                        return None
            sa, sb = plan.translation_segments(ga.body_id), plan.translation_segments(gb.body_id)
            if sa is None or sb is None:
                return None
            items.append((int(sel[k]), ga, gb, (sa, sb)))
    except BudgetExhausted:
        return None
    ext_stats: dict[str, Any] = {}
    try:
        outs = _run_extrusion(plan, items, margin, tol, bud, t0, t1)
        ext_stats = extrusion_stats(outs)
    except BudgetExhausted:
        outs = [PairOutcome(Outcome.UNRESOLVED, intervals=[(t0, t1)]) for _ in items]
    P = len(sel)
    mix: dict[str, int] = {}
    if P - S:
        mix["culled"] = P - S
    results: dict[int, PairResult] = {}
    tests, depth = 0, 0
    for (i, ga, gb, _), o in zip(items, outs):
        tests += int(o.tests)
        depth = max(depth, int(o.max_depth))
        r = results[i] = _checked_result(plan, "extrusion", o, ga, gb, False, t0, t1, margin, tol, bud)
        mix[r.method] = mix.get(r.method, 0) + 1
    checked_r, has_viol, has_unc, cand = _python_decided(results)
    verdict = Verdict.VIOLATION if has_viol else Verdict.UNCERTAIN if has_unc else Verdict.CERTIFIED
    lazy = _WindowPairs(sel, pid, code, gap, sv, res[:S], _none_unfinished(P), results, geoms, (t0, t1),
                        sc, sr, info.item(KS.WI_PAD))
    witness = None
    if cand:
        witness = (cand[0] if len(cand) == 1 else min(cand, key=lambda c: (c[0], c[1])))[2]
    earliest = None
    if verdict != Verdict.CERTIFIED:
        starts = _open_starts(checked_r) + [c[0] for c in cand]
        earliest = float(min(starts)) if starts else t0
    clears = [r.clearance for r in checked_r]
    return _window_certificate(_VERDICT_OF[verdict], witness, earliest, clears, lazy, info, P, S, tests,
                               depth, mix, ext_stats, t0=t0, t1=t1, margin=margin, epsilon=epsilon,
                               method=method, bud=bud, wall0=wall0, allowed=allowed, KS=KS)

_VERDICT_OF = {v.value: v for v in Verdict}
_METHOD_OF = {m.value: m for m in Method}
"""Verdict / Method member of a validated string (a member is its own key: StrEnum hashes as its value)."""
_NONE = np.zeros(0, np.int64)
"""The empty ``route`` of a window_kernel call (nothing is ever written to it)."""


def _plan_inputs(scene: Any, plan: Any, memo: dict, t0: float, t1: float, margin: float, epsilon: float,
                 tol: Tolerances, KS: Any) -> tuple:
    """(moving (nbody,) bool, fixed, mov, prm): the window kernel's inputs derived from the plan.

    Kept in ``memo``, the dict cached with the plan's motion pack (per trajectory object:
    a Plan / BodyMotion never changes after construction, so ``moving_bodies()`` is
    computed once), the kernel flags held with the ``scene.body_static`` array they were
    made from (``Scene.sync`` replaces it, never edits it; :func:`_body_flags`; only for a
    :class:`monitor.Scene`), and ``prm`` with the exact
    values and the :class:`Tolerances` object it was built from. The kernel only reads
    ``fixed``, ``mov`` and ``prm``; ``moving`` is read-only.
    """
    static = scene.body_static
    hit = memo.get("moving")
    if hit is None:
        # a Plan's flags array is read-only and shared by the plans of one moving pattern (Plan's
        # flag cache): the gate's new Plan per window finds the last one's moving / kernel flags
        # in the scene's cache (the same values: a copy of that very array, _body_flags of it)
        src = plan._moving if type(plan) is _plan_class() else None
        hot = _hot(scene) if src is not None else None
        pm = None if hot is None else hot.get("plan_moving")
        if pm is not None and pm[0] is src and pm[1] is static:
            memo["moving"], memo["flags"] = pm[2], pm[3]
            return pm[2], pm[3][1], pm[3][2], _window_prm(memo, t0, t1, margin, epsilon, tol, KS)
        hit = memo["moving"] = np.asarray(plan.moving_bodies(), bool).copy()
        hit.setflags(write=False)
        if hot is not None and not src.flags.writeable:
            fixed, mov = _body_flags(scene, hit)
            memo["flags"] = fl = (static, fixed, mov)
            hot["plan_moving"] = (src, static, hit, fl)
    moving = hit
    fl = memo.get("flags")
    if fl is None or fl[0] is not static:
        fixed, mov = _body_flags(scene, moving)
        fl = (static, fixed, mov)
        if _hot(scene) is not None:   # a Scene (sync replaces body_static); duck-typed scenes: per call
            memo["flags"] = fl
    return moving, fl[1], fl[2], _window_prm(memo, t0, t1, margin, epsilon, tol, KS)


def _window_prm(memo: dict, t0: float, t1: float, margin: float, epsilon: float, tol: Tolerances,
                KS: Any) -> np.ndarray:
    """(WP_SIZE,) the window kernel's ``prm`` for these values, kept in ``memo`` (:func:`_plan_inputs`)."""
    pr = memo.get("prm")
    if (pr is None or pr[0] != t0 or pr[1] != t1 or pr[2] != margin or pr[3] != epsilon or pr[4] is not tol
            or (t0 == 0.0 and math.copysign(1.0, t0) != math.copysign(1.0, pr[0]))    # -0.0 == 0.0
            or (margin == 0.0 and math.copysign(1.0, margin) != math.copysign(1.0, pr[2]))):
        prm = np.array([t0, t1, margin, epsilon, tol.rel_pad, tol.abs_pad, tol.scale_pad,
                        float(tol.max_depth), float(KS.WHOLE_SHAPE_MAX_TESTS)])
        memo["prm"] = pr = (t0, t1, margin, epsilon, tol, prm)
    return pr[5]


def _body_flags(scene: Any, moving: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(fixed, mov): (nbody,) int64 ``body_static & ~moving`` and ``moving``, the window kernel's flags.

    Cached per scene (``Scene._hot``) for each moving mask, keyed on the mask's bytes and held
    with the ``body_static`` array they were made from (``Scene.sync`` replaces it); the kernel
    only reads them. Duck-typed scenes without the cache compute them per call.
    """
    static = scene.body_static
    hot = _hot(scene)
    if hot is not None:
        memo = hot.get("body_flags")
        if memo is None or memo[0] is not static:
            memo = hot["body_flags"] = (static, {})
        key = moving.tobytes()
        hit = memo[1].get(key)
        if hit is not None:
            return hit
    fixed = (np.asarray(static, bool) & ~moving).astype(np.int64)
    mov = moving.astype(np.int64)
    if hot is not None:
        if len(memo[1]) >= 64:
            memo[1].clear()
        memo[1][key] = (fixed, mov)
    return fixed, mov


def _translates(plan: Any, mp: Any, b: int) -> bool:
    """``plan.translation_segments(b) is not None``, from the motion pack's flags where they settle it.

    ``translation_segments`` of a Plan / BodyMotion returns segments for a body that does not
    move and None for one that moves and rotates; a Plan's first answer needs the FK of every
    waypoint (~1 ms per window on the Arm). The pack's ``body_moving`` / ``body_rotating`` are
    the plan's own flags (``pack.plan_data_agrees`` compares them on every Plan). Only a body
    that moves without rotating asks the trajectory. (Either answer only picks the checker, the
    extrusion or the toleranced one; both are sound.)
    """
    if mp.body_moving[b] == 0:
        return True
    if mp.body_rotating[b] != 0:
        return False
    if type(plan) in _known_trajectories():
        # Plan and BodyMotion: translation_segments(b) is None exactly when the body moves and
        # its own _rotating flag is set (a Plan's equals the pack's, checked above)
        return not plan._rotating[b]
    return plan.translation_segments(b) is not None


def _known_trajectories() -> tuple:
    """Loaded trajectory classes whose ``translation_segments`` is None iff moving and ``_rotating``."""
    hit = _KNOWN[0]
    if hit is not None:
        return hit
    out = []
    for mod, name in (("monitor.motion.plan", "Plan"), ("monitor.motion.bodymotion", "BodyMotion")):
        m = sys.modules.get(mod)
        c = None if m is None else getattr(m, name, None)
        if c is not None:
            out.append(c)
    if len(out) == 2:   # both loaded: the answer is final (a module is not unloaded)
        _KNOWN[0] = tuple(out)
    return tuple(out)


_KNOWN: list = [None]
"""(Plan, BodyMotion) once both are loaded (:func:`_known_trajectories`)."""


_FULL_SEARCH_TESTS = 1024
"""Distance tests the full whole-shape search may spend on one pair the first search left open."""


def _full_search(KS: Any, gp: Any, mp: Any, pid: np.ndarray, surv: np.ndarray, code: np.ndarray,
                 res: np.ndarray, n: int, t0: float, t1: float, margin: float, epsilon: float,
                 tol: Tolerances, bud: Budget) -> int:
    """Look for a witness on the pairs the window kernel's whole-shape stage left open (issue 12).

    The window kernel runs :func:`~monitor.certify.kernels.pair_window` in
    ``MODE_CERTIFY_ONLY``: it stops at the first sub-interval it can neither exclude nor
    convict, which for a colliding pair is usually the one where contact begins, just before
    the first midpoint that would have given a witness. Those pairs used to fall through to
    the Python fat-feature checker, which subdivides the whole window to epsilon before any
    witness is tried (~100 ms on the Arm). Here the same depth-first, earliest-first search
    runs again in ``MODE_FULL`` (at most ``_FULL_SEARCH_TESTS`` tests, charged to ``bud``):
    it goes on past the open sub-intervals and, at the first midpoint where the exact static
    test confirms a violation (``upper + approx < margin``, the kernel's own witness rule),
    refines only the part before it.

    Only a confirmed violation is taken (the pair becomes ``WK_VIOL``, exactly as when the
    first search finds the witness itself; ``R_FIRST_UNRES``, the first sub-interval not
    excluded, bounds the first contact from below). Anything else (no witness, test cap,
    budget) leaves the pair ``WK_UNRES`` for the Python stages, as before: no verdict is
    certified here, and a pair that would have ended "violation" still does.

    Args:
        KS: the kernels module.
        gp, mp: scene and motion packs.
        pid: (P, 2) geom pairs; surv: (S,) survivor pair rows; code: (P,) kernel codes
            (updated); res: (S, R_SIZE) result rows per survivor slot (updated).
        n: slots [0, n) were run by the kernel.
        t0, t1, margin, epsilon, tol: as in :func:`certify`.
        bud: the stage budget (tests charged; checked before every pair).

    Returns:
        The tests spent on pairs left open (a convicted pair's are in its result row).
    """
    slots = [s for s, k in enumerate(surv[:n].tolist()) if code[k] == KS.WK_UNRES]
    if not slots:
        return 0
    spent = 0
    stack = np.empty((int(tol.max_depth) + 2, 3))
    for s in slots:
        if bud.exhausted:
            break
        cap = _FULL_SEARCH_TESTS
        if bud.tests is not None:
            cap = min(cap, max(1, bud.tests - bud._used_tests))
        k = int(surv[s])
        row = KS.new_result()
        row[KS.R_STARTED] = 2.0        # start pose tested by the window kernel (clear: not a start violation)
        v = KS.pair_window(gp, mp, int(pid[k, 0]), int(pid[k, 1]), float(t0), float(t1), float(margin),
                           float(epsilon), int(tol.max_depth), int(cap), KS.MODE_FULL, float(tol.rel_pad),
                           float(tol.abs_pad), stack, row)
        used = int(row[KS.R_TESTS])
        bud.charge(used)
        if v != KS.VIOLATION:
            spent += used
            continue
        wt, fu = row[KS.R_WTIME], row[KS.R_FIRST_UNRES]
        if not (fu <= wt):
            row[KS.R_FIRST_UNRES] = wt
        row[KS.R_START_LO] = res[s, KS.R_START_LO]
        row[KS.R_TESTS] += res[s, KS.R_TESTS]     # the first search's tests (incl. the start test)
        row[KS.R_DEPTH] = max(row[KS.R_DEPTH], res[s, KS.R_DEPTH])
        res[s] = row
        code[k] = KS.WK_VIOL
    return spent


def _python_stages(scene: Any, plan: Any, margin: float, epsilon: float, method: str, t0: float, t1: float,
                   bud: Budget, tol: Tolerances, todo: list, moving: np.ndarray, results: dict, mix: dict,
                   unfinished: Any, whole_shape: bool,
                   start_known: dict[int, bool] | None = None,
                   mp: Any = None) -> tuple[int, int, dict[str, Any]]:
    """Stages 3-5 (start pose, dispatch, checkers, witnesses) on ``todo`` [(i, GeomInfo a, GeomInfo b)].

    Fills ``results`` {i: PairResult} and ``mix``; calls ``unfinished(items)`` for pairs the
    budget left undecided. ``whole_shape``: run the compiled whole-shape stage
    (:func:`monitor.certify.kernels.whole_shape_stage`) before the fat-feature checker
    (False when :func:`window_kernel` already ran it on these pairs). ``start_known``:
    pairs of moving bodies whose start pose the window kernel has tested exactly
    (``posed_distance``, rigorous bounds; no violation at t0), mapped to "start pose not
    proven clear"; they skip the start-pose stage here. ``mp``: the trajectory's motion pack
    on the compiled path: a pair with a rotating moving body is routed without asking the
    trajectory (:func:`_translates`; same answer, no waypoint FK).
    Returns (tests, deepest level, extrusion stats for ``cert.stats``: :func:`extrusion_stats`).
    """
    tests_total, depth_max = 0, 0

    def done(i: int, r: PairResult) -> None:
        results[i] = r
        mix[r.method] = mix.get(r.method, 0) + 1

    # -- 3. start pose -----------------------------------------------------------------
    from monitor.geometry.distance import shape_distance

    start_unproven: set[int] = set()
    checked = []
    try:
        if any(start_known is None or it[0] not in start_known for it in todo):
            bud.check()
            pos0, rot0 = plan.body_poses(np.array([t0]))
        for i, ga, gb in todo:
            if start_known is not None and i in start_known:
                if start_known[i]:
                    start_unproven.add(i)
                checked.append((i, ga, gb))
                continue
            bud.check()
            d = shape_distance(ga.shape, (rot0[0, ga.body_id], pos0[0, ga.body_id]),
                               gb.shape, (rot0[0, gb.body_id], pos0[0, gb.body_id]), tolerances=tol)
            if d.upper + _approx(ga, gb) < margin:
                w = Witness(t0, (ga.name, gb.name), 0.5 * (d.p_a + d.p_b),
                            float(d.upper + _approx(ga, gb)))
                done(i, PairResult((ga.name, gb.name), (ga.body, gb.body), Verdict.VIOLATION, "static",
                                   intervals=((t0, t0),), witness=w))
                continue
            cores_apart = d.lower + ga.shape.radius + gb.shape.radius > 0
            if not (d.lower > margin or cores_apart):
                start_unproven.add(i)
            if not moving[ga.body_id] and not moving[gb.body_id]:
                if d.lower > margin:
                    done(i, PairResult((ga.name, gb.name), (ga.body, gb.body), Verdict.CERTIFIED, "static",
                                       clearance=float(d.lower)))
                else:
                    done(i, PairResult((ga.name, gb.name), (ga.body, gb.body), Verdict.UNCERTAIN, "static",
                                       intervals=((t0, t1),)))
                continue
            checked.append((i, ga, gb))
    except BudgetExhausted:
        unfinished(todo)
        checked = []
    # -- 4. dispatch ---------------------------------------------------------------------
    ext_items, tol_items = [], []
    try:
        for i, ga, gb in checked:
            trans = None
            if method in ("auto", "extrusion"):
                if mp is not None and not (_translates(plan, mp, ga.body_id)
                                           and _translates(plan, mp, gb.body_id)):
                    sa = sb = None
                else:
                    sa, sb = plan.translation_segments(ga.body_id), plan.translation_segments(gb.body_id)
                if sa is not None and sb is not None:
                    trans = (sa, sb)
                elif method == "extrusion":
                    raise InvalidInputError(f"method='extrusion' but pair ({ga.name!r}, {gb.name!r}) "
                                            "does not translate with piecewise-constant velocity")
            if trans is not None:
                ext_items.append((i, ga, gb, trans))
            else:
                tol_items.append((i, ga, gb))
    except BudgetExhausted:
        unfinished(checked)
        checked, ext_items, tol_items = [], [], []
    outcomes: dict[int, tuple[str, PairOutcome]] = {}
    ext_stats: dict[str, Any] = {}
    if ext_items:
        try:
            outs = _run_extrusion(plan, ext_items, margin, tol, bud, t0, t1)
            ext_stats = extrusion_stats(outs)
        except BudgetExhausted:
            outs = [PairOutcome(Outcome.UNRESOLVED, intervals=[(t0, t1)]) for _ in ext_items]
        for (i, _ga, _gb, _), o in zip(ext_items, outs):
            outcomes[i] = ("extrusion", o)
    if tol_items and whole_shape:  # issue 12: the compiled whole-shape stage first; what it certifies is done
        from monitor.certify.kernels import whole_shape_stage
        try:
            pre = whole_shape_stage(scene, plan, [(ga, gb) for _i, ga, gb in tol_items], (t0, t1), margin,
                                    epsilon, tol, bud)
        except BudgetExhausted:  # nothing decided here: the pairs go on (and end "uncertain" below)
            pre = [None] * len(tol_items)
        for k, ((i, ga, gb), r) in enumerate(zip(tol_items, pre)):
            w = None
            if r is not None and r["verdict"] == Verdict.VIOLATION:  # re-confirmed by the engine's own rule
                try:
                    w = _find_witness(plan, ga, gb, np.array([r["witness_time"]]), margin, tol)
                except BudgetExhausted:
                    w = None
                if w is None:
                    pre[k] = r = None
            if r is not None:
                tests_total += r["tests"]
                depth_max = max(depth_max, r["max_depth"])
                iv = () if w is None else ((r["first_unresolved"], w.time),)
                results[i] = PairResult((ga.name, gb.name), (ga.body, gb.body), r["verdict"], "toleranced",
                                        r["tests"], r["max_depth"], iv, float(r["clearance"]), w)
                mix["toleranced/whole-shape"] = mix.get("toleranced/whole-shape", 0) + 1
        tol_items = [x for x, r in zip(tol_items, pre) if r is None]
    if tol_items:
        from monitor.certify import toleranced
        items = [(ga.shape, ga.body_id, gb.shape, gb.body_id) for _i, ga, gb in tol_items]
        try:
            outs = toleranced.check_pairs(plan, items, (t0, t1), margin, epsilon, tol, bud,
                                          static=~moving, check_start=False)
        except BudgetExhausted:
            outs = [PairOutcome(Outcome.UNRESOLVED, intervals=[(t0, t1)]) for _ in tol_items]
        for (i, _ga, _gb), o in zip(tol_items, outs):
            outcomes[i] = ("toleranced", o)
    # -- 5. witnesses ---------------------------------------------------------------------
    by_i = {i: (ga, gb) for i, ga, gb in checked}
    refine: list[int] = []
    for i, (meth, o) in outcomes.items():
        ga, gb = by_i[i]
        tests_total += int(o.tests)
        depth_max = max(depth_max, int(o.max_depth))
        r = _checked_result(plan, meth, o, ga, gb, i in start_unproven, t0, t1, margin, tol, bud)
        if r.verdict == Verdict.CERTIFIED and meth == "toleranced":
            refine.append(i)
        done(i, r)
    cl = []
    if refine and not bud.exhausted:  # better clearance bounds for toleranced-certified pairs
        try:
            cl = _sampled_clearances(plan, [by_i[i] for i in refine], t0, t1, tol)
        except BudgetExhausted:  # optional refinement: the checker's bound (margin) stands
            cl = []
    if cl:
        for i, c in zip(refine, cl):
            r = results[i]
            if c > r.clearance:
                results[i] = PairResult(r.geoms, r.bodies, r.verdict, r.method, r.tests, r.max_depth,
                                        r.intervals, float(c), r.witness)
    return tests_total, depth_max, ext_stats


def _checked_result(plan: Any, meth: str, o: PairOutcome, ga: Any, gb: Any, unproven: bool, t0: float,
                    t1: float, margin: float, tol: Tolerances, bud: Budget) -> PairResult:
    """Stage 5 for one checked pair: the PairResult of checker ``meth``'s outcome ``o``.

    ``unproven``: the pair's start pose is not proven clear (the toleranced argument needs
    disjoint cores at t0; the extrusion checker decides t0 itself, exactly). A certified
    outcome keeps its clearance (the margin when not finite; at least the margin for the
    toleranced checker). Anything else gets a witness confirmed by the engine's own rule
    (:func:`_find_witness`: the plan's poses, exact static distance) at the checker's
    witness time and ``tol.witness_candidates`` times per open interval: "violation" with it,
    else "uncertain" (also when the budget runs out here).
    """
    names, bodies = (ga.name, gb.name), (ga.body, gb.body)
    if o.verdict == Outcome.CERTIFIED and (meth == "extrusion" or not unproven):
        clear = o.clearance if np.isfinite(o.clearance) else margin
        if meth == "toleranced":
            clear = max(clear, margin)
        return _pair_result(names, bodies, Verdict.CERTIFIED, meth, o.tests, o.max_depth, (), float(clear),
                            None)
    intervals = list(o.intervals)
    if o.verdict == Outcome.CERTIFIED:  # start pose not proven clear
        intervals = [(t0, t0)]
    cands: list[float] = []
    if o.verdict == Outcome.VIOLATION and o.witness_time is not None:
        cands.append(float(o.witness_time))
        if not intervals:
            intervals = [(float(o.witness_time), float(o.witness_time))]
    spans = intervals[:_MAX_WITNESS_INTERVALS]
    w = None
    if cands or spans:
        try:  # a budget that runs out here leaves the pair "uncertain" (no witness)
            w = _find_witness_of(plan, ga, gb, cands, spans, margin, tol, bud)
        except BudgetExhausted:
            w = None
    if w is not None:
        return _pair_result(names, bodies, Verdict.VIOLATION, meth, o.tests, o.max_depth, tuple(intervals),
                            float("-inf"), w)
    return _pair_result(names, bodies, Verdict.UNCERTAIN, meth, o.tests, o.max_depth,
                        tuple(intervals) if intervals else ((t0, t1),), float("-inf"), None)


def _pair_result(geoms: tuple[str, str], bodies: tuple[str, str], verdict: Verdict, method: str, tests: int,
                 max_depth: int, intervals: tuple, clearance: float, witness: Witness | None) -> PairResult:
    """``PairResult(geoms, bodies, verdict, method, tests, max_depth, intervals, clearance, witness)``.

    For a ``verdict`` that is already a :class:`Verdict` (what ``__post_init__`` would make of
    it): the frozen dataclass built field for field, without its per-field
    ``object.__setattr__`` (as :meth:`_WindowPairs.kernel_witness` builds a Witness).
    """
    r = _new(PairResult)
    r.__dict__.update(geoms=geoms, bodies=bodies, verdict=verdict, method=method, tests=tests,
                      max_depth=max_depth, intervals=intervals, clearance=clearance, witness=witness, note="")
    return r


def _broad_phase(scene: Any, plan: Any, margin: float, tol: Tolerances, t0: float, t1: float,
                 sel_a: np.ndarray, pid: np.ndarray, geom_body: np.ndarray, live: np.ndarray,
                 cull_clear: np.ndarray) -> list[tuple[int, Any, Any]]:
    """Swept-sphere cull of the ``live`` pairs; fills ``cull_clear`` and returns the pairs left.

    May raise :class:`BudgetExhausted` (from the motion); ``cull_clear`` is then partial.
    """
    if not len(live):
        return []
    used = np.unique(pid[live].ravel())
    local = np.full(len(scene.geoms), -1, np.int64)
    local[used] = np.arange(len(used))
    shapes = [scene.geoms[int(g)].shape for g in used]
    sph = swept_geom_spheres(plan, shapes, geom_body[used], (t0, t1), _NSUB, tol)
    ia, ib = local[pid[live, 0]], local[pid[live, 1]]
    gaps = sphere_pair_gaps(sph, ia, ib)
    half_a = np.array([s.kind == "halfspace" for s in shapes])
    ha, hb = half_a[ia], half_a[ib]
    one = np.nonzero(ha ^ hb)[0]
    if len(one):
        pl = np.where(ha, ia, ib)[one]
        gaps[one] = halfspace_gaps(plan, sph, [shapes[j] for j in pl], geom_body[used][pl],
                                   np.where(ha, ib, ia)[one], (t0, t1), _NSUB)
    culled = gaps > margin
    cull_clear[live[culled]] = gaps[culled]
    return [(int(sel_a[k]), scene.geoms[int(pid[k, 0])], scene.geoms[int(pid[k, 1])])
            for k in live[~culled]]


def _run_extrusion(plan: Any, ext_items: list, margin: float, tol: Tolerances, bud: Budget,
                   t0: float, t1: float) -> list[PairOutcome]:
    """Extrusion checker on the translating pairs: a compiled first pass, then one n-ary search (Cameron §6).

    First pass (issue 12; ``_SWEPT_FIRST``): :func:`monitor.certify.extrusion_swept.decide_pair`,
    the checker's exact swept test per span in one compiled call per pair (certified at the
    stronger margin below, violation at the true margin with the exact first contact);
    ``info["test"] == "swept_kernel"``, stage ``"exact_swept"`` (``"null_set"`` for the
    half-space closed form). The pairs it leaves (the exactness band, two half-spaces,
    penetrations of sharp polytopes at margin 0, bad input) go to the Python checker exactly
    as before:

    Per pair the checker runs S-bounds (§4.3, App. B; shared per body, §6.3), divide
    and conquer (§4.1) and the null-set LP on the half-spaces offset by the pair's
    radii + margin + pad (§4.2); only what that leaves open goes to the exact swept
    test. ``PairOutcome.info["stage"]`` names the deciding stage;
    :func:`extrusion_stats` summarises a list of outcomes for ``cert.stats``.
    """
    extrusion = _module("monitor.certify.extrusion")
    ext_margin = margin + tol.extrusion_slack + tol.pad(margin)
    rot = _rotations(plan, t0)
    outs: list[PairOutcome | None] = [None] * len(ext_items)
    if _SWEPT_FIRST and not bud.exhausted:
        # issue 12: the compiled exact swept test first, one call per pair
        # (monitor.certify.extrusion_swept); what it cannot settle goes to the Python checker
        decide_pair = _module("monitor.certify.extrusion_swept").decide_pair
        n_fast = 0
        for k, (_i, ga, gb, ((ta, oa), (tb, ob))) in enumerate(ext_items):
            Ra, Rb = rot(ga.body_id, True), rot(gb.body_id, True)
            outs[k] = o = decide_pair(ga.shape, Ra, ta, oa, gb.shape, Rb, tb, ob, (t0, t1), margin,
                                      ext_margin, tol, (ga.name, gb.name))
            if o is not None:
                n_fast += o.tests
        if n_fast:
            bud.charge(n_fast)
    rest = [k for k, o in enumerate(outs) if o is None]
    if rest:
        eps_pairs = []
        for k in rest:
            _i, ga, gb, ((ta, oa), (tb, ob)) = ext_items[k]
            eps_pairs.append(extrusion.TranslatingPair(
                ga.shape, rot(ga.body_id), np.asarray(ta, float), np.asarray(oa, float),
                gb.shape, rot(gb.body_id), np.asarray(tb, float), np.asarray(ob, float),
                name=(ga.name, gb.name), bodies=(ga.body, gb.body)))
        for k, o in zip(rest, _run_extrusion_python(eps_pairs, margin, ext_margin, tol, bud, t0, t1)):
            outs[k] = o
    return outs  # type: ignore[return-value]


def _rotations(plan: Any, t0: float) -> Any:
    """``rot(body, fast=False) -> R_WB`` (3, 3) at ``t0`` for the bodies of translating pairs.

    The rotation of such a body is constant over the window. A
    :class:`~monitor.motion.plan.Plan` has it already: its waypoint FK rotations
    (``_wp0``, row 0 of ``_wp_mat``; the same at every waypoint). A
    :class:`~monitor.motion.bodymotion.BodyMotion`: its first waypoint quaternion
    (``quat[0]``, normalised; a translating body's quaternions are equal bit for bit), by
    ``quat_to_mat`` (one vectorised call) or, with ``fast=True`` (the compiled first pass,
    whose pads cover a few ulp in R), the same formula on Python floats without the
    re-normalisation. Other trajectories: one ``body_poses`` call at ``t0``, made on first use.
    """
    cls = _plan_class()
    if cls is not None and type(plan) is cls:
        wm = plan._wp0[1]    # FK at the first waypoint only (row 0 of _wp_mat: the same numbers)
        return lambda b, fast=False: wm[b]
    bm = sys.modules.get("monitor.motion.bodymotion")
    if bm is not None and type(plan) is getattr(bm, "BodyMotion", None):
        mats: list = []

        def rot_bm(b: int, fast: bool = False) -> np.ndarray:
            if fast:
                w, x, y, z = plan.quat[0, b].tolist()
                return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                                 [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                                 [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
            if not mats:   # one vectorised conversion per call (the same arithmetic per body)
                mats.append(bm.K.quat_to_mat(plan.quat[0]))
            return mats[0][b]
        return rot_bm
    memo: list = []

    def rot(b: int, fast: bool = False) -> np.ndarray:
        if not memo:
            memo.append(plan.body_poses(np.array([t0]))[1])
        return memo[0][0, b]
    return rot


_SWEPT_FIRST = True
"""Run :func:`monitor.certify.extrusion_swept.decide_pair` before the Python extrusion checker
(tests switch it off to compare with the Python checker alone)."""


def _run_extrusion_python(eps_pairs: list, margin: float, ext_margin: float, tol: Tolerances, bud: Budget,
                          t0: float, t1: float) -> list[PairOutcome]:
    """The Python extrusion checker (one n-ary search, Cameron §6) on ``eps_pairs``, re-run for witnesses."""
    from monitor.certify import extrusion
    # The extrusion checker is exact up to Tolerances.extrusion_slack with Cameron's
    # regularised semantics (touching is not a collision). The engine's contract is
    # stricter (certified => clearance > margin, rounding included), so it asks the
    # checker the stronger question: a certificate at margin + slack + pad implies
    # clearance > margin. Exact touching (or a sub-slack shortfall) then ends as
    # "uncertain" (never "certified", and "violation" only if a witness confirms it).
    # Pairs that fail the stronger question (only those) are re-run at the true margin
    # for a witness deep enough to confirm (with margin > 0 the checker caps its depth
    # at the margin it is given); "certified" there means the sub-slack band: unresolved.
    outs = extrusion.check_pairs(eps_pairs, (t0, t1), ext_margin, tol, bud, nary=True)
    redo = [k for k, o in enumerate(outs) if o.verdict != Outcome.CERTIFIED]
    if redo and not bud.exhausted:
        again = extrusion.check_pairs([eps_pairs[k] for k in redo], (t0, t1), margin, tol, bud, nary=True)
        for k, o2 in zip(redo, again):
            if o2.verdict == Outcome.VIOLATION:
                o2.tests += outs[k].tests
                o2.info["first_pass_stats"] = outs[k].info.get("stats")
                outs[k] = o2
            elif outs[k].verdict == Outcome.VIOLATION:  # band case: never a confirmed witness time
                o1 = outs[k]
                o1.verdict, o1.witness_time = Outcome.UNRESOLVED, None
    else:
        for k in redo:
            if outs[k].verdict == Outcome.VIOLATION:  # not re-run: never a confirmed witness time
                outs[k].verdict, outs[k].witness_time = Outcome.UNRESOLVED, None
    return outs


def extrusion_stats(outs: list[PairOutcome]) -> dict[str, Any]:
    """``cert.stats`` entries for extrusion outcomes (empty without outcomes).

    ``extrusion_stages``: {deciding stage: pairs}; ``extrusion``: LP / offset / exact-swept
    counts and S-bound survivors per span and body pair
    (:func:`monitor.certify.extrusion.search_summary`).
    """
    if not outs:
        return {}
    summ = _module("monitor.certify.extrusion").search_summary(outs)
    # bounded size (certificates are logged): at most 64 span/body-pair entries, 32 names each
    sb = summ["sbounds"]
    if len(sb) > 64:
        summ["sbounds_left_off"] = len(sb) - 64
        summ["sbounds"] = sb = sb[:64]
    for e in sb:
        if len(e.get("survivors", ())) > 32:
            e["survivors"] = e["survivors"][:32] + ["..."]
    return {"extrusion_stages": summ.pop("stages"), "extrusion": summ}


def _build_ordered(sel: list[int], cull_clear: list[float], unfin: list[bool], window: tuple[float, float],
                   ga: list[int], gb: list[int], results: dict[int, PairResult], names: list[str],
                   bnames: list[str]) -> tuple:
    """One PairResult per selected pair, in order; culled and budget-unfinished ones are built here.

    ``pairs="all"`` makes hundreds of thousands of culled results; the cyclic garbage
    collector would re-scan the growing tuple at every generation-0 threshold (about half
    of the build time), so it is paused while building (the objects hold no cycles) and
    restored to its previous state afterwards. ``unfin[k]``: the budget ran out before any
    stage decided pair k ("uncertain", method ``"budget"``, the whole window).
    """
    was = gc.isenabled()
    gc.disable()
    inf = float("-inf")
    budget_iv = (tuple(window),)
    new = object.__new__

    def quick(a: int, b: int, verdict: str, method: str, intervals: tuple, clearance: float) -> PairResult:
        # Field-for-field the same PairResult as the constructor makes (frozen dataclass; its
        # __post_init__ only makes verdict a Verdict, so pass a member), at a third of the cost.
        r = new(PairResult)
        r.__dict__.update(geoms=(names[a], names[b]), bodies=(bnames[a], bnames[b]), verdict=verdict,
                          method=method, tests=0, max_depth=0, intervals=intervals, clearance=clearance,
                          witness=None)
        return r

    try:
        return tuple(quick(a, b, Verdict.UNCERTAIN, "budget", budget_iv, inf) if u else
                     results[i] if cc != cc else  # NaN: not culled
                     quick(a, b, Verdict.CERTIFIED, "culled", (), cc)
                     for i, cc, u, a, b in zip(sel, cull_clear, unfin, ga, gb))
    finally:
        if was:
            gc.enable()


def _sampled_clearances(plan: Any, geoms: list[tuple[Any, Any]], t0: float, t1: float, tol: Tolerances,
                        n: int = 8) -> list[float]:
    """Certified clearance lower bounds from n sub-intervals: d_lower(mid) - deviation bounds.

    On [a, b] with midpoint m every point of a shape moves by at most
    trans + chord(angle) * max_p |p - ref| from its pose at m (motion-bound contract), so
    the distance stays >= lower(m) - delta_A - delta_B. Half-spaces on a moving body: -inf.
    """
    from monitor.certify.broadphase import subinterval_bounds
    from monitor.geometry.distance import shape_distance_batch

    pos, rot, mb, ref, ch = subinterval_bounds(plan, t0, t1, n)
    out = []
    for ga, gb in geoms:
        dev = np.zeros(n)
        ok = True
        for g in (ga, gb):
            if g.shape.kind == "halfspace":
                ok &= not ((mb.trans[:, g.body_id] > 0).any() or (mb.angle[:, g.body_id] > 0).any())
                continue
            lever = float(np.linalg.norm(g.shape.points - ref[g.body_id], axis=1).max() + g.shape.radius)
            dev = dev + mb.trans[:, g.body_id] + ch[:, g.body_id] * lever
        if not ok:
            out.append(float("-inf"))
            continue
        lo, _ = shape_distance_batch(ga.shape, (rot[:, ga.body_id], pos[:, ga.body_id]),
                                     gb.shape, (rot[:, gb.body_id], pos[:, gb.body_id]), tolerances=tol)
        out.append(float((lo - dev * (1.0 + 8 * tol.rel_pad)).min()))
    return out


def _approx(ga: Any, gb: Any) -> float:
    """Metres by which the pair's shapes over-approximate the true geoms.

    Circumscribed cylinders/ellipsoids lie within ``approx_error`` of the true geom,
    so the true distance is at most the shapes' distance plus this: a witness is
    confirmed only if ``upper + _approx < margin``.
    """
    return float(ga.shape.approx_error) + float(gb.shape.approx_error)


def _candidate_times(cands: list[float], spans: list[tuple[float, float]], tol: Tolerances) -> np.ndarray:
    """(T,) sorted distinct witness candidate times (s) of :func:`_checked_result`.

    ``cands`` and, per span ``(a, b)``, ``np.linspace(a, b, k)`` (k = 1 for an empty span, else
    ``max(2, tol.witness_candidates)``). ``cands`` is extended in place.
    """
    for a, b in spans:
        k = 1 if b <= a else max(2, tol.witness_candidates)
        cands += np.linspace(a, b, k).tolist()   # Python floats: the same values, cheaper set/sort
    return np.array(sorted(set(cands)))


def _earliest_candidate(cands: list[float], spans: list[tuple[float, float]]) -> float | None:
    """``_candidate_times(cands, spans, tol)[0]`` without the linspaces, or None where that is not sure.

    ``np.linspace(a, b, k)`` starts with ``0 * step + a`` (``0 * (b - a) + a`` for k = 1), which
    is ``a`` itself for a finite, non-zero ``a`` and a finite ``b - a`` (a zero ``a`` may turn
    -0.0 into 0.0; an overflowing span gives NaN); its other entries are ``>= a`` (monotone
    rounding). So, with finite ``cands``, the smallest distinct candidate is ``min`` over
    ``cands`` and the spans' starts, in the same order (``set`` keeps the first of equal
    values, ``min`` returns the first). None otherwise (the caller builds every candidate).
    Issue 12 (tunnel gate): the first candidate, the checker's exact first contact, confirms
    every tunnel violation, and 8 of 9 candidates were built unused.
    """
    isfinite = math.isfinite
    for x in cands:
        if not isfinite(x):
            return None
    firsts = list(cands)
    for a, b in spans:
        if not (a != 0.0 and isfinite(a) and isfinite(b - a)):
            return None
        firsts.append(a)
    return float(min(firsts)) if firsts else None


def _find_witness_of(plan: Any, ga: Any, gb: Any, cands: list[float], spans: list[tuple[float, float]],
                     margin: float, tol: Tolerances, budget: Budget) -> Witness | None:
    """``_find_witness(plan, ga, gb, _candidate_times(cands, spans, tol), margin, tol, budget)``.

    When :func:`_find_witness` would pose its first candidate alone (a Plan without quaternion
    tracks), that candidate comes from :func:`_earliest_candidate` and the others are built only
    if it does not confirm: the same poses (``body_poses`` of the same one-time array, then of the
    rest), tests and witness.
    """
    cls = _plan_class()
    first = None
    if cls is not None and type(plan) is cls and not plan._quat_tracks:
        first = _earliest_candidate(cands, spans)
    if first is None:
        return _find_witness(plan, ga, gb, _candidate_times(cands, spans, tol), margin, tol, budget)
    shape_distance = _module("monitor.geometry.distance").shape_distance
    slack = _approx(ga, gb)
    t_first = np.array([first])
    pos, rot = plan.body_poses(t_first)
    w = _confirm(shape_distance, ga, gb, t_first, pos, rot, margin, slack, tol, budget)
    if w is not None or budget.exhausted:
        return w
    times = _candidate_times(cands, spans, tol)
    if len(times) <= 1:
        return None      # (the one candidate, posed and tested above)
    pos, rot = plan.body_poses(times[1:])
    return _confirm(shape_distance, ga, gb, times[1:], pos, rot, margin, slack, tol, budget)


def _find_witness(plan: Any, ga: Any, gb: Any, times: np.ndarray, margin: float,
                  tol: Tolerances, budget: Budget | None = None) -> Witness | None:
    """Earliest candidate time whose confirmed distance is below margin.

    The exact static upper bound plus the shapes' over-approximation (circumscribed
    geoms) must be below the margin. Stops (None) when ``budget`` runs out.
    """
    shape_distance = _module("monitor.geometry.distance").shape_distance

    slack = _approx(ga, gb)
    first = 0
    cls = _plan_class()
    if (budget is not None and len(times) > 1 and cls is not None and type(plan) is cls
            and not plan._quat_tracks):
        # issue 12 (tunnel gate): the first candidate usually confirms; its pose alone first.
        # A Plan without quaternion tracks poses each time on its own (Python-float location,
        # elementwise lerp, one mj_kinematics per row), so these are the values of the batch.
        pos, rot = plan.body_poses(times[:1])
        w = _confirm(shape_distance, ga, gb, times[:1], pos, rot, margin, slack, tol, budget)
        if w is not None or (budget is not None and budget.exhausted):
            return w
        first = 1
    pos, rot = plan.body_poses(times[first:])
    return _confirm(shape_distance, ga, gb, times[first:], pos, rot, margin, slack, tol, budget)


def _module(name: str) -> Any:
    """The module ``name``, imported on first use (``sys.modules`` after that).

    The engine imports its checkers lazily (its own import stays light); a ``from ... import``
    statement in a per-window function costs ~1-3 us per call (issue 12, tunnel gate). The
    module, not the function, is looked up, so a monkeypatched module attribute is seen.
    """
    m = sys.modules.get(name)
    if m is None:
        import importlib

        m = importlib.import_module(name)
    return m


def _confirm(shape_distance: Any, ga: Any, gb: Any, times: np.ndarray, pos: np.ndarray, rot: np.ndarray,
             margin: float, slack: float, tol: Tolerances, budget: Budget | None) -> Witness | None:
    """:func:`_find_witness`'s loop over candidate ``times`` (T,) posed at ``pos`` (T, nbody, 3), ``rot``."""
    for k, t in enumerate(times):
        if budget is not None and budget.exhausted:
            return None
        d = shape_distance(ga.shape, (rot[k, ga.body_id], pos[k, ga.body_id]),
                           gb.shape, (rot[k, gb.body_id], pos[k, gb.body_id]), tolerances=tol)
        if d.upper + slack < margin:
            # = Witness(time, geoms, point, distance), field for field (see _WindowPairs.kernel_witness)
            w = _new(Witness)
            w.__dict__.update(time=float(t), geoms=(ga.name, gb.name), point=0.5 * (d.p_a + d.p_b),
                              distance=float(d.upper + slack))
            return w
    return None


_OWN_CERTIFY = certify
"""This module's own :func:`certify`: the gate's shortcuts stand for its result only while
``engine.certify`` is still it (a test or a user may replace it with another checker)."""

__all__ = ["certify"]
