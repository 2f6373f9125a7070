"""Our gymnasium environments: registration, check_env, no MuJoCo warnings, scene facts."""

from __future__ import annotations

import warnings

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import monitor.envs  # noqa: F401  (registers the ids)
from monitor._paths import scene_path

OWN_ENVS = ["monitor/Arm-v0", "monitor/Tunnel-v0"]


ALL_ENVS = [*OWN_ENVS, "monitor/AGV-v0"]  # all part of this repository: a broken one fails, never skips


@pytest.mark.parametrize("env_id", ALL_ENVS)
def test_check_env_passes(env_id):
    env = gym.make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # gymnasium's advisory warnings (unbounded obs, asymmetric box)
        check_env(env.unwrapped, skip_render_check=True)
    env.close()


@pytest.mark.parametrize("env_id", ALL_ENVS)
def test_steps_without_mujoco_warnings(env_id):
    env = gym.make(env_id)
    env.reset(seed=3)
    env.action_space.seed(3)
    for _ in range(150):
        env.step(env.action_space.sample())
    u = env.unwrapped
    assert [w.number for w in u.data.warning] == [0] * len(u.data.warning)
    assert np.all(np.isfinite(u.data.qpos))
    env.close()


@pytest.mark.parametrize("name", ["arm", "tunnel"])
def test_scene_compiles_and_has_readme(name):
    p = scene_path(name)
    m = mujoco.MjModel.from_xml_path(str(p))
    d = mujoco.MjData(m)
    if m.nkey:
        mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    assert d.ncon == 0, "initial pose must be contact free"
    assert (p.parent / "README.md").is_file()


