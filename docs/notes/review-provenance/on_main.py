"""The three gaps and the allowed-pair forgery, end to end, against whatever `monitor` is on PYTHONPATH.

Run from a checkout: PYTHONPATH=<checkout> python docs/notes/review-provenance/on_main.py
Prints, per scenario: windows re-derived, critical count, exit code, first critical reason.
"""
import sys
import tempfile
from pathlib import Path

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests"))
import test_review_provenance as t  # noqa: E402  (the scenarios of the regression tests)

from monitor import review  # noqa: E402
from monitor.log import MonitorLog, read_log  # noqa: E402

model = mujoco.MjModel.from_xml_string(t.XML)
tmp = Path(tempfile.mkdtemp())


def show(name, contents, **kw):
    """One line: windows re-derived, critical count, exit code, first critical reason."""
    ver = review.verify(contents, **kw)
    crit = [f["reason"] for f in ver["findings"] if f["severity"] == "critical"]
    crit += [f"flip {m['logged']} -> {m['recomputed']}" for m in ver["mismatches"] if m["critical"]]
    code = review.verify_exit_code(ver)
    print(f"{name:34} checked {ver['checked']:3} critical {ver['critical']:3} exit {code}"
          f"  {crit[0][:110] if crit else ''}")


t._run(model, tmp / "h.mcap", 6, allowed=None, hazards=[("ball", "wall")])
show("gap 1 hazards=", read_log(tmp / "h.mcap"))


def tighten(k, gate):
    """Window 8 on: a larger margin and the plain rule."""
    if k == 8:
        gate.margin, gate.ongoing = 0.002, "violation"


t._run(model, tmp / "t.mcap", 14, between=tighten, allowed=None)
show("gap 2 margin/ongoing tightened", read_log(tmp / "t.mcap"))


def loosen(k, gate):
    """Window 8 on: the ongoing-contact rule."""
    if k == 8:
        gate.ongoing = "deepen"


t._run(model, tmp / "l.mcap", 14, between=loosen, allowed=None, ongoing="violation")
show("gap 2 ongoing loosened", read_log(tmp / "l.mcap"))
with MonitorLog(tmp / "g.mcap", model=model, model_source=t._spec()) as log:
    t._run(model, log, 12)
show("gap 3 MonitorLog object", read_log(tmp / "g.mcap"))
c = t._forged_allowed_log(model, tmp / "f.mcap", {"allowed_pairs": [["wall", "ball", "Default"]],
                                                  "allowed_mode": "auto", "reference_qpos": None})
show("forged allowed pair (Default)", c)
c = t._forged_allowed_log(model, tmp / "f2.mcap", {"allowed_pairs": [["wall", "ball", "Adjacent"]]})
show("forged allowed pair (Adjacent)", c)
