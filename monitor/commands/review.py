"""``python -m monitor review LOG.mcap [LOG2.mcap ...]``: summarise, re-verify and report logs.

Exit codes: 0 fine; 1 ``--verify`` found a window whose verdict flips between
certified and not certified; 2 an input is unreadable (missing, not MCAP, no
certificates recovered) or the verification could not run. Truncated logs (a
killed writer) are reviewed from their recovered part with a warning, exit 0.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any


def add_parser(p: argparse.ArgumentParser) -> None:
    """Add the review options to the subcommand parser ``p``."""
    p.add_argument("logs", nargs="+", metavar="LOG.mcap", help="monitor MCAP log(s)")
    p.add_argument("--verify", action="store_true",
                   help="recompute every certificate from the attached model and logged plan")
    p.add_argument("--model-source", choices=("auto", "xml", "mjb"), default="auto",
                   help="model attachment used by --verify "
                        "(auto: exact MJB if same MuJoCo version, else XML)")
    p.add_argument("--limit", type=int, default=None, help="--verify only the first N windows of each log")
    p.add_argument("--json", action="store_true", help="print machine-readable JSON instead of text")
    p.add_argument("--report", metavar="OUT.html", default=None, help="write a self-contained HTML report")
    p.add_argument("--progress", dest="progress", action="store_true", default=None,
                   help="always show progress bars (default: only for large logs)")
    p.add_argument("--no-progress", dest="progress", action="store_false", help="never show progress bars")


def _review_one(path: str, args: argparse.Namespace) -> tuple[dict[str, Any], int]:
    from monitor.errors import LogFormatError, MonitorError
    from monitor.log.reader import read_log
    from monitor.review import analyze, verify

    try:
        contents = read_log(path, progress=args.progress)
    except (LogFormatError, OSError) as exc:
        return {"path": path, "file": {"path": path}, "error": str(exc)}, 2
    entry = analyze(contents)
    code = 0
    if entry["windows"] == 0:
        why = contents.stop_reason or "no /monitor/certificate messages"
        entry["error"] = (f"{path}: no certificate could be recovered ({contents.n_messages} message(s) "
                          f"read, {contents.unreadable_bytes} unreadable byte(s); {why})")
        return entry, 2
    if args.verify:
        try:
            entry["verify"] = verify(contents, model_source=args.model_source, progress=args.progress,
                                     limit=args.limit)
            if entry["verify"]["critical"]:
                code = 1
        except ImportError as exc:
            entry["verify"] = {"error": f"verification needs the certification engine: {exc}"}
            code = 2
        except (MonitorError, ValueError) as exc:
            entry["verify"] = {"error": str(exc)}
            code = 2
    return entry, code


def run(args: argparse.Namespace) -> int:
    """Run the review; returns the exit code (0 ok, 1 verify mismatch, 2 unreadable input)."""
    from monitor.review import combine, render_text, strip_series, write_report

    entries, codes = [], []
    for path in args.logs:
        try:
            entry, code = _review_one(path, args)
        except Exception as exc:  # noqa: BLE001 - last resort: a clear message, never a traceback
            entry, code = {"path": path, "file": {"path": path},
                           "error": f"{path}: unexpected {type(exc).__name__}: {exc}"}, 2
        entries.append(entry)
        codes.append(code)
    ok = [e for e in entries if not e.get("error")]
    result = {"logs": entries, "total": combine(ok) if ok else None, "exit_code": max(codes)}
    if args.report:
        try:
            n = write_report(result, args.report)
            print(f"wrote {args.report} ({n} plots)", file=sys.stderr)
        except OSError as exc:
            print(f"error: cannot write report {args.report}: {exc}", file=sys.stderr)
            codes.append(2)
    if args.json:
        print(json.dumps(strip_series(result), indent=1, default=str))
    else:
        print(render_text(result))
    for e in entries:
        if e.get("error"):
            print(f"error: {e['error']}", file=sys.stderr)
    return max(codes)
