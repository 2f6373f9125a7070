"""Offline review of monitor MCAP logs: pure analysis, re-verification, rendering.

* :func:`analyze` turns a :class:`~monitor.log.reader.LogContents` into a plain,
  JSON-serialisable summary dict (no I/O, no printing).
* :func:`verify` recomputes every logged certificate from the model attached to
  the log and the logged plan, with the logged margin, epsilon, method, pair
  policy and tolerances, and lists the windows whose verdict changed.
* :func:`render_text` and :func:`write_report` present those dicts (text table,
  self-contained HTML with embedded matplotlib PNGs).

The CLI (``python -m monitor review``) lives in :mod:`monitor.commands.review`.
"""

from __future__ import annotations

import base64
import html
import io
import math
from collections import Counter
from typing import Any

import numpy as np

from monitor.log import topics
from monitor.log.reader import LogContents

VERDICTS = ("certified", "violation", "uncertain")


def _percentile(x: list[float], q: float) -> float | None:
    return float(np.percentile(np.asarray(x, float), q)) if x else None


def _checker_mix(cert: dict[str, Any]) -> Counter:
    mix = (cert.get("stats") or {}).get("checker_mix")
    if isinstance(mix, dict) and mix:
        return Counter({str(k): int(v) for k, v in mix.items() if isinstance(v, (int, float))})
    return Counter(str(p.get("method", "?")) for p in cert.get("pairs", []))


def _violation_row(cert: dict[str, Any]) -> dict[str, Any]:
    wit = cert.get("witness")
    bad = [p for p in cert.get("pairs", []) if p.get("verdict") != "certified"]
    if wit:
        pair = next((p for p in bad if list(p.get("geoms", [])) == list(wit.get("geoms", []))), None)
        geoms = list(wit.get("geoms", []))
        bodies = list(pair.get("bodies", [])) if pair else []
        return {"index": cert.get("index"), "sim_time": cert.get("sim_time"), "verdict": cert["verdict"],
                "time": wit.get("time"), "geoms": geoms, "bodies": bodies, "point": wit.get("point"),
                "distance": wit.get("distance"), "clearance": cert.get("clearance"),
                "pairs": len(bad)}
    first = bad[0] if bad else {}
    return {"index": cert.get("index"), "sim_time": cert.get("sim_time"), "verdict": cert["verdict"],
            "time": cert.get("earliest_time"), "geoms": list(first.get("geoms", [])),
            "bodies": list(first.get("bodies", [])), "point": None, "distance": None,
            "clearance": cert.get("clearance"), "pairs": len(bad)}


