"""Red team 3: ``certified`` for a motion that collides, at the gate layer (issue 12, h12ag).

Oracles are independent of the checkers: a sphere on a slide joint along x moves toward a
box wall that MuJoCo does not collide (contype 0, an explicitly monitored pair), so it passes
through it; the signed distance of the sphere to the wall's face is ``x_face - x - r`` in
closed form. Along one window the sphere moves monotonically (constant force), so the
smallest distance of the applied window is at one of its end states, which the test reads
from the live data (the motion that actually ran).
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.envs.mujoco.mujoco_env import MujocoEnv

from monitor.errors import InvalidInputError
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate

RADIUS = 0.05
FACE_X = 0.15  # wall's face (m): the box spans x in [0.15, 0.25]
DT = 0.002

_XML = f"""
<mujoco>
  <option timestep="{DT}" gravity="0 0 0"/>
  <worldbody>
    <body name="ball" pos="0 0 0">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="{RADIUS}" mass="1" contype="0" conaffinity="0"/>
    </body>
    <geom name="wall" type="box" pos="{FACE_X + 0.05} 0 0" size="0.05 0.3 0.3" contype="0" conaffinity="0"/>
  </worldbody>
  <actuator><motor name="push" joint="x" ctrlrange="-1 1"/></actuator>
</mujoco>
"""


def _model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(_XML)


def _distance(x: float) -> float:
    """Closed-form signed distance (m) of the ball at slide position ``x`` to the wall's face."""
    return FACE_X - x - RADIUS


# --------------------------------------------------------------------------- dynamics edit, committed brake
def test_committed_brake_is_not_reused_after_a_gravity_edit():
    """A committed braking tail certified under one gravity is not the motion under another.

    Step 1 (no gravity): the ball coasts at 0.05 m/s toward the wall 0.1 m away; the window and
    its 0.25 s braking tail (motor off: it coasts 12.5 mm) are certified, the tail committed.
    Then ``model.opt.gravity`` points at the wall (500 m/s^2). Step 2's proposal collides and is
    replaced by the committed brake (control 0), whose window is a waypoint range of the
    committed tail in time, qpos, qvel and mocap: on main the gate reused the tail's
    certificate (``applied_verdict == "certified"``) although under the new gravity that window
    carries the ball 0.1 m, through the wall.
    """
    m = _model()
    d = mujoco.MjData(m)
    d.qvel[0] = 0.05
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10)
    r1 = gate.step(d, np.zeros(1))
    assert r1.verdict == "certified" and not r1.replaced and r1.brake_verdict == "certified"
    m.opt.gravity[:] = (500.0, 0.0, 0.0)
    x0 = float(d.qpos[0])
    r2 = gate.step(d, np.zeros(1))
    x1 = float(d.qpos[0])
    assert r2.replaced
    assert min(_distance(x0), _distance(x1)) < -0.01  # the oracle: the applied window went through
    assert r2.applied_verdict != "certified", (x0, x1, r2.applied_verdict)
    assert not r2.fallback_certified


def test_committed_brake_is_still_reused_without_an_edit():
    """The replay check keeps the exact reuse: an unchanged model reuses the committed tail.

    The ball coasts at 0.4 m/s; step 1's window and tail are certified (the tail ends 5 mm
    before contact). Step 2 pushes (+1 N): its own tail reaches the wall, so it is replaced by
    the committed brake, whose window is the committed tail's: the tail's certificate is reused
    (``tail_reused``) and the ball stays clear.
    """
    m = _model()
    d = mujoco.MjData(m)
    d.qpos[0] = -0.013
    d.qvel[0] = 0.4  # window 8 mm + tail 0.25 s coasting 0.1 m: ends at x = 0.095, 5 mm before contact
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10)
    r1 = gate.step(d, np.zeros(1))
    assert r1.verdict == "certified" and r1.brake_verdict == "certified"
    r2 = gate.step(d, np.ones(1))  # push: the tail after it reaches the wall
    assert r2.replaced and r2.applied_verdict == "certified"
    assert gate.stats["tail_reused"] == 1
    x = float(d.qpos[0])
    assert _distance(x) > 0.0


