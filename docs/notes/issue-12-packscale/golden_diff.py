"""Every golden call of tests/test_engine_entry.py: list all differences (not just the first)."""
import json
import sys
from pathlib import Path

tests = Path(sys.argv[1]) / "tests"
sys.path.insert(0, str(tests))
import test_engine_entry as T
from _engine_entry_cases import _summary, calls

from monitor.certify import engine


def diffs(got, want, path=""):
    out = []
    if T._first_difference(got, want, path) is None:
        return out
    if isinstance(got, dict) and isinstance(want, dict) and got.keys() == want.keys():
        for k in want:
            out += diffs(got[k], want[k], f"{path}.{k}")
        return out
    if isinstance(got, list) and isinstance(want, list) and len(got) == len(want):
        for i, (a, b) in enumerate(zip(got, want)):
            out += diffs(a, b, f"{path}[{i}]")
        return out
    return [(path, got, want)]

golden = json.loads(T.GOLDEN.read_text())
engine._SWEPT_FIRST = False
res = {}
n = 0
for name, run in calls():
    got = json.loads(json.dumps(_summary(run())))
    n += 1
    d = diffs(got, golden[name])
    if d:
        res[name] = {"verdict": (got.get("verdict"), golden[name].get("verdict")),
                     "diffs": [(p, g, w) for p, g, w in d]}
print(json.dumps({"calls": n, "differing": len(res), "detail": res}, default=str))