def analyze(contents: LogContents) -> dict[str, Any]:
    """Summary of one log (pure function of the recovered contents).

    Returns:
        dict with ``file`` (path, size, complete, unreadable_bytes, stop_reason,
        messages, bad_payloads), ``run`` (metadata), ``windows``, ``verdicts``
        ({verdict: count}), ``blocked_actions``, ``actions``, ``latency_us``
        ({p50, p95, max, n}), ``checker_mix`` ({method: pairs}), ``violations``
        (rows: index, sim_time, verdict, time, geoms, bodies, point, distance,
        clearance), and ``series`` (per-window sim_time, verdict, clearance,
        latency_us for plots).
    """
    certs = contents.certificates()
    verdicts = Counter({v: 0 for v in VERDICTS})
    mix: Counter = Counter()
    lat: list[float] = []
    series = {"sim_time": [], "verdict": [], "clearance": [], "latency_us": [], "margin": []}
    rows = []
    for c in certs:
        v = c.get("verdict")
        if v not in VERDICTS:
            continue
        verdicts[v] += 1
        mix.update(_checker_mix(c))
        ws = (c.get("stats") or {}).get("wall_seconds")
        us = float(ws) * 1e6 if isinstance(ws, (int, float)) and math.isfinite(ws) else None
        if us is not None:
            lat.append(us)
        series["sim_time"].append(float(c.get("sim_time", c["_log_time"] * 1e-9)))
        series["verdict"].append(v)
        cl = c.get("clearance")
        series["clearance"].append(float(cl) if isinstance(cl, (int, float)) else None)
        series["latency_us"].append(us)
        series["margin"].append(c.get("margin"))
        if v != "certified":
            rows.append(_violation_row(c))
    actions = contents.topic(topics.ACTION)
    run = {k: v for k, v in contents.run.items() if not k.startswith("version.")}
    for key in ("margin", "epsilon", "method"):  # not in the metadata: from the first certificate
        if run.get(key) is None and certs and key in certs[0]:
            run[key] = certs[0][key]
    return {
        "file": {"path": contents.path, "size": contents.size, "complete": contents.complete,
                 "unreadable_bytes": contents.unreadable_bytes, "stop_reason": contents.stop_reason,
                 "messages": dict(contents.counts), "bad_payloads": contents.bad_payloads,
                 "library": contents.library, "attachments": sorted(contents.attachments)},
        "run": run,
        "versions": {k[len("version."):]: v for k, v in contents.run.items() if k.startswith("version.")},
        "windows": sum(verdicts.values()),
        "verdicts": dict(verdicts),
        "actions": len(actions),
        "blocked_actions": sum(1 for a in actions if a.get("replaced")),
        "latency_us": {"n": len(lat), "p50": _percentile(lat, 50), "p95": _percentile(lat, 95),
                       "max": max(lat) if lat else None},
        "checker_mix": dict(mix),
        "violations": rows,
        "series": series,
    }


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


def _rebuild_plan(model: Any, msg: dict[str, Any]) -> Any:
    from monitor.errors import InvalidInputError

    times = np.asarray(msg["times"], dtype=np.float64)
    if msg.get("kind", "plan") == "bodymotion":
        from monitor.motion.bodymotion import BodyMotion

        return BodyMotion(times, np.asarray(msg["pos"], np.float64), np.asarray(msg["quat"], np.float64))
    from monitor.motion.plan import Plan

    qpos = np.asarray(msg["qpos"], dtype=np.float64)
    if qpos.ndim != 2 or qpos.shape[1] != model.nq:
        raise InvalidInputError(f"logged plan qpos has shape {qpos.shape}, model has nq={model.nq}")
    kw = {}
    for key, width in (("mocap_pos", 3), ("mocap_quat", 4)):
        if msg.get(key) is not None:  # JSON writes a (0, 3) array as []: restore the shape
            kw[key] = np.asarray(msg[key], dtype=np.float64).reshape(-1, width)
    return Plan(times, qpos, model=model, **kw)


def _engine() -> tuple[Any, Any]:
    """(Scene class, certify function); ImportError while the engine is not installed."""
    from monitor.certify.engine import certify
    from monitor.scene import Scene

    return Scene, certify


def _tolerances(run: dict[str, Any]) -> Any:
    from monitor.tolerances import DEFAULT, Tolerances

    tol = run.get("tolerances")
    if isinstance(tol, dict):
        known = {k: v for k, v in tol.items() if k in Tolerances.__dataclass_fields__}
        return Tolerances(**known)
    return DEFAULT


def _pair_policy(run: dict[str, Any], cert: dict[str, Any]) -> Any:
    pol = run.get("pairs", run.get("pair_policy"))
    if pol in ("mujoco", "all"):
        return pol
    if isinstance(pol, list):
        return [tuple(p) for p in pol]
    return [tuple(p["geoms"]) for p in cert.get("pairs", [])]  # no policy logged: the certificate's pairs