# --------------------------------------------------------------------------- SafetyGate: substeps per step
BAND = 0.015  # Tunnel-v0: wall half thickness 5 mm + ball radius 1 cm


def _tunnel_touches(x0: float, x1: float) -> bool:
    """Closed form: a window from x0 to x1 (continuous in x) meets the wall's band |x| <= BAND."""
    return min(x0, x1) <= BAND and max(x0, x1) >= -BAND


def _tunnel_rows(env: gym.Env, steps: int) -> list[tuple[float, float, str]]:
    d = env.unwrapped.data
    out = []
    for _ in range(steps):
        x0 = float(d.qpos[0])
        info = env.step(np.array([5.0]))[4]
        out.append((x0, float(d.qpos[0]), str(info["safety"]["applied_verdict"])))
    return out


def test_frame_skip_changed_after_construction_is_certified_as_it_runs():
    """``env.unwrapped.frame_skip`` set after the gate was built (a curriculum, a user's tuning).

    On main the gate kept the construction-time count (1 substep of 10 ms) and certified that
    window while the env simulated 10 substeps: step 0 at 5 m/s went from x = -0.32 to 0.175,
    through the wall, reported ``applied_verdict == "certified"``. Now every step certifies
    the live count; the oracle (closed form on x before and after) finds no certified window
    that meets the wall.
    """
    import monitor.envs  # noqa: F401  (registers monitor/Tunnel-v0)

    env = SafetyGate(gym.make("monitor/Tunnel-v0"))
    env.reset(seed=0)
    env.unwrapped.frame_skip = 10
    rows = _tunnel_rows(env, 4)
    env.close()
    for k, (x0, x1, verdict) in enumerate(rows):
        assert not (_tunnel_touches(x0, x1) and verdict == "certified"), (k, x0, x1, verdict)
    assert env.gate.frame_skip == 10


@pytest.mark.parametrize("bad", [0, -1, 2.5, True, "3"])
def test_invalid_live_frame_skip_is_a_typed_error(bad):
    import monitor.envs  # noqa: F401

    env = SafetyGate(gym.make("monitor/Tunnel-v0"))
    env.reset(seed=0)
    env.unwrapped.frame_skip = bad
    with pytest.raises(InvalidInputError, match="frame_skip"):
        env.step(np.array([0.0]))
    env.close()


class _TwiceTunnel(MujocoEnv):
    """A user's MujocoEnv whose step simulates two windows (calls ``do_simulation`` twice)."""

    metadata = {"render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"], "render_fps": 100}

    def __init__(self) -> None:
        from monitor.envs.assets import scene

        MujocoEnv.__init__(self, str(scene("tunnel")), 1,
                           observation_space=gym.spaces.Box(-np.inf, np.inf, shape=(2,), dtype=np.float64))

    def step(self, action):
        self.do_simulation(action, self.frame_skip)
        self.do_simulation(action, self.frame_skip)
        obs = np.array([self.data.qpos[0], self.data.qvel[0]])
        return obs, 0.0, False, False, {}

    def reset_model(self):
        self.set_state(np.array([-0.32]), np.zeros(1))
        return np.array([-0.32, 0.0])


def test_env_step_that_simulates_two_windows_is_detected():
    """On main the second ``do_simulation`` ran uncertified and silently (the ctrl check passes:
    the control is the certified one). Now, with the commit hook, the second simulation is
    refused before it runs (one window's time elapsed); without it (``commit=False``) the step
    raises right after, naming data.time."""
    env = SafetyGate(_TwiceTunnel())
    env.reset(seed=0)
    d = env.unwrapped.data
    with pytest.raises(InvalidInputError, match="second simulation"):
        env.step(np.array([1.0]))
    assert d.time == 0.01  # the certified window ran, the second one did not
    env.commit = False
    with pytest.raises(InvalidInputError, match="data.time"):
        env.step(np.array([1.0]))
    env.close()


