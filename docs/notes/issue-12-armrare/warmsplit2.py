"""Warm split of the rare calls on a FRESH plan object each time (as in the gate: a new Plan per step); thread CPU, medians of 15."""
import time, statistics, pickle, cProfile, pstats, io, sys
import monitor.certify.engine as E
import monitor.certify.toleranced as T
caps = pickle.load(open("/tmp/armrare/caps.pkl", "rb"))
acc = {}
def wrap(mod, name):
    f = getattr(mod, name)
    def w(*a, **k):
        t = time.thread_time()
        try: return f(*a, **k)
        finally: acc[name] = acc.get(name, 0.0) + time.thread_time() - t
    setattr(mod, name, w)
for mod, nm in ((E, "_full_search"), (E, "_python_stages"), (T, "check_pairs"), (E, "_window_kernel"), (E, "_checked_result"), (E, "_plan_inputs"), (E, "_fast_inputs")):
    wrap(mod, nm)
prof = len(sys.argv) > 1
for c in caps:
    scene, plan, a, k = pickle.loads(c["blob"])
    for _ in range(3): E.certify(scene, pickle.loads(c["blob"])[1], *a, **k)
    rows = []
    pr = cProfile.Profile() if prof else None
    for i in range(15):
        p = pickle.loads(c["blob"])[1]
        acc.clear()
        if pr and i == 14: pr.enable()
        t = time.thread_time(); E.certify(scene, p, *a, **k); tot = time.thread_time() - t
        if pr and i == 14: pr.disable()
        rows.append(dict(total=tot, **acc))
    print(c["where"], {kk: round(statistics.median(r.get(kk, 0) for r in rows) * 1e3, 3) for kk in rows[0]}, "ms")
    if pr:
        s = io.StringIO(); pstats.Stats(pr, stream=s).sort_stats("cumulative").print_stats(30); print(s.getvalue()[:6000])