def verify(contents: LogContents, *, model_source: str = "auto", progress: bool | None = None,
           limit: int | None = None) -> dict[str, Any]:
    """Recompute every logged certificate from the log alone.

    For each certificate message: rebuild ``Plan`` from the logged plan (same
    index), ``Scene.from_model`` on the attached model with the logged pair policy
    (and facets/tolerances if logged), and call ``monitor.certify`` with the
    certificate's margin, epsilon, method and window.

    Args:
        contents: a read log.
        model_source: ``"auto" | "xml" | "mjb"`` (see :func:`monitor.log.reader.load_model`).
        progress: tqdm bar over windows; None = when there are more than 200.
        limit: verify only the first ``limit`` windows.

    Returns:
        dict with ``checked``, ``model_source``, ``mismatches`` (rows: index,
        sim_time, logged, recomputed, critical, logged_clearance, clearance),
        ``critical`` (number of certified <-> not-certified flips, except logged
        "uncertain" windows whose ``stats["budget_exhausted"]`` is true), ``missing_plans``,
        ``errors`` (rows: index, error), ``pairs_differ`` (windows whose pair set
        differs from the scene's).

    Raises:
        LogFormatError: the model cannot be rebuilt from the attachments.
    """
    from monitor.errors import MonitorError
    from monitor.log.reader import load_model

    scene_cls, certify = _engine()
    model, how = load_model(contents, model_source)
    run = contents.run
    tol = _tolerances(run)
    plans = contents.plans_by_index()
    certs = contents.certificates()
    if limit is not None:
        certs = certs[:limit]
    out: dict[str, Any] = {"checked": 0, "model_source": how, "mismatches": [], "critical": 0,
                           "missing_plans": 0, "errors": [], "pairs_differ": 0}
    scenes: dict[Any, Any] = {}
    it = certs
    if progress is None:
        progress = len(certs) > 200
    if progress:
        from tqdm import tqdm

        it = tqdm(certs, desc=f"verifying {contents.path}", unit="win", leave=False)
    for c in it:
        k = int(c.get("index", -1))
        if k not in plans:
            out["missing_plans"] += 1
            continue
        try:
            policy = _pair_policy(run, c)
            key = policy if isinstance(policy, str) else tuple(policy)
            if key not in scenes:
                kw = {"tolerances": tol}
                if run.get("facets") is not None:
                    kw["facets"] = int(run["facets"])
                scenes[key] = scene_cls.from_model(model, pairs=policy, **kw)
            scene = scenes[key]
            plan = _rebuild_plan(model, plans[k])
            logged_pairs = [tuple(p["geoms"]) for p in c.get("pairs", [])]
            ckw: dict[str, Any] = {"window": tuple(c["window"]), "tolerances": tol}
            if logged_pairs and set(logged_pairs) != set(map(tuple, scene.candidate_pairs)):
                out["pairs_differ"] += 1
                ckw["pairs"] = logged_pairs
            new = certify(scene, plan, margin=float(c["margin"]), epsilon=float(c["epsilon"]),
                                  method=str(c.get("method", "auto")), **ckw)
        except (MonitorError, ValueError, KeyError, TypeError, IndexError) as exc:
            out["errors"].append({"index": k, "sim_time": c.get("sim_time"),
                                  "error": f"{type(exc).__name__}: {exc}"})
            continue
        out["checked"] += 1
        if new.verdict != c["verdict"]:
            critical = (new.verdict == "certified") != (c["verdict"] == "certified")
            budget = bool((c.get("stats") or {}).get("budget_exhausted")) and c["verdict"] == "uncertain"
            if budget:  # the logged run ran out of its work budget: "uncertain" was the honest answer then
                critical = False
            out["critical"] += int(critical)
            out["mismatches"].append({"index": k, "sim_time": c.get("sim_time"), "logged": c["verdict"],
                                      "recomputed": new.verdict, "critical": critical,
                                      "logged_clearance": c.get("clearance"),
                                      "clearance": new.clearance if math.isfinite(new.clearance) else None,
                                      "witness": new.witness.to_dict() if new.witness else None,
                                      "reason": "budget exhausted when logged" if budget else None})
    return out