# --------------------------------------------------------------------------- SafetyGate: the env's step edits
_MOCAP_XML = """<mujoco><option timestep="0.01" gravity="0 0 0" integrator="implicitfast"/><worldbody>
<body name="wall" mocap="true" pos="0.3 0 0">
  <geom name="wall" type="box" size="0.005 0.2 0.2" contype="0" conaffinity="0"/></body>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/>
  <geom name="ball" type="sphere" size="0.01" mass="0.01" contype="0" conaffinity="0"/></body>
</worldbody><actuator><velocity name="vx" joint="x" kv="10" ctrlrange="-6 6"/></actuator></mujoco>"""


class _MovingWall(MujocoEnv):
    """A user's env whose ``step`` moves a mocap obstacle 0.1 m toward the ball, then simulates."""

    metadata = {"render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"], "render_fps": 100}

    def __init__(self, path: str, edit: str = "mocap") -> None:
        self.edit = edit
        MujocoEnv.__init__(self, path, 1,
                           observation_space=gym.spaces.Box(-np.inf, np.inf, shape=(2,), dtype=np.float64))

    def step(self, action):
        if self.edit == "mocap":
            self.data.mocap_pos[0, 0] -= 0.1  # the obstacle moves (the env's own dynamics)
        else:
            self.model.actuator_gainprm[0, 0] *= 100.0  # domain randomisation inside step
            self.model.actuator_biasprm[0, 2] *= 100.0
        self.do_simulation(action, self.frame_skip)
        return np.array([self.data.qpos[0], self.data.qvel[0]]), 0.0, False, False, {}

    def reset_model(self):
        self.set_state(np.zeros(1), np.zeros(1))
        return np.zeros(2)


@pytest.fixture
def mocap_xml(tmp_path):
    path = tmp_path / "moving_wall.xml"
    path.write_text(_MOCAP_XML)
    return str(path)


@pytest.mark.parametrize("commit", [True, False])
def test_env_step_moving_a_mocap_obstacle_is_not_certified(mocap_xml, commit):
    """On main step 2 ran with the wall overlapping the ball (closed-form distance -0.015 m) and
    reported ``applied_verdict == "certified"`` (the plan held the mocap pose of the decision).
    Now: with the commit hook the step is refused BEFORE the motion runs (time unchanged);
    without it (``commit=False``) right after, never silently."""
    env = SafetyGate(_MovingWall(mocap_xml), pairs=[("ball", "wall")])
    env.commit = commit
    env.reset(seed=0)
    d = env.unwrapped.data
    with pytest.raises(InvalidInputError, match="mocap"):
        for _ in range(3):
            t0 = float(d.time)
            info = env.step(np.array([0.0]))[4]
            gap = abs(float(d.mocap_pos[0, 0]) - float(d.qpos[0])) - 0.015  # closed form
            assert not (gap < 0.0 and info["safety"]["applied_verdict"] == "certified")
    if commit:
        assert float(d.time) == t0  # refused before simulating
    env.close()


def test_env_step_editing_the_dynamics_is_detected_without_commit(mocap_xml):
    """``commit=False`` and a gain edit inside ``step``: the motion that ran is not the
    certified window (the qpos row differs): InvalidInputError after the step, never silent."""
    env = SafetyGate(_MovingWall(mocap_xml, edit="gain"), pairs=[("ball", "wall")])
    env.commit = False
    env.reset(seed=0)
    with pytest.raises(InvalidInputError, match="qpos"):
        env.step(np.array([1.0]))
    env.close()


# --------------------------------------------------------------------------- model edits in the log (item 3)
def _edited_run(path, *, note: bool = True) -> tuple[list[str], int]:
    """A gate run on the ball/wall model whose wall is moved onto the ball's path at step 4.

    Returns the logged verdicts and the log index of the first window after the edit.
    """
    m = _model()
    d = mujoco.MjData(m)
    d.qvel[0] = 1.0  # coasts along +x
    wall = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "wall")
    m.geom_pos[wall] = (2.0, 0.0, 0.0)  # far away at the start
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10, brake=False, on_violation="warn", log=str(path))
    verdicts = []
    for k in range(8):
        if k == 4:
            m.geom_pos[wall] = (float(d.qpos[0]) + 0.11, 0.0, 0.0)  # gap 1 cm: reached in the next window
        verdicts.append(str(gate.step(d, np.zeros(1)).verdict))
    gate.close()
    return verdicts, 4


