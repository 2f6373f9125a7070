"""Review: analysis, CLI output (text/JSON/HTML), and --verify (fake engine + real engine end to end)."""

from __future__ import annotations

import base64
import json
import re
import types
from pathlib import Path

import mujoco
import numpy as np
import pytest
from mcap_rewrite import rewrite

import monitor.review as review
from monitor.certify.certificate import Certificate, PairResult, Witness
from monitor.certify.types import Verdict
from monitor.cli import main
from monitor.log import MonitorLog, read_log, topics

REPO = Path(__file__).resolve().parents[1]
ARM = REPO / "models" / "arm" / "scene.xml"

XML = """
<mujoco model="review">
  <worldbody>
    <body name="table" pos="0.6 0 0.2"><geom name="table_top" type="box" size="0.2 0.3 0.02"/></body>
    <body name="link1" pos="0 0 0.2">
      <joint name="j1" type="hinge" axis="0 0 1"/>
      <geom name="link1_geom" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
    </body>
  </worldbody>
</mujoco>
"""

LAT_S = [1e-4, 3e-4, 2e-4, 8e-4, 5e-4, 4e-4, 6e-4, 7e-4, 9e-4, 1.5e-3]


def _cert(k, verdict, t0, dt=0.01):
    wit = None
    if verdict == "violation":
        wit = Witness(t0 + dt / 2, ("link1_geom", "table_top"), np.array([0.3, 0.0, 0.21]), -2e-3)
    ok = verdict == "certified"
    method = "extrusion" if k % 2 else "toleranced"
    pr = PairResult(("table_top", "link1_geom"), ("table", "link1"), verdict, method, 7, 2,
                    () if ok else ((t0, t0 + dt),), 0.05 - 0.001 * k if ok else float("-inf"), wit)
    return Certificate(verdict, (t0, t0 + dt), 0.0, 1e-3, "auto", wit, None if ok else t0,
                       pr.clearance, (pr,), {"wall_seconds": LAT_S[k % len(LAT_S)],
                                             "checker_mix": {pr.method: 1}})


def _plan(model, t0, q0, dt=0.01):
    return types.SimpleNamespace(times=np.array([t0, t0 + dt]), qpos=np.array([[q0], [q0]]), model=model)


VERDICTS = ["certified", "certified", "violation", "certified", "uncertain",
            "certified", "violation", "certified", "certified", "certified"]


@pytest.fixture
def hand_log(tmp_path):
    model = mujoco.MjModel.from_xml_string(XML)
    path = tmp_path / "hand.mcap"
    with MonitorLog(path, model=model, metadata={"margin": 0.0, "epsilon": 1e-3, "pairs": "all"}) as log:
        for k, v in enumerate(VERDICTS):
            log.write_window(0.01 * k, _plan(model, 0.01 * k, 0.0), _cert(k, v, 0.01 * k),
                             np.array([1.0]), np.array([0.0 if v != "certified" else 1.0]),
                             replaced=v != "certified")
    return path


def test_analyze_counts_latency_mix_and_rows(hand_log):
    s = review.analyze(read_log(hand_log))
    assert s["windows"] == 10
    assert s["verdicts"] == {"certified": 7, "violation": 2, "uncertain": 1}
    assert s["blocked_actions"] == 3 and s["actions"] == 10
    us = np.array(LAT_S) * 1e6
    assert s["latency_us"]["p50"] == pytest.approx(np.percentile(us, 50))
    assert s["latency_us"]["p95"] == pytest.approx(np.percentile(us, 95))
    assert s["latency_us"]["max"] == pytest.approx(us.max())
    assert s["checker_mix"] == {"toleranced": 5, "extrusion": 5}
    rows = s["violations"]
    assert [r["verdict"] for r in rows] == ["violation", "uncertain", "violation"]
    assert rows[0]["geoms"] == ["link1_geom", "table_top"] and rows[0]["point"] == [0.3, 0.0, 0.21]
    assert rows[0]["distance"] == -2e-3 and rows[0]["sim_time"] == pytest.approx(0.02)
    assert rows[1]["bodies"] == ["table", "link1"] and rows[1]["point"] is None


