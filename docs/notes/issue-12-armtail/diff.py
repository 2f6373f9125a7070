import sys, pickle, math
a, sa = pickle.load(open(sys.argv[1], "rb")); b, sb = pickle.load(open(sys.argv[2], "rb"))
print("steps", len(a), len(b))
nd = 0
for k, (x, y) in enumerate(zip(a, b)):
    for f in ("key", "state", "safety"):
        if x[f] != y[f]:
            nd += 1; print("step", k, f, "differs:", x[f] if f != "state" else "", "|", y[f] if f != "state" else "")
    for f in ("cert", "fb"):
        cx, cy = x[f], y[f]
        if (cx is None) != (cy is None) or (cx and (cx[0], cx[1], cx[2], cx[4]) != (cy[0], cy[1], cy[2], cy[4])):
            nd += 1; print("step", k, f, "differs:", cx, "|", cy)
        elif cx and cx[3] != cy[3]:
            rel = abs(cx[3] - cy[3]) / max(abs(cx[3]), 1e-300) if math.isfinite(cx[3]) else float("nan")
            print("step", k, f, "clearance", cx[3], cy[3], "rel", rel)
print("differences:", nd)
for k in sorted(set(sa) | set(sb)):
    if sa.get(k) != sb.get(k): print("summary", k, sa.get(k), sb.get(k))
