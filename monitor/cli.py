"""Command line: ``python -m monitor {demo,review,bench,certify,acm,pairs} ...``.

Each subcommand lives in ``monitor/commands/<name>.py`` and exposes
``add_parser(subparsers)`` and ``run(args) -> int``. They are imported lazily so
that ``review`` does not import MuJoCo rendering or gymnasium.
"""

from __future__ import annotations

import argparse
import importlib
import sys

SUBCOMMANDS = {
    "demo": "Run a gated rollout on the arm env and print a summary.",
    "review": "Summarise, re-verify and report MCAP certificate logs.",
    "bench": "Benchmarks: run time against error, peers, scaling, gate overhead.",
    "certify": "Certify a library of plans from an .npz file.",
    "acm": "Compute a model's allowed-contact matrix (JSON file).",
    "pairs": "Print the pairs a gate will check, and the allowed ones with reasons.",
}


def build_parser() -> argparse.ArgumentParser:
    """The full argparse tree (subcommand modules add their own options)."""
    parser = argparse.ArgumentParser(prog="python -m monitor", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name, help_text in SUBCOMMANDS.items():
        try:
            mod = importlib.import_module(f"monitor.commands.{name}")
        except ImportError as exc:  # subcommand not available in this build
            p = sub.add_parser(name, help=f"{help_text} (unavailable: {exc})")
            p.set_defaults(_unavailable=str(exc))
            continue
        p = sub.add_parser(name, help=help_text, description=help_text)
        mod.add_parser(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Parse ``argv`` and run the subcommand; returns the process exit code."""
    args = build_parser().parse_args(argv)
    if getattr(args, "_unavailable", None):
        print(f"error: subcommand {args.command!r} unavailable: {args._unavailable}", file=sys.stderr)
        return 2
    return int(args._run(args) or 0)
