"""Per captured gate certify call: verdict, clearance, earliest time, per-pair verdicts/clearances (JSON)."""
import json
import sys

sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent))
from ab import capture, fresh

from monitor.certify.engine import certify

name, steps = sys.argv[1], int(sys.argv[2])
scene, got = capture(name, steps)
out = []
for plan, req in got:
    if type(plan).__name__ != "Plan":
        continue
    c = certify(scene, fresh(plan), request=req)
    pairs = [(str(p.verdict), p.clearance, p.tests) for p in (getattr(c, "pairs", None) or [])]
    out.append({"verdict": str(c.verdict), "clearance": getattr(c, "clearance", None),
                "earliest": getattr(c, "earliest_time", None), "pairs": pairs})
print(json.dumps(out, default=str))
