"""Every motion that ran is in the log: the applied motion of replaced (blocked) steps.

A gate logs a blocked step as its proposal's window; the action names (``applied_window``) an
applied-motion record holding what actually ran: a fresh fallback's own window, or, for the
committed brake, the braking tail's plan and certificate (written once per committed tail and
named by every later step braking on it; ``covered_by`` = the accepted window it was certified
with). ``review --verify`` re-derives those records and checks that each covers its step.

Oracles: the live simulation (the state before and after every step, read from ``MjData`` by the
test, must lie on the record's plan at the step's start and end times), the gate's own counters
(replaced, fallback_uncertified), and the forger's edit (known).
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from mcap_rewrite import rewrite

import monitor.envs  # noqa: F401  (registers the ids)
from monitor import review
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate
from monitor.log import MonitorLog, read_log, topics

STEPS = 40


def _critical(ver):
    return [f["reason"] for f in ver["findings"] if f["severity"] == "critical"] + [
        f"flip {m['index']}" for m in ver["mismatches"] if m["critical"]]


def _unverifiable(ver):
    return [f["reason"] for f in ver["findings"] if f["severity"] == "unverifiable"]


def _records(contents):
    certs = {c["index"]: c for c in contents.certificates()}
    plans = contents.plans_by_index()
    acts = {a["index"]: a for a in contents.topic(topics.ACTION)}
    return certs, plans, acts


def _on_plan(plan, t, qpos):
    """The plan has a waypoint at time t (exactly) whose qpos is ``qpos`` (1e-9)."""
    times = np.asarray(plan["times"], float)
    hit = np.flatnonzero(times == t)
    return len(hit) == 1 and np.allclose(np.asarray(plan["qpos"], float)[hit[0]], qpos, rtol=0, atol=1e-9)


def _arm_run(path, steps=STEPS, **gate_kw):
    """SafetyGate on monitor/Arm-v0 (seeded random actions); per step (t0, q0, t1, q1) of the live data."""
    env = SafetyGate(gym.make("monitor/Arm-v0"), log=path, **gate_kw)
    env.reset(seed=0)
    env.action_space.seed(0)
    d = env.unwrapped.data
    states = []
    for _ in range(steps):
        t0, q0 = float(d.time), d.qpos.copy()
        env.step(env.action_space.sample())
        states.append((t0, q0, float(d.time), d.qpos.copy()))
    stats = dict(env.gate.stats)
    env.close()
    return stats, states


@pytest.fixture(scope="module")
def arm_log(tmp_path_factory):
    path = tmp_path_factory.mktemp("applied") / "arm.mcap"
    stats, states = _arm_run(path)
    return path, stats, states


def _check_applied_records(contents, states, stats):
    """Each replaced step names a record whose plan passes through the live states before and after it."""
    certs, plans, acts = _records(contents)
    steps = [c for c in contents.certificates() if "applied" not in c]
    assert len(steps) == len(states)
    uses: dict[int, int] = {}
    for c, (t0, q0, t1, q1) in zip(steps, states, strict=True):
        a = acts[c["index"]]
        assert c["window"] == [t0, t1]
        if not a["replaced"]:
            assert "applied_window" not in a
            continue
        j = a["applied_window"]
        rec = certs[j]
        assert rec["applied"]["kind"] in ("fallback", "brake_tail")
        assert rec["window"][0] <= t0 and t1 <= rec["window"][1]
        assert _on_plan(plans[j], t0, q0) and _on_plan(plans[j], t1, q1), (c["index"], j)
        uses[j] = uses.get(j, 0) + 1
    assert sum(uses.values()) == stats["replaced"]
    n_records = sum(1 for c in certs.values() if "applied" in c)
    assert n_records == len(uses)  # every record is named; a tail is written once, not per step
    return uses


def test_arm_block_logs_every_applied_motion_and_review_rederives_it(arm_log):
    path, stats, states = arm_log
    assert stats["replaced"] >= 5 and stats["tail_reused"] >= 5  # random Arm actions get blocked
    contents = read_log(path)
    assert contents.run.get("applied_motions") == "logged"
    certs, plans, acts = _records(contents)
    uses = _check_applied_records(contents, states, stats)
    tails = [j for j in uses if certs[j]["applied"]["kind"] == "brake_tail"]
    assert tails and max(uses[j] for j in tails) >= 2  # the committed brake over several steps
    for j in tails:
        by = certs[j]["applied"]["covered_by"]
        assert by < j and "applied" not in certs[by] and not acts[by]["replaced"]
        assert certs[by]["window"][1] == certs[j]["window"][0]  # the tail starts where its step ends
        jw = certs[j]["stats"].get("joint_window")
        if jw is not None:  # certified jointly with the accepted window: one certificate
            assert certs[by]["stats"]["joint_window"] == jw
    ver = review.verify(contents)
    assert ver["critical"] == 0 and _unverifiable(ver) == [], (_critical(ver), _unverifiable(ver))
    assert ver["applied_records"] == len(uses) and ver["applied_checked"] == len(uses)
    assert ver["applied_steps"] == stats["replaced"] and ver["applied_missing"] == 0
    assert ver["checked"] == ver["windows"] == STEPS + len(uses)
    assert review.verify_exit_code(ver) == 0
    assert not any("not in the log" in n for n in ver["notes"]), ver["notes"]
    s = review.analyze(contents)
    assert s["windows"] == STEPS and s["applied_motions"]["records"] == len(uses)
    assert s["blocked_actions"] == stats["replaced"]


def test_two_call_path_logs_the_tail_with_its_own_certificate(tmp_path):
    """The gate's two-call path (tail certified by its own call): the record carries that certificate."""
    path = tmp_path / "two.mcap"
    env = SafetyGate(gym.make("monitor/Arm-v0"), log=path)
    env.gate._joint_tail = False
    env.reset(seed=0)
    env.action_space.seed(0)
    d = env.unwrapped.data
    states = []
    for _ in range(30):
        t0, q0 = float(d.time), d.qpos.copy()
        env.step(env.action_space.sample())
        states.append((t0, q0, float(d.time), d.qpos.copy()))
    stats = dict(env.gate.stats)
    env.close()
    assert stats["joint"] == 0 and stats["tail_reused"] >= 2
    contents = read_log(path)
    uses = _check_applied_records(contents, states, stats)
    certs, _, _ = _records(contents)
    assert all("joint_window" not in (certs[j].get("stats") or {}) for j in uses)
    ver = review.verify(contents)
    assert ver["critical"] == 0 and ver["applied_steps"] == stats["replaced"], _critical(ver)
    assert review.verify_exit_code(ver) == 0


