"""What a log must carry for ``review --verify`` to re-derive every window (and what it checks of it).

* The pair policy: a gate's ``hazards=`` / ``allow=`` items, how its allowed pairs were chosen
  (``allowed_mode``) and the reference pose of ``allowed="auto"`` are logged; review rebuilds the
  gate's pair set from them and re-derives the allowed pairs from the model where it can.
* The request per window: every certificate names its :class:`CertifyRequest` (``request_id``;
  one ``monitor.request`` record per distinct request), so a gate setting changed during the run
  is re-derived with the setting that produced each window, and a gate writing into a user's
  open :class:`MonitorLog` logs its requests too.
* Forged provenance: a request id naming no request, a request redefined, a looser request
  added, an allowed pair the model does not allow: never a clean (exit 0) review.

Oracles: the gate's own reports and settings (known to the test), the forger's edit (known), and
for the allowed-pair forgery a body motion that provably passes through the wall (the ball's
centre crosses the wall's interior; checked by MuJoCo-independent arithmetic below).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor import review
from monitor.certify.engine import certify
from monitor.certify.request import CertifyRequest
from monitor.gate import Gate
from monitor.log import MonitorLog, read_log, topics
from monitor.motion.bodymotion import BodyMotion
from monitor.scene import Scene

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <geom name="wall" type="box" size=".05 1 1" pos="1 0 1"/>
    <body name="ball" pos="0 0 .06"><freejoint/><geom name="ball" type="sphere" size=".05"/></body>
  </worldbody>
</mujoco>
"""
WALL_X, WALL_HALF, BALL_R = 1.0, 0.05, 0.05


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(XML)


def _spec():
    return mujoco.MjSpec.from_string(XML)


def _run(model, path, steps, log_options=None, between=None, qpos=None, **gate_kw):
    """A gated run of the ball dropping 1 cm onto the floor (a resting contact from ~window 5)."""
    data = mujoco.MjData(model)
    if qpos is not None:
        data.qpos[:] = qpos
    reports = []
    kw = {"pairs": "all", "frame_skip": 5, "log": path,
          "log_options": {"model_source": _spec(), **(log_options or {})}}
    kw.update(gate_kw)
    with Gate(model, **kw) as gate:
        for k in range(steps):
            if between is not None:
                between(k, gate)
            reports.append(gate.step(data, np.zeros(0)))
    return reports


def _critical(ver):
    return [f["reason"] for f in ver["findings"] if f["severity"] == "critical"]


# ----------------------------------------------------------------------------- gap 1: pair policy


def test_a_hazards_gate_log_rebuilds_its_pair_set(model, tmp_path):
    """Regression: review rebuilt the scene without ``hazards=``: every window was a CRITICAL
    "pairs differ" (1 missing of 2). Now 0 critical, and a note lists the pair left out."""
    path = tmp_path / "hazards.mcap"
    reports = _run(model, path, 6, allowed=None, hazards=[("ball", "wall")])
    assert all([p.geoms for p in r.certificate.pairs] == [("wall", "ball")] for r in reports)
    ver = review.verify(read_log(path))
    assert ver["checked"] >= 6 and ver["pairs_differ"] == 0 and ver["critical"] == 0, _critical(ver)
    assert any("hazards=" in n and "1 candidate pair(s) were not certified" in n and "ball/floor" in n
               for n in ver["notes"]), ver["notes"]
    assert review.verify_exit_code(ver) == 0
    # an auditor who requires every pair: the hazards= subset is CRITICAL and ignored
    strict = review.verify(read_log(path), expect_pairs="all")
    assert any("logged hazards=[['ball', 'wall']] selects a subset" in r for r in _critical(strict))
    assert strict["pairs_differ"] >= 6
    # the same log without the record (a log from before): the pair sets differ on every window
    old = read_log(path)
    old.run.pop("hazards")
    assert review.verify(old)["pairs_differ"] >= 6


