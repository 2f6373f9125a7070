"""Red team 14: rotating-only windows under test budgets and tiny clock budgets (armcert's chunking).

Usage: PYTHONPATH=<tree>:<tree>/tests:docs/notes/redteam-14 python armbudget.py SEED0 NSEEDS

Same models and plans as armfuzz.py; margin = the oracle's verified minimum + 0.002 m (a violation
exists). Under budget={"tests": k} (k = 1..12), {"seconds": 1e-4 .. 1e-2} and a Budget subclass
counting its polls, certify ("auto") must never say certified; "auto" must equal the previous
path (_no_extrusion_route off, _kernel_decided off) under the same test budget.
"""
from __future__ import annotations

import sys

import numpy as np
import redteam_oracle as O
from armfuzz import _key, _old_path, seeded_cases

import monitor
from monitor.certify.common import Budget


class CountingBudget(Budget):
    """A Budget subclass (the engine keeps chunks of 4 for subclasses) counting its polls."""

    polls = 0

    @property
    def exhausted(self):   # noqa: D102
        CountingBudget.polls += 1
        return super().exhausted


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    st = dict(cases=0, false_cert=0, auto_vs_old=0, uncertain=0, violation=0, certified=0)
    for seed, (m, scene, times, q, plan) in seeded_cases(s0, n):
        orc = O.PlanOracle(m, times, q)
        best = np.inf
        for ga, gb in scene.pair_ids.tolist():
            if O.PLANE in (m.geom_type[ga], m.geom_type[gb]):
                continue
            best = min(best, O.motion_min(orc, ga, gb, 0.0, 1.0, n=60, refine=1).upper)
        if not np.isfinite(best) or best + 0.002 <= 0:
            continue
        margin = best + 0.002
        budgets = [{"tests": k} for k in range(1, 13)] + [{"seconds": s} for s in (1e-4, 1e-3, 1e-2)]
        for b in budgets + ["counting"]:
            st["cases"] += 1
            bud = CountingBudget(seconds=10.0) if b == "counting" else b
            c = monitor.certify(scene, plan, margin=margin, budget=bud)
            st[str(c.verdict)] += 1
            if str(c.verdict) == "certified":
                st["false_cert"] += 1
                print(seed, b, "FALSE CERTIFICATE", margin, flush=True)
            if isinstance(b, dict) and "tests" in b:
                o = _old_path(scene, plan, margin=margin, budget=b)
                if _key(o) != _key(c):
                    st["auto_vs_old"] += 1
                    print(seed, b, "auto != old", _key(c)[:3], _key(o)[:3], flush=True)
    print(st)


if __name__ == "__main__":
    main()