def test_a_fresh_fallback_logs_its_own_window(tmp_path):
    """brake=False: a blocked step runs the fallback, certified afresh; its record covers itself."""
    env = gym.make("monitor/Arm-v0")
    env.reset(seed=1)
    model, d = env.unwrapped.model, env.unwrapped.data
    rng = np.random.default_rng(3)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    path = tmp_path / "fb.mcap"
    states = []
    with Gate(model, log=path, brake=False, frame_skip=env.unwrapped.frame_skip) as gate:
        for _ in range(30):
            t0, q0 = float(d.time), d.qpos.copy()
            gate.step(d, rng.uniform(lo, hi))
            states.append((t0, q0, float(d.time), d.qpos.copy()))
        stats = dict(gate.stats)
    env.close()
    assert stats["replaced"] >= 2, stats
    contents = read_log(path)
    uses = _check_applied_records(contents, states, stats)
    certs, _, _ = _records(contents)
    assert all(certs[j]["applied"] == {"kind": "fallback", "covered_by": j} for j in uses)
    n_uncert = sum(certs[j]["verdict"] != "certified" for j in uses)
    assert n_uncert == stats["fallback_uncertified"]
    ver = review.verify(contents)
    assert ver["critical"] == 0 and ver["applied_steps"] == stats["replaced"], _critical(ver)
    assert ver["mismatches"] == []


# --------------------------------------------------------------------------- forgeries


def _forge(src, dst, **kw):
    rewrite(src, dst, **kw)
    return review.verify(read_log(dst))


def test_forged_applied_window_naming_a_record_that_does_not_cover_the_step_is_critical(arm_log, tmp_path):
    path, _, _ = arm_log
    certs, _, acts = _records(read_log(path))
    tails = sorted({a["applied_window"] for a in acts.values() if a["replaced"]})
    assert len(tails) >= 2
    first, last = tails[0], tails[-1]
    victim = max(k for k, a in acts.items() if a["replaced"] and a["applied_window"] == last)
    assert not (certs[first]["window"][0] <= certs[victim]["window"][0]
                and certs[victim]["window"][1] <= certs[first]["window"][1])  # the oracle: no cover

    def msg(topic, p):
        if topic == topics.ACTION and p["index"] == victim:
            p["applied_window"] = first
        return p

    ver = _forge(path, tmp_path / "moved.mcap", msg=msg)
    crit = _critical(ver)
    assert any(f"applied record {first} (window" in r and "does not cover the span" in r
               and f"of replaced step {victim}" in r for r in crit), crit
    assert review.verify_exit_code(ver) == 1


