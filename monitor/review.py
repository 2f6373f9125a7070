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
    series = {"sim_time": [], "verdict": [], "clearance": [], "latency_us": [], "margin": [], "episode": [],
              "index": []}
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
        series["episode"].append(int(c.get("episode", 0)))
        series["index"].append(int(c.get("index", len(series["index"]))))
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
    colors = {"certified": "tab:green", "uncertain": "tab:orange", "violation": "tab:red"}
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
    parts = [_table(["model", "re-derived", "mismatches", "critical flips", "without plan", "errors",
                     "pair set differs"],
                    [[ver.get("model_source"), ver.get("checked"), len(ver.get("mismatches", [])),
                      ver.get("critical"), ver.get("missing_plans"), len(ver.get("errors", [])),
                      ver.get("pairs_differ", 0)]], "summary")]
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


__all__ = ["analyze", "combine", "verify", "render_text", "write_report", "strip_series", "split_warmup",
           "VERDICTS", "WARMUP_WINDOWS"]
