"""The HTML review report: warm-up apart from the latency histogram, blocked actions with
reasons, the --verify table, page width, and a clear error without matplotlib."""

from __future__ import annotations

import re
import sys
import types

import mujoco
import numpy as np
import pytest

from monitor.certify.certificate import Certificate, PairResult
from monitor.cli import main
from monitor.log import MonitorLog, read_log
from monitor.review import analyze, split_warmup, write_report

XML = """<mujoco><worldbody><body name="table" pos=".6 0 .2"><geom name="top" type="box" size=".2 .3 .02"/>
</body><body name="arm" pos="0 0 .3"><joint type="hinge" axis="0 0 1"/>
<geom name="link" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/></body></worldbody></mujoco>"""

REASONS = {3: "braking tail uncertain", 7: "uncertain", 8: "uncertain"}
"""Window -> reason of its blocked action: given for window 3, the default (the verdict) for 7 and 8."""
WARMUP_S = 19.0


def _cert(v: str, t0: float, seconds: float) -> Certificate:
    pr = PairResult(("link", "top"), ("arm", "table"), v, "toleranced", 3, 1, (), 0.02 if v == "certified"
                    else float("-inf"))
    return Certificate(v, (t0, t0 + 0.01), 0.001, 1e-3, "auto", None, None if v == "certified" else t0,
                       0.02 if v == "certified" else float("-inf"), (pr,), {"wall_seconds": seconds})


@pytest.fixture(scope="module")
def log_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("rep") / "r.mcap"
    model = mujoco.MjModel.from_xml_string(XML)
    rng = np.random.default_rng(0)
    with MonitorLog(path, model=model, foxglove=False) as log:
        for episode in range(2):
            for k in range(10):
                t0 = 0.01 * k
                v = "uncertain" if k in (7, 8) else "certified"
                sec = WARMUP_S if (episode, k) == (0, 0) else float(rng.uniform(1e-4, 1e-2))
                plan = types.SimpleNamespace(times=np.array([t0, t0 + 0.01]), qpos=np.zeros((2, 1)),
                                             model=model)
                log.write_window(t0, plan, _cert(v, t0, sec), np.array([0.1]), np.array([0.0]),
                                 replaced=k in REASONS, reason=REASONS.get(k) if k == 3 else None)
    return path


def test_warmup_is_split_off():
    assert split_warmup([19e6, 5.0, None, 7.0]) == ([19e6], [5.0, 7.0])
    assert split_warmup([None, 5.0]) == ([], [5.0])


def test_report_sections(log_path, tmp_path):
    entry = analyze(read_log(log_path))
    assert [b["reason"] for b in entry["blocked"]] == [REASONS[k] for k in sorted(REASONS)] * 2
    entry["verify"] = {"model_source": "model.mjb", "checked": 19, "mismatches": [
        {"index": 7, "sim_time": 0.07, "logged": "uncertain", "recomputed": "certified", "critical": True,
         "logged_clearance": None, "clearance": 0.004, "reason": None}], "critical": 1, "missing_plans": 0,
        "errors": [{"index": 12, "sim_time": 0.02, "error": "ValueError: bad plan"}], "pairs_differ": 0}
    out = tmp_path / "r.html"
    n = write_report({"logs": [entry], "total": None, "exit_code": 1}, str(out))
    text = out.read_text()
    assert n == 4
    assert "max-width:100%" in text and "width=device-width" in text and "max-width:none" in text
    assert f"JIT warm-up): {WARMUP_S:.3g} s" in text
    rows = re.findall(r"<tr><td>(\d+)</td><td>(\d)</td><td>[\d.]+</td><td>([^<]+)</td></tr>", text)
    assert [(int(i), int(e), r) for i, e, r in rows] == [
        (10 * ep + k, ep, REASONS[k]) for ep in (0, 1) for k in sorted(REASONS)]
    assert "<th>re-derived</th>" in text and "<td>19</td>" in text and "CRITICAL" in text
    assert "ValueError: bad plan" in text and "could not be re-verified" in text
    assert "Verdict timeline and blocked actions" in text


def test_report_without_matplotlib_is_a_clear_error(log_path, tmp_path, monkeypatch, capsys):
    for mod in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, mod)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    out = tmp_path / "x.html"
    assert main(["review", str(log_path), "--report", str(out)]) == 2
    err = capsys.readouterr().err
    assert "pip install 'monitor[report]'" in err and "Traceback" not in err
    assert not out.exists()
