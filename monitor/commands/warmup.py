"""``monitor warmup``: compile the certification kernels once and say how long it took.

The first ``certify`` of a process compiles the numba kernels (about 50 s of CPU with an
empty on-disk cache, e.g. right after installing; well under a second once cached). The
command prints each case, the number of numba functions compiled and the compiled entry
points with their seconds ("nothing compiled" when everything came from the cache). ``certify``
does this before starting its default budget, so compilation never makes a window
"uncertain"; run this command after installing (the quick-start scripts do) so that the
first gated step of every later process is fast, and so that an explicit ``budget`` is
not spent on compilation.

With an empty cache and several cores, the kernels compile in child processes (``--processes``,
default: one per usable core, at most 2), then this process loads what they cached (and
compiles whatever a failed child left); each child gets one line.

Exit codes: 0 compiled (or loaded) and every case gave its expected verdict; 1 otherwise.
"""

from __future__ import annotations

import argparse

from monitor.certify.types import Verdict

_EXPECTED = {"rotating clear": Verdict.CERTIFIED, "colliding swing": Verdict.VIOLATION,
             "translating": Verdict.CERTIFIED}


def _processes(text: str) -> int | str:
    """``--processes`` value: ``auto`` or an int >= 0."""
    if text == "auto":
        return text
    try:
        n = int(text)
    except ValueError:
        n = -1
    if n < 0:
        raise argparse.ArgumentTypeError(f"expected 'auto' or an int >= 0, got {text!r}")
    return n


def add_parser(p: argparse.ArgumentParser) -> None:
    """Options of the ``warmup`` subcommand."""
    p.description = __doc__
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument("--processes", type=_processes, default="auto",
                   help="child processes compiling the independent kernels first (auto: the usable cores, "
                        "at most 2; 0 or 1: compile everything in this process)")


def run(args: argparse.Namespace) -> int:
    """Compile, print one line per case and the total; exit 0 when every verdict is as expected."""
    from monitor.warmup import warm_up

    rep = warm_up(getattr(args, "processes", "auto"))
    ok = True
    for task, child in rep.get("children", {}).items():
        if child["ok"]:
            print(f"  child {task:12s} {child['seconds']:8.2f} s wall {child['cpu']:8.2f} s CPU, "
                  f"{child['compiled']['functions']} numba functions compiled")
        else:   # not fatal: this process compiles what the child left
            print(f"  child {task:12s} failed ({child['error']}); compiled here instead")
    for name, (verdict, seconds) in rep["cases"].items():
        good = verdict == _EXPECTED.get(name, verdict)
        ok &= good
        note = "" if good else f"  (expected {_EXPECTED[name]})"
        print(f"  {name:18s} {verdict:10s} {seconds:8.2f} s{note}")
    comp = rep.get("compiled", {})
    if comp.get("functions"):
        print(f"  compiled {comp['functions']} numba functions in {comp['seconds']:.1f} s; entry points:")
        for name, seconds in sorted(comp["entry_points"].items(), key=lambda kv: -kv[1]):
            print(f"    {name:58s} {seconds:8.2f} s")
    elif rep.get("children"):
        print("  nothing compiled in this process: it loaded what the child processes compiled")
    else:
        print("  nothing compiled: every kernel loaded from the on-disk numba cache")
    print(f"monitor warmup: certification kernels ready in {rep.get('total_seconds', rep['seconds']):.1f} s "
          "(numba machine code cached on disk for later processes)")
    return 0 if ok else 1