def test_arm_scene_requirements():
    m = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
    hinges = [j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    assert len(hinges) >= 3
    assert m.nu == 3 and np.all(m.actuator_ctrllimited)
    assert np.all(m.actuator_biastype == int(mujoco.mjtBias.mjBIAS_AFFINE))  # position servos
    mesh_geoms = [g for g in range(m.ngeom) if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH]
    assert {"finger_l", "finger_r"} <= {m.geom(g).name for g in mesh_geoms}
    for g in mesh_geoms:
        assert m.body(int(m.geom_bodyid[g])).name == "gripper"


def test_arm_planned_trajectory_matches_step():
    env = gym.make("monitor/Arm-v0").unwrapped
    env.reset(seed=1)
    a = np.array([0.4, -0.3, 0.6], dtype=np.float32)
    plan = env.planned_trajectory(a)
    qpos_before = env.data.qpos.copy()
    env.step(a)
    assert np.array_equal(plan.qpos[-1], env.data.qpos)  # exact prediction
    assert np.array_equal(plan.qpos[0], qpos_before)
    assert plan.qpos.shape == (env.frame_skip + 1, env.model.nq)


def _ncon_between(m, d, geoms_a, geoms_b):
    n = 0
    for c in d.contact[: d.ncon] if d.ncon else []:
        g1, g2 = int(c.geom[0]), int(c.geom[1])
        if (g1 in geoms_a and g2 in geoms_b) or (g2 in geoms_a and g1 in geoms_b):
            n += 1
    return n


def test_tunnel_mujoco_misses_the_wall():
    """At the env timestep MuJoCo's contacts never see the wall, yet the ball crosses it."""
    env = gym.make("monitor/Tunnel-v0").unwrapped
    env.reset(seed=0)
    m, d = env.model, env.data
    xs, ncons = [float(d.qpos[0])], []
    for _ in range(12):
        env.step(np.array([5.0], dtype=np.float32))
        mujoco.mj_forward(m, d)
        xs.append(float(d.qpos[0]))
        ncons.append(d.ncon)
    xs = np.array(xs)
    assert xs[0] < 0 < xs[-1], "ball crossed the wall"
    assert sum(ncons) == 0, "MuJoCo never reported a contact"
    # the crossing step jumps over the whole contact band |x| < r + half thickness
    k = int(np.argmax(xs > 0))
    band = 0.01 + 0.005
    assert xs[k - 1] < -band and xs[k] > band


# ----------------------------------------------------------------------------- gated arm vs a post
def _arm_obstacle_contacts(gated, steps):
    from monitor.gym_gate import SafetyGate

    env = gym.make("monitor/Arm-v0", max_episode_steps=steps + 1)
    if gated:
        env = SafetyGate(env, on_violation="block")
    u = env.unwrapped
    m = u.model
    body_of = [m.body(int(m.geom_bodyid[g])).name for g in range(m.ngeom)]
    arm = {g for g, b in enumerate(body_of) if b in ("link1", "link2", "link3", "gripper")}
    obstacles = {g for g, b in enumerate(body_of) if b in ("post_a", "post_b", "shelf")}
    env.reset(seed=0)
    # the stretched arm aimed at post_a
    into_post = np.array([np.arctan2(0.25, 0.45), 0.0, 0.0], dtype=np.float32)
    n, replaced = 0, 0
    for _ in range(steps):
        _, _, _, _, info = env.step(into_post)
        n += _ncon_between(m, u.data, arm, obstacles)
        replaced += int(gated and info["safety"]["replaced"])
    env.close()
    return n, replaced


def _gate_keeps_arm_off_the_post(steps):
    free, _ = _arm_obstacle_contacts(gated=False, steps=steps)
    assert free > 0, "without the gate the policy drives the arm into the post"
    blocked, replaced = _arm_obstacle_contacts(gated=True, steps=steps)
    assert blocked == 0, "with the gate MuJoCo reports no arm/obstacle contact"
    assert replaced > 0


def test_gate_keeps_arm_off_the_post_500_steps():
    _gate_keeps_arm_off_the_post(500)  # acceptance figure; contact comes at step ~7 without the gate


# ----------------------------------------------------------------------------- AGV and trays


def _run_agv(schedule, mode, steps, rate=1.0):
    from monitor.gym_gate import SafetyGate

    env = SafetyGate(gym.make("monitor/AGV-v0", schedule=schedule), predictor="plan", on_violation=mode)
    env.reset(seed=0)
    u = env.unwrapped
    rows = []
    for _ in range(steps):
        obs, _, term, trunc, info = env.step(np.array([rate], dtype=np.float32))
        s = info["safety"]
        rows.append((s["verdict"], s["time"], s["earliest_time"], tuple(s["witness_geoms"]), s["replaced"],
                     u.data.ncon, float(obs[2])))
        if term or trunc:
            break
    env.close()
    return rows


def test_agv_straight_schedule_violation_found_in_its_window():
    from monitor.bench.extrusion_scenes import STRAIGHT_FIRST_CONTACT

    rows = _run_agv("straight", "warn", 100)
    first = next(i for i, r in enumerate(rows) if r[0] == "violation")
    verdict, t0, earliest, geoms, *_ = rows[first]
    assert t0 <= STRAIGHT_FIRST_CONTACT <= t0 + 0.1  # the window holding the analytic first contact
    assert earliest <= STRAIGHT_FIRST_CONTACT + 1e-9
    assert "plate1" in geoms or "load1" in geoms
    assert all(r[0] == "certified" for r in rows[:first])
    assert sum(r[5] for r in rows) > 0, "MuJoCo sees the collision too (independent check)"


def test_agv_straight_schedule_blocked_never_touches():
    rows = _run_agv("straight", "block", 130)
    assert sum(r[4] for r in rows) > 0, "the gate stopped the vehicle"
    assert all(r[5] == 0 for r in rows), "MuJoCo reports no contact at any step state"


def test_agv_weaving_narrow_miss_is_certified():
    rows = _run_agv("weaving", "block", 125)  # plate 1 passes over the vehicle for t in 8.2..11.8 s
    assert all(r[0] == "certified" for r in rows)
    assert not any(r[4] for r in rows)


@pytest.mark.parametrize("env_id", ALL_ENVS)
def test_check_env_passes_when_gated(env_id):
    from monitor.gym_gate import SafetyGate

    predictor = "plan" if env_id == "monitor/AGV-v0" else "rollout"
    env = SafetyGate(gym.make(env_id), predictor=predictor, margin=0.002)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(env, skip_render_check=True)
    env.close()


def test_plan_and_callable_predictors_on_the_arm():
    from monitor.gym_gate import SafetyGate

    calls = []

    def predictor(env, obs, action):
        calls.append(obs is not None)
        return env.unwrapped.planned_trajectory(action)

    for pred in ("plan", predictor):
        env = SafetyGate(gym.make("monitor/Arm-v0"), predictor=pred, on_violation="warn")
        env.reset(seed=5)
        for _ in range(3):
            env.step(np.array([0.2, -0.2, 0.4], dtype=np.float32))
            assert np.array_equal(env.gate.last_report.plan.qpos[-1], env.unwrapped.data.qpos)
        env.close()
    assert calls == [True, True, True]
