import json, sys, collections
sys.path.insert(0, "/tmp/rt12")
def load(f):
    out = {}
    for line in open(f):
        r = json.loads(line)
        out[(r["seed"], r["method"], tuple(r["sel"]), r["margin"])] = r
    return out
a, b = load(sys.argv[1]), load(sys.argv[2])   # base, branch
c = collections.Counter(); ex = collections.defaultdict(list)
for k in a.keys() & b.keys():
    va, vb = a[k].get("verdict", "ERR"), b[k].get("verdict", "ERR")
    c[(va, vb)] += 1
    if va != vb:
        ex[(va, vb)].append((k, a[k]["meta"], a[k]["dmin"]))
print(len(a.keys() & b.keys()), dict(c))
for key, lst in ex.items():
    print(key, len(lst))
    for x in lst[:4]: print("   ", x)