def test_review_rederives_windows_on_the_model_as_edited(tmp_path):
    """The wall moved onto the ball's path mid-run: the gate's later windows are violations.

    On main the log did not say so: review re-derived every window on the model attached at
    open (wall 2 m away) and flagged the genuine violations as CRITICAL flips
    (``critical == 4``). Now the edit is logged before the first window certified on it and
    review re-derives each window on the model as edited: 0 critical, a note names it; exit 2 by
    default (the edit record is the run's unsigned claim: a forger could add one), exit 0 when the
    auditor trusts the run's edit records.
    """
    from monitor.log.reader import read_log
    from monitor.review import verify, verify_exit_code

    verdicts, first = _edited_run(tmp_path / "edit.mcap")
    assert verdicts[:first] == ["certified"] * first and "violation" in verdicts[first:]
    contents = read_log(tmp_path / "edit.mcap")
    ver = verify(contents, progress=False)
    assert ver["checked"] == ver["windows"] == 8
    assert ver["critical"] == 0 and not ver["mismatches"], ver["mismatches"]
    assert [e["window"] for e in contents.model_edits] == [first]
    assert any("model edit" in n and "geom_pos" in n for n in ver["notes"])
    assert verify_exit_code(ver) == 2 and ver["unverifiable"] == 1
    trusted = verify(contents, progress=False, trust_model_edits=True)
    assert trusted["critical"] == 0 and trusted["unverifiable"] == 0 and verify_exit_code(trusted) == 0


def test_review_of_an_edit_record_removed_is_critical(tmp_path):
    """The same run re-read without its edit record (a forger dropping it, or a pre-edit-logging
    gate): the genuine violations re-derive as certified on the attached model: CRITICAL flips."""
    from monitor.log.reader import read_log
    from monitor.review import verify, verify_exit_code

    _edited_run(tmp_path / "edit.mcap")
    contents = read_log(tmp_path / "edit.mcap")
    contents.model_edits.clear()
    ver = verify(contents, progress=False)
    assert ver["critical"] >= 1 and verify_exit_code(ver) == 1


def test_review_malformed_model_edit_is_unverifiable(tmp_path):
    """A model edit record the attached model cannot take (an unknown field): the windows from
    its index are UNVERIFIABLE (exit 2), never re-derived on a model the run did not certify on."""
    from monitor.log import topics
    from monitor.log.reader import read_log
    from monitor.log.writer import MonitorLog
    from monitor.review import verify, verify_exit_code

    m = _model()
    d = mujoco.MjData(m)
    d.qvel[0] = 1.0
    path = tmp_path / "bad_edit.mcap"
    with MonitorLog(path, model=m, foxglove=False) as log:
        gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10, brake=False, log=log)
        for k in range(4):
            if k == 2:
                log.add_metadata({"window": log.windows, "fields": {"geom_rgba": {"shape": [2, 4],
                                  "values": [0.0] * 8}}}, name=topics.METADATA_MODEL_EDIT)
            gate.step(d, np.zeros(1))
    ver = verify(read_log(path), progress=False)
    assert ver["checked"] == 2 and ver["critical"] == 0
    assert any("malformed" in f["reason"] for f in ver["findings"])
    assert verify_exit_code(ver) == 2


def test_model_edit_record_round_trips_the_arrays(tmp_path):
    """``MonitorLog.note_model``: the changed fields only, values exact, nothing when unchanged."""
    from monitor.log.reader import read_log
    from monitor.log.writer import MonitorLog

    m = _model()
    path = tmp_path / "note.mcap"
    with MonitorLog(path, model=m, foxglove=False) as log:
        assert log.note_model(m) == []
        m.geom_size[1, 0] = 0.1 + 1e-13
        m.opt.disableflags = int(m.opt.disableflags) | int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        assert sorted(log.note_model(m)) == ["geom_size", "opt.disableflags"]
        assert log.note_model(m) == []
    rec = read_log(path).model_edits
    assert len(rec) == 1 and rec[0]["window"] == 0
    assert np.array_equal(np.reshape(rec[0]["fields"]["geom_size"]["values"], (2, 3)), m.geom_size)
    assert rec[0]["disableflags"] == int(m.opt.disableflags)


