"""``python -m monitor review LOG.mcap [LOG2.mcap ...]``: summarise, re-verify and report logs.

Exit codes (1 takes precedence over 2, 2 over 0):

  0  every log was read whole (a killed writer's cut tail excepted), nothing was
     skipped, and with --verify every window was re-derived from the attached
     model and the logged plan and agreed with every claim in the log;
  1  CRITICAL: --verify found a forged or wrong claim (verdict flip between certified
     and not certified, a certificate pair set or window that differs from the model
     and the plan, a duplicated window index, an unknown verdict/method, an invalid
     margin/epsilon/tolerance, model.xml and model.mjb that differ, ...);
  2  INCOMPLETE: an input is unreadable (missing, not MCAP, no certificate recovered),
     damaged (a corrupt record, a file closed by its writer that cannot be read to its
     footer), bad messages were skipped, an unknown verdict was seen without --verify,
     or with --verify some window could not be re-verified (no plan, an error, --limit,
     no model.mjb to cross-check model.xml against, ...).

Truncated logs (a killed writer: the file ends inside a record and has no closing
magic) are reviewed from their recovered part with a warning and do not change the code.

Signed logs (``MonitorLog(key=...)``, see monitor.log.sign): ``--key-file PATH`` (else the file
named by $MONITOR_LOG_KEY_FILE) checks every signed checkpoint, with or without --verify: a
checkpoint that does not verify, an unsigned log or one signed by another key, records after the
signed close, or a seal without a signed close are critical (1); windows after the last valid
checkpoint are unverifiable (2). Without a key a signed log gets the note "signature not checked:
no key". An unusable key file: exit 2 with a one-line message.

A LOG argument may be a directory: its ``*.mcap`` files are reviewed (sorted).
``--ray`` re-verifies the logs in parallel, one Ray task per log
(:func:`monitor.distributed.verify_logs`); it implies ``--verify`` and gives the
same summary and exit code as the serial review.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any


def add_parser(p: argparse.ArgumentParser) -> None:
    """Add the review options to the subcommand parser ``p``."""
    import re

    p.description = re.sub(r":\w+:`~?([^`]+)`", r"\1", __doc__).replace("``", "'")  # no raw reST
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument("logs", nargs="+", metavar="LOG.mcap", help="monitor MCAP log(s)")
    p.add_argument("--verify", action="store_true",
                   help="recompute every certificate from the attached model and logged plan")
    p.add_argument("--model-source", choices=("auto", "xml", "mjb"), default="auto",
                   help="model attachment used by --verify "
                        "(auto: the exact MJB if it loads in this MuJoCo, else the XML; both are "
                        "cross-checked when both load)")
    p.add_argument("--limit", type=int, default=None,
                   help="--verify only the first N windows of each log (the rest are unverified: exit 2)")
    p.add_argument("--expect-pairs", choices=("mujoco", "all"), default=None,
                   help="--verify requires this pair policy (a log claiming another one, e.g. a short "
                        "explicit list or hazards= items, is critical, and so are allowed pairs that "
                        "rest on the run's claim rather than on the model: allow= items, a user's "
                        "matrix, a reference pose that is not the first window's start); default: the "
                        "logged policy, reported")
    p.add_argument("--max-penetration", metavar="M", type=float, default=None,
                   help="--verify requires every window's ongoing-contact rule to allow at most M metres "
                        "of penetration (a window certified under ongoing='deepen' with a larger "
                        "penetration_tol is critical; 0 requires the plain rule); default: reported")
    p.add_argument("--trust-model-edits", action="store_true",
                   help="--verify accepts the log's model-edit records (monitor.model_edit: arrays the run "
                        "changed in place) as the model the windows were certified on; default: such "
                        "windows are re-derived on the edited model but reported unverifiable (exit 2), "
                        "because an unsigned edit record could be forged to shrink an obstacle")
    p.add_argument("--tolerances", metavar="JSON", default=None,
                   help="tolerance fields for --verify, e.g. '{\"abs_pad\": 1e-10}' (default: the library's; "
                        "logged tolerances are only compared, never used)")
    p.add_argument("--ray", action="store_true",
                   help="re-verify the logs in parallel as Ray tasks (implies --verify; uses a running "
                        "ray.init(), else starts a local instance; needs the 'ray' extra)")
    p.add_argument("--reindex", action="store_true",
                   help="first rewrite each LOG in place as a chunked, indexed MCAP (finalises the "
                        "journal a killed writer left; a record cut by the kill is dropped), then review it")
    p.add_argument("--key-file", metavar="PATH", default=None,
                   help="check the logs' signatures with the key in PATH (default: the file named by "
                        "$MONITOR_LOG_KEY_FILE, if set); an unsigned log or another key is critical")
    p.add_argument("--json", action="store_true", help="print machine-readable JSON instead of text")
    p.add_argument("--report", metavar="OUT.html", default=None, help="write a self-contained HTML report")
    p.add_argument("--progress", dest="progress", action="store_true", default=None,
                   help="always show progress bars (default: only for large logs)")
    p.add_argument("--no-progress", dest="progress", action="store_false", help="never show progress bars")


def _read_code(entry: dict[str, Any]) -> int:
    """2 when anything was damaged or skipped while reading, or an unknown verdict was seen.

    Sets ``entry["problem"]`` (one line for stderr) when it returns 2.
    """
    f = entry.get("file", {})
    why = []
    if f.get("stop_kind") == "corrupt":
        why.append(f"damaged file ({f.get('stop_reason')})")
    n_skipped = ((f.get("bad_payloads") or 0) + (f.get("bad_records") or 0)
                 + len(entry.get("bad_messages", [])))
    if n_skipped:
        why.append(f"{n_skipped} bad message(s)/record(s) skipped")
    if entry.get("unknown_verdicts"):
        why.append(f"{len(entry['unknown_verdicts'])} certificate(s) with an unknown verdict")
    if entry.get("integrity"):
        why.append(entry["integrity"][0])
    if why:
        entry["problem"] = f"{f.get('path')}: " + "; ".join(why)
        return 2
    return 0


def _review_one(path: str, args: argparse.Namespace,
                verified: dict[str, Any] | None = None) -> tuple[dict[str, Any], int]:
    from monitor.errors import LogFormatError, MonitorError
    from monitor.log.reader import read_log
    from monitor.review import add_signature, analyze, signature_exit_code, verify, verify_exit_code

    try:
        contents = read_log(path, progress=args.progress)
    except (LogFormatError, OSError) as exc:
        return {"path": path, "file": {"path": path}, "error": str(exc)}, 2
    entry = analyze(contents)
    code = _read_code(entry)
    if entry["windows"] == 0 and not entry["unknown_verdicts"] and not entry["bad_messages"]:
        why = contents.stop_reason or "no /monitor/certificate messages"
        entry["error"] = (f"{path}: no certificate could be recovered ({contents.n_messages} message(s) "
                          f"read, {contents.unreadable_bytes} unreadable byte(s); {why})")
        return entry, 2
    key = getattr(args, "key", None)
    if verified is not None:  # computed in parallel (--ray): same dict as verify(), or {"error": ...}
        entry["verify"] = add_signature(verified, contents, key)
    elif args.verify:
        try:
            entry["verify"] = verify(contents, model_source=args.model_source, progress=args.progress,
                                     limit=args.limit, tolerances=getattr(args, "tolerance_values", None),
                                     expect_pairs=getattr(args, "expect_pairs", None),
                                     max_penetration=getattr(args, "max_penetration", None),
                                     trust_model_edits=bool(getattr(args, "trust_model_edits", False)),
                                     key=key)
        except ImportError as exc:
            entry["verify"] = {"error": f"verification needs the certification engine: {exc}"}
        except (MonitorError, ValueError) as exc:
            entry["verify"] = {"error": str(exc)}
    if "signature" not in entry.get("verify", {}):  # no --verify, or it failed: still checked (cheap)
        from monitor.log.sign import check_signatures

        entry["signature"] = check_signatures(contents, key).to_json()
        code = _worst(code, signature_exit_code(entry["signature"]))
    if "verify" in entry:
        code = _worst(code, verify_exit_code(entry["verify"]))
    return entry, code


def _worst(*codes: int) -> int:
    """Combine exit codes: 1 (critical) over 2 (incomplete) over 0."""
    return 1 if 1 in codes else (2 if 2 in codes else 0)


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
    """Run the review; returns the exit code (module docstring: 0 ok, 1 critical, 2 incomplete)."""
    from monitor.distributed import expand_logs
    from monitor.review import combine, render_text, strip_series, write_report

    args.tolerance_values = None
    if getattr(args, "tolerances", None):
        from monitor.errors import InvalidInputError
        from monitor.log.reader import loads_strict
        from monitor.review import make_tolerances

        try:
            args.tolerance_values = loads_strict(args.tolerances)
            make_tolerances(args.tolerance_values)
        except (ValueError, InvalidInputError) as exc:
            print(f"error: --tolerances: {exc}", file=sys.stderr)
            return 2
    mp = getattr(args, "max_penetration", None)
    if mp is not None and not (math.isfinite(mp) and mp >= 0):
        print(f"error: --max-penetration must be a finite number >= 0 (m), got {mp}", file=sys.stderr)
        return 2
    from monitor.errors import LogKeyError
    from monitor.log.sign import key_from_env, load_key

    try:
        args.key = load_key(args.key_file) if getattr(args, "key_file", None) else key_from_env()
    except LogKeyError as exc:
        print(f"error: {'--key-file: ' if getattr(args, 'key_file', None) else ''}{exc}", file=sys.stderr)
        return 2
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
            verified = dict(zip(paths, verify_logs(
                paths, backend="ray", model_source=args.model_source, limit=args.limit,
                progress=args.progress,
                tolerances=args.tolerance_values, expect_pairs=getattr(args, "expect_pairs", None),
                max_penetration=mp, trust_model_edits=bool(getattr(args, "trust_model_edits", False)))))
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
    try:
        total = combine(ok) if ok else None
    except Exception as exc:  # noqa: BLE001 - totals are a convenience, never a traceback
        total, codes = None, codes + [2]
        print(f"error: cannot total the logs: {type(exc).__name__}: {exc}", file=sys.stderr)
    result = {"logs": entries, "total": total, "exit_code": _worst(*codes)}
    if args.report:
        from monitor.errors import DependencyNotInstalled

        try:
            n = write_report(result, args.report)
            print(f"wrote {args.report} ({n} plots)", file=sys.stderr)
        except DependencyNotInstalled as exc:
            print(f"error: {exc}", file=sys.stderr)
            codes.append(2)
            result["exit_code"] = _worst(*codes)
        except Exception as exc:  # noqa: BLE001 - OSError, or an entry the report cannot draw
            print(f"error: cannot write report {args.report}: {type(exc).__name__}: {exc}", file=sys.stderr)
            codes.append(2)
            result["exit_code"] = _worst(*codes)
    if args.json:
        print(json.dumps(strip_series(result), indent=1, default=str))
    else:
        text = render_text(result)
        if any(e.get("render_error") for e in entries):
            codes.append(2)
            result["exit_code"] = _worst(*codes)
            text = render_text(result)
        print(text)
    for e in entries:
        if e.get("error"):
            print(f"error: {e['error']}", file=sys.stderr)
        elif e.get("problem"):
            print(f"error: {e['problem']}", file=sys.stderr)
    return _worst(*codes)
