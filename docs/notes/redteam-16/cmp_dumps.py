"""Compare two onecall_fuzz.py dumps (base tree vs this tree): verdict flips by direction, per-pair
verdict flips, certified clearances that grew, witnesses that moved. Usage: cmp_dumps.py A B"""
import sys

inf, nan = float("inf"), float("nan")


def load(p):
    out = {}
    for line in open(p):
        i, _, rest = line.partition(" ")
        out[int(i)] = eval(rest, {"inf": inf, "nan": nan}) if rest.startswith("{") else rest.strip()  # noqa: S307
    return out


a, b = load(sys.argv[1]), load(sys.argv[2])
flips, pflips, grew, wmoved, same, other = [], 0, [], 0, 0, 0
rank = {"certified": 0, "uncertain": 1, "violation": 2}
for i in sorted(set(a) | set(b)):
    x, y = a.get(i), b.get(i)
    if not isinstance(x, dict) or not isinstance(y, dict):
        if x != y:
            other += 1
            print("non-cert differs", i, x, "|", y)
        continue
    if x["verdict"] != y["verdict"]:
        flips.append((i, x["verdict"], y["verdict"]))
        continue
    same += 1
    for p, q in zip(x["pairs"], y["pairs"]):
        if p["verdict"] != q["verdict"]:
            pflips += 1
            print("pair flip", i, p["geoms"], p["verdict"], "->", q["verdict"])
        elif p["verdict"] == "certified" and q["clearance"] > p["clearance"]:
            grew.append((i, p["geoms"], q["clearance"] - p["clearance"]))
    if (x.get("witness") or {}).get("time") != (y.get("witness") or {}).get("time"):
        wmoved += 1
print(f"calls {len(a)}: same verdict {same}, verdict flips {flips}, pair flips {pflips}, "
      f"certified clearances that grew {len(grew)} (max {max([g[2] for g in grew], default=0):.3g}), "
      f"witness time moved {wmoved}, other differences {other}")
