"""Per-case time, route and verdict of the quick peers cases, numpy oracle vs compiled.

Toleranced, eps 1e-3; the fat-feature stage compiled (``toleranced.USE_COMPILED = True``)
and with the numpy oracle kernels (False), interleaved in the same run. Usage:

    PYTHONPATH=$PWD .venv/bin/python scripts/measure_fat_kernels.py [min seconds per case]
"""

import sys
import time

import numpy as np

import monitor  # noqa: F401
import monitor.certify.toleranced as TT
from monitor.bench.cases import make_cases
from monitor.certify.engine import certify


def _route(mix: dict, group: str) -> str:
    if "toleranced/whole-shape" in mix:
        return "compiled whole-shape"
    if "culled" in mix:
        return "culled"
    return "fat features" + (" (screw/Bezier)" if group in ("screw", "bezier") else "")


def main() -> None:
    """Print the per-case table and the medians."""
    min_s = float(sys.argv[1]) if len(sys.argv) > 1 else 0.2
    cases = make_cases(seed=7, quick=True)
    res = {True: [], False: []}
    print(f"{'case':28s} {'route':28s} {'numpy us':>10s} {'compiled us':>12s} {'ratio':>6s} verdicts")
    for c in cases:
        s, m = c.scene(16), c.body_motion()
        out = {}
        for comp in (False, True):
            TT.USE_COMPILED = comp
            cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")   # warm
            ts = []
            while sum(ts) < min_s or len(ts) < 3:
                t = time.perf_counter()
                cert = certify(s, m, margin=0.0, epsilon=1e-3, method="toleranced")
                ts.append(time.perf_counter() - t)
                if len(ts) >= 200:
                    break
            us = 1e6 * float(np.median(ts))
            out[comp] = (us, str(cert.verdict), cert.stats["tests"], cert.earliest_time)
            res[comp].append(us)
        TT.USE_COMPILED = True
        # verdict and earliest time must agree; the row count may drop (fat_kernels short circuit)
        keys = (1, 3)
        same = ("same" if all(out[True][k] == out[False][k] for k in keys)
                else f"DIFF {out[False][1:]} {out[True][1:]}")
        print(f"{c.name:28s} {_route(cert.stats['checker_mix'], c.group):28s} {out[False][0]:10.0f} "
              f"{out[True][0]:12.0f} {out[False][0] / out[True][0]:6.1f} {out[True][1]} {same} "
              f"tests {out[False][2]} -> {out[True][2]}", flush=True)
    print(f"median over {len(cases)} cases: numpy {np.median(res[False]):.0f} us, compiled "
          f"{np.median(res[True]):.0f} us")


if __name__ == "__main__":
    main()