def test_per_window_verdicts_are_verdict_members(hand_log, tmp_path, monkeypatch):
    """Review hands back Verdict members (not the log's plain strings): series, rows, counts, mismatches."""
    s = review.analyze(read_log(hand_log))
    assert s["series"]["verdict"] == VERDICTS  # oracle: the verdicts written, as plain strings
    assert all(type(v) is Verdict for v in s["series"]["verdict"])
    assert all(type(r["verdict"]) is Verdict for r in s["violations"]) and len(s["violations"]) == 3
    assert all(type(v) is Verdict for v in s["verdicts"])
    monkeypatch.setattr(review, "_engine", lambda: (_FakeScene, _fake_certify))
    model = mujoco.MjModel.from_xml_string(XML)
    path, bad = tmp_path / "ok.mcap", tmp_path / "bad.mcap"
    _consistent_log(path, model, [1.0, 0.1])
    rewrite_plan(path, bad, 0, lambda o: o.update(qpos=[[0.05], [0.05]]))  # logged certified, collides
    (m,) = review.verify(read_log(bad), progress=False)["mismatches"]
    assert (m["logged"], m["recomputed"]) == ("certified", "violation")
    assert type(m["logged"]) is Verdict and type(m["recomputed"]) is Verdict


def test_cli_text_json_and_multiple_logs(hand_log, tmp_path, capsys):
    assert main(["review", str(hand_log)]) == 0
    out = capsys.readouterr().out
    assert "windows 10: certified 7, violation 2, uncertain 1" in out
    assert "blocked/replaced 3" in out and "p50" in out and "checker mix" in out
    assert "link1_geom / table_top" in out and "(0.3000, 0.0000, 0.2100)" in out
    other = tmp_path / "other.mcap"
    other.write_bytes(hand_log.read_bytes())
    assert main(["review", "--json", str(hand_log), str(other)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert len(res["logs"]) == 2 and res["total"]["windows"] == 20 and res["exit_code"] == 0
    assert res["total"]["verdicts"]["violation"] == 4


def test_report_html_has_embedded_plots(hand_log, tmp_path):
    out = tmp_path / "r.html"
    assert main(["review", str(hand_log), "--report", str(out)]) == 0
    text = out.read_text()
    imgs = re.findall(r"src='data:image/png;base64,([A-Za-z0-9+/=]+)'", text)
    assert len(imgs) >= 3
    for b in imgs:
        assert base64.b64decode(b)[:8] == b"\x89PNG\r\n\x1a\n"
    for title in ("Verdict timeline", "Clearance over time", "Latency histogram"):
        assert title in text
    assert "http" not in text.split("<body>", 1)[1].replace("https://json-schema", "")  # self-contained


# --------------------------------------------------------------------------- --verify plumbing


class _FakeScene:
    def __init__(self, model):
        self.model = model
        self.candidate_pairs = (("table_top", "link1_geom"),)

    @classmethod
    def from_model(cls, model, pairs="mujoco", **kw):
        return cls(model)


def _fake_certify(scene, plan, margin=0.0, epsilon=1e-3, method="auto", *, window=None, tolerances=None,
                  pairs=None, budget=None):
    """Oracle stand-in: the capsule (length 0.33 incl. radius) reaches the table iff |yaw| < 0.3."""
    q = np.asarray(plan.qpos)[:, 0]
    v = "violation" if np.any(np.abs(q) < 0.3) else "certified"
    wit = Witness(window[0], ("table_top", "link1_geom"), np.zeros(3), -1e-3) if v == "violation" else None
    pr = PairResult(("table_top", "link1_geom"), ("table", "link1"), v, "toleranced", 1, 0, (),
                    0.1 if v == "certified" else float("-inf"), wit)
    return Certificate(v, tuple(window), margin, epsilon, method, wit, None if wit is None else window[0],
                       pr.clearance, (pr,), {"wall_seconds": 1e-5})


def _consistent_log(path, model, yaws):
    with MonitorLog(path, model=model, metadata={"margin": 0.0, "epsilon": 1e-3, "pairs": "all"},
                    foxglove=False) as log:
        for k, y in enumerate(yaws):
            t0 = 0.01 * k
            p = _plan(model, t0, y)
            log.write_window(t0, p, _fake_certify(None, p, window=(t0, t0 + 0.01)))


def rewrite_plan(src: Path, dst: Path, index: int, edit) -> None:
    """Copy a finished log record by record, applying ``edit(payload)`` to one plan message."""
    def one(topic: str, o: dict) -> dict:
        if topic == topics.PLAN and o.get("index") == index:
            edit(o)
        return o

    rewrite(src, dst, msg=one)


def test_verify_plumbing_with_oracle_engine(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(review, "_engine", lambda: (_FakeScene, _fake_certify))
    model = mujoco.MjModel.from_xml_string(XML)
    path = tmp_path / "ok.mcap"
    _consistent_log(path, model, [1.0, 0.8, 0.1, 2.0, 1.5])
    assert main(["review", "--verify", str(path)]) == 0
    assert "5 re-derived, 0 mismatch(es), 0 critical" in capsys.readouterr().out
    # a logged plan edited so that it collides: the logged "certified" no longer holds
    bad = tmp_path / "bad.mcap"
    rewrite_plan(path, bad, 3, lambda o: o.update(qpos=[[0.05], [0.05]]))
    assert main(["review", "--verify", "--json", str(bad)]) == 1
    res = json.loads(capsys.readouterr().out)
    ver = res["logs"][0]["verify"]
    assert ver["critical"] == 1 and [m["index"] for m in ver["mismatches"]] == [3]
    assert ver["mismatches"][0]["logged"] == "certified" and ver["mismatches"][0]["recomputed"] == "violation"
    # and back: a logged violation whose plan is in fact clear
    back = tmp_path / "back.mcap"
    rewrite_plan(path, back, 2, lambda o: o.update(qpos=[[1.0], [1.0]]))
    assert main(["review", "--verify", str(back)]) == 1
    assert "logged violation -> recomputed certified  [CRITICAL]" in capsys.readouterr().out


def test_verify_budget_uncertain_is_not_critical(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(review, "_engine", lambda: (_FakeScene, _fake_certify))
    model = mujoco.MjModel.from_xml_string(XML)
    path = tmp_path / "budget.mcap"
    with MonitorLog(path, model=model, foxglove=False) as log:
        for k, (y, exhausted) in enumerate([(1.0, True), (1.2, False)]):
            t0 = 0.01 * k
            c = _fake_certify(None, _plan(model, t0, y), window=(t0, t0 + 0.01)).to_dict()
            c.update(verdict="uncertain", stats={"budget_exhausted": exhausted})
            log.write_window(t0, _plan(model, t0, y), c)
    # neither is critical: window 0 ran out of its budget, window 1 claimed less than is proven now
    # (an "uncertain" that re-derives as certified is never a safety flip; it was critical before
    # 2026-11-28 night, see test_review_replay's test of it)
    assert main(["review", "--verify", "--json", str(path)]) != 1
    ver = json.loads(capsys.readouterr().out)["logs"][0]["verify"]
    assert [(m["index"], m["critical"]) for m in ver["mismatches"]] == [(0, False), (1, False)]
    assert ver["mismatches"][0]["reason"] == "budget exhausted when logged"
    assert "claimed less" in ver["mismatches"][1]["reason"]


def test_verify_without_engine_is_a_clear_error(hand_log, monkeypatch, capsys):
    def missing():
        raise ImportError("No module named 'monitor.certify.engine'")

    monkeypatch.setattr(review, "_engine", missing)
    assert main(["review", "--verify", str(hand_log)]) == 2
    assert "verification needs the certification engine" in capsys.readouterr().out


# --------------------------------------------------------------------------- real engine, end to end


def _engine_or_skip():
    """The real engine (imported directly: a broken import must fail, never skip)."""
    from monitor.certify.engine import certify
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    return Scene, Plan, certify


def test_verify_end_to_end_scripted_rollout(tmp_path, capsys):
    Scene, Plan, certify = _engine_or_skip()
    model = mujoco.MjModel.from_xml_path(str(ARM))
    scene = Scene.from_model(model, pairs="mujoco")
    path = tmp_path / "e2e.mcap"
    rng = np.random.default_rng(7)
    q = model.qpos0.copy()
    verdicts = []
    with MonitorLog(path, model=model, metadata={"margin": 0.005, "epsilon": 1e-3, "pairs": "mujoco",
                                                 "predictor": "scripted"}) as log:
        for k in range(8):
            t0 = 0.02 * k
            q1 = q.copy()
            q1[:3] += rng.uniform(-0.15, 0.15, 3)
            plan = Plan(np.array([t0, t0 + 0.02]), np.stack([q, q1]), model=model)
            cert = certify(scene, plan, margin=0.005, epsilon=1e-3)
            verdicts.append(cert.verdict)
            log.write_window(t0, plan, cert)
            q = q1
    assert main(["review", "--verify", str(path)]) == 0
    out = capsys.readouterr().out
    assert "8 re-derived, 0 mismatch(es), 0 critical" in out
    # edit window 2 so that the arm dives through the floor: --verify must catch it
    k = 2 if verdicts[2] == "certified" else verdicts.index("certified")
    bad = tmp_path / "bad.mcap"

    def dive(o):
        qq = np.asarray(o["qpos"])
        qq[1, 1] = 1.55  # shoulder pitch: link2 points down through the floor
        qq[1, 2] = 0.0
        o["qpos"] = qq.tolist()

    rewrite_plan(path, bad, k, dive)
    assert main(["review", "--verify", "--json", str(bad)]) == 1
    ver = json.loads(capsys.readouterr().out)["logs"][0]["verify"]
    assert ver["critical"] >= 1 and k in [m["index"] for m in ver["mismatches"]]
    # the portable XML attachment gives the same verdicts as the exact MJB
    assert main(["review", "--verify", "--model-source", "xml", str(path)]) == 0
    assert "0 critical" in capsys.readouterr().out


def test_gated_rollout_log_verifies(tmp_path, capsys):
    _engine_or_skip()
    from monitor.gate import Gate

    model = mujoco.MjModel.from_xml_path(str(ARM))
    data = mujoco.MjData(model)
    path = tmp_path / "gate.mcap"
    rng = np.random.default_rng(11)
    with Gate(model, margin=0.002, epsilon=1e-3, log=path, frame_skip=5,
              log_options={"model_source": str(ARM)}) as gate:
        for _ in range(15):
            gate.step(data, rng.uniform(model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]))
    assert main(["review", str(path)]) == 0
    assert "windows" in capsys.readouterr().out
    assert main(["review", "--verify", "--json", str(path)]) == 0
    ver = json.loads(capsys.readouterr().out)["logs"][0]["verify"]
    assert ver["checked"] >= 15 and ver["mismatches"] == [] and ver["errors"] == []


# --------------------------------------------------------------------------- issue 15: rendering, exit codes


def test_unrenderable_entry_costs_only_itself(hand_log, capsys):
    """A crafted entry (clearance "x", point "zz") gets an ERROR line; the genuine log's text stays."""
    good = review.analyze(read_log(hand_log))
    bad = review.analyze(read_log(hand_log))
    bad["file"] = dict(bad["file"], path="crafted.mcap")
    bad["violations"][0].update(clearance="x", point="zz")
    bad["verdicts"] = "not a dict"
    text = review.render_text({"logs": [bad, good], "total": None})
    assert "ERROR: cannot render this log" in text and bad.get("render_error")
    assert "windows 10: certified 7, violation 2, uncertain 1" in text


def test_help_documents_exit_codes(capsys):
    with pytest.raises(SystemExit):
        main(["review", "--help"])
    out = capsys.readouterr().out
    for needle in ("0  every log was read whole", "1  CRITICAL", "2  INCOMPLETE", "--tolerances"):
        assert needle in out


def test_unknown_verdict_without_verify_exits_2(tmp_path, capsys):
    model = mujoco.MjModel.from_xml_string(XML)
    path = tmp_path / "v.mcap"
    with MonitorLog(path, model=model, metadata={"pairs": "all"}, foxglove=False) as log:
        log.write_window(0.0, _plan(model, 0.0, 1.0), _cert(0, "certified", 0.0))
    rewrite_plan(path, tmp_path / "same.mcap", 0, lambda o: None)
    data = (tmp_path / "same.mcap").read_bytes()
    data = data.replace(b'"verdict":"certified"', b'"verdict":"Certified"', 1)  # same length: framing intact
    (tmp_path / "cap.mcap").write_bytes(data)
    assert main(["review", str(tmp_path / "cap.mcap")]) == 2
    captured = capsys.readouterr()
    assert "UNKNOWN VERDICT 'Certified' in window 0" in captured.out
    assert "unknown verdict" in captured.err


def test_bad_tolerances_option_is_one_line(hand_log, capsys):
    assert main(["review", "--verify", "--tolerances", '{"abs_pad": -1}', str(hand_log)]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "error: --tolerances: tolerances: abs_pad=-1 is not a finite number >= 0"


def test_fmt_bound_keeps_the_sign():
    assert review.fmt_bound(-1e308) == "-inf" and review.fmt_bound(1e308) == "inf"
    assert review.fmt_bound(None) == "unknown" and review.fmt_bound(0.0123) == "0.0123"


def test_unexplained_noncritical_disagreement_exits_2(tmp_path, monkeypatch, capsys):
    """Logged "uncertain" (no budget flag) that recomputes to "violation": not a safety flip, but
    the window did not agree, so not exit 0; with the budget flag it is explained (exit 0)."""
    pytest.importorskip("monitor.motion.plan")
    monkeypatch.setattr(review, "_engine", lambda: (_FakeScene, _fake_certify))
    model = mujoco.MjModel.from_xml_string(XML)
    for exhausted, want in ((False, 2), (True, 0)):
        path = tmp_path / f"u{exhausted}.mcap"
        with MonitorLog(path, model=model, metadata={"pairs": "all"}, foxglove=False) as log:
            c = _fake_certify(None, _plan(model, 0.0, 0.1), window=(0.0, 0.01)).to_dict()
            assert c["verdict"] == "violation"
            c.update(verdict="uncertain", stats={"budget_exhausted": exhausted})
            log.write_window(0.0, _plan(model, 0.0, 0.1), c)
        assert main(["review", "--verify", str(path)]) == want
        assert "logged uncertain -> recomputed violation" in capsys.readouterr().out
