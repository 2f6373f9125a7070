import json, sys, collections
A = [json.loads(l) for l in open(sys.argv[1])]
B = [json.loads(l) for l in open(sys.argv[2])]
assert len(A) == len(B), (len(A), len(B))
cnt = collections.Counter(); tests = collections.defaultdict(lambda: [0, 0])
ex = []
for a, b in zip(A, B):
    w = a["work"].split("/")[0]
    cnt[w, "calls"] += 1
    tests[w][0] += a["tests"]; tests[w][1] += b["tests"]
    assert (a["work"], a["i"], a["K"]) == (b["work"], b["i"], b["K"])
    for k in ("verdict", "witness", "earliest", "culled"):
        if a[k] != b[k]:
            cnt[w, k] += 1; ex.append((k, a["work"], a["i"], a[k], b[k]))
    if [p[:3] for p in a["pairs"]] != [p[:3] for p in b["pairs"]]:
        cnt[w, "pair verdicts"] += 1
    if [p[3] for p in a["pairs"]] != [p[3] for p in b["pairs"]]:
        cnt[w, "pair methods"] += 1
    if a["clearance"] != b["clearance"]:
        cnt[w, "clearance differs"] += 1
        if b["clearance"] < a["clearance"]:
            cnt[w, "clearance lower in new"] += 1
    if a["tests"] != b["tests"]:
        cnt[w, "tests differ"] += 1
    cnt[w, "verdict=" + a["verdict"]] += 1
for k in sorted(cnt): print(k, cnt[k])
for w, (x, y) in tests.items(): print(w, "tests base", x, "new", y, "ratio %.3f" % (y / max(x, 1)))
for e in ex[:10]: print(e)
# per pair: pairs present in both lists keep their verdict; a pair the new run culls was certified in the base
bad = 0; newly_culled = 0; both = 0; new_only = 0
for a, b in zip(A, B):
    pa = {(p[0], p[1]): p[2] for p in a["pairs"]}
    pb = {(p[0], p[1]): p[2] for p in b["pairs"]}
    for k, v in pa.items():
        if k in pb:
            both += 1
            bad += pb[k] != v
        else:
            newly_culled += 1
            bad += v != "certified"
    new_only += len(set(pb) - set(pa))
print("pairs in both", both, "newly culled (all certified in base unless counted bad)", newly_culled,
      "open only in new", new_only, "BAD", bad)
