"""Defaults that work (issue 13): SafetyGate(gym.make(env_id)) with no arguments on stock envs.

With a seeded random policy over 200 steps the gate never blocks every action,
and every block is justified: a proposal violation is re-confirmed by an exact
static distance on a monitored (not allowed) pair at the witness time; an
uncertain proposal names, per uncertain pair, the unresolved intervals or the
rule's note; a rejected braking tail is reported as such.
"""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest

from monitor.geometry.distance import shape_distance
from monitor.gym_gate import SafetyGate

FAST = ["Reacher-v5", "InvertedPendulum-v5", "Pusher-v5", "Ant-v5"]
SLOW = ["HalfCheetah-v5", "Hopper-v5", "Walker2d-v5", "Swimmer-v5", "InvertedDoublePendulum-v5",
        "Humanoid-v5", "HumanoidStandup-v5"]
STEPS = 200


def _justified(gate, report) -> str:
    """Check one block; returns its reason."""
    info = report.info()
    reason = info["block_reason"]
    assert reason, "a replaced proposal must say why"
    scene = gate.scene
    monitored = set(scene.candidate_pairs)
    allowed = {(a, b) for a, b, _ in scene.allowed_pairs}
    cert = report.certificate
    if reason.startswith("proposal_violation"):
        w = cert.witness
        assert tuple(w.geoms) in monitored and tuple(w.geoms) not in allowed
        pr = next(p for p in cert.pairs if p.geoms == tuple(w.geoms))
        ga, gb = scene.geom(w.geoms[0]), scene.geom(w.geoms[1])
        pos, rot = report.plan.body_poses(np.array([w.time]))
        d = shape_distance(ga.shape, (rot[0, ga.body_id], pos[0, ga.body_id]),
                           gb.shape, (rot[0, gb.body_id], pos[0, gb.body_id]))
        limit = -gate.penetration_tol if pr.note.startswith("ongoing") else gate.margin
        approx = ga.shape.approx_error + gb.shape.approx_error
        assert d.upper + approx < limit, (w, d)  # the window really comes closer than allowed
    elif reason.startswith("proposal_uncertain"):
        bad = [p for p in cert.pairs if p.verdict == "uncertain"]
        assert bad
        for p in bad:
            assert p.geoms in monitored and p.geoms not in allowed
            assert p.intervals or p.note, p  # a stated reason: where, or which rule
    else:
        assert reason.startswith("brake_tail_uncertified")
        assert report.verdict == "certified" and info["brake_verdict"] in ("violation", "uncertain")
    return reason


def _run(env_id: str, steps: int = STEPS) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = SafetyGate(gym.make(env_id))
    env.reset(seed=0)
    assert env.describe().startswith("monitor.Gate:")
    env.action_space.seed(0)
    blocked, reasons, cost = 0, {}, 0.0
    for _ in range(steps):
        _o, _r, term, trunc, info = env.step(env.action_space.sample())
        s = info["safety"]
        assert s["version"] == 2 and s["intervened"] == s["replaced"]
        assert info["cost"] == (1.0 if s["applied_verdict"] == "violation" else 0.0)
        if s["intervened"]:
            blocked += 1
            r = _justified(env.gate, env.gate.last_report)
            reasons[r] = reasons.get(r, 0) + 1
        else:
            assert s["block_reason"] == ""
        cost += info["cost"]
        if term or trunc:
            env.reset()
    env.close()
    assert blocked < steps, f"{env_id}: every action blocked ({reasons})"
    return {"blocked": blocked, "reasons": reasons, "cost": cost}


@pytest.mark.parametrize("env_id", FAST)
def test_defaults_never_block_everything(env_id):
    _run(env_id)


@pytest.mark.slow
@pytest.mark.parametrize("env_id", SLOW)
def test_defaults_never_block_everything_heavy(env_id):
    _run(env_id)


def test_pusher_defaults_allow_the_resting_object_and_check_the_arm():
    env = SafetyGate(gym.make("Pusher-v5"))
    env.reset(seed=0)
    allowed = {(a, b): r for a, b, r in env.gate.scene.allowed_pairs}
    assert allowed == {("table", "geom18"): "Default"}  # object/0 rests on the table
    assert ("table", "geom13") in env.gate.scene.candidate_pairs
    env.close()


def test_gate_with_nothing_to_check_warns_once():
    with pytest.warns(UserWarning, match="no candidate pairs"):  # known from MuJoCo's filter at once
        env = SafetyGate(gym.make("Reacher-v5"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env.reset(seed=0)  # the pair policy is resolved at the first reset: no second warning
        env.reset(seed=1)
        env.step(env.action_space.sample())
        env.gate._scene = None  # rebuilding the scene does not warn again
        env.gate.scene  # noqa: B018
    assert "0 pairs monitored" in env.describe()
    env.close()


def test_ant_feet_rest_allowed_torso_floor_checked():
    """Ant: feet on the floor are allowed (Default); the torso hitting the floor is still checked."""
    env = SafetyGate(gym.make("Ant-v5"))
    env.reset(seed=0)
    allowed = {(a, b) for a, b, _ in env.gate.scene.allowed_pairs}
    assert ("floor", "torso_geom") not in allowed
    assert ("floor", "torso_geom") in env.gate.scene.candidate_pairs
    assert {("floor", f) for f in ("left_ankle_geom", "right_ankle_geom", "third_ankle_geom",
                                   "fourth_ankle_geom")} == allowed
    env.close()


def test_default_reference_is_the_reset_state_not_qpos0():
    """AGV: at qpos0 the tray plate touches the crate (a designed-away pose the env never visits);
    the gate's ACM uses the first reset state, so that pair stays checked (regression)."""
    pytest.importorskip("envs")
    import envs  # noqa: F401

    env = SafetyGate(gym.make("monitor/AGV-v0", schedule="straight"), predictor="plan")
    env.reset(seed=0)
    assert ("plate1", "crate_top") not in {tuple(sorted(p[:2])) for p in env.gate.scene.allowed_pairs}
    assert ("crate_top", "plate1") in env.gate.scene.candidate_pairs
    env.close()