# --------------------------------------------------------------------------- bad input to Gate.decide / step
@pytest.mark.parametrize("ctrl", [np.array([np.nan]), np.array([np.inf]), np.array(["a"]), np.zeros(3), None])
def test_decide_refuses_a_bad_control(ctrl):
    """On main ``Gate.decide(data, [nan])`` answered ``certified`` (MuJoCo zeroes a NaN control,
    so the window certified was the zero control's, not the proposal's), ``None`` too; a string
    or a wrong shape gave a bare ValueError. Now: InvalidInputError naming ctrl."""
    m = _model()
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10)
    with pytest.raises(InvalidInputError, match="ctrl"):
        gate.decide(mujoco.MjData(m), ctrl)


def test_decide_refuses_data_of_another_model():
    """On main: ``InvalidInputError: reference must be a finite (nq,) = (1,) qpos`` (misleading)."""
    m = _model()
    other = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><freejoint/><geom size="0.1"/></body></worldbody></mujoco>')
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=10)
    with pytest.raises(InvalidInputError, match="another model"):
        gate.step(mujoco.MjData(other), np.zeros(1))


@pytest.mark.parametrize("bad", [2.5, "3", True, 0])
def test_substep_counts_are_integers(bad):
    """On main ``nstep=2.5`` ran 2 substeps, ``"3"`` ran 3 and ``True`` 1, silently (``int()``);
    ``Gate(frame_skip=2.5)`` likewise. Now InvalidInputError naming the argument."""
    m = _model()
    gate = Gate(m, pairs=[("ball", "wall")])
    with pytest.raises(InvalidInputError, match="nstep"):
        gate.step(mujoco.MjData(m), np.zeros(1), nstep=bad)
    with pytest.raises(InvalidInputError, match="frame_skip"):
        Gate(m, frame_skip=bad)


@pytest.mark.parametrize("commit", [True, False])
def test_env_that_replaced_its_model_is_refused(commit):
    """The env recompiled its model (wall moved to x = -0.25) after the gate was built.

    On main the gate kept certifying on the old model: step 1 went x -0.2745 -> -0.2250 through
    the new wall (band |x + 0.25| <= 0.015, closed form), ``certified`` (with or without the
    commit hook). Now the step is refused before anything is certified or simulated.
    """
    import monitor.envs  # noqa: F401
    from monitor.envs.assets import scene

    env = SafetyGate(gym.make("monitor/Tunnel-v0"))
    env.commit = commit
    env.reset(seed=0)
    u = env.unwrapped
    spec = mujoco.MjSpec.from_file(str(scene("tunnel")))
    spec.geom("wall").pos = [-0.25, 0.0, 0.0]
    u.model = spec.compile()
    u.data = mujoco.MjData(u.model)
    mujoco.mj_resetDataKeyframe(u.model, u.data, 0)
    d = u.data
    with pytest.raises(InvalidInputError, match="MjModel"):
        for k in range(3):
            x0 = float(d.qpos[0])
            info = env.step(np.array([5.0]))[4]
            x1 = float(d.qpos[0])
            touches = min(x0, x1) <= -0.25 + BAND and max(x0, x1) >= -0.25 - BAND
            assert not (touches and info["safety"]["applied_verdict"] == "certified"), (k, x0, x1)
    assert float(d.time) == 0.0  # nothing ran
    env.close()


