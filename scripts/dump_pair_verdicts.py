"""Dump verdict, earliest time, tests, witness time and intervals of the quick peers cases as JSON.

Toleranced checker, epsilon 1e-3, margin 0. For comparing two trees (old vs new code) case by
case: run it once per tree and diff the files, e.g.

    PYTHONPATH=/path/to/old_tree .venv/bin/python scripts/dump_pair_verdicts.py /tmp/old.json
    PYTHONPATH=$PWD .venv/bin/python scripts/dump_pair_verdicts.py /tmp/new.json
"""

import json
import sys

import monitor  # noqa: F401
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify


def main() -> None:
    """Write {case: [verdict, earliest_time, tests, witness time, per-pair intervals]} to argv[1]."""
    out = {}
    for c in make_cases(seed=7, quick=True):
        cert = certify(c.scene(16), c.body_motion(), margin=0.0, epsilon=1e-3, method="toleranced")
        w = cert.witness
        out[c.name] = [str(cert.verdict), cert.earliest_time, cert.stats["tests"],
                       None if w is None else w.time, [list(p.intervals) for p in cert.pairs]]
    with open(sys.argv[1], "w") as f:
        json.dump(out, f)


if __name__ == "__main__":
    main()
