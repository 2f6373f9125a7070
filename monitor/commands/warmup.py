"""``monitor warmup``: compile the certification kernels once and say how long it took.

The first ``certify`` of a process compiles the numba kernels (about 50 s of CPU with an
empty on-disk cache, e.g. right after installing; well under a second once cached). The
command prints each case, the number of numba functions compiled and the compiled entry
points with their seconds ("nothing compiled" when everything came from the cache). ``certify``
does this before starting its default budget, so compilation never makes a window
"uncertain"; run this command after installing (the quick-start scripts do) so that the
first gated step of every later process is fast, and so that an explicit ``budget`` is
not spent on compilation.

Exit codes: 0 compiled (or loaded) and every case gave its expected verdict; 1 otherwise.
"""

from __future__ import annotations

import argparse

_EXPECTED = {"rotating clear": "certified", "colliding swing": "violation", "translating": "certified"}


def add_parser(p: argparse.ArgumentParser) -> None:
    """Options of the ``warmup`` subcommand (none)."""
    p.description = __doc__
    p.formatter_class = argparse.RawDescriptionHelpFormatter


def run(args: argparse.Namespace) -> int:
    """Compile, print one line per case and the total; exit 0 when every verdict is as expected."""
    from monitor.warmup import ensure_warm

    rep = ensure_warm()
    ok = True
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
    else:
        print("  nothing compiled: every kernel loaded from the on-disk numba cache")
    print(f"monitor warmup: certification kernels ready in {rep['seconds']:.1f} s "
          "(numba machine code cached on disk for later processes)")
    return 0 if ok else 1