# --------------------------------------------------------------------------- rendering


def _fmt(x: Any, spec: str = ".4g") -> str:
    if x is None:
        return "-"
    if isinstance(x, float):
        return format(x, spec)
    return str(x)


def _fmt_point(p: Any) -> str:
    return "-" if not p else "(" + ", ".join(f"{v:.4f}" for v in p) + ")"


def render_text(result: dict[str, Any]) -> str:
    """Human-readable text of a review result (``{"logs": [...], "total": ...}``)."""
    lines: list[str] = []
    for entry in result["logs"]:
        f = entry.get("file", {})
        lines.append(f"== {f.get('path', entry.get('path'))}")
        if entry.get("error"):
            lines.append(f"   ERROR: {entry['error']}")
            continue
        if not f.get("complete"):
            lines.append(f"   WARNING: incomplete log: {f.get('stop_reason')}; {f.get('unreadable_bytes')} "
                         f"unreadable byte(s) at the end; showing the recovered part")
        if f.get("bad_payloads"):
            lines.append(f"   WARNING: {f['bad_payloads']} undecodable message(s) skipped")
        run = entry.get("run", {})
        v = entry["verdicts"]
        lat = entry["latency_us"]
        lines += [
            f"   mujoco {entry.get('versions', {}).get('mujoco', '?')}, margin {_fmt(run.get('margin'))}, "
            f"epsilon {_fmt(run.get('epsilon'))}, pairs {_fmt(run.get('pairs'))}, "
            f"predictor {_fmt(run.get('predictor'))}",
            f"   windows {entry['windows']}: certified {v['certified']}, violation {v['violation']}, "
            f"uncertain {v['uncertain']}",
            f"   actions {entry['actions']}, blocked/replaced {entry['blocked_actions']}",
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
                    f"{' / '.join(r['bodies']) or '-':28} {' / '.join(r['geoms']) or '-':32} "
                    f"{_fmt_point(r['point']):32} {_fmt(r['distance'], '.3g'):>10} "
                    f"{_fmt(r['clearance'], '.3g'):>10}")
        ver = entry.get("verify")
        if ver:
            if ver.get("error"):
                lines.append(f"   verify: ERROR {ver['error']}")
            else:
                lines.append(f"   verify ({ver['model_source']}): {ver['checked']} re-derived, "
                             f"{len(ver['mismatches'])} mismatch(es), {ver['critical']} critical, "
                             f"{ver['missing_plans']} without plan, {len(ver['errors'])} error(s)")
                for mm in ver["mismatches"]:
                    lines.append(f"     window {mm['index']} t={_fmt(mm['sim_time'], '.4f')}: logged "
                                 f"{mm['logged']} -> recomputed {mm['recomputed']}"
                                 + ("  [CRITICAL]" if mm["critical"] else "")
                                 + (f"  ({mm['reason']})" if mm.get("reason") else ""))
                for e in ver["errors"][:10]:
                    lines.append(f"     window {e['index']}: {e['error']}")
    tot = result.get("total")
    if tot and tot["logs"] > 1:
        v = tot["verdicts"]
        lines.append(f"== total over {tot['logs']} logs: windows {tot['windows']}: "
                     f"certified {v['certified']}, violation {v['violation']}, "
                     f"uncertain {v['uncertain']}; blocked {tot['blocked_actions']}")
    return "\n".join(lines)


