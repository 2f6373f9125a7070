"""Stage 0 of window_kernel (k1 = 0: the cull only): pair loop vs sort-and-sweep, per scaling scene.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-sweep-2/cutover.py [N ...] [--reps R]
Captures the first window_kernel call of monitor.certify on scaling_scene(N, density, motion)
(pairs="all", sweep forced) and replays stage 0 alone, alternating the two paths; medians (ms).
"""
import sys
import time

import numpy as np

import monitor
from monitor.bench.suites import scaling_scene
from monitor.certify import engine
from monitor.certify import kernels as KS

args = [a for a in sys.argv[1:] if not a.startswith("--")]
reps = int(sys.argv[sys.argv.index("--reps") + 1]) if "--reps" in sys.argv else 21
if "--reps" in sys.argv:
    args.remove(str(reps))
sizes = [int(a) for a in args] or [10, 30, 60, 100, 150, 200, 300, 1000, 3000]
print("| bodies | density | motion | P | survivors | pair loop (ms) | sweep (ms) | sweep / loop |")
print("|---|---|---|---|---|---|---|---|")
for n in sizes:
    for density in [d for d in ("sparse", "dense") if "--" + d not in sys.argv]:
        for motion in [m for m in ("translating", "rotating") if "--" + m not in sys.argv]:
            model, bm = scaling_scene(n, density, motion)
            scene = monitor.Scene.from_model(model, pairs="all")
            calls: list = []
            orig = engine._window_kernel

            def spy(*a, calls=calls, orig=orig):
                """Record the first stage-0 call."""
                if a[7] == 0 and not calls:
                    calls.append(a)
                return orig(*a)

            engine._window_kernel, engine.SWEEP_MIN_GEOMS = spy, 0
            monitor.certify(scene, bm, epsilon=1e-3)
            engine._window_kernel, engine.SWEEP_MIN_GEOMS = orig, 128
            (_K, gp, mp, pairs, fixed, mov, route, _s, _k0, _k1, prm, code, gap, surv, res, sc, sr, rows,
             info) = calls[0]
            ts = {0: [], 1: []}
            S = {}
            for r in range(reps):
                for mode in (0, 1) if r % 2 == 0 else (1, 0):
                    c = np.zeros_like(code)
                    t = time.perf_counter()
                    S[mode] = KS.window_kernel(gp, mp, pairs, fixed, mov, route, 0, 0, 0, prm, c, gap, surv,
                                               res, sc, sr, rows if mode else engine._NONE, info)
                    ts[mode].append(time.perf_counter() - t)
            assert S[0] == S[1]
            a, b = np.median(ts[0]) * 1e3, np.median(ts[1]) * 1e3
            print(f"| {n} | {density} | {motion} | {len(pairs)} | {S[0]} | {a:.3f} | {b:.3f} | {b / a:.2f} |",
                  flush=True)
