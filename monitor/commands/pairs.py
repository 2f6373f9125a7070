"""``python -m monitor pairs MODEL [--hazards P ...] [--allow P ...] [--acm FILE]``: what will be checked.

Prints the resolved pair set: every monitored pair, and every candidate pair
that is NOT checked with its reason (Adjacent / Default / Always / User from the
allowed-contact matrix and ``--allow``). Patterns (:mod:`monitor.pairsel`):

  link*         geom or body names (fnmatch glob; a body selects its own geoms)
  arm/**        a body and all its descendants
  object/0      the first geom of body "object" (how unnamed geoms are addressed)
  group:3       MuJoCo geom group 3
  A:B           (for --hazards/--allow) pairs with one geom in A and the other in B

``--acm auto`` (default) computes the gate's default matrix (32 samples; reference pose:
the env's state after ``reset(seed=0)`` for an env id, as a SafetyGate does, else keyframe 0
or qpos0);
``--acm FILE`` reads one written by ``python -m monitor acm``; ``--acm none``
checks every candidate pair. MODEL is an MJCF path, a shipped scene name or a
Gymnasium env id.

Exit codes: 0 printed; 2 bad input (a pattern that matches nothing lists the names).
"""

from __future__ import annotations

import argparse
import json
import sys


def add_parser(p: argparse.ArgumentParser) -> None:
    """Options of the ``pairs`` subcommand."""
    p.description = __doc__
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument("model", metavar="MODEL", help="MJCF path, shipped scene name or Gymnasium env id")
    p.add_argument("--pairs", choices=("mujoco", "all"), default="mujoco",
                   help="candidate pairs: MuJoCo's contact filter (default) or every pair of bodies")
    p.add_argument("--hazards", nargs="+", default=None, metavar="PATTERN",
                   help="check only pairs with a geom matching one of these (or A:B pattern pairs)")
    p.add_argument("--allow", nargs="+", default=None, metavar="PATTERN",
                   help="allow (do not check) pairs matching these (reason User)")
    p.add_argument("--acm", default="auto", metavar="auto|none|FILE",
                   help="allowed-contact matrix: auto (default), none, or a file from `monitor acm`")
    p.add_argument("--json", action="store_true", help="print the pair set as JSON")


def _items(xs: list[str] | None) -> list | None:
    if xs is None:
        return None
    return [tuple(x.split(":", 1)) if ":" in x and not x.startswith("group:") else x for x in xs]


def run(args: argparse.Namespace) -> int:
    """Resolve and print the pair set; returns the exit code."""
    from monitor.acm import apply_policy, describe
    from monitor.commands.acm import load_model, reset_qpos
    from monitor.errors import MonitorError
    from monitor.pairsel import ModelNames
    from monitor.scene import Scene

    allowed = {"auto": "auto", "none": None}.get(args.acm, args.acm)
    if allowed not in ("auto", None):
        from pathlib import Path

        allowed = Path(allowed)
    try:
        model, desc = load_model(args.model)
        scene = Scene.from_model(model, pairs=args.pairs)
        ref = reset_qpos(args.model) if allowed == "auto" else None
        policy = apply_policy(model, scene.pair_ids, args.pairs, allowed=allowed,
                              hazards=_items(args.hazards), allow=_items(args.allow), reference=ref)
    except MonitorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    names = ModelNames.from_model(model)
    if args.json:
        out = {"model": desc, "candidates": len(scene.pair_ids),
               "monitored": [[names.geom_names[a], names.geom_names[b]]
                             for a, b in policy.monitored.tolist()],
               "allowed": [list(x) for x in policy.allowed], "not_hazard": policy.not_hazard,
               "never": [list(x) for x in policy.never]}
        print(json.dumps(out, indent=1))
        return 0
    print(f"{desc}: {len(scene.pair_ids)} candidate pairs (pairs={args.pairs!r})")
    for line in describe(policy, names):
        print(line)
    return 0
