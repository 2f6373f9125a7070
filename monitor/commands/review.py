"""``python -m monitor review LOG.mcap [LOG2.mcap ...]``: summarise, re-verify and report logs.

Exit codes: 0 fine; 1 ``--verify`` found a window whose verdict flips between
certified and not certified; 2 an input is unreadable (missing, not MCAP, no
certificates recovered) or the verification could not run. Truncated logs (a
killed writer) are reviewed from their recovered part with a warning, exit 0.

A LOG argument may be a directory: its ``*.mcap`` files are reviewed (sorted).
``--ray`` re-verifies the logs in parallel, one Ray task per log
(:func:`monitor.distributed.verify_logs`); it implies ``--verify`` and gives the
same summary and exit code as the serial review.
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
    p.add_argument("--ray", action="store_true",
                   help="re-verify the logs in parallel as Ray tasks (implies --verify; uses a running "
                        "ray.init(), else starts a local instance; needs the 'ray' extra)")
    p.add_argument("--reindex", action="store_true",
                   help="first rewrite each LOG in place as a chunked, indexed MCAP (finalises the "
                        "journal a killed writer left; a record cut by the kill is dropped), then review it")
    p.add_argument("--json", action="store_true", help="print machine-readable JSON instead of text")
    p.add_argument("--report", metavar="OUT.html", default=None, help="write a self-contained HTML report")
    p.add_argument("--progress", dest="progress", action="store_true", default=None,
                   help="always show progress bars (default: only for large logs)")
    p.add_argument("--no-progress", dest="progress", action="store_false", help="never show progress bars")


def _review_one(path: str, args: argparse.Namespace,
                verified: dict[str, Any] | None = None) -> tuple[dict[str, Any], int]:
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
    if verified is not None:  # computed in parallel (--ray): same dict as verify(), or {"error": ...}
        entry["verify"] = verified
        code = 2 if verified.get("error") else (1 if verified["critical"] else 0)
    elif args.verify:
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


def _reindex(paths: list[str]) -> list[int]:
    """``--reindex``: finalise every log in place; a message per file on stderr; exit codes."""
    from monitor.errors import LogFormatError
    from monitor.log.writer import finalise_log

    codes = []
    for path in paths:
        try:
            r = finalise_log(path)
        except (LogFormatError, OSError) as exc:
            print(f"error: cannot reindex {path}: {exc}", file=sys.stderr)
            codes.append(2)
            continue
        lost = "" if r.source_complete else f"; {r.dropped_bytes} trailing byte(s) of a cut record dropped"
        print(f"reindexed {path}: {r.windows} window(s), {r.messages} message(s){lost}", file=sys.stderr)
        codes.append(0)
    return codes


def run(args: argparse.Namespace) -> int:
    """Run the review; returns the exit code (0 ok, 1 verify mismatch, 2 unreadable input)."""
    from monitor.distributed import expand_logs
    from monitor.review import combine, render_text, strip_series, write_report

    paths = expand_logs(args.logs)
    if not paths:
        print(f"error: no .mcap logs in {' '.join(map(str, args.logs))}", file=sys.stderr)
        return 2
    reindex_codes = _reindex(paths) if getattr(args, "reindex", False) else []
    verified: dict[str, Any] = {}
    if getattr(args, "ray", False):
        from monitor.distributed import verify_logs
        from monitor.errors import DependencyNotInstalled

        args.verify = True
        try:
            verified = dict(zip(paths, verify_logs(paths, backend="ray", model_source=args.model_source,
                                                   limit=args.limit, progress=args.progress)))
        except DependencyNotInstalled as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        except Exception as exc:  # noqa: BLE001 - Ray start-up/cluster failure: a message, not a traceback
            print(f"error: parallel re-verification on Ray failed: {type(exc).__name__}: {exc}",
                  file=sys.stderr)
            return 2
    entries, codes = [], []
    for path in paths:
        try:
            entry, code = _review_one(path, args, verified.get(path))
        except Exception as exc:  # noqa: BLE001 - last resort: a clear message, never a traceback
            entry, code = {"path": path, "file": {"path": path},
                           "error": f"{path}: unexpected {type(exc).__name__}: {exc}"}, 2
        entries.append(entry)
        codes.append(code)
    codes.extend(reindex_codes)
    ok = [e for e in entries if not e.get("error")]
    result = {"logs": entries, "total": combine(ok) if ok else None, "exit_code": max(codes)}
    if args.report:
        from monitor.errors import DependencyNotInstalled

        try:
            n = write_report(result, args.report)
            print(f"wrote {args.report} ({n} plots)", file=sys.stderr)
        except DependencyNotInstalled as exc:
            print(f"error: {exc}", file=sys.stderr)
            codes.append(2)
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