def test_forged_record_window_and_covered_by_are_critical(arm_log, tmp_path):
    """A certified record whose window is shrunk off the step, or which names a covering window
    that is not where the tail starts: CRITICAL."""
    path, _, _ = arm_log
    certs, _, acts = _records(read_log(path))
    j = next(a["applied_window"] for a in acts.values() if a["replaced"])
    by = certs[j]["applied"]["covered_by"]
    assert certs[j]["verdict"] == "certified"

    def wrong_by(topic, p):
        if topic == topics.CERTIFICATE and p["index"] == j:
            p["applied"]["covered_by"] = max(0, by - 1)
        return p

    crit = _critical(_forge(path, tmp_path / "by.mcap", msg=wrong_by))
    assert any(f"not where window {max(0, by - 1)} (its covering step) ends" in r
               or "is no earlier step window" in r for r in crit), crit


def test_a_missing_applied_record_is_flagged(arm_log, tmp_path):
    """The record's window named by a replaced step turned into an ordinary window: unverifiable."""
    path, _, _ = arm_log
    _, _, acts = _records(read_log(path))
    j = next(a["applied_window"] for a in acts.values() if a["replaced"])

    def drop_marker(topic, p):
        if topic == topics.CERTIFICATE and p["index"] == j:
            del p["applied"]
        return p

    ver = _forge(path, tmp_path / "gone.mcap", msg=drop_marker)
    assert ver["applied_missing"] >= 1
    assert any(f"applied motion record (window {j}) is missing" in r for r in _unverifiable(ver))
    assert review.verify_exit_code(ver) == 2

    def strip_field(topic, p):
        if topic == topics.ACTION:
            p.pop("applied_window", None)
        return p

    ver = _forge(path, tmp_path / "unnamed.mcap", msg=strip_field)  # the run still says it logs them
    assert ver["applied_missing"] == sum(a["replaced"] for a in acts.values())
    assert review.verify_exit_code(ver) == 2


def test_an_old_gate_log_still_reviews_with_a_note(monkeypatch, tmp_path):
    """A gate from before applied records (only uncertified applied windows logged): a note, exit 0."""
    monkeypatch.setattr(MonitorLog, "logs_applied_motions", False, raising=False)  # (main: absent)
    policy = Gate._policy_metadata
    monkeypatch.setattr(Gate, "_policy_metadata",
                        lambda self: {k: v for k, v in policy(self).items() if k != "applied_motions"})
    path = tmp_path / "old.mcap"
    stats, _ = _arm_run(path, steps=30)
    contents = read_log(path)
    assert "applied_motions" not in contents.run
    assert not any("applied" in c for c in contents.certificates())
    ver = review.verify(contents)
    unlogged = stats["replaced"] - stats["fallback_uncertified"]
    assert unlogged > 0 and ver["critical"] == 0 and _unverifiable(ver) == []
    assert any(n.startswith(f"{unlogged} replaced action(s) (blocked proposals) ran a motion that is not in "
                            f"the log") for n in ver["notes"]), ver["notes"]
    assert review.verify_exit_code(ver) == 0


def test_writer_validates_applied_fields(tmp_path):
    from monitor.errors import InvalidInputError

    model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='.1'/></worldbody></mujoco>")
    cert = {"verdict": "certified", "window": [0.0, 0.1], "margin": 0.0, "epsilon": 1e-3, "method": "auto",
            "pairs": []}
    with MonitorLog(tmp_path / "v.mcap", model=model, foxglove=False) as log:
        with pytest.raises(InvalidInputError, match="applied_window"):
            log.write_window(0.0, None, cert, applied_window=-1)
        with pytest.raises(InvalidInputError, match="kind"):
            log.write_window(0.0, None, cert, applied={"kind": "teleport", "covered_by": 0})
        with pytest.raises(InvalidInputError, match="covered_by"):
            log.write_window(0.0, None, cert, applied={"kind": "fallback", "covered_by": 5})
        assert log.write_window(0.0, None, cert, applied={"kind": "fallback", "covered_by": 0}) == 0


def test_forged_record_motion_that_leaves_the_step_elsewhere_is_critical(arm_log, tmp_path):
    """A tail record whose motion is edited after the step's start (a different motion that still
    covers the span and starts right): it no longer ends the step where the next window starts."""
    path, _, _ = arm_log
    certs, plans, acts = _records(read_log(path))
    starts = {c["window"][0] for c in certs.values() if "applied" not in c}
    k, j = next((k, a["applied_window"]) for k, a in sorted(acts.items())
                if a["replaced"] and certs[a["applied_window"]]["verdict"] == "certified"
                and certs[k]["window"][1] in starts)
    t1 = certs[k]["window"][1]
    hit = int(np.flatnonzero(np.asarray(plans[j]["times"]) == t1)[0])

    def move(topic, p):
        if topic == topics.PLAN and p["index"] == j:
            p["qpos"][hit] = [q + 1e-3 for q in p["qpos"][hit]]  # 1 mrad off at the step's end
        return p

    ver = _forge(path, tmp_path / "elsewhere.mcap", msg=move)
    crit = _critical(ver)
    assert any(f"applied record {j}'s motion does not end replaced step {k} in the state the next window" in r
               for r in crit), crit