def test_an_allow_gate_log_rederives_its_user_pairs(model, tmp_path):
    path = tmp_path / "allow.mcap"
    _run(model, path, 6, allowed=None, allow=[("ball", "wall")])
    contents = read_log(path)
    assert contents.run["allow"] == [["ball", "wall"]] and contents.run["allowed_mode"] == "none"
    ver = review.verify(contents)
    assert ver["critical"] == 0 and ver["pairs_differ"] == 0, _critical(ver)
    assert any("re-derived from the model and the logged policy (allowed='none')" in n
               for n in ver["notes"]), ver["notes"]
    assert any("1 allowed pair(s) are the run's claim" in n and "allow= items" in n
               for n in ver["notes"]), ver["notes"]
    strict = review.verify(contents, expect_pairs="all")  # an auditor who requires every pair
    assert any("cannot be re-derived from the model" in r for r in _critical(strict)), _critical(strict)
    # the allow record edited away: the logged User pair is no longer what the policy gives
    contents.run["allow"] = None
    ver = review.verify(contents)
    assert any("allowed pair ball/wall (reason User) is not what allowed='none' gives" in r
               for r in _critical(ver)), _critical(ver)


def test_a_default_gate_logs_its_auto_reference_and_review_rederives_it(model, tmp_path):
    path = tmp_path / "auto.mcap"
    ref = model.qpos0.copy()
    ref[2] = 0.05  # the ball resting on the floor: Default at the reference pose

    def set_reference(k, gate):  # the documented reference: the first state (Gate.step resolves
        if k == 0:               # "auto" before reading it on bc78fcb: set it as SafetyGate does)
            gate.reference_qpos = ref

    _run(model, path, 8, between=set_reference, qpos=ref)  # allowed="auto"
    contents = read_log(path)
    assert contents.run["allowed_mode"] == "auto" and contents.run["reference_qpos"] == ref.tolist()
    assert [r[2] for r in contents.run["allowed_pairs"]] == ["Default"]
    ver = review.verify(contents)
    assert ver["critical"] == 0, _critical(ver)
    assert any("1 allowed pair(s) were re-derived from the model and the logged policy (allowed='auto')" in n
               for n in ver["notes"]), ver["notes"]
    assert not any("claim" in n for n in ver["notes"]), ver["notes"]


# ----------------------------------------------------------------------------- gap 2: settings change


def _request_ids(contents):
    return [c.get("request_id") for c in contents.certificates()]


def test_a_tightened_setting_mid_run_is_rederived_per_window(model, tmp_path):
    """Regression: the request was logged once, at open. After ``gate.margin = 0.002`` and
    ``gate.ongoing = "violation"`` every later window was CRITICAL ("margin=0.002 differs from
    the run's 0.0") and re-derived with the old rule. Now each window names its request."""
    path = tmp_path / "tight.mcap"

    def change(k, gate):
        if k == 8:
            gate.margin = 0.002
            gate.ongoing = "violation"
            gate.budget = {"tests": 10**7}

    reports = _run(model, path, 14, between=change, allowed=None)
    assert {r.certificate.margin for r in reports} == {0.0, 0.002}
    contents = read_log(path)
    ids = _request_ids(contents)
    assert ids[0] == 0 and ids[-1] >= 1 and None not in ids
    assert len(contents.requests) == len(set(ids)) - 1  # id 0 is the run metadata's request
    ver = review.verify(contents)
    assert ver["mismatches"] == [] and ver["critical"] == 0, _critical(ver)
    assert ver["unverifiable"] == 0 and review.verify_exit_code(ver) == 0, ver["findings"]
    assert any("differs from request 0: margin 0.0 -> 0.002, ongoing deepen -> violation" in n
               for n in ver["notes"]), ver["notes"]


def test_a_loosened_setting_mid_run_is_rederived_and_never_passes_clean(model, tmp_path):
    """``gate.ongoing = "deepen"`` after a plain-rule start: the resting-contact windows are
    certified by the new rule; review agrees window by window (before: certified -> violation
    flips, CRITICAL) but cannot tell a genuine change from an added looser record: exit 2."""
    path = tmp_path / "loose.mcap"

    def change(k, gate):
        if k == 8:
            gate.ongoing = "deepen"

    reports = _run(model, path, 14, between=change, allowed=None, ongoing="violation")
    late = [r for r in reports[8:] if r.certificate.verdict == "certified" and r.certificate.ongoing]
    assert late  # the new rule decided windows
    ver = review.verify(read_log(path))
    assert ver["mismatches"] == [] and ver["critical"] == 0, _critical(ver)
    loosen = [f for f in ver["findings"] if "loosens what 'certified' means" in f["reason"]]
    assert len(loosen) == 1 and "ongoing violation -> deepen" in loosen[0]["reason"], ver["findings"]
    assert review.verify_exit_code(ver) == 2


