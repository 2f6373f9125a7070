"""``python -m monitor bench [--quick] [--out DIR] [--suite NAME ...]``.

Writes ``results.json``, ``results.md`` and the PNG plots to ``--out``. Suites:
accuracy (run time against error), peers (python-fcl, MuJoCo sampling, ipctk),
seeds (paper reproductions), gate (overhead on gymnasium envs), scaling,
review (per-window cost of read_log + analyze + render_text on an N-window log),
targets (issue 12: every target as a ratio against its reference in the same run, MET / MISSED
against the issue's target and floor; it reuses the accuracy, peers and scaling results of the
same run when they ran). The targets are also printed to stdout, summarised at the top of
results.md and stored under ``targets`` in results.json.
A suite whose dependency is missing is recorded as skipped, never silently dropped;
an exception inside a suite is recorded in the results and the exit code is 1.
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time
import traceback
from pathlib import Path

from monitor.bench import SUITES as _BASE_SUITES

SUITES = tuple(_BASE_SUITES)
"""Suite names in run order; ``targets`` last (it reads the other suites' results)."""


def add_parser(p: argparse.ArgumentParser) -> None:
    """Add the bench options to the subcommand parser ``p``."""
    p.add_argument("--quick", action="store_true", help="CI-sized run (< 5 min on 2 cores)")
    p.add_argument("--out", type=Path, default=Path("bench_out"), help="output directory (default bench_out)")
    p.add_argument(
        "--suite",
        action="extend",
        nargs="+",
        choices=SUITES,
        metavar="NAME",
        help=f"run only these suites (one or more, repeatable): {', '.join(SUITES)}",
    )
    p.add_argument("--seed", type=int, default=7, help="case-set seed (default 7)")
    p.add_argument("--reps", type=int, default=None, help="timing repetitions (default 3 quick, 5 full)")


def run(args: argparse.Namespace) -> int:
    """Run the selected suites and write the report; returns the exit code."""
    from monitor.bench import report
    from monitor.bench.suites import SUITE_FUNCS, BenchConfig, finalize

    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    reps = args.reps if args.reps is not None else (3 if args.quick else 5)
    cfg = BenchConfig(quick=bool(args.quick), out=out, seed=int(args.seed), reps=reps)
    names = [s for s in SUITES if not args.suite or s in args.suite]
    cfg.shared["planned_suites"] = tuple(names)
    command = (
        "python -m monitor bench " + " ".join(shlex.quote(a) for a in sys.argv[2:])
        if len(sys.argv) > 1 and sys.argv[1] == "bench"
        else "python -m monitor bench"
    )
    results = {
        "command": command,
        "quick": cfg.quick,
        "seed": cfg.seed,
        "reps": reps,
        "machine": report.machine_info(),
        "suites": {},
    }
    t0 = time.perf_counter()
    failed = False
    for name in names:
        cfg.log(f"[bench] suite {name} ...")
        t = time.perf_counter()
        try:
            res = SUITE_FUNCS[name](cfg)
        except Exception as exc:  # noqa: BLE001  (report and continue with the other suites)
            failed = True
            res = {
                "error": f"{type(exc).__name__}: {exc}",
                "trace": traceback.format_exc(),
                "markdown": [f"**Suite failed**: `{type(exc).__name__}: {exc}`"],
            }
        res["suite_seconds"] = time.perf_counter() - t
        results["suites"][name] = res
        cfg.shared.setdefault("suite_results", {})[name] = res
        cfg.log(
            f"[bench] suite {name}: {res['suite_seconds']:.1f} s"
            + (f" (skipped: {res['skipped']})" if res.get("skipped") else "")
        )
    finalize(cfg, results)
    results["wall_seconds"] = time.perf_counter() - t0
    report.write_json(out / "results.json", results)
    report.write_markdown(out / "results.md", results)
    if results.get("targets"):
        from monitor.bench.targets import summary_lines

        print("issue 12 targets (ratios against references measured in this run):")
        for line in summary_lines(results["targets"]):
            print(f"  {line}")
        sys.stdout.flush()
    cfg.log(
        f"[bench] wrote {out / 'results.json'} and {out / 'results.md'} in {results['wall_seconds']:.1f} s"
    )
    return 1 if failed else 0
