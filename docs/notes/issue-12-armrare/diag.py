"""Why the compiled search leaves the pair open: the first search's row, _full_search's row, bigger caps, the Python outcome."""
import sys, numpy as np
import load
import monitor.certify.engine as E
import monitor.certify.toleranced as T
KS = E._kernels()
names = {getattr(KS, n): n for n in dir(KS) if n.startswith("WK_")}
vn = {KS.CERTIFIED: "CERT", KS.VIOLATION: "VIOL", KS.UNRESOLVED: "UNRES", getattr(KS, "PAUSED", 3): "PAUSED"}
def show(tag, row):
    print(f"    {tag}: verdict {vn.get(int(row[KS.R_VERDICT]), row[KS.R_VERDICT])} tests {int(row[KS.R_TESTS])} depth {int(row[KS.R_DEPTH])} "
          f"unres {int(row[KS.R_UNRES])} first_unres {row[KS.R_FIRST_UNRES]:.6f} wtime {row[KS.R_WTIME]:.6f} wupper {row[KS.R_WUPPER]:.3e} clear {row[KS.R_CLEAR]:.3e} start_lo {row[KS.R_START_LO]:.3e}")
_fs = E._full_search
def fs(KS_, gp, mp, pid, surv, code, res, n, t0, t1, margin, epsilon, tol, bud):
    slots = [s for s, k in enumerate(surv[:n].tolist()) if code[k] == KS.WK_UNRES]
    for s in slots:
        k = int(surv[s])
        print(f"  slot {s} geoms {gp.body[pid[k,0]]}/{pid[k,0]} {gp.body[pid[k,1]]}/{pid[k,1]} window [{t0:.6f}, {t1:.6f}] eps {epsilon} margin {margin} max_depth {tol.max_depth}")
        show("first search (certify-only)", res[s])
        for cap, depth, eps in ((1024, tol.max_depth, epsilon), (10**6, tol.max_depth, epsilon), (10**6, 60, epsilon), (10**6, tol.max_depth, epsilon / 10)):
            row = KS.new_result(); row[KS.R_STARTED] = 2.0
            stack = np.empty((int(depth) + 2, 3))
            KS.pair_window(gp, mp, int(pid[k, 0]), int(pid[k, 1]), float(t0), float(t1), float(margin), float(eps), int(depth), int(cap),
                           KS.MODE_FULL, float(tol.rel_pad), float(tol.abs_pad), stack, row)
            show(f"MODE_FULL cap {cap} depth {depth} eps {eps}", row)
    r = _fs(KS_, gp, mp, pid, surv, code, res, n, t0, t1, margin, epsilon, tol, bud)
    print("  after _full_search codes:", [names.get(int(code[int(surv[s])])) for s in slots], "spent", r)
    return r
E._full_search = fs
_cp = T.check_pairs
def cp(plan, items, window, margin, epsilon, tol, bud, **k):
    outs = _cp(plan, items, window, margin, epsilon, tol, bud, **k)
    for o in outs:
        print("  toleranced.check_pairs:", o.verdict, "tests", o.tests, "depth", o.max_depth, "intervals", [(round(a, 6), round(b, 6)) for a, b in (o.intervals or [])][:6],
              "clearance", getattr(o, "clearance", None))
    return outs
T.check_pairs = cp
for c, scene, plan, a, k in load.load():
    print(c["where"], c["todo"], "rows", len(plan.times), "t", plan.times[0], plan.times[-1])
    r = E.certify(scene, plan, *a, **k)
    print("  verdict", r.verdict, "witness", r.witness.geoms if r.witness else None, r.witness.time if r.witness else None, "earliest", r.earliest_time)
    for p in r.pairs:
        if p.method == "toleranced":
            print("  pair", p.geoms, p.verdict, p.method, p.intervals[:3], p.clearance, p.witness)