# ----------------------------------------------------------------------------- gap 3: a given MonitorLog


def test_a_gate_writing_into_an_open_monitorlog_logs_requests_and_policy(model, tmp_path):
    """Regression: a gate given a MonitorLog object logged neither its request nor its allowed
    pairs: review re-derived with the plain rule and without the allowed resting contact
    (CRITICAL pairs differ on every window). Now both are in the log."""
    path = tmp_path / "given.mcap"
    with MonitorLog(path, model=model, model_source=_spec(), metadata={"note": "user log"}) as log:
        _run(model, log, 12)
    contents = read_log(path)
    assert set(_request_ids(contents)) == {0} and len(contents.requests) == 1
    assert CertifyRequest.from_json(contents.requests[0]["request"]).ongoing == "deepen"
    assert contents.run["note"] == "user log" and contents.run["allowed_mode"] == "auto"
    ver = review.verify(contents)
    assert ver["checked"] >= 12 and ver["critical"] == 0, _critical(ver)
    assert review.verify_exit_code(ver) == 0, ver["findings"]


def test_a_log_without_request_ids_still_reviews_with_a_note(model, tmp_path):
    path = tmp_path / "old.mcap"
    _run(model, path, 6, allowed=None, ongoing="violation")
    contents = read_log(path)
    for c in contents.topic(topics.CERTIFICATE):
        c.pop("request_id")
    contents.requests.clear()
    contents.run.pop("request")
    ver = review.verify(contents)
    assert ver["checked"] >= 6 and ver["critical"] == 0 and ver["errors"] == [], ver["findings"]
    assert any("no logged request" in n for n in ver["notes"]), ver["notes"]


# ----------------------------------------------------------------------------- red team: forged fields


def test_a_request_id_naming_no_request_is_critical(model, tmp_path):
    path = tmp_path / "ids.mcap"
    _run(model, path, 6, allowed=None)
    contents = read_log(path)
    for c in contents.topic(topics.CERTIFICATE):
        c["request_id"] = 7
    ver = review.verify(contents)
    assert sum("request_id 7 names no logged request" in r for r in _critical(ver)) >= 6


def test_a_request_redefined_with_other_contents_is_critical(model, tmp_path):
    path = tmp_path / "twice.mcap"
    _run(model, path, 6, allowed=None)
    contents = read_log(path)
    looser = {**contents.run["request"], "penetration_tol": 0.5}
    contents.requests.append({"id": 0, "request": looser})
    ver = review.verify(contents)
    assert any("request id 0 is defined twice with different contents" in r for r in _critical(ver))


def _ball_motion(model, x0, x1, z0, z1):
    d = mujoco.MjData(model)
    mujoco.mj_kinematics(model, d)
    pos = np.repeat(np.array(d.xpos)[None], 2, axis=0)
    quat = np.repeat(np.array(d.xquat)[None], 2, axis=0)
    b = model.body("ball").id
    pos[0, b] = (x0, 0.0, z0)
    pos[1, b] = (x1, 0.0, z1)
    return BodyMotion(np.array([0.0, 0.1]), pos, quat)


def test_a_looser_request_added_by_a_forger_cannot_pass_clean(model, tmp_path):
    """The forger's window: the ball starts 1 mm into the floor and sinks 2 cm more (a real
    penetration of 2.1 cm), certified under an added request with penetration_tol 5 cm. The
    run metadata's request (tol 5 mm) is request 0. Review re-derives with the window's
    request (it is certified under it) but reports the loosening: never exit 0."""
    motion = _ball_motion(model, 0.0, 0.0, 0.049, 0.029)  # centre below the radius: penetrating
    assert BALL_R - 0.029 > 0.02  # oracle: the final penetration depth, plane at z = 0
    scene = Scene.from_model(model, pairs="all")
    loose = CertifyRequest(ongoing="deepen", penetration_tol=0.05)
    cert = certify(scene, motion, request=loose)
    assert cert.verdict == "certified" and cert.ongoing
    run_req = CertifyRequest(ongoing="deepen").to_json()
    path = tmp_path / "loose_forged.mcap"
    with MonitorLog(path, model=model, model_source=_spec(),
                    metadata={"pairs": "all", "margin": 0.0, "request": run_req}) as log:
        log.write_window(0.0, motion, cert)
    contents = read_log(path)
    assert _request_ids(contents) == [1]
    ver = review.verify(contents)
    assert ver["mismatches"] == []
    assert any("penetration_tol 0.005 -> 0.05" in f["reason"] for f in ver["findings"]), ver["findings"]
    assert review.verify_exit_code(ver) != 0