def _png(fig: Any) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _plots(entry: dict[str, Any]) -> list[tuple[str, str]]:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    s = entry["series"]
    t = np.asarray(s["sim_time"], float)
    out = []
    colors = {"certified": "tab:green", "uncertain": "tab:orange", "violation": "tab:red"}
    fig, ax = plt.subplots(figsize=(8, 2.2))
    for i, v in enumerate(VERDICTS):
        sel = [j for j, x in enumerate(s["verdict"]) if x == v]
        ax.scatter(t[sel], np.full(len(sel), i), s=8, color=colors[v], label=v)
    ax.set_yticks(range(3), VERDICTS)
    ax.set_xlabel("simulation time (s)")
    ax.set_title("verdict timeline")
    out.append(("Verdict timeline", _png(fig)))
    fig, ax = plt.subplots(figsize=(8, 3))
    cl = np.array([np.nan if c is None else c for c in s["clearance"]], float)
    cl[cl < -1e300] = np.nan
    ax.plot(t, cl, ".-", ms=3, lw=0.8, label="certified clearance lower bound")
    margins = [m for m in s["margin"] if isinstance(m, (int, float))]
    if margins:
        ax.axhline(float(np.max(margins)), color="tab:red", ls="--", lw=0.8, label="margin")
    ax.set_xlabel("simulation time (s)")
    ax.set_ylabel("clearance (m)")
    ax.legend(loc="best", fontsize=8)
    ax.set_title("clearance over time")
    out.append(("Clearance over time", _png(fig)))
    fig, ax = plt.subplots(figsize=(8, 3))
    lat = [x for x in s["latency_us"] if x is not None]
    if lat:
        ax.hist(lat, bins=min(50, max(5, len(lat) // 5)), color="tab:blue")
    ax.set_xlabel("µs per certification")
    ax.set_ylabel("windows")
    ax.set_title("certification latency")
    out.append(("Latency histogram", _png(fig)))
    mix = entry["checker_mix"]
    fig, ax = plt.subplots(figsize=(6, 2.5))
    if mix:
        ax.barh(list(mix), list(mix.values()), color="tab:purple")
    ax.set_xlabel("pairs")
    ax.set_title("checker mix")
    out.append(("Checker mix", _png(fig)))
    return out


def write_report(result: dict[str, Any], path: str) -> int:
    """Write a self-contained HTML page (summary, tables, embedded PNG plots).

    Returns:
        Number of embedded plots.
    """
    esc = html.escape
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>monitor review</title>",
             "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
             "td,th{border:1px solid #ccc;padding:2px 6px;font-size:90%}pre{background:#f6f6f6;padding:1em}"
             "</style></head><body><h1>monitor review</h1>",
             f"<pre>{esc(render_text(result))}</pre>"]
    n_plots = 0
    for entry in result["logs"]:
        if entry.get("error") or "series" not in entry:
            continue
        parts.append(f"<h2>{esc(entry['file']['path'])}</h2>")
        for title, b64 in _plots(entry):
            parts.append(f"<h3>{esc(title)}</h3><img alt='{esc(title)}' src='data:image/png;base64,{b64}'/>")
            n_plots += 1
        if entry["violations"]:
            parts.append("<h3>Violations and uncertain windows</h3><table><tr><th>sim time</th>"
                         "<th>verdict</th><th>at t</th><th>bodies</th><th>geoms</th><th>witness point</th>"
                         "<th>distance</th><th>clearance</th></tr>")
            for r in entry["violations"]:
                parts.append("<tr>" + "".join(f"<td>{esc(x)}</td>" for x in (
                    _fmt(r["sim_time"], ".4f"), r["verdict"], _fmt(r["time"], ".4f"), " / ".join(r["bodies"]),
                    " / ".join(r["geoms"]), _fmt_point(r["point"]), _fmt(r["distance"], ".3g"),
                    _fmt(r["clearance"], ".3g"))) + "</tr>")
            parts.append("</table>")
    parts.append("</body></html>")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(parts))
    return n_plots


def strip_series(result: dict[str, Any]) -> dict[str, Any]:
    """Copy of a review result without the per-window series (compact JSON)."""
    logs = [{k: v for k, v in e.items() if k != "series"} for e in result["logs"]]
    return {**result, "logs": logs}


__all__ = ["analyze", "combine", "verify", "render_text", "write_report", "strip_series", "VERDICTS"]
