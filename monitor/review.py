"""Offline review of monitor MCAP logs: pure analysis, re-verification, rendering.

* :func:`analyze` turns a :class:`~monitor.log.reader.LogContents` into a plain,
  JSON-serialisable summary dict (no I/O, no printing).
* :func:`verify` recomputes every logged certificate from the model attached to
  the log and the logged plan. Everything else in the log is a claim that is
  checked, never obeyed: the certificate's pair set must equal the one the model
  and the logged pair policy give, its window must equal the plan's span, its
  margin/epsilon/method must be valid and equal its request's (each certificate names the
  request it answers; older logs: the run's), window indices must be
  unique, verdicts must be one of the three, logged tolerances must be valid (the
  recomputation uses the library defaults unless the caller passes others), and
  ``model.xml`` must describe the same model as ``model.mjb``. A failed claim is a
  *critical* finding; a window that cannot be recomputed (no plan, an error, a
  malformed message) is an *unverifiable* finding. The rows of a gate's own rollouts
  are themselves re-simulated from their logged start states and controls, and the
  steps of an episode must continue each other (:func:`_replay_findings`). See :func:`verify`.
* :func:`render_text` and :func:`write_report` present those dicts (text table,
  self-contained HTML with embedded matplotlib PNGs).

The CLI (``python -m monitor review``) lives in :mod:`monitor.commands.review`.
"""

from __future__ import annotations

import base64
import html
import io
import math
import re
from collections import Counter
from collections.abc import Callable
from typing import Any

import numpy as np

from monitor.certify.types import Method, Verdict, as_verdict
from monitor.log import topics
from monitor.log.reader import LogContents

VERDICTS: tuple[Verdict, ...] = tuple(Verdict)
"""The three window verdicts (members equal their strings: ``"certified" in VERDICTS``)."""


def _percentile(x: list[float], q: float) -> float | None:
    return float(np.percentile(np.asarray(x, float), q)) if x else None


def _checker_mix(cert: dict[str, Any]) -> Counter:
    mix = (cert.get("stats") or {}).get("checker_mix")
    if isinstance(mix, dict) and mix:
        return Counter({str(k): int(v) for k, v in mix.items() if isinstance(v, (int, float))})
    return Counter(str(p.get("method", "?")) for p in cert.get("pairs", []))


def _violation_row(cert: dict[str, Any]) -> dict[str, Any]:
    wit = cert.get("witness")
    bad = [p for p in cert.get("pairs", []) if p.get("verdict") != Verdict.CERTIFIED]
    if wit:
        pair = next((p for p in bad if list(p.get("geoms", [])) == list(wit.get("geoms", []))), None)
        geoms = list(wit.get("geoms", []))
        bodies = list(pair.get("bodies") or []) if pair else []
        return {"index": cert.get("index"), "sim_time": cert.get("sim_time"),
                "verdict": as_verdict(cert["verdict"]),
                "time": wit.get("time"), "geoms": geoms, "bodies": bodies, "point": wit.get("point"),
                "distance": wit.get("distance"), "clearance": cert.get("clearance"),
                "pairs": len(bad)}
    first = bad[0] if bad else {}
    return {"index": cert.get("index"), "sim_time": cert.get("sim_time"),
            "verdict": as_verdict(cert["verdict"]), "time": cert.get("earliest_time"),
            "geoms": list(first.get("geoms", [])),
            "bodies": list(first.get("bodies") or []), "point": None, "distance": None,
            "clearance": cert.get("clearance"), "pairs": len(bad)}


_NUM = (int, float)


def _short(x: Any, n: int = 40) -> str:
    """``repr(x)`` cut to ``n`` characters (hostile values stay one short line)."""
    r = repr(x)
    return r if len(r) <= n else r[:n] + "..."


def _is_num(x: Any) -> bool:
    return isinstance(x, _NUM) and not isinstance(x, bool) and math.isfinite(x)