def _forged_allowed_log(model, path, metadata):
    """A log whose one certified window moves the ball straight through the wall, certified on a
    scene that allows (never checks) the ball/wall pair, as the metadata claims."""
    motion = _ball_motion(model, 0.0, 2.0, 0.5, 0.5)
    # oracle: the ball's centre path x in [0, 2] at y = 0, z = 0.5 crosses the wall's interior
    assert 0.0 < WALL_X - WALL_HALF and WALL_X + WALL_HALF < 2.0
    rows = [r[:3] for r in metadata["allowed_pairs"]]
    forged = Scene.from_model(model, pairs="all", allowed=[tuple(r) for r in rows])
    cert = certify(forged, motion)
    assert cert.verdict == "certified" and [p.geoms for p in cert.pairs] == [("floor", "ball")]
    with MonitorLog(path, model=model, model_source=_spec(), metadata={"pairs": "all", **metadata}) as log:
        log.write_window(0.0, motion, cert)
    return read_log(path)


def test_an_allowed_pair_the_auto_matrix_does_not_give_is_critical(model, tmp_path):
    """The hole (main: 0 critical, a note): ball/wall claimed Default under allowed="auto"."""
    contents = _forged_allowed_log(model, tmp_path / "auto.mcap", {
        "allowed_pairs": [["wall", "ball", "Default"]], "allowed_mode": "auto", "reference_qpos": None})
    ver = review.verify(contents)
    crit = _critical(ver)
    assert any("allowed pair ball/wall (reason Default) is not what allowed='auto' gives" in r for r in crit)
    assert [m["recomputed"] for m in ver["mismatches"]] == ["violation"] and ver["mismatches"][0]["critical"]
    assert review.verify_exit_code(ver) == 1


def test_the_cli_names_the_forged_allowed_pair(model, tmp_path, capsys):
    from monitor.cli import main

    path = tmp_path / "cli.mcap"
    _forged_allowed_log(model, path, {"allowed_pairs": [["wall", "ball", "Default"]], "allowed_mode": "auto",
                                      "reference_qpos": None})
    assert main(["review", "--verify", "--no-progress", str(path)]) == 1
    out = capsys.readouterr().out
    assert "[CRITICAL] log: allowed pair ball/wall (reason Default) is not what allowed='auto' gives" in out
    assert "logged certified -> recomputed violation  [CRITICAL]" in out


def test_an_adjacent_claim_for_unrelated_bodies_is_critical(model, tmp_path):
    contents = _forged_allowed_log(model, tmp_path / "adj.mcap",
                                   {"allowed_pairs": [["wall", "ball", "Adjacent"]]})
    crit = _critical(review.verify(contents))
    assert any("allowed pair wall/ball claims reason Adjacent, but its bodies are not adjacent" in r
               for r in crit), crit


def test_a_user_matrix_claim_is_noted_and_critical_when_the_auditor_requires_the_pair_set(model, tmp_path):
    contents = _forged_allowed_log(model, tmp_path / "given.mcap", {
        "allowed_pairs": [["wall", "ball", "User"]], "allowed_mode": "given"})
    ver = review.verify(contents)
    assert ver["critical"] == 0
    assert any("1 allowed pair(s) are the run's claim" in n and "given by its user" in n
               for n in ver["notes"]), ver["notes"]
    strict = review.verify(contents, expect_pairs="all")
    assert any("cannot be re-derived from the model" in r for r in _critical(strict)), _critical(strict)
    assert [m["recomputed"] for m in strict["mismatches"]] == ["violation"]


def test_forged_policy_records_are_findings_never_tracebacks(model, tmp_path):
    path = tmp_path / "junk.mcap"
    _run(model, path, 4)
    for key, value, want in (("allowed_mode", "sometimes", "allowed_mode='sometimes' is not"),
                             ("reference_qpos", ["x"], "reference_qpos is not 7 finite numbers"),
                             ("hazards", ["no_such_geom"], "is not valid for the attached model")):
        contents = read_log(path)
        contents.run[key] = value
        ver = review.verify(contents)
        assert any(want in r for r in _critical(ver)), (key, _critical(ver))


