"""Check and time the sweep prototype against window_kernel's stage 0 on the scaling scenes.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-sweep/run_sweep.py [sizes...] [--reps R]

For each scene the first ``window_kernel`` call of ``monitor.certify(scene, bm, epsilon=1e-3)``
is captured (then certify is stopped), and replayed with stage 0 and k1 = 0 (the cull only,
no survivor processed) -- "current cull" -- against :func:`sweep_proto.proto_cull`.
Soundness: every pair the current cull keeps (codes OPEN / PYTHON) is in the prototype's
output, every produced pair is in ``scene.pair_ids``, and every selected pair the prototype
leaves out has a sphere gap > margin (oracle: the sphere gap of every selected pair).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import sweep_proto as sp  # noqa: E402

import monitor  # noqa: E402
from monitor.bench.suites import scaling_scene  # noqa: E402
from monitor.certify import engine  # noqa: E402


class _Captured(Exception):
    """Raised by the spy to stop certify after the first window_kernel call."""


def capture(scene, bm):
    """The arguments of the first window_kernel call of certify(scene, bm, epsilon=1e-3)."""
    box = {}
    orig = engine._window_kernel

    def spy(KS, gp, mp, pairs, fixed, moving, *rest):
        box["args"] = (KS, gp, mp, pairs, fixed, moving, rest)
        raise _Captured

    engine._window_kernel = spy
    try:
        monitor.certify(scene, bm, epsilon=1e-3)
    except _Captured:
        pass
    finally:
        engine._window_kernel = orig
    return box["args"]


def median_time(f, reps):
    """Median wall time (s) of reps calls of f, and the times."""
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), ts


def one_scene(motion, density, n, reps):
    """One row of the table (checks, then interleaved timings)."""
    model, bm = scaling_scene(n, density, motion)
    scene = monitor.Scene.from_model(model, pairs="all")
    KS, gp, mp, pairs, fixed, moving, rest = capture(scene, bm)
    prm = rest[4]
    sc, sr = rest[9], rest[10]
    T = sc.shape[0]
    P = pairs.shape[0]
    margin = float(prm[KS.WP_MARGIN])
    code = np.empty(P, np.int64)
    gap = np.empty(P)
    surv = np.empty(P, np.int64)
    res = np.empty((1, KS.R_SIZE))
    info = np.zeros(KS.WI_SIZE)
    none = np.zeros(0, np.int64)

    def cur():
        info[:] = 0.0
        return KS.window_kernel(gp, mp, pairs, fixed, moving, none, 0, 0, 0, prm, code, gap, surv,
                                res, sc, sr, info)

    pol = sp.policy_arrays(model, scene)

    def proto():
        return sp.proto_cull(gp, mp, prm, T, margin, *pol)

    S = cur()
    pp, keep = proto()
    cur_keep = pairs[surv[:S]]
    enc = lambda a: a[:, 0] * (1 << 32) + a[:, 1]  # noqa: E731
    sel_set, pp_set = enc(pairs), enc(pp)
    ok_sup = bool(np.isin(enc(cur_keep), pp_set).all())
    ok_pol = bool(np.isin(pp_set, sel_set).all())
    # oracle: every selected pair left out by the prototype has a sphere gap > margin
    left = pairs[~np.isin(sel_set, pp_set)]
    lo, hi, sc2, sr2, pad = sp.swept_boxes(gp, mp, prm, T)
    g_left = sp.all_sphere_gaps(sc2, sr2, left, pad) if len(left) else np.zeros(0)
    ok_orc = bool((g_left > margin).all())
    # same survivor set after the sphere test
    same = set(map(tuple, pp[keep == 1].tolist())) == set(map(tuple, cur_keep.tolist()))
    best, nsw = sp.proto_best(gp, mp, prm, T, margin, *pol)
    best_ok = best == info[KS.WI_BEST]
    tb = median_time(lambda: sp.proto_best(gp, mp, prm, T, margin, *pol), 3)[0]
    best_txt = (f"{best:.6g} vs {info[KS.WI_BEST]:.6g}: {'equal' if best_ok else 'DIFFERENT'}, "
                f"{nsw} sweeps, {tb * 1e3:.3f} ms")
    r = reps if n < 3000 else max(3, reps // 2)
    # interleave: current, proto, current, proto ...
    tc, tp = [], []
    for _ in range(r):
        tc.append(median_time(cur, 1)[0])
        tp.append(median_time(proto, 1)[0])
    mc, mpv = float(np.median(tc)), float(np.median(tp))
    print(f"| {motion} | {density} | {n} | {P} | {S} | {len(pp)} | {int(keep.sum())} | "
          f"{len(pp) - S} | {ok_sup and ok_pol and ok_orc and same} "
          f"(sup {ok_sup}, policy {ok_pol}, oracle {ok_orc}, same survivors {same}) | "
          f"{mc * 1e3:.3f} | {mpv * 1e3:.3f} | {mpv / mc:.3f} | {best_txt} |", flush=True)



def main():
    """Print the markdown table."""
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    reps = 7
    if "--reps" in sys.argv:
        reps = int(sys.argv[sys.argv.index("--reps") + 1])
        args.remove(str(reps))
    sizes = [int(a) for a in args] or [10, 100, 1000, 3000]
    print("| motion | density | bodies | selected pairs | current survivors | proto pairs | "
          "proto survivors | extra pairs (proto - current survivors) | superset | "
          "current cull ms | proto ms | ratio | "
          "best culled gap: proto_best vs kernel |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for motion in ("translating", "rotating"):
        for density in ("sparse", "dense"):
            for n in sizes:
                one_scene(motion, density, n, reps)

if __name__ == "__main__":
    main()
