"""Machine info, ``results.json``, ``results.md`` and the PNG plots of a bench run."""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
from pathlib import Path
from typing import Any

import numpy as np

from monitor._json import jsonable
from monitor.certify.types import Verdict


def machine_info() -> dict[str, Any]:
    """CPU model (``/proc/cpuinfo``), core counts, load, versions and the UTC date."""
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.lower().startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    versions = {}
    for mod in ("numpy", "scipy", "mujoco", "numba", "gymnasium", "fcl", "ipctk"):
        try:
            versions[mod] = str(__import__(mod).__version__)
        except Exception:  # noqa: BLE001  (optional module or no __version__)
            versions[mod] = None
    try:
        load = list(os.getloadavg())
    except OSError:
        load = None
    return {
        "cpu": cpu,
        "cores_logical": os.cpu_count(),
        "cores_available": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "loadavg_1_5_15": load,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "date_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
        "versions": versions,
    }


def _clean(x: Any) -> Any:
    return jsonable(x, "null")


def write_json(path: Path, results: dict[str, Any]) -> None:
    """Write ``results`` as JSON (non-finite floats become null)."""
    path.write_text(json.dumps(_clean(results), indent=1))


# ------------------------------------------------------------------------------ markdown
def _fmt(v: Any) -> str:
    if v is None:
        return "–"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if not math.isfinite(v):
            return "–"
        if v == 0:
            return "0"
        a = abs(v)
        if a >= 1e5 or a < 1e-3:
            return f"{v:.2e}"
        if a >= 100:
            return f"{v:.0f}"
        if a >= 10:
            return f"{v:.1f}"
        return f"{v:.3g}"
    return str(v)


def table(rows: list[dict[str, Any]], cols: list[str], headers: list[str] | None = None) -> str:
    """A GitHub markdown table of ``rows`` restricted to ``cols``."""
    headers = headers or cols
    out = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        out.append("| " + " | ".join(_fmt(r.get(c)) for c in cols) + " |")
    return "\n".join(out)


def targets_table(rows: list[dict[str, Any]]) -> str:
    """The issue-12 summary table: target, reference, measured value, target / floor and their status."""
    from monitor.bench.targets import bound_text, value_text

    out = []
    for r in rows:
        unit = r.get("unit") or ""
        goal, floor = r.get("target"), r.get("floor")
        out.append(
            {
                "target": r["target_name"],
                "reference": r.get("reference") or "–",
                "measured": value_text(r.get("value"), unit),
                "goal": "–" if goal is None else f"≤ {bound_text(goal, unit)}: {r['target_status']}",
                "floor": "–" if floor is None else f"≤ {bound_text(floor, unit)}: {r['floor_status']}",
            }
        )
    return table(
        out,
        ["target", "reference", "measured", "goal", "floor"],
        ["target", "reference (same run)", "measured", "issue target", "floor"],
    )


def write_markdown(path: Path, results: dict[str, Any]) -> None:
    """Write the human-readable report: machine, command, one section per suite."""
    m = results["machine"]
    lines = [
        f"# monitor bench results ({'quick' if results['quick'] else 'full'})",
        "",
        f"- date: {m['date_utc']}",
        f"- machine: {m['cpu']}, {m['cores_available']} cores available "
        f"({m['cores_logical']} logical), load average {m['loadavg_1_5_15']}",
        f"- command: `{results['command']}`",
        f"- total wall time: {_fmt(results['wall_seconds'])} s",
        f"- versions: {', '.join(f'{k} {v}' for k, v in m['versions'].items() if v)}",
        "",
        "Times are medians of repetitions on a shared machine; compare ratios from the same run, "
        "not absolute times.",
        "",
    ]
    if results.get("targets"):
        lines += [
            "## Targets (issue 12)",
            "",
            "Each ratio is ours / its reference, both measured in this run; MET / MISSED against the "
            "issue's target and against its floor (the minimum for resolving the issue; '–' = none set). "
            "Details per target: the `targets` section below.",
            "",
            targets_table(results["targets"]),
            "",
        ]
    for name, suite in results["suites"].items():
        lines += [f"## {name}", ""]
        if suite.get("skipped"):
            lines += [f"Skipped: {suite['skipped']}", ""]
            continue
        for block in suite.get("markdown", []):
            lines += [block, ""]
        for fig in suite.get("figures", []):
            lines += [f"![{fig}]({fig})", ""]
    path.write_text("\n".join(lines))


