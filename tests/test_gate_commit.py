"""Gate.step commits the scratch window it certified instead of stepping again (issue 12, item 5).

Oracle: a second, ungated ``MjData`` stepped with plain ``mj_step`` and the same applied
controls. After every step both must agree bit for bit on every array of ``MjData`` and on
the diagnostics (warning counters, solver statistics, memory high-water marks, contact and
constraint counts). Excluded: the sparse-Jacobian index arrays (``efc_*_rownnz/rowadr/
rowsuper/colind``) of a model that uses the dense Jacobian, which MuJoCo leaves
uninitialised (they hold whatever the arena held), and the wall-clock timer durations.
"""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest

from monitor._paths import scene_path
from monitor.gate import Gate, Rollout

_SPARSE_INDEX = re.compile(r"^efc_.*_(rownnz|rowadr|rowsuper|colind)$")


def _compared_fields(model: mujoco.MjModel, data: mujoco.MjData) -> list[str]:
    dense = not mujoco.mj_isSparse(model)
    return [a for a in dir(data) if not a.startswith("_") and isinstance(getattr(data, a), np.ndarray)
            and not (dense and _SPARSE_INDEX.match(a))]


def _diagnostics(d: mujoco.MjData) -> tuple:
    return ([(d.warning[i].number, d.warning[i].lastinfo) for i in range(len(d.warning))],
            [d.timer[i].number for i in range(len(d.timer))],
            d.maxuse_stack, d.maxuse_arena, d.maxuse_con, d.maxuse_efc, d.ncon, d.nefc, d.time)


def _assert_same(model, d, oracle, fields, k):
    bad = [a for a in fields if not np.array_equal(getattr(d, a), getattr(oracle, a), equal_nan=True)]
    assert not bad, f"step {k}: fields differ from the ungated oracle: {bad}"
    assert _diagnostics(d) == _diagnostics(oracle), f"step {k}: diagnostics differ"


def _run_against_oracle(model, steps, ctrl_of, *, reset_every=100, **gate_kwargs):
    d, oracle = mujoco.MjData(model), mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, d, 0)
    mujoco.mj_resetDataKeyframe(model, oracle, 0)
    gate = Gate(model, **gate_kwargs)
    fields = _compared_fields(model, d)
    for k in range(steps):
        if k % reset_every == reset_every - 1:
            mujoco.mj_resetDataKeyframe(model, d, 0)
            mujoco.mj_resetDataKeyframe(model, oracle, 0)
            gate.reset()
        r = gate.step(d, ctrl_of(k, d))
        oracle.ctrl[:] = r.applied_ctrl
        mujoco.mj_step(model, oracle, nstep=gate.frame_skip)
        _assert_same(model, d, oracle, fields, k)
    return gate


