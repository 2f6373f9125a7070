import json, sys, collections
bad = []; n = 0; cnt = collections.Counter()
for f in sys.argv[1:]:
    for line in open(f):
        r = json.loads(line); n += 1
        if "error" in r:
            bad.append(("error", r["seed"], r["error"], r.get("tb", "")[-300:])); continue
        cnt[(r["verdict"])] += 1
        dm = min(r["dmin"])
        if r["verdict"] == "certified" and r["margin"] >= dm:
            bad.append(("FALSE-CERT", r["seed"], r["meta"], r["margin"], dm, r["pairs"]))
        for (g, v, meth, cl, wt), d in zip(r["pairs"], r["dmin"]):
            cnt[meth] += 1
            if v == "certified" and cl > d + 1e-9:
                bad.append(("CLEARANCE>TRUE", r["seed"], r["meta"], g, meth, cl, d, r["margin"]))
        if r["verdict"] == "certified" and r["clearance"] > dm + 1e-9:
            bad.append(("CERT-CLEAR>TRUE", r["seed"], r["clearance"], dm))
print(n, dict(cnt))
for b in bad[:30]: print(b)
print("bad", len(bad))