# ------------------------------------------------------------------------------ plots
def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _finish(plt, fig, ax, path: Path) -> None:
    """Legend and log grid (when ``ax`` is given), tight layout, save at 110 dpi, close."""
    if ax is not None:
        ax.legend(fontsize=7)
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_time_vs_epsilon(path: Path, rows: list[dict], peer_lines: dict[str, float]) -> None:
    """Median µs per pair-window against epsilon, per checker and group (log-log)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    keys = sorted({(r["checker"], r["group"]) for r in rows if r.get("epsilon") is not None})
    for checker, group in keys:
        rr = sorted(
            (
                r
                for r in rows
                if r["checker"] == checker
                and r["group"] == group
                and r.get("epsilon") is not None
                and r.get("us_median")
            ),
            key=lambda r: r["epsilon"],
        )
        if not rr:
            continue
        eps = [r["epsilon"] for r in rr]
        med = np.array([r["us_median"] for r in rr])
        p95 = np.array([r["us_p95"] for r in rr])
        ax.errorbar(
            eps,
            med,
            yerr=[np.zeros_like(med), np.maximum(p95 - med, 0)],
            marker="o",
            capsize=3,
            label=f"ours {checker} ({group})",
        )
    for i, (name, us) in enumerate(sorted(peer_lines.items())):
        ax.axhline(us, ls="--", lw=1, color=f"C{(i + 5) % 10}", label=f"{name} (median)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.invert_xaxis()
    ax.set_xlabel("epsilon (m)")
    ax.set_ylabel("µs per pair-window (median; bar: p95)")
    ax.set_title("Run time against error tolerance")
    _finish(plt, fig, ax, path)


def plot_uncertain(path: Path, points: list[dict]) -> None:
    """Fraction uncertain against clearance / epsilon (log x), per checker."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for checker in sorted({p["checker"] for p in points}):
        pp = [p for p in points if p["checker"] == checker and p["clearance"] > 0]
        if not pp:
            continue
        x = np.array([p["clearance"] / p["epsilon"] for p in pp])
        y = np.array([1.0 if p["verdict"] != Verdict.CERTIFIED else 0.0 for p in pp])
        edges = np.logspace(np.floor(np.log10(x.min())), np.ceil(np.log10(x.max())) + 1e-9, 12)
        idx = np.digitize(x, edges)
        xs, ys, ns = [], [], []
        for k in np.unique(idx):
            sel = idx == k
            xs.append(np.exp(np.log(x[sel]).mean()))
            ys.append(y[sel].mean())
            ns.append(int(sel.sum()))
        ax.plot(xs, ys, marker="o", label=f"ours {checker}")
    ax.set_xscale("log")
    ax.set_xlabel("true clearance / epsilon")
    ax.set_ylabel("fraction not certified (clear cases)")
    ax.set_ylim(-0.05, 1.05)
    ax.set_title("Uncertain fraction against clearance / epsilon")
    _finish(plt, fig, ax, path)


def plot_peers(path: Path, rows: list[dict]) -> None:
    """µs per query (log) per checker, annotated with misses / collisions."""
    plt = _plt()
    rr = [r for r in rows if r.get("us_median")]
    fig, ax = plt.subplots(figsize=(7.5, 0.3 * len(rr) + 1.5))
    names = [r["checker"] for r in rr]
    ax.barh(
        range(len(rr)),
        [r["us_median"] for r in rr],
        color=["C3" if r["checker"].startswith("ours") else "C0" for r in rr],
    )
    for i, r in enumerate(rr):
        extra = f", uncertain {r['uncertain']}" if r.get("uncertain") else ""
        ax.text(
            r["us_median"],
            i,
            f"  misses {r['misses']}/{r['collide_cases']}, false alarms {r['false_alarms']}{extra}",
            va="center",
            fontsize=7,
        )
    ax.set_yticks(range(len(rr)), names, fontsize=7)
    ax.set_xscale("log")
    ax.set_xlim(min(r["us_median"] for r in rr) * 0.5, max(r["us_median"] for r in rr) * 3000)
    ax.set_xlabel("µs per pair-window query (median over cases)")
    ax.set_title("Ours and peers on the same cases")
    _finish(plt, fig, None, path)


def plot_scaling(path: Path, rows: list[dict]) -> None:
    """Seconds per window against the number of moving bodies (log-log)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for key in sorted({(r["density"], r["motion"]) for r in rows}):
        rr = sorted(
            (r for r in rows if (r["density"], r["motion"]) == key and r.get("seconds")),
            key=lambda r: r["bodies"],
        )
        if rr:
            ax.plot(
                [r["bodies"] for r in rr], [r["seconds"] for r in rr], marker="o", label=f"{key[0]} {key[1]}"
            )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("moving bodies")
    ax.set_ylabel("seconds per window (median)")
    ax.set_title("Scaling with the number of moving bodies")
    _finish(plt, fig, ax, path)


__all__ = [
    "machine_info",
    "targets_table",
    "write_json",
    "write_markdown",
    "table",
    "plot_time_vs_epsilon",
    "plot_uncertain",
    "plot_peers",
    "plot_scaling",
]