def test_a_reference_pose_that_is_not_the_first_state_is_a_claim(model, tmp_path):
    """The forger moves the logged reference so that the ball touches the wall there: "auto"
    then re-derives ball/wall as Default. The reference is not the first window's start state,
    so the pair is listed as the run's claim, and is CRITICAL when the auditor requires the pair set."""
    touching = model.qpos0.copy()
    touching[0], touching[2] = WALL_X - WALL_HALF - BALL_R, 0.5  # the ball's surface on the wall's face
    again = Scene.from_model(model, pairs="all", allowed="auto", reference=touching)
    rows = [list(r) for r in again.allowed_pairs if "wall" in r]
    assert [r[2] for r in rows] == ["Default"]  # the forger's premise
    contents = _forged_allowed_log(model, tmp_path / "ref.mcap", {
        "allowed_pairs": rows, "allowed_mode": "auto", "reference_qpos": touching.tolist()})
    ver = review.verify(contents)
    assert any("1 allowed pair(s) are the run's claim" in n and "reference pose" in n
               for n in ver["notes"]), ver["notes"]
    strict = review.verify(contents, expect_pairs="all")
    assert any("cannot be re-derived from the model" in r for r in _critical(strict)), _critical(strict)
    assert [m["recomputed"] for m in strict["mismatches"]] == ["violation"]


def test_request_0_must_carry_the_run_metadata_margin(model, tmp_path):
    """The forger lowers the margin in request 0 and in every certificate but leaves the run
    metadata's margin (both are written at open by the gate): CRITICAL."""
    path = tmp_path / "m0.mcap"
    _run(model, path, 6, allowed=None, margin=0.004)
    contents = read_log(path)
    contents.run["request"] = {**contents.run["request"], "margin": 0.0}
    for c in contents.topic(topics.CERTIFICATE):
        c["margin"] = 0.0
    crit = _critical(review.verify(contents))
    assert any("request 0 (the run's first) has margin=0.0, the run metadata margin=0.004" in r
               for r in crit), crit


def test_max_penetration_makes_a_loose_rule_critical_in_library_and_cli(model, tmp_path, capsys):
    """A log claiming a loose rule from its first window (the residual of the looser-request attack:
    consistent from the start) passes with a note; an auditor's bound makes it CRITICAL."""
    from monitor.cli import main
    from monitor.errors import InvalidInputError

    path = tmp_path / "deep.mcap"
    _run(model, path, 12, allowed=None, penetration_tol=0.02)
    contents = read_log(path)
    assert review.verify(contents)["critical"] == 0
    assert review.verify(contents, max_penetration=0.02)["critical"] == 0
    crit = _critical(review.verify(contents, max_penetration=0.005))
    assert any("lets ongoing contacts deepen to penetration_tol=0.02 m, more than the required 0.005 m" in r
               for r in crit), crit
    assert main(["review", "--verify", "--no-progress", "--max-penetration", "0", str(path)]) == 1
    assert "more than the required 0.0 m" in capsys.readouterr().out
    assert main(["review", "--verify", "--max-penetration", "nan", str(path)]) == 2
    assert "--max-penetration must be a finite number" in capsys.readouterr().err
    with pytest.raises(InvalidInputError, match="max_penetration"):
        review.verify(contents, max_penetration=-1.0)


def test_review_rederives_the_applied_motions_of_blocked_steps(tmp_path):
    """A blocked step whose applied motion is certified (the committed brake's tail, a certified
    fallback) names the record of that motion (h12ac; before, only its proposal was logged and
    review said how many motions it did not re-derive: that note is now for older logs only,
    tests/test_review_applied.py). Oracle: the gate's own counters."""
    import gymnasium as gym

    import monitor.envs  # noqa: F401  (registers the ids)
    from monitor.gym_gate import SafetyGate

    path = tmp_path / "arm.mcap"
    env = SafetyGate(gym.make("monitor/Arm-v0"), log=path)
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(40):
        env.step(env.action_space.sample())
    stats = dict(env.gate.stats)
    env.close()
    assert stats["replaced"] - stats["fallback_uncertified"] > 0  # random actions on the Arm get blocked
    ver = review.verify(read_log(path))
    assert ver["critical"] == 0, _critical(ver)
    assert ver["applied_steps"] == stats["replaced"] and ver["applied_missing"] == 0
    assert not any("ran a motion that is not in the log" in n for n in ver["notes"]), ver["notes"]
