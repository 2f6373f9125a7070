"""Command line: ``monitor {demo,review,bench,certify,acm,pairs,warmup} ...``.

Also ``python -m monitor ...``.

Each subcommand lives in ``monitor/commands/<name>.py`` and exposes
``add_parser(subparsers)`` and ``run(args) -> int``. They are imported lazily so
that ``review`` does not import MuJoCo rendering or gymnasium. Help texts written
in reST (module docstrings) are shown as plain text (:func:`plain_text`).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys

SUBCOMMANDS = {
    "demo": "Run a gated rollout on the arm env and print a summary.",
    "review": "Summarise, re-verify and report MCAP certificate logs.",
    "bench": "Benchmarks: run time against error, peers, scaling, gate overhead.",
    "certify": "Certify a library of plans from an .npz file.",
    "acm": "Compute a model's allowed-contact matrix (JSON file).",
    "pairs": "Print the pairs a gate will check, and the allowed ones with reasons.",
    "warmup": "Compile the certification kernels once (run after installing).",
}

_ROLE = re.compile(r":(?:func|class|meth|mod|data|attr|obj|exc|ref):`~?([^`]+)`")
_LITERAL = re.compile(r"``([^`]+)``")
_STRONG = re.compile(r"\*\*([^*]+)\*\*")


def plain_text(text: str | None) -> str | None:
    """Turn reST inline markup into plain text: ``x`` -> x, :func:`x` -> x, **x** -> x."""
    if text is None:
        return None
    text = _ROLE.sub(lambda m: m.group(1), text)
    text = _LITERAL.sub(lambda m: m.group(1), text)
    return _STRONG.sub(lambda m: m.group(1), text)


def prog_name(argv0: str | None = None) -> str:
    """``monitor`` when run as the installed script, ``python -m monitor`` when run as a module."""
    base = os.path.basename(argv0 if argv0 is not None else (sys.argv[0] if sys.argv else ""))
    return "python -m monitor" if base in ("__main__.py", "-m", "", "-c") else "monitor"


def version() -> str:
    """The installed monitor version (package metadata, else ``monitor.__version__``)."""
    import importlib.metadata

    try:
        return importlib.metadata.version("monitor")
    except importlib.metadata.PackageNotFoundError:
        import monitor

        return monitor.__version__


def build_parser(prog: str | None = None) -> argparse.ArgumentParser:
    """The full argparse tree (subcommand modules add their own options)."""
    prog = prog or prog_name()
    parser = argparse.ArgumentParser(prog=prog, description=plain_text(__doc__.splitlines()[0]))
    parser.add_argument("--version", action="version", version=f"monitor {version()}")
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
        p.description = plain_text(p.description)
        p.epilog = plain_text(p.epilog)
        for action in p._actions:  # argparse has no public API to rewrite option help
            action.help = plain_text(action.help)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Parse ``argv`` and run the subcommand; returns the process exit code."""
    args = build_parser().parse_args(argv)
    if getattr(args, "_unavailable", None):
        print(f"error: subcommand {args.command!r} unavailable: {args._unavailable}", file=sys.stderr)
        return 2
    return int(args._run(args) or 0)