def _is_int(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _names2(x: Any) -> bool:
    return isinstance(x, list) and len(x) == 2 and all(isinstance(v, str) for v in x)


def _witness_problem(w: Any, where: str) -> str | None:
    if w is None:
        return None
    if not isinstance(w, dict):
        return f"{where} is not an object"
    if not _is_num(w.get("time")):
        return f"{where}.time is not a finite number"
    if not _names2(w.get("geoms")):
        return f"{where}.geoms is not two names"
    pt = w.get("point")
    if not (isinstance(pt, list) and len(pt) == 3 and all(_is_num(v) for v in pt)):
        return f"{where}.point is not three finite numbers"
    if w.get("distance") is not None and not _is_num(w.get("distance")):
        return f"{where}.distance is not a number or null"
    return None


def certificate_problem(c: dict[str, Any]) -> str | None:
    """Why a logged certificate payload is malformed (None when its fields are well typed).

    Checks types only (the verdict's *value*, margin/epsilon ranges and the method name
    are claims checked by :func:`verify`): ``index`` int >= 0, ``sim_time`` finite >= 0,
    ``verdict``/``method`` strings, ``window`` two finite numbers, ``margin``/``epsilon``
    numbers, ``clearance``/``earliest_time`` number or null, ``pairs`` a list of objects
    with two geom names, a verdict string, a method string and a number-or-null
    clearance, ``witness`` null or a well-formed witness, ``stats`` null or an object.
    """
    k = c.get("index")
    if not _is_int(k) or k < 0:
        return f"index {_short(k, 40)} is not an integer >= 0"
    if not _is_num(c.get("sim_time")) or c["sim_time"] < 0:
        return f"sim_time {_short(c.get('sim_time'), 40)} is not a finite number >= 0"
    for key in ("verdict", "method"):
        if not isinstance(c.get(key), str):
            return f"{key} is not a string"
    win = c.get("window")
    if not (isinstance(win, list) and len(win) == 2 and all(_is_num(v) for v in win)):
        return "window is not two finite numbers"
    for key in ("margin", "epsilon"):
        v = c.get(key)
        if not (isinstance(v, _NUM) and not isinstance(v, bool)):
            return f"{key} is not a number"
    for key in ("clearance", "earliest_time"):
        if c.get(key) is not None and not _is_num(c.get(key)):
            return f"{key} {_short(c.get(key), 40)} is not a number or null"
    pairs = c.get("pairs")
    if not isinstance(pairs, list):
        return "pairs is not a list"
    for i, p in enumerate(pairs):
        if not isinstance(p, dict) or not _names2(p.get("geoms")):
            return f"pairs[{i}] has no two geom names"
        if not isinstance(p.get("verdict"), str) or not isinstance(p.get("method", ""), str):
            return f"pairs[{i}] verdict/method is not a string"
        if p.get("bodies") is not None and not _names2(p.get("bodies")):
            return f"pairs[{i}].bodies is not two names"
        if p.get("clearance") is not None and not _is_num(p.get("clearance")):
            return f"pairs[{i}].clearance is not a number or null"
        why = _witness_problem(p.get("witness"), f"pairs[{i}].witness")
        if why:
            return why
    why = _witness_problem(c.get("witness"), "witness")
    if why:
        return why
    st = c.get("stats")
    if st is not None and not isinstance(st, dict):
        return "stats is not an object"
    ap = c.get("applied")
    if ap is not None and not (isinstance(ap, dict) and ap.get("kind") in APPLIED_KINDS
                               and _is_int(ap.get("covered_by")) and ap["covered_by"] >= 0):
        return f"applied {_short(ap, 60)} is not {{kind: fallback | brake_tail, covered_by: index}}"
    return None


APPLIED_KINDS = ("fallback", "brake_tail")
"""Kinds of applied-motion records (:data:`monitor.log.topics.APPLIED_MOTIONS_KEY`)."""


def is_applied_record(c: dict[str, Any]) -> bool:
    """True for an applied-motion record (the motion a replaced step ran), not a step's own window."""
    return isinstance(c.get("applied"), dict)


def split_certificates(contents: LogContents) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """(well-typed certificates in window order, rows ``{index, problem}`` of malformed ones)."""
    good, bad = [], []
    for c in contents.certificates():
        why = certificate_problem(c)
        if why is None:
            good.append(c)
        else:
            k = c.get("index")
            bad.append({"index": k if _is_int(k) else None, "problem": why})
    return good, bad


def _integrity(contents: LogContents, certs: list[dict[str, Any]],
               bad_messages: list[dict[str, Any]]) -> list[str]:
    """Cheap whole-log consistency checks that catch dropped or re-routed messages.

    The writer numbers windows 0, 1, 2, ... and writes one ``/monitor/violation`` message
    per non-certified certificate, every JSON payload with an integer ``index``. So: a gap
    in the certificate indices, a violation message without a matching non-certified
    certificate (or the reverse), or a payload without an integer index means messages
    were lost or moved (bit rot in a channel id, an edited log).
    """
    out = []
    for topic in topics.JSON_TOPICS:
        n = sum(1 for m in contents.topic(topic) if not _is_int(m.get("index")) or m["index"] < 0)
        if n and topic != topics.CERTIFICATE:  # malformed certificates are listed in bad_messages
            out.append(f"{n} {topic} message(s) without an integer index")
    for p in contents.topic(topics.PLAN):
        if not isinstance(p.get("times"), list):
            out.append(f"{topics.PLAN} message {str(p.get('index'))[:20]} has no times list")
            break
    have = {c["index"] for c in certs} | {b["index"] for b in bad_messages if b["index"] is not None}
    if have:
        gaps = sorted(set(range(max(have) + 1)) - have) if max(have) < 10 * len(have) + 10 else None
        if gaps is None:
            out.append(f"certificate indices reach {max(have)} with only {len(have)} certificates")
        elif gaps:
            out.append(f"certificate indices have {len(gaps)} gap(s) (first: {gaps[:5]}): certificates lost")
    if contents.seal_status == "mismatch":
        out.append(f"digest seal: {contents.seal_detail}")
    flagged = Counter(c["index"] for c in certs if c["verdict"] != Verdict.CERTIFIED)
    viol = Counter(m["index"] for m in contents.topic(topics.VIOLATION) if _is_int(m.get("index")))
    if contents.stop_kind == "truncated" and have:  # a killed writer may have cut the last window short
        flagged.pop(max(have), None)
        viol.pop(max(have), None)
    if flagged != viol:
        only_v = sorted((viol - flagged).keys())[:5]
        only_c = sorted((flagged - viol).keys())[:5]
        out.append(f"{topics.VIOLATION} messages do not match the non-certified certificates "
                   f"(violation message without such a certificate: {only_v}; certificate without "
                   f"violation message: {only_c})")
    return out


def analyze(contents: LogContents) -> dict[str, Any]:
    """Summary of one log (pure function of the recovered contents).

    Malformed certificate payloads (:func:`certificate_problem`) are skipped and
    listed in ``bad_messages``; certificates whose verdict is not one of the three
    are never dropped silently: they are listed in ``unknown_verdicts``.

    Returns:
        dict with ``file`` (path, size, complete, unreadable_bytes, stop_reason,
        stop_kind, messages, bad_payloads, bad_records, problems), ``run`` (metadata),
        ``bad_messages`` (rows: index, problem), ``unknown_verdicts`` (rows: index,
        verdict), ``integrity`` (problems found by :func:`_integrity`), ``windows``, ``verdicts``
        ({verdict: count}; applied-motion records excluded: ``applied_motions`` {records,
        verdicts}), ``blocked_actions``, ``actions``, ``latency_us``
        ({p50, p95, max, n}), ``checker_mix`` ({method: pairs}), ``violations``
        (rows: index, sim_time, verdict, time, geoms, bodies, point, distance,
        clearance), and ``series`` (per-window sim_time, verdict, clearance,
        latency_us for plots).
    """
    certs, bad_messages = split_certificates(contents)
    unknown = []
    verdicts = Counter({v: 0 for v in VERDICTS})
    mix: Counter = Counter()
    lat: list[float] = []
    series = {"sim_time": [], "verdict": [], "clearance": [], "latency_us": [], "margin": [], "episode": [],
              "index": []}
    rows = []
    applied: Counter = Counter()
    for c in certs:
        v = c.get("verdict")
        if is_applied_record(c) and v in VERDICTS:  # the motion a replaced step ran: counted apart
            applied[v] += 1
            if v != Verdict.CERTIFIED:
                rows.append(_violation_row(c))
            continue
        if v not in VERDICTS:
            unknown.append({"index": c["index"], "sim_time": c["sim_time"], "verdict": str(v)[:60]})
            continue
        verdicts[v] += 1
        mix.update(_checker_mix(c))
        ws = (c.get("stats") or {}).get("wall_seconds")
        us = float(ws) * 1e6 if _is_num(ws) and 0 <= ws < 1e6 else None  # a crafted 1e308 s is not a latency
        if us is not None:
            lat.append(us)
        series["sim_time"].append(float(c["sim_time"]))
        series["verdict"].append(as_verdict(v))
        cl = c.get("clearance")
        series["clearance"].append(float(cl) if isinstance(cl, (int, float)) else None)
        series["latency_us"].append(us)
        series["margin"].append(c.get("margin"))
        series["episode"].append(int(c.get("episode", 0)))
        series["index"].append(int(c.get("index", len(series["index"]))))
        if v != Verdict.CERTIFIED:
            rows.append(_violation_row(c))
    actions = [a for a in contents.topic(topics.ACTION) if _is_int(a.get("index"))]
    integrity = _integrity(contents, certs, bad_messages)
    run = {k: v for k, v in contents.run.items() if not k.startswith("version.")}
    for key in ("margin", "epsilon", "method"):  # not in the metadata: from the first certificate
        if run.get(key) is None and certs and key in certs[0]:
            run[key] = certs[0][key]
    return {
        "file": {"path": contents.path, "size": contents.size, "complete": contents.complete,
                 "unreadable_bytes": contents.unreadable_bytes, "stop_reason": contents.stop_reason,
                 "stop_kind": contents.stop_kind, "messages": dict(contents.counts),
                 "bad_payloads": contents.bad_payloads, "bad_records": contents.bad_records,
                 "problems": list(contents.problems), "seal": contents.seal_status,
                 "seal_detail": contents.seal_detail,
                 "library": contents.library, "attachments": sorted(contents.attachments)},
        "bad_messages": bad_messages,
        "unknown_verdicts": unknown,
        "integrity": integrity,
        "run": run,
        "versions": {k[len("version."):]: v for k, v in contents.run.items() if k.startswith("version.")},
        "windows": sum(verdicts.values()),
        "verdicts": dict(verdicts),
        "applied_motions": {"records": sum(applied.values()), "verdicts": dict(applied)},
        "actions": len(actions),
        "blocked_actions": sum(1 for a in actions if a.get("replaced")),
        "latency_us": {"n": len(lat), "p50": _percentile(lat, 50), "p95": _percentile(lat, 95),
                       "max": max(lat) if lat else None},
        "checker_mix": dict(mix),
        "violations": rows,
        "series": series,
        "blocked": _blocked_rows(actions),
    }


def _blocked_rows(actions: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Replaced actions: index, episode, sim_time, reason (version-1 logs: reason None)."""
    return [{"index": a.get("index"), "episode": a.get("episode", 0), "sim_time": a.get("sim_time"),
             "reason": a.get("reason")} for a in actions if a.get("replaced")]


def combine(summaries: list[dict[str, Any]]) -> dict[str, Any]:
    """Totals over several :func:`analyze` results."""
    verdicts = Counter({v: 0 for v in VERDICTS})
    mix: Counter = Counter()
    lat = []
    for s in summaries:
        verdicts.update(s["verdicts"])
        mix.update(s["checker_mix"])
        lat += [x for x in s["series"]["latency_us"] if x is not None]
    return {"logs": len(summaries), "windows": sum(verdicts.values()), "verdicts": dict(verdicts),
            "blocked_actions": sum(s["blocked_actions"] for s in summaries),
            "latency_us": {"n": len(lat), "p50": _percentile(lat, 50), "p95": _percentile(lat, 95),
                           "max": max(lat) if lat else None},
            "checker_mix": dict(mix)}


# --------------------------------------------------------------------------- verification


METHODS: tuple[Method, ...] = tuple(Method)
"""Certificate-level methods :func:`monitor.certify` accepts."""

CRITICAL = "critical"
UNVERIFIABLE = "unverifiable"

_POLICY_TEXT_LIMIT = 100_000


def _rebuild_plan(model: Any, msg: dict[str, Any]) -> Any:
    from monitor.errors import InvalidInputError

    times = np.asarray(msg["times"], dtype=np.float64)
    if msg.get("kind", "plan") == "bodymotion":
        from monitor.motion.bodymotion import BodyMotion

        # the interpolation decides the motion between waypoints: replay exactly the logged one
        # (older logs have none: lerp + slerp); an unknown value is an InvalidInputError
        return BodyMotion(times, np.asarray(msg["pos"], np.float64), np.asarray(msg["quat"], np.float64),
                          interpolation=str(msg.get("interpolation", "lerp_slerp")))
    if msg.get("kind", "plan") != "plan":
        raise InvalidInputError(f"logged plan kind {_short(msg.get('kind'), 40)} is unknown")
    from monitor.motion.plan import Plan

    qpos = np.asarray(msg["qpos"], dtype=np.float64)
    if qpos.ndim != 2 or qpos.shape[1] != model.nq:
        raise InvalidInputError(f"logged plan qpos has shape {qpos.shape}, model has nq={model.nq}")
    kw = {}
    for key, width in (("mocap_pos", 3), ("mocap_quat", 4)):
        if msg.get(key) is not None:  # JSON writes a (0, 3) array as []: restore the shape
            kw[key] = np.asarray(msg[key], dtype=np.float64).reshape(-1, width)
    return Plan(times, qpos, model=model, **kw)


_ALLOWED_REASONS = ("Adjacent", "Default", "Always", "User")


def _logged_allowed(run: dict[str, Any], find: Callable[..., None], notes: list[str]) -> list | None:
    """The run's allowed (never certified) candidate pairs as (geom_a, geom_b, reason) triples, or None.

    A gate logs the pairs its allowed-contact matrix took out of the candidate set
    (``allowed_pairs``, issue 13: e.g. ``allowed="auto"`` frees a resting contact at the first
    state); the scene is rebuilt with them so the re-derived pair set is the run's. Each one
    is listed in a note (an auditor sees what was not certified). Malformed: a CRITICAL finding
    and the scene is rebuilt without them (then the pair sets differ, also CRITICAL).
    """
    raw = run.get("allowed_pairs")
    if raw is None:
        return None
    ok = isinstance(raw, list) and all(
        isinstance(r, list) and len(r) == 3 and all(isinstance(x, str) for x in r)
        and r[2] in _ALLOWED_REASONS for r in raw)
    if not ok:
        find(CRITICAL, f"run metadata allowed_pairs is malformed (want [[geom_a, geom_b, reason], ...] with "
                       f"reason in {_ALLOWED_REASONS}): {_short(raw, 120)}")
        return None
    if raw:
        reasons = Counter(r[2] for r in raw)
        shown = ", ".join(f"{a}/{b} ({why})" for a, b, why in raw[:8]) + (" ..." if len(raw) > 8 else "")
        notes.append(f"the run allowed {len(raw)} candidate pair(s) ({dict(sorted(reasons.items()))}); "
                     f"they were not certified, in the log nor here: {shown}")
    return [tuple(r) for r in raw]


def _parse_request(raw: Any, where: str, tol: Any, find: Callable[..., None], notes: list[str]) -> Any:
    """A logged request record, ready to re-derive with, or None (malformed: a CRITICAL finding).

    The request's window, budget and pairs are replaced (window: each plan's span; budget: the
    library default per window; pairs: all of the scene's, the pair policy decides them) and
    its tolerances by the ones this verification uses (a note says when they differ).
    """
    from monitor.certify.request import BudgetLimits, CertifyRequest
    from monitor.errors import MonitorError

    try:
        req = CertifyRequest.from_json(raw)
    except (MonitorError, TypeError, ValueError) as exc:
        find(CRITICAL, f"{where} is malformed: {_short(str(exc), 200)}; its windows were re-derived "
                       f"without it (plain rule)")
        return None
    if req.pairs is not None:
        find(CRITICAL, f"{where} restricts the pairs to {len(req.pairs)}: ignored, the "
                       f"pair policy decides them")
    if req.tolerances != tol:
        notes.append(f"{where}: its tolerances differ from the ones used here; the logged ones "
                     f"were not used")
    if req.window is not None:
        notes.append(f"{where}: its window {list(req.window)} was not used (each plan's span is)")
    return req.replace(window=None, pairs=None, budget=BudgetLimits.of(None), tolerances=tol)


def _logged_requests(contents: LogContents, tol: Any, find: Callable[..., None],
                     notes: list[str]) -> dict[int, Any]:
    """Every logged request by id: ``{id: ready CertifyRequest or None (malformed/ambiguous)}``.

    Id 0 may be the run metadata's ``"request"`` (a gate's request at log open; the only
    one in logs written before per-window request ids); every ``monitor.request`` record adds
    one id. A record without an integer id, or an id defined twice with different contents,
    is a CRITICAL finding (the id is then unusable: its windows are re-derived without it).
    """
    raw: dict[int, Any] = {}
    where: dict[int, str] = {}
    broken: set[int] = set()
    if "request" in contents.run:
        raw[0], where[0] = contents.run["request"], "run metadata request"
    for rec in getattr(contents, "requests", ()):
        rid, r = rec.get("id"), rec.get("request")
        if not _is_int(rid) or rid < 0:
            find(CRITICAL, f"monitor.request record with id {_short(rid, 40)} (not an integer >= 0)")
            continue
        if isinstance(r, dict):
            r = {**r, "window": None}  # the writer records requests without their window
        if rid in raw:
            old = raw[rid] if not isinstance(raw[rid], dict) else {**raw[rid], "window": None}
            if old != r:
                find(CRITICAL, f"request id {rid} is defined twice with different contents ({where[rid]} "
                               f"and a monitor.request record): its windows were re-derived without it")
                broken.add(rid)
            continue
        raw[rid], where[rid] = r, f"monitor.request record {rid}"
    out: dict[int, Any] = {}
    for rid in sorted(raw):
        out[rid] = None if rid in broken else _parse_request(raw[rid], where[rid], tol, find, notes)
    return out


_RULE_FIELDS = ("margin", "epsilon", "ongoing", "penetration_tol")


def _loosened(base: Any, req: Any) -> list[str]:
    """The settings of ``req`` that make "certified" weaker than under ``base`` (empty: none).

    A lower margin; the ongoing-contact rule (``"deepen"``) where ``base`` had the plain rule;
    a larger ``penetration_tol`` under ``"deepen"``. Epsilon, method and budget only move
    answers between certified and uncertain, never what a certificate claims.
    """
    out = []
    if req.margin < base.margin:
        out.append(f"margin {base.margin} -> {req.margin}")
    if req.ongoing == "deepen" and base.ongoing != "deepen":
        out.append(f"ongoing {base.ongoing} -> deepen (penetration_tol {req.penetration_tol})")
    elif req.ongoing == "deepen" and req.penetration_tol > base.penetration_tol:
        out.append(f"penetration_tol {base.penetration_tol} -> {req.penetration_tol}")
    return out


def _request_findings(used: dict[int, list[int]], requests: dict[int, Any], find: Callable[..., None],
                      notes: list[str], run_claims: dict[str, float] | None = None,
                      max_penetration: float | None = None) -> None:
    """Notes on the requests the windows were re-derived with; an UNVERIFIABLE finding per loosening.

    The baseline is request 0 when the run metadata has it (a gate's settings at log open),
    else the request of the earliest window. A later request that loosens what "certified"
    means (:func:`_loosened`) is what a gate setting changed during the run looks like, and
    also what a forger adding a looser request record would write: the log cannot tell the
    two apart (its seal is not signed), so such windows are reported as unverifiable (exit 2),
    never as agreed. Tightening or neutral changes are notes. The run metadata's margin and
    epsilon (``run_claims``) are the settings the run started with: the baseline must have
    them (CRITICAL otherwise: a forger cannot lower request 0 and leave the run's claim).
    With ``max_penetration`` (m, the auditor's bound), a request that lets ongoing contacts
    deepen beyond it (``ongoing="deepen"`` with a larger ``penetration_tol``) is CRITICAL.
    """
    if not used:
        return
    if max_penetration is not None:
        for rid in sorted(used):
            req = requests[rid]
            if req.ongoing == "deepen" and req.penetration_tol > max_penetration:
                ks = used[rid]
                find(CRITICAL, f"request {rid} lets ongoing contacts deepen to penetration_tol="
                               f"{req.penetration_tol} m, more than the required {max_penetration} m "
                               f"({len(ks)} window(s), first {min(ks)})", min(ks))
    ids = sorted(used, key=lambda r: min(used[r]))
    base_id = 0 if requests.get(0) is not None else ids[0]
    base = requests[base_id]
    for key, v in (run_claims or {}).items():
        if getattr(base, key) != v:
            find(CRITICAL, f"request {base_id} (the run's first) has {key}={getattr(base, key)}, the run "
                           f"metadata {key}={v}")
    for rid in ids:
        req, ks = requests[rid], used[rid]
        fields = ", ".join(f"{f}={getattr(req, f)}" for f in _RULE_FIELDS)
        line = (f"request {rid} ({fields}) answers {len(ks)} window(s)"
                + (f", first {min(ks)}, last {max(ks)}" if len(used) > 1 else ""))
        if rid != base_id:
            diff = [f"{f} {getattr(base, f)} -> {getattr(req, f)}" for f in _RULE_FIELDS
                    if getattr(base, f) != getattr(req, f)]
            line += f"; differs from request {base_id}: {', '.join(diff) or 'budget/method/tolerances only'}"
            looser = _loosened(base, req)
            if looser:
                find(UNVERIFIABLE, f"request {rid} loosens what 'certified' means relative to request "
                                   f"{base_id} ({'; '.join(looser)}) for {len(ks)} window(s), first "
                                   f"{min(ks)}: a setting changed during the run or an edited log, which "
                                   f"the log cannot tell apart", min(ks))
        notes.append(line)


def _allowed_set(rows: Any) -> set[tuple[frozenset, str]]:
    return {(frozenset(map(str, r[:2])), str(r[2])) for r in rows}


def _check_pair_policy(model: Any, scene_cls: Any, scene: Any, policy: Any, tol: Any,
                       run: dict[str, Any], allowed: list | None, hazards: Any,
                       find: Callable[..., None], notes: list[str], expect_pairs: str | None = None,
                       first_start: np.ndarray | None = None) -> Any:
    """Check the logged pair policy's claims against the model; the scene to re-derive with.

    * ``hazards``: a note lists the candidate pairs it left out (never certified).
    * An allowed pair with reason Adjacent whose bodies are not adjacent (:func:`monitor.acm`
      rule): CRITICAL.
    * ``allowed_mode`` ``"auto"`` / ``"none"`` (a gate's ``allowed="auto"`` / ``None``): the
      allowed pairs are re-derived from the model (the ACM at the logged ``reference_qpos``,
      ``allow`` patterns, ``hazards``); a logged allowed pair the re-derivation does not give
      is CRITICAL and the windows are then re-derived on the re-derived pair set (so the pair
      comes back into every window).
    * What rests on a claim of the run, not on the model: every non-Adjacent reason under
      ``"given"`` (a user's matrix) or without ``allowed_mode`` (older logs), User pairs (the
      ``allow=`` items), and Default/Always at a ``reference_qpos`` that is not
      ``first_start`` (the first window's start qpos, (nq,), None when unknown: a gate resolves
      ``"auto"`` at the first state it sees). A note lists them; with ``expect_pairs`` (the
      auditor requires the model's pair set) they are CRITICAL and the windows are re-derived
      without them.
    """
    from monitor.acm import _adjacent
    from monitor.errors import MonitorError

    if hazards is not None:
        try:
            every = scene_cls.from_model(model, pairs=policy, tolerances=tol,
                                         **({"allowed": allowed} if allowed else {}))
            kept = set(map(_pair_key, scene.candidate_pairs))
            left = sorted(set(map(_pair_key, every.candidate_pairs)) - kept, key=sorted)
            shown = ", ".join("/".join(sorted(p)) for p in left[:8]) + (" ..." if len(left) > 8 else "")
            notes.append(f"the run checked only the pairs hazards={_short(hazards, 80)} selects: {len(left)} "
                         f"candidate pair(s) were not certified, in the log nor here: {shown or '-'}")
        except (MonitorError, ValueError, TypeError) as exc:  # pragma: no cover - the scene above built
            notes.append(f"cannot list the pairs hazards= left out: {exc}")
    for a, b, why in allowed or ():
        if why != "Adjacent":
            continue
        try:
            ok = _adjacent(model, scene.geom(a).id, scene.geom(b).id)
        except (MonitorError, KeyError, ValueError):
            ok = False
        if not ok:
            find(CRITICAL, f"allowed pair {a}/{b} claims reason Adjacent, but its bodies are not adjacent in "
                           f"the attached model")
    mode = run.get("allowed_mode")
    if mode is not None and mode not in ("auto", "none", "given"):
        find(CRITICAL, f"run metadata allowed_mode={_short(mode, 40)} is not 'auto', 'none' or 'given'")
        mode = None
    ref = run.get("reference_qpos")
    if ref is not None and not (isinstance(ref, list) and len(ref) == model.nq
                                and all(_is_num(x) for x in ref)):
        find(CRITICAL, f"run metadata reference_qpos is not {model.nq} finite numbers: {_short(ref, 80)}")
        mode = None if mode == "auto" else mode
        ref = None
    rows = [tuple(r) for r in allowed or ()]
    out = scene
    if mode in ("auto", "none") and rows:  # nothing allowed: nothing to re-derive (and no ACM to compute)
        try:
            again = scene_cls.from_model(model, pairs=policy, tolerances=tol,
                                         allowed="auto" if mode == "auto" else None, hazards=hazards,
                                         allow=run.get("allow"),
                                         reference=None if ref is None else np.asarray(ref, np.float64))
        except (MonitorError, ValueError, TypeError) as exc:
            find(CRITICAL, f"cannot re-derive the allowed pairs (allowed={mode!r}, "
                           f"allow={_short(run.get('allow'), 60)}) for the attached model: "
                           f"{_short(str(exc), 200)}")
            return scene
        logged, derived = _allowed_set(rows), _allowed_set(again.allowed_pairs)
        extra = sorted(logged - derived, key=lambda x: (sorted(x[0]), x[1]))
        for pair, why in extra:
            find(CRITICAL, f"allowed pair {'/'.join(sorted(pair))} (reason {why}) is not what "
                           f"allowed={mode!r} gives for the attached model at the logged reference pose: "
                           f"re-derived with the pair")
        if derived - logged:
            notes.append(f"{len(derived - logged)} pair(s) the re-derived policy allows were checked by the "
                         f"run (stricter than needed)")
        if extra:
            out, rows = again, [tuple(r) for r in again.allowed_pairs]
        else:
            notes.append(f"the {len(logged)} allowed pair(s) were re-derived from the model and the logged "
                         f"policy (allowed={mode!r})")
    # what rests on a claim of the run rather than on the model: a user's matrix (or an old log's
    # unexplained reasons), allow= items, and Default/Always at a reference pose that is not the
    # first window's start state (a gate resolves "auto" at the first state it sees)
    ref_claimed = (mode == "auto" and ref is not None
                   and (first_start is None or not np.array_equal(np.asarray(ref, np.float64), first_start)))
    claimed = [r for r in rows if r[2] != "Adjacent" and (
        mode in (None, "given") or r[2] == "User" or (ref_claimed and r[2] in ("Default", "Always")))]
    if not claimed:
        return out
    why = {None: "the log does not say how they were chosen (no allowed_mode: a log from before it was "
                 "logged)", "given": "the run's allowed-contact matrix was given by its user",
           "none": "they come from the run's allow= items",
           "auto": "they come from the run's allow= items or rest on a reference pose that is not the "
                   "first window's start state"}[mode]
    shown = _short([list(r) for r in claimed], 160)
    if expect_pairs is None:
        notes.append(f"{len(claimed)} allowed pair(s) are the run's claim, not re-derived from the model "
                     f"({why}): {shown}")
        return out
    find(CRITICAL, f"{len(claimed)} allowed pair(s) whose reasons cannot be re-derived from the model "
                   f"({why}): {shown}; the required {expect_pairs!r} pair set checks them")
    keep = [r for r in rows if r not in claimed]
    try:
        return scene_cls.from_model(model, pairs=policy, tolerances=tol,
                                    **({"allowed": keep} if keep else {}))
    except (MonitorError, ValueError, TypeError):  # pragma: no cover - the same policy built above
        return out


def _first_start(contents: LogContents, model: Any) -> np.ndarray | None:
    """(nq,) qpos at the start of window 0's joint-space plan, or None (no such plan)."""
    for p in contents.topic(topics.PLAN):
        if p.get("index") == 0 and p.get("kind", "plan") == "plan":
            try:
                q = np.asarray(p["qpos"][0], np.float64)
            except (KeyError, IndexError, TypeError, ValueError):
                return None
            return q if q.shape == (model.nq,) else None
    return None


def _unlogged_applied(contents: LogContents) -> int:
    """Replaced actions whose applied window has no certificate of its own in the log.

    A gate writes a blocked step as its proposal's window (action ``replaced``) and, only when
    the applied motion is not certified, a second window at the same episode and sim time.
    """
    def at(m: dict[str, Any]) -> tuple[str, str]:  # text: crafted values may be unhashable
        return str(m.get("episode", 0)), str(m.get("sim_time"))

    per_time = Counter(at(c) for c in contents.certificates())
    return sum(1 for a in contents.topic(topics.ACTION) if a.get("replaced") is True and per_time[at(a)] < 2)


_SPAN_TOL = 1e-12  # s: window ends of one run are the same float sums; a little slack, never a gap


def _covers(outer: Any, inner: Any) -> bool:
    """``outer`` [a, b] contains ``inner`` [c, d] (finite numbers; ``_SPAN_TOL`` slack)."""
    return outer[0] <= inner[0] + _SPAN_TOL and inner[1] <= outer[1] + _SPAN_TOL


def _applied_findings(contents: LogContents, certs: list[dict[str, Any]],
                      plan_msgs: dict[int, list[dict[str, Any]]], find: Callable[..., None],
                      notes: list[str]) -> dict[str, int]:
    """Check that every replaced step names the record of the motion that ran, and that it covers it.

    A gate that logs applied motions (run metadata ``applied_motions``, or any action naming an
    ``applied_window``) writes, for each replaced action of window k, ``applied_window`` j: an
    applied-motion record (``applied``: kind, covered_by; :data:`topics.APPLIED_MOTIONS_KEY`)
    whose plan and certificate are re-derived like any window. Here:

    * the record exists and is one (else UNVERIFIABLE: what ran is not in the log);
    * its window contains window k's span, and its plan passes through window k's start state
      (the proposal's first waypoint; both were simulated from the same state) and through the
      start state of the step window that begins where window k ends (if logged): else CRITICAL
      when the record claims ``certified`` (a certificate claimed for a motion it does not
      cover), UNVERIFIABLE otherwise;
    * ``covered_by``: a fallback record names itself; a braking tail names an earlier step
      window (not a record) that ends where the tail starts and, when the record was
      certified jointly with it (``stats.joint_window``), has the same joint window: else
      CRITICAL when certified, UNVERIFIABLE otherwise.

    Older logs (neither marker): the replaced actions without a second certificate at the same
    time are counted in a note, as before.

    Returns:
        counts: ``applied_records``, ``applied_steps`` (replaced actions whose record checks
        passed), ``applied_missing``, ``unlogged_old`` (older logs' count for the note).
    """
    by_index = {c["index"]: c for c in certs}
    step_at = {(str(c.get("episode", 0)), float(c["window"][0])): c["index"] for c in certs
               if not is_applied_record(c)}  # the step window starting at each time (to find the next step)
    acts = [a for a in contents.topic(topics.ACTION) if a.get("replaced") is True]
    new_style = (contents.run.get(topics.APPLIED_MOTIONS_KEY) == "logged"
                 or any("applied_window" in a for a in acts))
    out = {"applied_records": sum(1 for c in certs if is_applied_record(c)), "applied_steps": 0,
           "applied_missing": 0, "unlogged_old": 0}
    if not new_style:
        out["unlogged_old"] = _unlogged_applied(contents)
        return out

    def bad(rec: dict[str, Any], reason: str, index: Any) -> None:
        find(CRITICAL if rec.get("verdict") == Verdict.CERTIFIED else UNVERIFIABLE, reason, index)

    ok_records = set()
    for c in certs:
        if not is_applied_record(c):
            continue
        j, ap = c["index"], c["applied"]
        by = ap["covered_by"]
        if ap["kind"] == "fallback":
            if by != j:
                bad(c, f"applied fallback record names window {_short(by, 20)}'s certificate, not its own", j)
                continue
        else:
            src = by_index.get(by)
            if src is None or is_applied_record(src) or by >= j:
                bad(c, f"applied braking-tail record: covered_by={_short(by, 20)} is no earlier step "
                       f"window", j)
                continue
            if not math.isclose(float(src["window"][1]), float(c["window"][0]), rel_tol=0, abs_tol=_SPAN_TOL):
                bad(c, f"applied braking-tail record starts at t={c['window'][0]!r}, not where window {by} "
                       f"(its covering step) ends (t={src['window'][1]!r})", j)
                continue
            jw = (c.get("stats") or {}).get("joint_window")
            if jw is not None:
                sjw = (src.get("stats") or {}).get("joint_window")
                if sjw != jw or not (isinstance(jw, list) and len(jw) == 2 and all(_is_num(v) for v in jw)
                                     and _covers(jw, c["window"])):
                    bad(c, f"applied braking-tail record claims the joint certificate over {_short(jw, 60)}, "
                           f"window {by} has {_short(sjw, 60)}", j)
                    continue
        ok_records.add(j)
    for a in acts:
        k = a.get("index")
        jw = a.get("applied_window")
        step = by_index.get(k) if _is_int(k) else None
        if jw is None:
            out["applied_missing"] += 1
            find(UNVERIFIABLE, "replaced step names no record of the motion that ran (no applied_window)",
                 k if _is_int(k) else None)
            continue
        rec = by_index.get(jw) if _is_int(jw) else None
        if rec is None or not is_applied_record(rec):
            out["applied_missing"] += 1
            find(UNVERIFIABLE, f"replaced step's applied motion record (window {_short(jw, 20)}) is missing",
                 k if _is_int(k) else None)
            continue
        if step is None or is_applied_record(step):
            find(UNVERIFIABLE, f"replaced action {_short(k, 20)} has no step window", None)
            continue
        if not _covers(rec["window"], step["window"]):
            bad(rec, f"applied record {jw} (window {rec['window']}) does not cover the span {step['window']} "
                     f"of replaced step {k}: the motion that ran is not certified by it", k)
            continue
        if not _passes_through(plan_msgs.get(k), plan_msgs.get(jw), float(step["window"][0])):
            bad(rec, f"applied record {jw}'s motion does not pass through replaced step {k}'s start state", k)
            continue
        t_end = float(step["window"][1])
        nxt = step_at.get((str(step.get("episode", 0)), t_end))
        if nxt is not None and not _passes_through(plan_msgs.get(nxt), plan_msgs.get(jw), t_end):
            bad(rec, f"applied record {jw}'s motion does not end replaced step {k} in the state the next "
                     f"window {nxt} starts from", k)
            continue
        out["applied_steps"] += int(jw in ok_records)
    return out


def _passes_through(step_plans: Any, rec_plans: Any, t: float) -> bool:
    """The record's plan has a waypoint at ``t`` whose state equals the step plan's first (1e-9).

    The state is the qpos of a joint-space plan, the body positions and quaternions of a body
    motion; a record of another kind than the step's plan does not pass through it (a gate logs
    joint-space plans: a body-motion record could be any motion; red team 10).
    """
    if not step_plans or not rec_plans or len(step_plans) > 1 or len(rec_plans) > 1:
        return True  # a missing or duplicate plan is reported by verify's window loop
    p, r = step_plans[0], rec_plans[0]
    kind = p.get("kind", "plan")
    if kind not in ("plan", "bodymotion"):
        return True  # an unknown kind: verify's window loop reports it
    if r.get("kind", "plan") != kind:
        return False
    try:
        times = np.asarray(r["times"], np.float64)
        hit = np.flatnonzero(np.abs(times - t) <= _SPAN_TOL)
        if len(hit) == 0:
            return False
        for key in ("qpos",) if kind == "plan" else ("pos", "quat"):
            q0 = np.asarray(p[key][0], np.float64)
            q1 = np.asarray(r[key][int(hit[0])], np.float64)
            if q0.shape != q1.shape or not np.allclose(q0, q1, rtol=0.0, atol=1e-9):
                return False
        return True
    except (KeyError, IndexError, TypeError, ValueError):
        return False


def _replay_findings(contents: LogContents, certs: list[dict[str, Any]],
                     plan_msgs: dict[int, list[dict[str, Any]]],
                     edits: list[_Edit], edits_bad_from: int | None,
                     find: Callable[..., None], notes: list[str]) -> dict[str, int]:
    """Re-simulate every window whose rows come from the gate's own rollout; check the episode's continuity.

    For a log whose gate records rollouts (run metadata :data:`topics.ROLLOUTS_KEY`, format 3), each
    plan says where its rows come from (:mod:`monitor.log.replay`). Here, on the attached MJB model
    (bit-exact) with the logged in-place edits applied in window order:

    * a ``"rollout"`` plan is re-simulated from its logged integration state and controls, and its
      rows (times, qpos, held mocap poses) must be the logged ones bit for bit; else the first
      differing row is named;
    * records whose rollouts start at the same time of one episode (a step's proposal, its fallback,
      the braking tail simulated after it) must start from the same physical state (time, qpos,
      qvel, act, ...: :func:`monitor.log.replay.physics_index`);
    * consecutive steps of one episode: the motion that ran in step i (its window, or the applied
      record its replaced action names), re-simulated, must reach the next step's start time in
      the physical state the next window's rollout starts from (an edited control or state breaks
      it; so does user code that sets the state between steps without ``gate.reset()``).

    A failure is CRITICAL when the window claims ``certified`` (its certificate is about rows that
    are not the motion), UNVERIFIABLE otherwise. A log of a rollout gate whose plan lacks ``source``
    (stripped) is the same. Under another MuJoCo version than the logged one the re-simulation need
    not be bit-exact: every failure is UNVERIFIABLE and a note says so (an exact match still counts).
    Plans marked ``"user"`` are not re-simulated: a note, or UNVERIFIABLE when the run's predictor is
    the gate's rollout (it makes no user rows). Logs without rollouts (older): a note.

    Returns:
        counts: ``replayed`` (re-simulated and identical), ``replay_user``, ``replay_failed``
        (findings above, per window), ``continuity_checked`` (step pairs compared).
    """
    import mujoco

    from monitor.errors import LogFormatError, MonitorError
    from monitor.log import replay
    from monitor.log.reader import load_model

    run = contents.run
    marked = run.get(topics.ROLLOUTS_KEY) == "logged"
    out = {"replayed": 0, "replay_user": 0, "replay_failed": 0, "continuity_checked": 0}
    if not marked and not any("source" in p for ps in plan_msgs.values() for p in ps):
        version = run.get("format_version")
        gate_owned = run.get(topics.MODEL_EDITS_KEY) == "logged" and all(
            key in run for key in ("predictor", "on_violation", "unsafe", "frame_skip"))  # Gate._open_log's
        if certs and gate_owned and _is_int(version) and version >= 3:
            # a gate that opens its log writes "rollouts: logged" from format 3 on: stripped (red team 11)
            find(UNVERIFIABLE, f"the log is a gate's of format {version}, which marks its rollouts "
                               f"(rollouts: logged), but no rollout is marked: the plans' rows are "
                               f"re-certified but not re-simulated")
        elif certs:
            notes.append("no rollouts logged (a log before format 3, or not a gate's): the plans' rows are "
                         "re-certified but not re-simulated")
        return out
    try:
        model, _ = load_model(contents, "mjb")  # bit-exact (the XML keeps 6 digits)
    except LogFormatError as exc:
        find(UNVERIFIABLE, f"rollouts cannot be re-simulated: the MJB model does not load ({str(exc)[:200]})")
        return out
    exact = run.get("mujoco_version") == mujoco.__version__
    if not exact:
        notes.append(f"the log was written with MuJoCo {str(run.get('mujoco_version'))[:20]}, this is "
                     f"{mujoco.__version__}: re-simulated rows need not be bit-exact, so a difference is "
                     f"unverifiable, not critical")
    data = mujoco.MjData(model)
    phys = replay.physics_index(model)
    by_index = {c["index"]: c for c in certs}
    edits = list(edits)
    ends: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # record -> (row times, integration states)
    starts: dict[tuple[str, float], tuple[int, np.ndarray]] = {}  # (episode, t) -> (first record, state)
    step_start: dict[int, np.ndarray] = {}  # window -> its start state (rows_from 0)
    user: list[int] = []

    def fail(k: int, reason: str) -> None:
        out["replay_failed"] += 1
        certified = by_index[k].get("verdict") == Verdict.CERTIFIED
        find(CRITICAL if certified and exact else UNVERIFIABLE, reason, k)

    for k in sorted(plan_msgs):
        ps = plan_msgs[k]
        if len(ps) != 1 or k not in by_index or (edits_bad_from is not None and k >= edits_bad_from):
            continue  # duplicates / malformed certificates / unusable edits: reported by verify's loop
        while edits and edits[0][0] <= k:
            _apply_model_edit(model, edits.pop(0))
        p = ps[0]
        src = p.get("source")
        if src == "user":
            user.append(k)
            continue
        if src is None and p.get("kind", "plan") != "plan" and not marked:
            continue  # a body motion of a log that does not mark its sources: never a gate rollout
            # (in a marked log every plan says its source: a kind switched and the source stripped is
            # a removed rollout, red team 10)
        if src != "rollout":
            fail(k, "the run logs where every window's rows come from (rollouts: logged), but this plan has "
                    + ("no source: its rollout was removed" if src is None else f"source {_short(src, 30)}")
                    + "; its rows cannot be re-simulated")
            continue
        try:
            ro = replay.decode(p.get("rollout"), model)
        except (MonitorError, ValueError, TypeError) as exc:
            fail(k, f"its logged rollout cannot be re-simulated: {str(exc)[:200]}")
            continue
        applied = by_index[k].get("applied")
        tail = isinstance(applied, dict) and applied.get("kind") == "brake_tail"
        if (ro.rows_from > 0) != tail:
            # a gate's windows (proposals, fallbacks) start their rows at the logged state, only a braking
            # tail after its window's substeps: a step window with rows_from > 0 has no logged start state,
            # and the continuity checks skipped it (red team 11: every window from the forged one on re-made
            # from fabricated states one substep earlier gave exit 0)
            out["replay_failed"] += 1  # unverifiable, like a gap: no claim failed, the record fits no run
            find(UNVERIFIABLE, f"its rollout's rows start at substep {ro.rows_from}, but a gate's "
                 + ("braking tail starts them after its window's substeps" if tail else
                    "window starts them at its logged start state (substep 0): its continuity with the "
                    "steps around it cannot be checked"), k)
            continue
        logged_rows = len(p["times"]) if isinstance(p.get("times"), list) else None
        if logged_rows != ro.substeps - ro.rows_from + 1:
            # before simulating: a forged substep count (up to MAX_SUBSTEPS per plan) would
            # otherwise cost seconds of mj_step and (substeps, nstate) floats for every plan (red team 11)
            fail(k, f"the logged rows are not the re-simulation of its logged rollout (start state and "
                    f"controls) on the logged model: {logged_rows} logged row(s), the rollout makes "
                    f"{ro.substeps - ro.rows_from + 1} (not re-simulated)")
            continue
        try:
            plan, states = replay.resimulate(model, data, ro)
        except (MonitorError, ValueError, TypeError, mujoco.FatalError) as exc:  # (an option MuJoCo refuses)
            fail(k, f"its logged rollout cannot be re-simulated: {str(exc)[:200]}")
            continue
        diff = replay.first_difference(plan, p)
        if diff is not None:
            fail(k, f"the logged rows are not the re-simulation of its logged rollout (start state and "
                    f"controls) on the logged model: {diff}")
            continue
        out["replayed"] += 1
        ends[k] = (plan.times, states)
        at = (str(p.get("episode", 0)), float(ro.state[0]))
        first = starts.setdefault(at, (k, ro.state))
        if first[0] != k:
            d = float(np.max(np.abs(first[1][phys] - ro.state[phys]), initial=0.0))
            if not np.array_equal(first[1][phys], ro.state[phys]):
                fail(k, f"its rollout starts at t = {at[1]!r} s from another physical state than window "
                        f"{first[0]}'s (max |difference| {d:.3g}): both were simulated from the same step")
                continue
        if ro.rows_from == 0:
            step_start[k] = ro.state
    # consecutive steps: what ran in step i reaches step j's start state
    acts = {a.get("index"): a for a in contents.topic(topics.ACTION) if _is_int(a.get("index"))}
    steps = [c for c in certs if not is_applied_record(c)]
    for c_i, c_j in zip(steps, steps[1:]):
        i, j = c_i["index"], c_j["index"]
        if str(c_i.get("episode", 0)) != str(c_j.get("episode", 0)) or j not in step_start:
            continue
        a = acts.get(i)
        rec = a.get("applied_window") if a is not None and a.get("replaced") is True else i
        if not _is_int(rec) or rec not in ends or rec not in by_index:
            continue
        times, states = ends[rec]
        t_j = float(step_start[j][0])
        hit = np.flatnonzero(times == t_j)
        if len(hit) != 1:
            if rec == i and float(times[-1]) != t_j:  # a gate's step window ends where the next one starts
                find(UNVERIFIABLE, f"steps {i} and {j} of one episode do not meet (window {i} ends at "
                                   f"t = {float(times[-1])!r} s, window {j} starts at t = {t_j!r} s): the "
                                   f"motion in between is not in the log (a window removed, or the state "
                                   f"stepped without the gate)", j)
            elif rec != i and float(times[0]) <= t_j <= float(times[-1]):
                # the record spans t_j but has no row there: a gate's rows are the run's substep times (the
                # same float sums), so its start time was moved and the check would be skipped (red team 11)
                find(UNVERIFIABLE, f"the applied motion record {rec} that ran in step {i} spans t = {t_j!r} "
                                   f"s, where window {j} starts, without a row there (its rows are off the "
                                   f"run's substep times): steps {i} and {j} cannot be checked to continue "
                                   f"each other", j)
            continue  # (a replaced step's record: the applied-motion checks cover its span)
        out["continuity_checked"] += 1
        end, start = states[int(hit[0])][phys], step_start[j][phys]
        if not np.array_equal(end, start):
            d = float(np.max(np.abs(end - start), initial=0.0))
            fail(rec, f"re-simulated, the motion that ran in step {i} reaches t = {t_j!r} s in another "
                      f"physical state (time, qpos, qvel, act) than window {j} starts from (max |difference| "
                      f"{d:.3g}): "
                      f"an edited control or start state, or the state was set between steps without "
                      f"gate.reset()")
    out["replay_user"] = len(user)
    if user:
        text = (f"{len(user)} window(s) (first {user[0]}) have rows from user code (a predictor callable, an "
                f"adapter, an explicit plan, or a `cast` that edited the model while they were simulated): "
                f"not re-simulated")
        if marked and run.get("predictor") == "rollout":
            find(UNVERIFIABLE, text + ", although the run's predictor is the gate's own rollout")
        else:
            notes.append(text)
    if out["replayed"]:
        notes.append(f"{out['replayed']} window(s) re-simulated from their logged rollouts on the MJB model: "
                     f"rows identical; {out['continuity_checked']} step-to-step state continuity check(s)")
    return out


def _engine() -> tuple[Any, Any]:
    """(Scene class, certify function); ImportError while the engine is not installed."""
    from monitor.certify.engine import certify
    from monitor.scene import Scene

    return Scene, certify


_TOL_INT_RANGES = {"max_depth": (1, 64), "facets": (3, 4096), "witness_candidates": (2, 10_000),
                   "max_frontier": (0, 1 << 30)}


def tolerance_problems(tol: Any) -> list[str]:
    """Problems of a tolerances dict (logged or given): unknown fields, wrong types, bad ranges.

    Float fields must be finite and >= 0 (``quat_norm_tol`` > 0); integer fields must be
    integers in the ranges of ``_TOL_INT_RANGES`` (e.g. ``facets`` >= 3). Empty = valid.
    """
    from monitor.tolerances import Tolerances

    if not isinstance(tol, dict):
        return [f"tolerances is a {type(tol).__name__}, not an object"]
    fields = Tolerances.__dataclass_fields__
    out = []
    for k, v in tol.items():
        if k not in fields:
            out.append(f"unknown tolerance field {_short(k, 40)}")
        elif k in _TOL_INT_RANGES:
            lo, hi = _TOL_INT_RANGES[k]
            if not _is_int(v) or not lo <= v <= hi:
                out.append(f"{k}={_short(v, 40)} is not an integer in [{lo}, {hi}]")
        elif not _is_num(v) or v < 0 or (k == "quat_norm_tol" and v == 0):
            bound = "> 0" if k == "quat_norm_tol" else ">= 0"
            out.append(f"{k}={_short(v, 40)} is not a finite number {bound}")
    return out


def make_tolerances(values: dict[str, Any] | None) -> Any:
    """Library defaults, or a :class:`~monitor.tolerances.Tolerances` from validated ``values``.

    Raises:
        InvalidInputError: :func:`tolerance_problems` found any.
    """
    from monitor.errors import InvalidInputError
    from monitor.tolerances import DEFAULT, Tolerances

    if not values:
        return DEFAULT
    bad = tolerance_problems(values)
    if bad:
        raise InvalidInputError("tolerances: " + "; ".join(bad))
    return Tolerances(**values)


def parse_pair_policy(value: Any) -> str | list[tuple[str, str]]:
    """The logged pair policy: ``"mujoco"``, ``"all"`` or a list of (geom, geom) names.

    Accepts a JSON list of two-name lists, or the text of one (``str()`` of a Python list of
    tuples, as :class:`monitor.Gate` writes), parsed with :func:`ast.literal_eval` (literals
    only, at most 100 kB).

    Raises:
        InvalidInputError: anything else.
    """
    import ast

    from monitor.errors import InvalidInputError

    pol = value
    if isinstance(pol, str) and pol not in ("mujoco", "all"):
        if len(pol) > _POLICY_TEXT_LIMIT:
            raise InvalidInputError(f"pair policy text is longer than {_POLICY_TEXT_LIMIT} characters")
        try:
            pol = ast.literal_eval(pol)
        except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError) as exc:
            raise InvalidInputError(f"pair policy {value[:60]!r} is neither 'mujoco', 'all' nor a list of "
                                    f"geom-name pairs") from exc
    if pol in ("mujoco", "all"):
        return pol
    if isinstance(pol, (list, tuple)) and all(
            isinstance(p, (list, tuple)) and len(p) == 2 and all(isinstance(g, str) for g in p) for p in pol):
        return [(str(p[0]), str(p[1])) for p in pol]
    raise InvalidInputError(f"pair policy {_short(value, 60)} is neither 'mujoco', 'all' nor a list of "
                            f"geom-name pairs")


def _pair_key(geoms: Any) -> frozenset:
    return frozenset(map(str, geoms))


_Edit = tuple[int, dict[str, np.ndarray], int | None, dict[str, Any]]
"""A logged model edit: (window index, array field -> new array, disableflags or None, option -> value)."""

_STRUCTURE_SUFFIXES = ("adr", "num", "id", "nnz", "colind", "diag", "signature", "plugin", "_type", "trntype",
                       "dyntype", "gaintype", "biastype", "objtype", "reftype", "datatype", "history")
"""Integer ``MjModel`` arrays (indices, addresses, counts, sparsity, object types) that a model edit
record may not change: MuJoCo and the packed kernels index memory with them unchecked, so a record
that moved ``jnt_qposadr`` crashed review (a segmentation fault) and one that moved ``body_parentid``
raised a traceback (red team 11). ``geom_type`` may change among the primitives
(:data:`_PRIMITIVE_GEOM_TYPES`), as a user's in-place edit can (``tests/test_model_edits.py``)."""
_PRIMITIVE_GEOM_TYPES = frozenset(range(7)) - {1}
"""mjtGeom values that need no data (plane, sphere, capsule, ellipsoid, cylinder, box; not hfield, mesh,
sdf)."""


def _structure_problem(name: str, ref: np.ndarray, new: np.ndarray) -> str | None:
    """Why an edit of the integer array ``name`` from ``ref`` to ``new`` (same shape) is refused, or None."""
    structure = name.endswith(_STRUCTURE_SUFFIXES) or name.startswith("map") or name.startswith("pair_geom")
    if ref.dtype.kind not in "iu" or not structure:
        return None  # (not geom_contype / conaffinity / condim / priority / group, the *limited flags)
    changed = new != ref
    if not changed.any():
        return None
    if name == "geom_type" and set(new[changed].tolist()) <= _PRIMITIVE_GEOM_TYPES:
        return None
    return f"field {name}: changes model structure (an index, address, count or type), not an in-place edit"


def _option_problem(model: Any, options: Any) -> tuple[str | None, dict[str, Any]]:
    """(problem or None, checked options) of a model edit record's ``"options"`` (format 3)."""
    from monitor.log.replay import option_fields

    if options is None:
        return None, {}
    if not isinstance(options, dict):
        return "options is not an object", {}
    known = option_fields(model)
    out: dict[str, Any] = {}
    for name, val in options.items():
        ref = getattr(model.opt, name) if name in known else None
        if ref is None:
            return f"option {_short(name, 40)} is not a model option", {}
        if isinstance(ref, np.ndarray):
            ok = isinstance(val, list) and all(map(_is_num, val))
            arr = np.asarray(val, dtype=np.float64) if ok else None
            if arr is None or arr.shape != ref.shape:
                return f"option {name}: not {ref.size} finite numbers", {}
            out[name] = arr
        elif isinstance(ref, int) and not isinstance(ref, bool):
            if not _is_int(val):
                return f"option {name}: {_short(val, 30)} is not an integer", {}
            out[name] = int(val)
        elif not _is_num(val):
            return f"option {name}: {_short(val, 30)} is not a finite number", {}
        else:
            out[name] = float(val)
    return None, out


def _model_edits(contents: LogContents, model: Any, find: Callable[..., None], notes: list[str]
                 ) -> tuple[list[_Edit], int | None]:
    """The logged in-place model edits (``monitor.model_edit`` records), checked against ``model``.

    Returns:
        (edits in file order as (window index, field -> new array, disableflags or None,
        option -> value), the first window index from which the edits are unusable (a malformed
        record: those windows are reported UNVERIFIABLE, never re-derived on a model the run did
        not certify on), or None).
    """
    from monitor.log.replay import model_fields
    from monitor.scene import SYNC_FIELDS

    editable = set(SYNC_FIELDS) | set(model_fields(model))  # format 3 also logs dynamics arrays
    out: list[_Edit] = []
    bad_from: int | None = None
    last = 0
    for n, rec in enumerate(contents.model_edits):
        w = rec.get("window") if isinstance(rec, dict) else None
        problem = None
        if not _is_int(w) or w < last:
            problem = f"window {_short(w, 40)} is not an integer >= {last} (records in window order)"
        fields = rec.get("fields") if isinstance(rec, dict) else None
        arrays: dict[str, np.ndarray] = {}
        if problem is None and not isinstance(fields, dict):
            problem = "fields is not an object"
        for name, val in (fields.items() if problem is None else ()):
            if name not in editable:
                problem = f"field {_short(name, 40)} is not a model array a certificate or a simulation " \
                          f"depends on"
                break
            ref = getattr(model, name)
            try:
                shape = tuple(int(x) for x in val["shape"])
                arr = np.asarray(val["values"], dtype=np.float64)
            except (TypeError, ValueError, KeyError) as exc:
                problem = f"field {name}: {type(exc).__name__}"
                break
            if shape != ref.shape or arr.size != ref.size or not np.isfinite(arr).all():
                problem = f"field {name}: shape {shape} / {arr.size} values, the model's is {ref.shape}"
                break
            arrays[name] = arr.reshape(shape).astype(ref.dtype)
            if not np.array_equal(arrays[name], arr.reshape(shape)):
                problem = f"field {name}: values not representable as {ref.dtype}"
                break
            problem = _structure_problem(name, ref, arrays[name])
            if problem is not None:
                break
        flags = rec.get("disableflags") if isinstance(rec, dict) else None
        if problem is None and flags is not None and not _is_int(flags):
            problem = f"disableflags {_short(flags, 40)} is not an integer"
        options: dict[str, Any] = {}
        if problem is None:
            problem, options = _option_problem(model, rec.get("options"))
        if problem is not None:
            find(UNVERIFIABLE, f"model edit record {n} is malformed: {problem}")
            bad_from = w if _is_int(w) and w >= last else last
            break
        last = int(w)
        out.append((int(w), arrays, None if flags is None else int(flags), options))
    if out:
        names = sorted({k for _, a, _, _ in out for k in a} | ({"opt.disableflags"} if any(
            f is not None for _, _, f, _ in out) else set()) | {f"opt.{k}" for *_, o in out for k in o})
        notes.append(f"{len(out)} in-place model edit(s) logged by the run (first at window {out[0][0]}; "
                     f"fields: {', '.join(names)}): each window re-derived on the model as edited before "
                     f"it (the run's record, like its requests: a forged record reads like a genuine one)")
    return out, bad_from


def _apply_model_edit(model: Any, edit: _Edit) -> None:
    """Write one logged edit into ``model`` in place (review's own copy of the attached model)."""
    _, arrays, flags, options = edit
    for name, arr in arrays.items():
        getattr(model, name)[...] = arr
    if flags is not None:
        model.opt.disableflags = flags
    for name, value in options.items():
        if isinstance(value, np.ndarray):
            getattr(model.opt, name)[...] = value
        else:
            setattr(model.opt, name, value)


def verify(contents: LogContents, *, model_source: str = "auto", progress: bool | None = None,
           limit: int | None = None, tolerances: dict[str, Any] | None = None,
           expect_pairs: str | None = None, max_penetration: float | None = None,
           trust_model_edits: bool = False, key: bytes | None = None) -> dict[str, Any]:
    """Recompute every logged certificate from the attached model and the logged plan.

    Inputs of the recomputation: the model (attachments), the plan (same window index),
    the pair set ``Scene.from_model(model, pairs=<logged policy>, allowed=<logged allowed
    pairs>, hazards=<logged items>)`` (the policy is the one claim that defines *what* is
    certified; a missing policy is assumed ``"mujoco"`` and reported; the allowed pairs are
    re-derived from the model where the log says how they were chosen, see
    :func:`_check_pair_policy`), the library's default :class:`~monitor.tolerances.Tolerances`
    (or ``tolerances`` from the caller), the window's own request (its ``request_id``:
    ongoing rule, penetration_tol; logs without ids: the run's request, else the plain rule),
    and the certificate's margin, epsilon and method once they are checked against that
    request; the window is always the plan's span.

    Claims checked (a failure is a *critical* finding, exit 1 in the CLI): verdict is
    one of the three; index unique among certificates and among plans; method known;
    margin finite >= 0 and epsilon finite > 0, both equal to the run metadata's when
    that has them; window equal to the plan's span; the certificate's pair multiset equal
    to the scene's; the pair policy valid for the model; logged tolerances valid (when
    valid but different from the ones used, a note); ``model.xml`` and ``model.mjb`` the
    same model; and the recomputed verdict equal to the logged one (certified <->
    not-certified flips are critical, except logged "uncertain" windows whose
    ``stats["budget_exhausted"]`` is true or that re-derive as certified: those claimed less than
    the checker proves now, a non-critical mismatch).

    Also critical: a ``request_id`` naming no logged request, a request id defined twice
    with different contents, a malformed request, an allowed pair whose Adjacent reason the
    model contradicts or that the logged policy does not re-derive to.

    Unverifiable findings (exit 2 in the CLI): a malformed certificate, a window without
    plan, an error while rebuilding or certifying, windows left out by ``limit``, a model
    whose XML and MJB cannot be cross-checked, no logged pair policy, and a later request
    that loosens margin / the ongoing rule / penetration_tol relative to request 0 (a
    setting changed during the run and an added record look the same).

    Rows re-simulated (logs of format 3, :func:`_replay_findings`): every plan a gate made by its
    own MuJoCo rollout must be, bit for bit, the re-simulation of its logged start state and
    controls on the MJB model (with the logged edits), and consecutive steps of an episode must
    continue each other (an edited plan, control or start state is critical when certified); a
    plan that lost its rollout in a log that says it logs them is the same.

    In-place model edits the run logged (``monitor.model_edit`` records, written by a gate
    before the first window certified on the edited model) are applied in window order to
    the attached model, so each window is re-derived on the model it was certified on (flips
    there are critical as usual). A malformed record makes its windows unverifiable. A valid
    record is still the run's unsigned claim (an added record shrinking an obstacle reads like
    a genuine edit): the windows from the first edit are one unverifiable finding unless
    ``trust_model_edits`` (the auditor trusts the run's edit records) or the log's signature
    verified with ``key`` (every record covered, signed close: the records are the key holder's
    own), then a note.

    Args:
        contents: a read log.
        model_source: ``"auto" | "xml" | "mjb"`` (see :func:`monitor.log.reader.load_model`).
        progress: tqdm bar over windows; None = when there are more than 200.
        limit: verify only the first ``limit`` windows (the rest are reported unverifiable).
        tolerances: tolerance fields overriding the library defaults (validated).
        expect_pairs: ``"mujoco"`` or ``"all"``: the pair policy the auditor requires. A log
            whose policy differs is critical and is recomputed with this policy instead (a
            log that consistently claims fewer pairs is otherwise only reported in a note).
        max_penetration: metres, the deepest ongoing contact the auditor accepts: a window
            answered under ``ongoing="deepen"`` with a larger ``penetration_tol`` is critical
            (a log that consistently claims a loose rule is otherwise only reported in a note).
            0 requires the plain rule.
        trust_model_edits: accept the logged model edits as the run's model (see above).
        key: the log signing key: the log's signed checkpoints are checked
            (:func:`signature_findings`); None: a signed log gets the note "signature not checked".

    Returns:
        dict with ``windows`` (certificates in the log), ``checked`` (recomputed),
        ``model_source``, ``model_consistency``, ``tolerances`` (the values used),
        ``pair_policy``, ``mismatches`` (rows: index, sim_time, logged, recomputed, critical,
        logged_clearance, clearance, witness, reason), ``findings`` (rows: index or None,
        severity ``"critical" | "unverifiable"``, reason), ``notes`` (strings),
        ``critical`` (critical mismatches + critical findings), ``unverifiable`` (number
        of unverifiable findings), ``missing_plans``, ``errors`` (rows: index, error),
        ``pairs_differ``, and for applied-motion records (:func:`_applied_findings`)
        ``applied_checked`` (records re-derived, counted in ``checked`` too), ``applied_records``,
        ``applied_steps`` (replaced steps whose record covers them), ``applied_missing``, and
        ``replayed``, ``replay_user``, ``replay_failed``, ``continuity_checked``
        (:func:`_replay_findings`), ``signature`` (:class:`monitor.log.sign.SignatureCheck` as a dict).

    Raises:
        LogFormatError: the model cannot be rebuilt from the attachments.
        InvalidInputError: bad ``tolerances`` or ``model_source``.
    """
    from dataclasses import asdict

    from monitor.errors import InvalidInputError, MonitorError
    from monitor.log.reader import load_model, model_consistency

    tol = make_tolerances(tolerances)
    if max_penetration is not None and not (_is_num(max_penetration) and max_penetration >= 0):
        raise InvalidInputError(f"max_penetration must be a finite number >= 0 (m), got {max_penetration!r}")
    scene_cls, certify = _engine()
    model, how = load_model(contents, model_source)
    run = contents.run
    findings: list[dict[str, Any]] = []
    notes: list[str] = []

    def find(severity: str, reason: str, index: int | None = None) -> None:
        findings.append({"index": index, "severity": severity, "reason": reason})

    if contents.seal_status == "mismatch":
        find(CRITICAL, f"digest seal: {contents.seal_detail}")
    elif contents.seal_status == "unsealed":
        notes.append("log is not sealed (no digest): edits after writing cannot be detected by digest")
    signature = signature_findings(contents, key, find, notes)
    consistency = model_consistency(contents)
    if consistency["status"] == "inconsistent":
        find(CRITICAL, consistency["detail"])
    elif consistency["status"] == "unchecked":
        find(UNVERIFIABLE, consistency["detail"])

    logged_tol = run.get("tolerances")
    if logged_tol is not None:
        bad = tolerance_problems(logged_tol)
        if bad:
            find(CRITICAL, "logged tolerances are invalid: " + "; ".join(bad))
        else:
            used = asdict(tol)
            diff = {k: v for k, v in logged_tol.items() if used.get(k) != v}
            if diff:
                notes.append(f"logged tolerances {diff} differ from the ones used here; the logged "
                             f"ones were not used")
    run_claims: dict[str, float] = {}
    for key, ok in (("margin", lambda x: x >= 0), ("epsilon", lambda x: x > 0)):
        if key in run:
            v = run[key]
            if not _is_num(v) or not ok(v):
                find(CRITICAL, f"run metadata {key}={_short(v, 40)} is invalid")
            else:
                run_claims[key] = float(v)

    requests = _logged_requests(contents, tol, find, notes)
    logged_req = requests.get(0) if "request" in run else None  # windows without a request id
    used_requests: dict[int, list[int]] = {}
    no_request_id = 0

    policy: Any = None
    raw_policy = run.get("pairs", run.get("pair_policy"))
    if raw_policy is None:
        find(UNVERIFIABLE, "no pair policy in the run metadata: assumed the library default 'mujoco'")
        raw_policy = "mujoco"
    try:
        policy = parse_pair_policy(raw_policy)
    except MonitorError as exc:
        find(CRITICAL, f"logged pair policy is invalid: {exc}")
    if expect_pairs is not None:
        if expect_pairs not in ("mujoco", "all"):
            raise InvalidInputError(f"expect_pairs must be 'mujoco' or 'all', got {expect_pairs!r}")
        if policy != expect_pairs:
            find(CRITICAL, f"logged pair policy {_short(raw_policy, 80)} is not the required "
                           f"{expect_pairs!r}")
        policy = expect_pairs
    scene = None
    allowed = _logged_allowed(run, find, notes)
    hazards = run.get("hazards")  # None: every candidate pair (also logs from before it was logged)
    if hazards is not None and expect_pairs is not None:
        find(CRITICAL, f"logged hazards={_short(hazards, 80)} selects a subset of the pairs, not the "
                       f"required {expect_pairs!r}: ignored")
        hazards = None
    if policy is not None:
        try:
            scene = scene_cls.from_model(model, pairs=policy, tolerances=tol,
                                         **({"allowed": allowed} if allowed else {}),
                                         **({"hazards": hazards} if hazards is not None else {}))
        except (MonitorError, ValueError, TypeError) as exc:
            find(CRITICAL, f"logged pair policy {_short(raw_policy, 80)} (hazards={_short(hazards, 60)}) is "
                           f"not valid for the attached model: {exc}")
        if scene is not None:
            scene = _check_pair_policy(model, scene_cls, scene, policy, tol, run, allowed, hazards,
                                       find, notes, expect_pairs, _first_start(contents, model))
        if isinstance(policy, list):
            notes.append(f"pair policy is an explicit list of {len(policy)} pair(s): only those pairs are "
                         f"certified")
    if run.get("facets") is not None and run.get("facets") != tol.facets:
        notes.append(f"logged facets {str(run.get('facets'))[:20]} not used (tolerances.facets={tol.facets})")

    good, bad_rows = split_certificates(contents)
    for row in bad_rows:
        find(UNVERIFIABLE, f"malformed certificate skipped: {row['problem']}", row["index"])
    cert_count = Counter(c["index"] for c in good)
    for k, n in sorted(cert_count.items()):
        if n > 1:
            find(CRITICAL, f"window index {k} has {n} certificates", k)
    plan_msgs: dict[int, list[dict[str, Any]]] = {}
    for p in contents.topic(topics.PLAN):
        k = p.get("index")
        if _is_int(k):
            plan_msgs.setdefault(k, []).append(p)
        else:
            find(UNVERIFIABLE, f"plan message without an integer index ({_short(k, 40)})")
    for k, ps in sorted(plan_msgs.items()):
        if len(ps) > 1:
            find(CRITICAL, f"window index {k} has {len(ps)} plan messages", k)

    certs = good
    if limit is not None and len(certs) > limit:
        find(UNVERIFIABLE, f"{len(certs) - limit} window(s) not checked (--limit {limit})")
        certs = certs[:limit]
    out: dict[str, Any] = {"windows": len(good) + len(bad_rows), "checked": 0, "model_source": how,
                           "model_consistency": consistency, "tolerances": asdict(tol),
                           "pair_policy": policy if isinstance(policy, str) else
                           (None if policy is None else [list(p) for p in policy]),
                           "mismatches": [], "findings": findings, "notes": notes, "critical": 0,
                           "unverifiable": 0, "missing_plans": 0, "errors": [], "pairs_differ": 0,
                           "applied_checked": 0, "signature": signature}
    scene_pairs = Counter(_pair_key(p) for p in scene.candidate_pairs) if scene is not None else None
    edits, edits_bad_from = _model_edits(contents, model, find, notes)
    replay_edits = list(edits)  # the loop below consumes edits; the re-simulation applies them again
    # a log whose every record a valid signature covers, closed and signed (key given): the edit
    # records are the gate's own, as authentic as the rest; the unsigned-log reason for refusing
    # them (an added record shrinking an obstacle reads like a genuine edit) does not apply
    signed_edits = bool(edits) and signature.get("status") == "verified"
    if signed_edits and not trust_model_edits:
        notes.append(_signed_edits_note(len(edits)))
    if edits and not trust_model_edits and not signed_edits:
        first_edit = edits[0][0]
        n_after = sum(c["index"] >= first_edit and (edits_bad_from is None or c["index"] < edits_bad_from)
                      for c in certs)
        if n_after:
            find(UNVERIFIABLE, f"{n_after} window(s) from index {first_edit} {_UNSIGNED_EDITS}: re-derived "
                               f"on them, but an unsigned log cannot "
                               f"show that the edits happened (an added edit record reads the same; "
                               f"trust_model_edits accepts them)")
    if edits or edits_bad_from is not None:
        certs = sorted(certs, key=lambda c: c["index"])  # edits apply in window order
    unverifiable_after_edit: list[int] = []
    it = certs
    if progress is None:
        progress = len(certs) > 200
    if progress:
        from tqdm import tqdm

        it = tqdm(certs, desc=f"verifying {contents.path}", unit="win", leave=False)
    for c in it:
        k = c["index"]
        verdict = c["verdict"]
        if edits and edits[0][0] <= k and (edits_bad_from is None or k < edits_bad_from):
            while edits and edits[0][0] <= k:  # the model as the run certified this window on
                _apply_model_edit(model, edits.pop(0))
            if scene is not None:
                try:
                    scene.sync()
                    scene_pairs = Counter(_pair_key(p) for p in scene.candidate_pairs)
                except MonitorError as exc:
                    find(UNVERIFIABLE, f"the logged model edit cannot be applied to the scene: {exc}", k)
                    edits_bad_from = k if edits_bad_from is None else min(edits_bad_from, k)
        if edits_bad_from is not None and k >= edits_bad_from:
            unverifiable_after_edit.append(k)
            continue
        if verdict not in VERDICTS:
            find(CRITICAL, f"unknown verdict {verdict[:40]!r}", k)
        method = c["method"]
        claims_ok = True
        # the request this window answers: its request_id (per window, so a setting changed
        # during the run is seen), else the run's (logs before request ids), else none
        req, rid = logged_req, c.get("request_id")
        if rid is None:
            no_request_id += 1
            if logged_req is not None:
                used_requests.setdefault(0, []).append(k)
        elif not _is_int(rid) or rid not in requests:
            find(CRITICAL, f"request_id {_short(rid, 40)} names no logged request", k)
        elif requests[rid] is not None:
            req = requests[rid]
            used_requests.setdefault(rid, []).append(k)
        if method not in METHODS:
            find(CRITICAL, f"unknown method {method[:40]!r}", k)
            claims_ok = False
        for key, ok in (("margin", lambda x: x >= 0), ("epsilon", lambda x: x > 0)):
            v = c[key]
            if not _is_num(v) or not ok(v):
                find(CRITICAL, f"{key}={_short(v, 40)} is invalid", k)
                claims_ok = False
            elif key in run_claims and float(v) != run_claims[key] and rid is None:
                # with a request id the window's own request is the claim (checked below): the
                # run metadata holds the settings at log open, which the gate may change later
                find(CRITICAL, f"{key}={v} differs from the run's {run_claims[key]}", k)
        logged_pairs = Counter(_pair_key(p["geoms"]) for p in c["pairs"])
        if scene_pairs is not None and logged_pairs != scene_pairs:
            out["pairs_differ"] += 1
            missing = sum((scene_pairs - logged_pairs).values())
            extra = sum((logged_pairs - scene_pairs).values())
            find(CRITICAL, f"certificate pairs differ from the model's pair set ({missing} missing, "
                           f"{extra} extra of {sum(scene_pairs.values())})", k)
        ps = plan_msgs.get(k)
        if not ps:
            out["missing_plans"] += 1
            find(UNVERIFIABLE, "no plan logged for this window: cannot recompute", k)
            continue
        if len(ps) > 1 or scene is None or not claims_ok:
            continue  # already critical; there is no single trustworthy input to recompute from
        try:
            plan = _rebuild_plan(model, ps[0])
            t0, t1 = float(plan.t0), float(plan.t1)
            w0, w1 = (float(x) for x in c["window"])
            if not (math.isclose(w0, t0, rel_tol=1e-12, abs_tol=1e-12)
                    and math.isclose(w1, t1, rel_tol=1e-12, abs_tol=1e-12)):
                find(CRITICAL, f"window [{w0!r}, {w1!r}] is not the plan's span [{t0!r}, {t1!r}]", k)
            if req is None:  # an old log (or a forged request, already critical): as before
                new = certify(scene, plan, margin=float(c["margin"]), epsilon=float(c["epsilon"]),
                              method=method, window=(t0, t1), tolerances=tol)
            else:
                for key in ("margin", "epsilon", "method"):
                    if c[key] != getattr(req, key):
                        find(CRITICAL, f"{key}={_short(c[key], 40)} differs from the logged request's "
                                       f"{getattr(req, key)}", k)
                # the logged settings (ongoing rule, penetration_tol, ...) with this window's span,
                # the certificate's margin/epsilon/method and the default budget per window
                new = certify(scene, plan, request=req.replace(
                    margin=float(c["margin"]), epsilon=float(c["epsilon"]), method=method, window=(t0, t1)))
        except (MonitorError, ValueError, KeyError, TypeError, IndexError, OverflowError) as exc:
            out["errors"].append({"index": k, "sim_time": c.get("sim_time"),
                                  "error": f"{type(exc).__name__}: {str(exc)[:300]}"})
            find(UNVERIFIABLE, f"cannot recompute: {type(exc).__name__}: {str(exc)[:200]}", k)
            continue
        out["checked"] += 1
        out["applied_checked"] += int(is_applied_record(c))
        if new.verdict != verdict:
            critical = (new.verdict == Verdict.CERTIFIED) != (verdict == Verdict.CERTIFIED)
            budget = bool((c.get("stats") or {}).get("budget_exhausted")) and verdict == Verdict.UNCERTAIN
            if budget:  # the logged run ran out of its work budget: "uncertain" was the honest answer then
                critical = False
            # logged "uncertain", now certified: the log claimed less than the checker proves today
            # (e.g. a newer monitor: red team 12 counted 2 151 such windows of 25 340 after the relative
            # motion bounds). Not a safety flip: the gate acted on the weaker claim. Still a mismatch.
            proves_more = verdict == Verdict.UNCERTAIN and new.verdict == Verdict.CERTIFIED
            if proves_more:
                critical = False
            out["critical"] += int(critical)
            logged = as_verdict(verdict) if verdict in VERDICTS else verdict  # unknown: already critical
            out["mismatches"].append({"index": k, "sim_time": c.get("sim_time"), "logged": logged,
                                      "recomputed": new.verdict, "critical": critical,
                                      "logged_clearance": c.get("clearance"),
                                      "clearance": new.clearance if math.isfinite(new.clearance) else None,
                                      "witness": new.witness.to_dict() if new.witness else None,
                                      "reason": "budget exhausted when logged" if budget else
                                      "logged uncertain, certified now (the log claimed less)" if proves_more
                                      else None})
    if unverifiable_after_edit:
        find(UNVERIFIABLE, f"{len(unverifiable_after_edit)} window(s) from index "
                           f"{unverifiable_after_edit[0]} were certified on a model edit the log does not "
                           f"describe validly: not re-derived")
    _request_findings(used_requests, requests, find, notes, run_claims, max_penetration)
    applied = _applied_findings(contents, good, plan_msgs, find, notes)
    out.update(applied)
    out.update(_replay_findings(contents, certs, plan_msgs, replay_edits, edits_bad_from, find, notes))
    unlogged = applied["unlogged_old"]
    if unlogged:
        notes.append(f"{unlogged} replaced action(s) (blocked proposals) ran a motion that is not in the log "
                     f"(a gate logs the applied window only when it is not certified: the committed brake's "
                     f"tail or a certified fallback): re-derived are the proposals, not what was applied "
                     f"(a log from before applied motions were logged)")
    if no_request_id and (used_requests or len(requests) > 1):
        notes.append(f"{no_request_id} window(s) name no request (request_id absent): re-derived with the "
                     f"run's request" + ("" if logged_req is not None else " (none: plain rule)"))
    elif no_request_id and logged_req is None and certs:
        notes.append("no logged request (a log written before requests were logged, or certificates "
                     "without one): re-derived with the plain rule (ongoing='violation'); a run under the "
                     "ongoing-contact rule shows its resting contacts as flips")
    out["critical"] += sum(f["severity"] == CRITICAL for f in findings)
    out["unverifiable"] = sum(f["severity"] == UNVERIFIABLE for f in findings)
    return out


def signature_findings(contents: LogContents, key: bytes | None, find: Callable[..., None],
                       notes: list[str]) -> dict[str, Any]:
    """Check the log's signed checkpoints with ``key`` (:func:`monitor.log.sign.check_signatures`).

    Critical: a checkpoint that does not verify (the first is named), a key given and the log
    unsigned or signed by another key id, records after the signed close, a seal (a claimed
    close) without a signed close. Unverifiable: records after the last valid checkpoint, or no
    signed close (a copy cut after a checkpoint). Notes: no key for a signed log ("signature not
    checked: no key"), what verified. An unsigned log without a key: nothing (as before signing existed).

    Returns:
        the check as a dict (``status``, ``key_id``, ``signed_windows``, ``unsigned_windows``, ...).
    """
    from monitor.log.sign import check_signatures

    sig = check_signatures(contents, key)
    for text in sig.critical:
        find(CRITICAL, f"signature: {text}")
    for text in sig.unverifiable:
        find(UNVERIFIABLE, f"signature: {text}")
    notes.extend(sig.notes)
    return sig.to_json()


_UNSIGNED_EDITS = "were certified on in-place model edits the run logged"
"""Part of the reason of :func:`verify`'s finding on edit records it could not accept (found again by
:func:`add_signature` once the signature verified)."""
_UNSIGNED_EDITS_RE = re.compile(r"\d+ window\(s\) from index -?\d+ " + re.escape(_UNSIGNED_EDITS) + ": ")


def _signed_edits_note(n: int) -> str:
    return f"model edit records ({n}) are covered by the log's valid signature: accepted as the run's edits"


def add_signature(ver: dict[str, Any], contents: LogContents, key: bytes | None) -> dict[str, Any]:
    """Add the signature check to a :func:`verify` result made without it (``review --ray``).

    As in :func:`verify` with ``key``: when the signature verified (every record covered, signed
    close), the finding on the log's model-edit records (unverifiable without a signature) is
    dropped and the note says they were accepted.
    """
    if ver.get("error") or "findings" not in ver:
        return ver
    before = len(ver["findings"])

    def find(severity: str, reason: str, index: int | None = None) -> None:
        ver["findings"].append({"index": index, "severity": severity, "reason": reason})

    ver["notes"] = [n for n in ver.get("notes", []) if not n.startswith("signature not checked")]
    ver["signature"] = signature_findings(contents, key, find, ver["notes"])
    new = ver["findings"][before:]
    ver["critical"] = ver.get("critical", 0) + sum(f["severity"] == CRITICAL for f in new)
    if ver["signature"].get("status") == "verified":
        edits = [f for f in ver["findings"] if f["severity"] == UNVERIFIABLE and f["index"] is None
                 and _UNSIGNED_EDITS_RE.match(f["reason"])]
        if edits:
            ver["findings"] = [f for f in ver["findings"] if f not in edits]
            ver["notes"].append(_signed_edits_note(len(contents.model_edits)))
    ver["unverifiable"] = sum(f["severity"] == UNVERIFIABLE for f in ver["findings"])
    return ver


def verify_exit_code(ver: dict[str, Any]) -> int:
    """Exit code of one log's verification.

    1 a critical finding or flip; 2 anything left unverified, an error, or a non-critical
    disagreement that no logged reason explains (violation <-> uncertain); 0 all re-derived
    and agreed (a logged "uncertain" whose budget was exhausted may recompute to anything).
    """
    if ver.get("error"):
        return 2
    if ver.get("critical"):
        return 1
    if ver.get("unverifiable") or ver.get("errors") or ver.get("missing_plans") \
            or ver.get("checked", 0) < ver.get("windows", 0):
        return 2
    if any(not m.get("reason") for m in ver.get("mismatches", [])):
        return 2  # e.g. violation <-> uncertain: not a safety flip, but the window did not agree
    return 0


# --------------------------------------------------------------------------- rendering


def _fmt(x: Any, spec: str = ".4g") -> str:
    if x is None:
        return "-"
    if isinstance(x, float):
        try:
            return format(x, spec)
        except ValueError:
            return str(x)
    return str(x)


def fmt_bound(x: Any, spec: str = ".3g") -> str:
    """A clearance-like bound as text, keeping its sign.

    ``-inf``/``inf`` for the writers' +-1e308 stand-ins of infinite bounds, ``unknown`` for
    null (no bound), else ``format(x, spec)``.
    """
    if x is None:
        return "unknown"
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return str(x)[:20]
    if x <= -1e300:
        return "-inf"
    if x >= 1e300:
        return "inf"
    return format(float(x), spec)


def _fmt_point(p: Any) -> str:
    if not p:
        return "-"
    try:
        return "(" + ", ".join(f"{v:.4f}" for v in p) + ")"
    except (TypeError, ValueError):
        return str(p)[:40]


def render_text(result: dict[str, Any]) -> str:
    """Human-readable text of a review result (``{"logs": [...], "total": ...}``).

    Each log is rendered inside its own error handling: an entry that cannot be rendered
    gets an ``ERROR`` line and ``entry["render_error"]``; the other logs are unaffected.
    """
    lines: list[str] = []
    for entry in result["logs"]:
        part: list[str] = []
        try:
            _render_entry(entry, part)
        except Exception as exc:  # noqa: BLE001 - one unrenderable log never costs the others
            entry["render_error"] = f"{type(exc).__name__}: {exc}"
            part.append(f"   ERROR: cannot render this log: {entry['render_error']}")
        lines += part
    tot = result.get("total")
    if tot and tot["logs"] > 1:
        v = tot["verdicts"]
        lines.append(f"== total over {tot['logs']} logs: windows {tot['windows']}: "
                     f"certified {v[Verdict.CERTIFIED]}, violation {v[Verdict.VIOLATION]}, "
                     f"uncertain {v[Verdict.UNCERTAIN]}; blocked {tot['blocked_actions']}")
    if "exit_code" in result:
        lines.append(f"exit code {result['exit_code']}: {EXIT_MEANING.get(result['exit_code'], '?')}")
    return "\n".join(lines)


EXIT_MEANING = {0: "every window re-derived and agreed (or no --verify) and nothing skipped",
                1: "CRITICAL: a forged or wrong claim, or a certified <-> not-certified flip",
                2: "incomplete: something could not be read or re-verified"}
"""Review exit codes (1 takes precedence over 2)."""


def _render_entry(entry: dict[str, Any], lines: list[str]) -> None:
    f = entry.get("file", {})
    lines.append(f"== {f.get('path', entry.get('path'))}")
    if entry.get("error"):
        lines.append(f"   ERROR: {entry['error']}")
        return
    if f.get("stop_kind") == "corrupt":
        lines.append(f"   DAMAGED: {f.get('stop_reason')}; {f.get('unreadable_bytes')} unreadable byte(s); "
                     f"showing the readable part")
    elif not f.get("complete"):
        lines.append(f"   WARNING: incomplete log: {f.get('stop_reason')}; {f.get('unreadable_bytes')} "
                     f"unreadable byte(s) at the end; showing the recovered part")
    skipped = (f.get("bad_payloads") or 0) + (f.get("bad_records") or 0) + len(entry.get("bad_messages", []))
    if skipped:
        lines.append(f"   SKIPPED: {f.get('bad_payloads') or 0} undecodable message(s), "
                     f"{f.get('bad_records') or 0} damaged record(s), {len(entry.get('bad_messages', []))} "
                     f"malformed certificate(s)")
        for why in (f.get("problems") or [])[:5]:
            lines.append(f"     {why}")
        for row in entry.get("bad_messages", [])[:5]:
            lines.append(f"     certificate index {row['index']}: {row['problem']}")
    for why in entry.get("integrity", []):
        lines.append(f"   INTEGRITY: {why}")
    for row in entry.get("unknown_verdicts", [])[:10]:
        lines.append(f"   UNKNOWN VERDICT {row['verdict']!r} in window {row['index']} (not counted below)")
    run = entry.get("run", {})
    v = entry["verdicts"]
    lat = entry["latency_us"]
    lines += [
        f"   mujoco {entry.get('versions', {}).get('mujoco', '?')}, margin {_fmt(run.get('margin'))}, "
        f"epsilon {_fmt(run.get('epsilon'))}, pairs {_fmt(run.get('pairs'))}, "
        f"predictor {_fmt(run.get('predictor'))}",
        f"   windows {entry['windows']}: certified {v[Verdict.CERTIFIED]}, violation {v[Verdict.VIOLATION]}, "
        f"uncertain {v[Verdict.UNCERTAIN]}",
        f"   actions {entry['actions']}, blocked/replaced {entry['blocked_actions']}"
        + (f"; applied motions logged {entry['applied_motions']['records']} "
           f"({', '.join(f'{k} {n}' for k, n in sorted(entry['applied_motions']['verdicts'].items()))})"
           if entry.get("applied_motions", {}).get("records") else ""),
        f"   us per certification: p50 {_fmt(lat['p50'], '.1f')}, p95 {_fmt(lat['p95'], '.1f')}, "
        f"max {_fmt(lat['max'], '.1f')} (n={lat['n']})",
        "   checker mix: " + (", ".join(f"{k} {n}" for k, n in sorted(entry["checker_mix"].items()))
                              or "-"),
    ]
    rows = entry["violations"]
    if rows:
        lines.append(f"   {'sim time':>10} {'verdict':9} {'at t':>10}  {'bodies':28} {'geoms':32} "
                     f"{'witness point (m)':32} {'distance':>10} {'clearance':>10}")
        for r in rows:
            lines.append(
                f"   {_fmt(r['sim_time'], '.4f'):>10} {r['verdict']:9} {_fmt(r['time'], '.4f'):>10}  "
                f"{' / '.join(map(str, r['bodies'])) or '-':28} {' / '.join(map(str, r['geoms'])) or '-':32} "
                f"{_fmt_point(r['point']):32} {fmt_bound(r['distance']):>10} "
                f"{fmt_bound(r['clearance']):>10}")
    if entry.get("signature"):  # checked without --verify
        _render_signature(entry["signature"], lines, findings=True)
    ver = entry.get("verify")
    if ver:
        if ver.get("error"):
            lines.append(f"   verify: ERROR {ver['error']}")
            return
        lines.append(f"   verify ({ver['model_source']}): {ver['checked']} re-derived, "
                     f"{len(ver['mismatches'])} mismatch(es), {ver['critical']} critical, "
                     f"{ver['missing_plans']} without plan, {len(ver['errors'])} error(s); "
                     f"{ver.get('unverifiable', 0)} unverifiable, {ver.get('pairs_differ', 0)} with a "
                     f"different pair set; {ver.get('windows', '?')} window(s) in the log")
        if ver.get("replayed") or ver.get("replay_failed") or ver.get("replay_user"):
            lines.append(f"     rollouts re-simulated: {ver.get('replayed', 0)} window(s) identical, "
                         f"{ver.get('replay_failed', 0)} failed, {ver.get('replay_user', 0)} with rows from "
                         f"user code; {ver.get('continuity_checked', 0)} step-to-step continuity check(s)")
        if ver.get("applied_records") or ver.get("applied_missing"):
            lines.append(f"     applied motions re-derived: {ver.get('applied_checked', 0)} record(s) of "
                         f"{ver.get('applied_records', 0)}, covering {ver.get('applied_steps', 0)} replaced "
                         f"step(s); {ver.get('applied_missing', 0)} replaced step(s) without a record")
        _render_signature(ver.get("signature"), lines, findings=False)
        mc = ver.get("model_consistency")
        if mc:
            lines.append(f"     model: {mc['status']}: {mc['detail']}")
        for mm in ver["mismatches"]:
            lines.append(f"     window {mm['index']} t={_fmt(mm['sim_time'], '.4f')}: logged "
                         f"{mm['logged']} -> recomputed {mm['recomputed']}"
                         + ("  [CRITICAL]" if mm["critical"] else "")
                         + (f"  ({mm['reason']})" if mm.get("reason") else ""))
        findings = ver.get("findings", [])
        for sev in (CRITICAL, UNVERIFIABLE):
            rows_f = [x for x in findings if x["severity"] == sev]
            for x in rows_f[:20]:
                where = "log" if x["index"] is None else f"window {x['index']}"
                lines.append(f"     [{sev.upper()}] {where}: {x['reason']}")
            if len(rows_f) > 20:
                lines.append(f"     ... and {len(rows_f) - 20} more {sev} finding(s)")
        for note in ver.get("notes", []):
            lines.append(f"     note: {note}")


def _render_signature(sig: dict[str, Any] | None, lines: list[str], findings: bool) -> None:
    """One status line for a signature check (and, ``findings``, its findings and notes)."""
    if not sig or (sig.get("status") == "unsigned" and not sig.get("key_id")):
        return
    unsigned = sig.get("unsigned_windows") or []
    head = (f"   signature: {sig['status']} (log key id {sig.get('log_key_id') or '-'}, key given "
            f"{sig.get('key_id') or '-'})")
    if sig.get("key_id") is None:
        lines.append(f"{head}: {sig.get('checkpoints', 0)} checkpoint(s), not checked")
    else:
        lines.append(f"{head}: {sig.get('valid', 0)} of {sig.get('checkpoints', 0)} checkpoint(s) valid, "
                     f"{sig.get('signed_windows', 0)} window(s) signed, {len(unsigned)} not"
                     + ("; signed close" if sig.get("signed_close") else ""))
    if findings:
        for sev, texts in ((CRITICAL, sig.get("critical", [])), (UNVERIFIABLE, sig.get("unverifiable", []))):
            lines += [f"     [{sev.upper()}] log: signature: {t}" for t in texts]
        lines += [f"     note: {t}" for t in sig.get("notes", [])]


def signature_exit_code(sig: dict[str, Any]) -> int:
    """Exit code of a signature check alone (review without --verify): 1 critical, 2 unverifiable, else 0."""
    return 1 if sig.get("critical") else (2 if sig.get("unverifiable") else 0)


def _pyplot() -> Any:
    """matplotlib.pyplot with the Agg backend; DependencyNotInstalled names the extra when missing."""
    try:
        import matplotlib
    except ImportError as exc:
        from monitor.errors import DependencyNotInstalled

        raise DependencyNotInstalled("the HTML report (--report) needs matplotlib: "
                                     "pip install 'monitor[report]'") from exc
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _png(fig: Any) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    _pyplot().close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


WARMUP_WINDOWS = 1
"""Windows at the start of a log whose latency is reported apart from the histogram: the
first certification of a process compiles the numba kernels (seconds, not microseconds)."""


def split_warmup(latency_us: list[float | None]) -> tuple[list[float], list[float]]:
    """(warm-up latencies, the rest) in µs, dropping unknown values."""
    head = [x for x in latency_us[:WARMUP_WINDOWS] if x is not None]
    rest = [x for x in latency_us[WARMUP_WINDOWS:] if x is not None]
    return head, rest


def _x_axis(entry: dict[str, Any]) -> tuple[np.ndarray, str, list[int]]:
    """The x values, label and episode starts: sim time for one episode, window index for several."""
    s = entry["series"]
    eps = s.get("episode") or [0] * len(s["sim_time"])
    if len(set(eps)) > 1:
        idx = np.asarray(s.get("index") or range(len(eps)), float)
        starts = [int(idx[i]) for i in range(1, len(eps)) if eps[i] != eps[i - 1]]
        return idx, "window index (dashed: episode starts)", starts
    return np.asarray(s["sim_time"], float), "simulation time (s)", []


def _plots(entry: dict[str, Any]) -> list[tuple[str, str]]:
    plt = _pyplot()
    s = entry["series"]
    x, xlabel, starts = _x_axis(entry)
    out = []
    colors = {Verdict.CERTIFIED: "tab:green", Verdict.UNCERTAIN: "tab:orange", Verdict.VIOLATION: "tab:red"}
    blocked = entry.get("blocked", [])
    reasons = sorted({str(b.get("reason") or "replaced") for b in blocked})
    fig, axes = plt.subplots(2, 1, figsize=(17, 2.2 + 0.35 * max(len(reasons), 1) + 1.2), sharex=True,
                             gridspec_kw={"height_ratios": [3, max(len(reasons), 1) + 1]})
    ax = axes[0]
    for i, v in enumerate(VERDICTS):
        sel = [j for j, y in enumerate(s["verdict"]) if y == v]
        ax.scatter(x[sel], np.full(len(sel), i), s=8, color=colors[v], label=v)
    ax.set_yticks(range(3), VERDICTS)
    ax.set_title("verdict timeline and blocked actions")
    ax = axes[1]
    if blocked:
        pos = {int(k): float(v) for k, v in zip(s.get("index") or [], x)}
        bx = [pos.get(int(b["index"]), np.nan) if b.get("index") is not None else np.nan for b in blocked]
        by = [reasons.index(str(b.get("reason") or "replaced")) for b in blocked]
        ax.scatter(bx, by, s=10, marker="|", color="tab:red")
        ax.set_yticks(range(len(reasons)), [r if len(r) <= 48 else r[:45] + "..." for r in reasons])
    else:
        ax.set_yticks([0], ["no blocked actions"])
    ax.set_ylim(-0.7, max(len(reasons), 1) - 0.3)
    ax.set_xlabel(xlabel)
    for a in axes:
        for st in starts:
            a.axvline(st, color="grey", ls="--", lw=0.6)
    out.append(("Verdict timeline and blocked actions (with the reason for each block)", _png(fig)))
    fig, ax = plt.subplots(figsize=(13, 3))
    cl = np.array([np.nan if c is None else c for c in s["clearance"]], float)
    cl[cl < -1e300] = np.nan  # version-1 logs wrote unknown as -1e308
    ax.plot(x, cl, ".-", ms=3, lw=0.8, label="certified clearance lower bound (gaps: unknown)")
    margins = [m for m in s["margin"] if isinstance(m, (int, float))]
    if margins:
        ax.axhline(float(np.max(margins)), color="tab:red", ls="--", lw=0.8, label="margin")
    for st in starts:
        ax.axvline(st, color="grey", ls="--", lw=0.6)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("clearance (m)")
    ax.legend(loc="best", fontsize=8)
    ax.set_title("clearance over time")
    out.append(("Clearance over time", _png(fig)))
    fig, ax = plt.subplots(figsize=(13, 3))
    head, lat = split_warmup(s["latency_us"])
    lat_pos = [v for v in lat if v > 0]
    if lat_pos:
        lo, hi = min(lat_pos), max(lat_pos)
        bins = np.geomspace(lo, hi * 1.0001, min(50, max(5, len(lat_pos) // 5)) + 1) if hi > lo else 5
        ax.hist(lat_pos, bins=bins, color="tab:blue")
        ax.set_xscale("log")
    ax.set_xlabel("µs per certification (log scale)")
    ax.set_ylabel("windows")
    warm = f"; first window (JIT warm-up) {head[0] / 1e6:.3g} s, not shown" if head else ""
    ax.set_title(f"certification latency, {len(lat_pos)} windows{warm}")
    out.append(("Latency histogram (warm-up reported apart)", _png(fig)))
    mix = entry["checker_mix"]
    fig, ax = plt.subplots(figsize=(8, 2.5))
    if mix:
        ax.barh(list(mix), list(mix.values()), color="tab:purple")
    ax.set_xlabel("pairs")
    ax.set_title("checker mix")
    out.append(("Checker mix", _png(fig)))
    return out


def _table(header: list[str], rows: list[list[Any]], cls: str = "") -> str:
    esc = html.escape
    head = "".join(f"<th>{esc(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{esc(str(x))}</td>" for x in r) + "</tr>" for r in rows)
    return f"<table class='{cls}'><tr>{head}</tr>{body}</table>"


def _verify_html(ver: dict[str, Any]) -> str:
    if ver.get("error"):
        return f"<p class='bad'>verification could not run: {html.escape(str(ver['error']))}</p>"
    parts = [_table(["model", "re-derived", "applied motions re-derived", "mismatches", "critical flips",
                     "without plan", "errors", "pair set differs"],
                    [[ver.get("model_source"), ver.get("checked"), ver.get("applied_checked", 0),
                      len(ver.get("mismatches", [])), ver.get("critical"), ver.get("missing_plans"),
                      len(ver.get("errors", [])), ver.get("pairs_differ", 0)]], "summary")]
    sig = ver.get("signature") or {}
    if sig.get("key_id") or sig.get("status", "unsigned") != "unsigned":
        parts.append("<h4>Signature</h4>" + _table(
            ["status", "log key id", "key given", "checkpoints valid", "windows signed", "windows not signed",
             "signed close"],
            [[sig.get("status"), sig.get("log_key_id") or "-", sig.get("key_id") or "-",
              f"{sig.get('valid', 0)} of {sig.get('checkpoints', 0)}", sig.get("signed_windows", 0),
              len(sig.get("unsigned_windows") or []), "yes" if sig.get("signed_close") else "no"]],
            "bad" if sig.get("critical") or sig.get("unverifiable") else ""))
    if ver.get("mismatches"):
        parts.append("<h4>Windows whose verdict changed</h4>" + _table(
            ["window", "sim time", "logged", "recomputed", "critical", "logged clearance", "clearance",
             "note"],
            [[m["index"], _fmt(m["sim_time"], ".4f"), m["logged"], m["recomputed"],
              "CRITICAL" if m["critical"] else "", _fmt(m.get("logged_clearance"), ".3g"),
              _fmt(m.get("clearance"), ".3g"), m.get("reason") or ""] for m in ver["mismatches"]]))
    if ver.get("errors"):
        parts.append("<h4>Windows that could not be re-verified</h4>" + _table(
            ["window", "sim time", "error"],
            [[e["index"], _fmt(e.get("sim_time"), ".4f"), e["error"]] for e in ver["errors"]]))
    return "".join(parts)


_CSS = ("body{font-family:sans-serif;margin:1em 2em;max-width:none}"
        "table{border-collapse:collapse;margin:0.5em 0}"
        "td,th{border:1px solid #ccc;padding:2px 8px;font-size:90%;text-align:left}"
        "th{background:#f0f0f0}pre{background:#f6f6f6;padding:1em;overflow-x:auto}"
        "img{max-width:100%;height:auto;display:block}img.wide{width:100%}.bad{color:#b00}"
        ".grid{display:grid;grid-template-columns:repeat(auto-fit,minmax(560px,1fr));gap:1em}")


def write_report(result: dict[str, Any], path: str) -> int:
    """Write a self-contained HTML page (summary, tables, embedded PNG plots) using the page width.

    Returns:
        Number of embedded plots.

    Raises:
        DependencyNotInstalled: matplotlib is missing (``pip install 'monitor[report]'``).
    """
    esc = html.escape
    _pyplot()  # fail before writing anything when matplotlib is missing
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'>"
             "<meta name='viewport' content='width=device-width, initial-scale=1'>"
             "<title>monitor review</title>",
             f"<style>{_CSS}</style></head><body><h1>monitor review</h1>",
             f"<pre>{esc(render_text(result))}</pre>"]
    n_plots = 0
    for entry in result["logs"]:
        if entry.get("error") or "series" not in entry:
            continue
        parts.append(f"<h2>{esc(entry['file']['path'])}</h2>")
        if entry.get("verify"):
            parts.append("<h3>Re-verification (--verify)</h3>" + _verify_html(entry["verify"]))
        plots = _plots(entry)
        parts.append(f"<h3>{esc(plots[0][0])}</h3><img class='wide' alt='{esc(plots[0][0])}' "
                     f"src='data:image/png;base64,{plots[0][1]}'/><div class='grid'>")
        for title, b64 in plots[1:]:
            parts.append(f"<div><h3>{esc(title)}</h3><img alt='{esc(title)}' "
                         f"src='data:image/png;base64,{b64}'/></div>")
        parts.append("</div>")
        n_plots += len(plots)
        head, _ = split_warmup(entry["series"]["latency_us"])
        if head:
            parts.append(f"<p>First window (includes the JIT warm-up): {head[0] / 1e6:.3g} s; "
                         f"not in the histogram.</p>")
        if entry.get("blocked"):
            parts.append(f"<h3>Blocked actions ({len(entry['blocked'])})</h3>" + _table(
                ["window", "episode", "sim time", "reason"],
                [[b["index"], b.get("episode", 0), _fmt(b["sim_time"], ".4f"), b.get("reason") or "-"]
                 for b in entry["blocked"][:500]]))
        if entry["violations"]:
            parts.append("<h3>Violations and uncertain windows</h3>" + _table(
                ["sim time", "verdict", "at t", "bodies", "geoms", "witness point", "distance", "clearance"],
                [[_fmt(r["sim_time"], ".4f"), r["verdict"], _fmt(r["time"], ".4f"), " / ".join(r["bodies"]),
                  " / ".join(r["geoms"]), _fmt_point(r["point"]), _fmt(r["distance"], ".3g"),
                  _fmt(r["clearance"], ".3g")] for r in entry["violations"]]))
    parts.append("</body></html>")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(parts))
    return n_plots


def strip_series(result: dict[str, Any]) -> dict[str, Any]:
    """Copy of a review result without the per-window series (compact JSON)."""
    logs = [{k: v for k, v in e.items() if k != "series"} for e in result["logs"]]
    return {**result, "logs": logs}


__all__ = ["analyze", "combine", "verify", "verify_exit_code", "render_text", "write_report", "strip_series",
           "certificate_problem", "split_certificates", "tolerance_problems", "make_tolerances",
           "parse_pair_policy", "fmt_bound", "split_warmup", "VERDICTS", "METHODS", "EXIT_MEANING",
           "WARMUP_WINDOWS"]