@pytest.mark.parametrize("flag", ["", '<flag autoreset="disable"/>'])
def test_unstable_window_says_so(flag):
    """Explicit Euler with kv * dt / m = 10: the window diverges and MuJoCo resets the state.

    On main a typed error with a misleading message (``times must be strictly increasing:
    times[9] = 0.01 <= times[8] = 0.08``; with autoreset off ``X_b: translation beyond 1e+09 m``).
    Now the error says the predicted window is an unstable simulation. Never certified.
    """
    xml = f"""<mujoco><option timestep="0.01" gravity="0 0 0">{flag}</option><worldbody>
      <geom name="wall" type="box" pos="5 0 0" size="0.005 0.2 0.2" contype="0" conaffinity="0"/>
      <body name="ball"><joint name="x" type="slide" axis="1 0 0"/>
        <geom name="ball" type="sphere" size="0.01" mass="0.01" contype="0" conaffinity="0"/></body>
      </worldbody><actuator><velocity name="vx" joint="x" kv="10" ctrlrange="-6 6"/></actuator></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    gate = Gate(m, pairs=[("ball", "wall")], frame_skip=20)
    with pytest.raises(InvalidInputError, match="unstable simulation"):
        gate.step(mujoco.MjData(m), np.array([1.0]))


def test_unstable_braking_tail_says_so():
    """A stable 10 ms window, then a braking tail under a stiff position servo (kp dt^2 / m = 10,
    explicit Euler) that diverges; MuJoCo resets the state and the tail "stops" at rest.

    On main: ``times must be strictly increasing: times[11] = 0.01 <= times[10] = 0.1`` (the joint
    plan). Now the error names the braking tail as an unstable simulation. Never certified.
    """
    xml = """<mujoco><option timestep="0.01" gravity="0 0 0"/><worldbody>
      <geom name="wall" type="box" pos="5 0 0" size="0.005 0.2 0.2" contype="0" conaffinity="0"/>
      <body name="ball"><joint name="x" type="slide" axis="1 0 0"/>
        <geom name="ball" type="sphere" size="0.01" mass="0.01" contype="0" conaffinity="0"/></body>
      </worldbody><actuator><position name="px" joint="x" kp="1000"/></actuator></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qvel[0] = 1.0
    gate = Gate(m, pairs=[("ball", "wall")])
    with pytest.raises(InvalidInputError, match="braking tail .* unstable simulation"):
        gate.step(d, np.zeros(1))


def test_gate_still_pickles_after_a_step():
    """The gate remembers which MjData it size-checked by a weak reference: not pickled."""
    import pickle

    m = _model()
    d = mujoco.MjData(m)
    gate = Gate(m, pairs=[("ball", "wall")])
    gate.step(d, np.zeros(1))
    again = pickle.loads(pickle.dumps(gate))
    assert again.step(d, np.zeros(1)).verdict == "certified"


def test_review_cli_trust_model_edits_flag(tmp_path):
    """``python -m monitor review --verify`` on the edited run: exit 2 by default (the edit record is
    unverifiable), exit 0 with ``--trust-model-edits``."""
    from monitor.cli import main

    _edited_run(tmp_path / "edit.mcap")
    log = str(tmp_path / "edit.mcap")
    assert main(["review", log, "--verify", "--no-progress"]) == 2
    assert main(["review", log, "--verify", "--no-progress", "--trust-model-edits"]) == 0


def test_parallel_verify_takes_the_auditor_options(tmp_path):
    """``verify_logs`` (the ``review --ray`` path; local workers here) passes the auditor's options to
    every task: the same dicts as the serial ``verify`` with them. Before, ``--ray`` refused
    ``--trust-model-edits``, ``--expect-pairs``, ``--max-penetration`` and ``--tolerances``."""
    from monitor.distributed import verify_logs
    from monitor.log.reader import read_log
    from monitor.review import verify, verify_exit_code

    _edited_run(tmp_path / "edit.mcap")
    log = str(tmp_path / "edit.mcap")
    for opts in ({}, {"trust_model_edits": True}, {"expect_pairs": "all", "max_penetration": 0.0}):
        got = verify_logs([log], backend="local", workers=1, progress=False, **opts)[0]
        want = verify(read_log(log), progress=False, **opts)
        assert verify_exit_code(got) == verify_exit_code(want)
        assert {k: got[k] for k in ("checked", "critical", "unverifiable")} == \
            {k: want[k] for k in ("checked", "critical", "unverifiable")}
    assert verify_exit_code(verify_logs([log], backend="local", workers=1, progress=False,
                                        trust_model_edits=True)[0]) == 0
