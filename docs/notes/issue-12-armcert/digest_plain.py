"""sha256 of every gated step of hand30 / tunnel as the bench builds them (wl.py), old vs new tree.

PYTHONPATH=<tree>:<tree>/docs/notes/issue-12-tail-design python digest_plain.py WORK STEPS
Per step: tests/test_gate_reports.py's report key (verdicts, proposed / applied controls, both
certificates' to_dict() without wall time, info()) and the caller's qpos / qvel bytes after it.
"""
import collections, hashlib, os, sys

import monitor
import wl

sys.path.insert(0, os.path.join(os.path.dirname(monitor.__file__), os.pardir, "tests"))
from test_gate_reports import report_key  # noqa: E402

work, steps = sys.argv[1], int(sys.argv[2])
W = wl.make(work)
h = hashlib.sha256()
verdicts = collections.Counter()
for r in W.steps(steps, 0):
    h.update(repr(report_key(r)).encode())
    h.update(W.data.qpos.tobytes() + W.data.qvel.tobytes())
    verdicts[(str(r.verdict), str(r.applied_verdict), bool(r.replaced))] += 1
print(work, steps, dict(verdicts), h.hexdigest()[:20])
