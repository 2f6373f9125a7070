"""Kernel stage timings on captured hand30 joint certifies (plain timers around whole calls)."""
import sys, time
import numpy as np
import h30
import monitor.certify.engine as E
import monitor.certify.kernels as KS
pc = time.thread_time   # CPU time of this thread: robust to the shared machine's time-sharing
kept, W, scene, req = h30.setup(sys.argv[1])
nsamp = int(sys.argv[2]) if len(sys.argv) > 2 else 10
rec, _wk = h30.spy_kernel_calls()
def wkern(gp, mp, pairs, fixed, moving, *r):
    return _wk(KS, gp, mp, pairs, fixed, moving, *r)
out = {"stage0": [], "stage0_surv": [], "chunks": [], "one": [], "ncalls": [], "S": [], "tests": [], "start_only": []}
for i in range(0, len(kept), max(1, len(kept)//nsamp)):
    p = h30.joint_plan(W, kept[i])
    rec.clear()
    c = E.certify(scene, p, request=req)
    gp, mp, pairs, fixed, moving, rest, _ = rec[0]
    # rest: route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, rows, info
    def fresh(r):
        return [x.copy() if isinstance(x, np.ndarray) else x for x in r]
    def run(stage0_k1, chunks, zroute=False):
        r = fresh(rest); r[3] = stage0_k1
        if zroute:
            r[3] = 0
        S = wkern(gp, mp, pairs, fixed, moving, *r)
        d = stage0_k1
        route, prm, code, gap, surv, res, sc, sr, rows, info = r[0], r[4], r[5], r[6], r[7], r[8], r[9], r[10], r[11], r[12]
        n = 1
        if zroute:
            wkern(gp, mp, pairs, fixed, moving, np.zeros(S, np.int64), 1, 0, S, prm, code, gap, surv, res, sc, sr, rows, info)
        while d < S and chunks:
            k1 = min(S, d + chunks)
            wkern(gp, mp, pairs, fixed, moving, route, 1, d, k1, prm, code, gap, surv, res, sc, sr, rows, info)
            d = k1; n += 1
        return S, n, info
    best = {}
    for rep in range(7):
        for name, a, b in (("stage0", 0, 0), ("chunks", 4, 4), ("one", 10**6, 0), ("start_only", 0, 0)):
            t = pc(); S, n, info = run(a, b, name == "start_only"); dt = pc() - t
            best.setdefault(name, []).append(dt)
            if name == "chunks": out["ncalls"].append(n); out["S"].append(S); out["tests"].append(info[KS.WI_TESTS])
    for k, v in best.items():
        out[k].append(np.median(v))
for k in ("stage0", "chunks", "one", "start_only"):
    print(k, "median us %.1f" % (1e6 * np.median(out[k])))
print("S median", np.median(out["S"]), "calls", np.median(out["ncalls"]), "tests", np.median(out["tests"]))