def _tunnel_ctrl(seed):
    rng = np.random.default_rng(seed)
    ctrls = [np.array([rng.uniform(-6.0, 6.0)]) for _ in range(100)]
    return lambda k, d: ctrls[k // 20]


@pytest.mark.parametrize("steps", [pytest.param(500, marks=pytest.mark.slow), 120])
def test_tunnel_gate_step_is_bit_identical_to_an_ungated_oracle(steps):
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    gate = _run_against_oracle(m, steps, _tunnel_ctrl(1))
    s = gate.summary()
    # every kind of window was exercised: accepted, blocked with a predicted fallback,
    # blocked inside the committed tail (replayed against the tail's rows, then committed too)
    assert s["replaced"] > 0 and s["tail_reused"] > 0
    assert s["committed"] == steps and s["tail_replay_differs"] == 0


def test_arm_gate_step_with_substeps_is_bit_identical_to_an_ungated_oracle():
    m = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
    rng = np.random.default_rng(3)
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    ctrls = [rng.uniform(lo, hi) for _ in range(10)]
    gate = _run_against_oracle(m, 24, lambda k, d: ctrls[k // 4], frame_skip=3)
    assert gate.summary()["committed"] > 0


def test_commit_refuses_a_window_the_scratch_does_not_hold():
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    ro = Rollout(m)
    ro.states(d, np.array([2.0]), 2)
    before = np.array(d.qpos)
    assert not ro.commit(d, np.array([2.5]), 2)  # other control
    assert not ro.commit(d, np.array([2.0]), 3)  # other number of substeps
    d.qvel[0] += 1e-12  # other state
    assert not ro.commit(d, np.array([2.0]), 2)
    assert np.array_equal(d.qpos, before)  # nothing was written
    d.qvel[0] -= 1e-12
    d2 = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d2, 0)
    d2.qvel[:] = d.qvel
    assert ro.commit(d, np.array([2.0]), 2)
    d2.ctrl[:] = 2.0
    mujoco.mj_step(m, d2, nstep=2)
    assert np.array_equal(d.qpos, d2.qpos) and np.array_equal(d.qvel, d2.qvel) and d.time == d2.time
    assert not ro.commit(d, np.array([2.0]), 2)  # used up


@pytest.mark.parametrize("vel_tol", [1e-4, 1e-3, 0.05, 1.5, 1e3])  # stops: first, chunk start, mid-chunk, max
@pytest.mark.parametrize("scene", ["tunnel", "arm"])
def test_brake_tail_from_the_snapshot_equals_a_fresh_simulation(scene, vel_tol):
    """The tail continued from the predicted window equals the tail of a fresh rollout and an
    independent hand-stepped oracle, including where it stops (first substep with every
    |qvel| <= vel_tol, else max_steps)."""
    m = mujoco.MjModel.from_xml_path(str(scene_path(scene)))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    rng = np.random.default_rng(7)
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    gate = Gate(m)
    lengths = set()
    for _ in range(4):
        ctrl = rng.uniform(lo, hi)
        warm = Rollout(m)
        warm.plan(d, ctrl, 4)  # the gate's order: predict the window, then the tail
        got = warm.brake_tail(d, ctrl, 4, gate._brake_ctrl, 40, vel_tol)
        fresh = Rollout(m).brake_tail(d, ctrl, 4, gate._brake_ctrl, 40, vel_tol)
        # the oracle: the window and the brake integrated by hand on an independent MjData
        o = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, o, 0)
        o.qpos[:], o.qvel[:], o.act[:], o.time = d.qpos, d.qvel, d.act, d.time
        o.qacc_warmstart[:] = d.qacc_warmstart
        o.ctrl[:] = ctrl
        mujoco.mj_step(m, o, nstep=4)
        brake_oracle = gate._brake_ctrl(o)  # at the window's end
        o.ctrl[:] = brake_oracle
        times, qpos, qvel = [o.time], [np.array(o.qpos)], [np.array(o.qvel)]
        for _ in range(40):
            mujoco.mj_step(m, o)
            times.append(o.time)
            qpos.append(np.array(o.qpos))
            qvel.append(np.array(o.qvel))
            if np.max(np.abs(o.qvel)) <= vel_tol:
                break
        lengths.add(len(times))
        for plan, brake, qv in (got, fresh):
            assert np.array_equal(plan.times, np.array(times))
            assert np.array_equal(plan.qpos, np.array(qpos))
            assert np.array_equal(qv, np.array(qvel))
            assert np.array_equal(brake, brake_oracle)
        d.ctrl[:] = ctrl
        mujoco.mj_step(m, d, nstep=4)
    if vel_tol == 1e3:
        assert lengths == {2}  # stops after the first substep


def _gym_against_oracle(env_id, steps, **kw):
    """SafetyGate (committing its scratch window) vs an ungated env given the applied actions."""
    import gymnasium as gym

    import monitor.envs  # noqa: F401  (registers monitor/Arm-v0)
    from monitor.gym_gate import SafetyGate

    env, oracle = SafetyGate(gym.make(env_id), **kw), gym.make(env_id)
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(steps)]
    o1, _ = env.reset(seed=0)
    o2, _ = oracle.reset(seed=0)
    u, uo = env.unwrapped, oracle.unwrapped
    fields = _compared_fields(u.model, u.data)
    for k, a in enumerate(acts):
        o1, r1, te1, tr1, _ = env.step(a)
        o2, r2, te2, tr2, _ = oracle.step(env.gate.last_report.applied_ctrl)
        assert np.array_equal(o1, o2) and r1 == r2 and (te1, tr1) == (te2, tr2), f"step {k}"
        _assert_same(u.model, u.data, uo.data, fields, k)
        if te1 or tr1:
            env.reset(seed=k)
            oracle.reset(seed=k)
    s = env.gate.summary()
    env.close()
    oracle.close()
    return s


@pytest.mark.parametrize("env_id, kw", [("Pusher-v5", {"pairs": "mujoco"}), ("monitor/Arm-v0", {})])
def test_safety_gate_commit_is_bit_identical_to_an_ungated_env(env_id, kw):
    s = _gym_against_oracle(env_id, 30, **kw)
    assert s["committed"] > 0
    if env_id == "monitor/Arm-v0":  # rejections too: fallbacks predicted, or inside the committed tail
        assert s["replaced"] > 0 and s["tail_reused"] > 0 and s["committed"] == s["windows"]
    else:
        assert s["committed"] == s["windows"]


def test_safety_gate_never_commits_into_an_env_with_its_own_simulation():
    import gymnasium as gym

    from monitor.gym_gate import SafetyGate

    class OwnSim(gym.Wrapper):
        pass

    env = SafetyGate(OwnSim(gym.make("Pusher-v5")), pairs="mujoco")
    assert env._commit_ok
    u = env.unwrapped
    calls = []
    u._step_mujoco_simulation = lambda ctrl, n: calls.append(n)  # an env simulating its own way
    env.reset(seed=0)
    env.step(env.action_space.sample() * 0)
    assert calls == [u.frame_skip] and env.gate.stats["committed"] == 0
    env.close()
