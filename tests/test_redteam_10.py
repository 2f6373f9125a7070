"""Red team 10: the sealed waypoints, the gate's memos and shortcuts, review, huge coordinates.

Oracles are independent of ``monitor``'s checkers:

* a straight motion that crosses a wall: by continuity the ball's centre passes every point of its
  segment, including one inside the wall, so a "certified" window is a proven false certificate;
* the motion that actually ran: the ball's live ``qpos`` after each step against the wall's face, in
  closed form (a slide joint along x: the distance is monotone within a window, so the end states
  bound it);
* the general (Python) path of ``certify`` as the reference for the compiled path's typed errors.
"""

from __future__ import annotations

import copy
import pickle

import mujoco
import numpy as np
import pytest

from monitor import BodyMotion, Plan, Scene, certify
from monitor.certify.types import Verdict
from monitor.errors import InvalidInputError
from monitor.motion.bezier import BezierMotion, RigidBezier

_WALL = """
<mujoco>
  <option timestep="0.01"/>
  <worldbody>
    <geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0" contype="0" conaffinity="0"/>
    <body name="ball">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="0.02" mass="1" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
  <actuator><velocity joint="x" kv="100"/></actuator>
</mujoco>
"""
_WALL_X = 0.3 - 0.01 - 0.02   # the ball's centre x at which it touches the wall's near face (m)


@pytest.fixture(scope="module")
def wall():
    model = mujoco.MjModel.from_xml_string(_WALL)
    return model, Scene.from_model(model, pairs="all", allowed=None)


def _body_motion(x_end: float) -> BodyMotion:
    """The ball body (index 1) translating from x = 0 to ``x_end`` in 1 s, as a BodyMotion."""
    pos = np.zeros((2, 2, 3))
    pos[1, 1, 0] = x_end
    quat = np.zeros((2, 2, 4))
    quat[..., 0] = 1.0
    return BodyMotion([0.0, 1.0], pos, quat)


def _reopen(arr: np.ndarray) -> np.ndarray | None:
    """A writable array on ``arr``'s memory reached through its ``.base`` chain, or None."""
    a = arr
    while isinstance(a, np.ndarray):
        try:
            a.setflags(write=True)
            return a
        except ValueError:
            a = a.base
    return None


# --------------------------------------------------------------------- sealed waypoints


def _sealed_arrays() -> list[tuple[str, np.ndarray]]:
    model = mujoco.MjModel.from_xml_string(_WALL)
    plan = Plan([0.0, 1.0], [[0.0], [0.1]], model)
    bm = _body_motion(0.1)
    rb = RigidBezier([[1, 0, 0, 0], [1, 0, 0, 0]], [[0, 0, 0], [0.05, 0, 0], [0.1, 0, 0]])
    bz = BezierMotion([0.0, 1.0], np.zeros((2, 3)), [[1, 0, 0, 0]] * 2, {1: rb})
    return [("plan.times", plan.times), ("plan.qpos", plan.qpos), ("bm.times", bm.times), ("bm.pos", bm.pos),
            ("bm.quat", bm.quat), ("bm.ref_points", bm.ref_points), ("bezier.times", bz.times),
            ("bezier.ref_points", bz.ref_points), ("rigid._T", rb._T), ("rigid._Q", rb._Q)]


def test_sealed_waypoints_cannot_be_reopened_through_their_base():
    """``sealed`` made a read-only view of a read-only OWNER: numpy lets an owner turn
    ``WRITEABLE`` back on, and the view's ``.base`` hands it out (ca04081: every array below)."""
    reopened = [name for name, arr in _sealed_arrays() if _reopen(arr) is not None]
    assert reopened == []


def test_a_plan_edited_through_its_base_is_not_certified_from_the_memo(wall):
    """ca04081: certify a clear plan, push its end waypoint through the wall via ``qpos.base``:
    the call memo and the pack answered ``certified`` for the new motion."""
    model, scene = wall
    plan = Plan([0.0, 1.0], [[0.0], [0.1]], model)
    assert certify(scene, plan, margin=0.01).verdict == Verdict.CERTIFIED
    owner = _reopen(plan.qpos)
    if owner is None:
        return                                     # sealed: the edit is impossible (the fix)
    owner.reshape(-1)[-1] = 0.6                    # x: 0 -> 0.6 crosses the wall's face at 0.27
    assert plan.qpos[-1, 0] > _WALL_X
    assert certify(scene, plan, margin=0.01).verdict != Verdict.CERTIFIED


@pytest.mark.parametrize("clone", ["pickle", "deepcopy"])
def test_a_copied_plan_keeps_its_waypoints_sealed(wall, clone):
    """ca04081: a pickle / deepcopy round trip gave a Plan with WRITABLE waypoints that still
    carried the original's waypoint poses: edited through the wall, it was certified on its very
    first certify (auto; the toleranced method said violation)."""
    model, scene = wall
    plan = Plan([0.0, 1.0], [[0.0], [0.1]], model)
    assert certify(scene, plan, margin=0.01).verdict == Verdict.CERTIFIED
    dup = pickle.loads(pickle.dumps(plan)) if clone == "pickle" else copy.deepcopy(plan)
    assert not dup.qpos.flags.writeable and not dup.times.flags.writeable
    assert _reopen(dup.qpos) is None
    with pytest.raises(ValueError):
        dup.qpos[-1, 0] = 0.6
    assert certify(scene, dup, margin=0.01).verdict == Verdict.CERTIFIED   # the same clear motion


@pytest.mark.parametrize("clone", ["pickle", "deepcopy"])
def test_copied_body_and_bezier_motions_keep_their_arrays_sealed(clone):
    rb = RigidBezier([[1, 0, 0, 0], [1, 0, 0, 0]], [[0, 0, 0], [0.05, 0, 0], [0.1, 0, 0]])
    bz = BezierMotion([0.0, 1.0], np.zeros((2, 3)), [[1, 0, 0, 0]] * 2, {1: rb})
    dup = (lambda o: pickle.loads(pickle.dumps(o))) if clone == "pickle" else copy.deepcopy
    bm2, bz2 = dup(_body_motion(0.1)), dup(bz)
    for arr in (bm2.times, bm2.pos, bm2.quat, bz2.times, bz2.motions[1]._T):
        assert _reopen(arr) is None


def test_sealing_leaves_the_callers_arrays_alone(wall):
    """The old ``sealed`` froze a caller's own (base None) array in place; the copy does not."""
    model, _ = wall
    t, q = np.array([0.0, 1.0]), np.array([[0.0], [0.1]])
    plan = Plan(t, q, model)
    assert t.flags.writeable and q.flags.writeable
    t[1] = 5.0
    assert plan.times[1] == 1.0


# --------------------------------------------------------------------- huge coordinates


def test_the_compiled_path_and_the_general_path_agree_on_coordinates_beyond_1e9_m(wall, monkeypatch):
    """Red team 7: a ball 1e200 m away was certified by the compiled path (clearance -2.4e187 m)
    where the general path raises the geometry's typed "beyond 1e9 m" error."""
    import monitor.certify.engine as engine
    from monitor.geometry import distance
    from monitor.motion import kernel

    assert engine._FAST_MAX_COORD == distance._MAX_COORD
    assert (engine._PACK_TOL_SCALE, engine._PACK_TOL_QMAG) == (kernel.TOL_SCALE, kernel.TOL_QMAG)
    model, scene = wall
    for q in ([[-1e200], [-5e199]], [[-1e200], [-1e200]]):
        for method in ("auto", "toleranced"):
            with pytest.raises(InvalidInputError, match="beyond 1e\\+09 m"):
                certify(scene, Plan([0.0, 1.0], q, model), method=method)
    monkeypatch.setattr(engine, "_fast_inputs", lambda scene, plan: None)
    with pytest.raises(InvalidInputError, match="beyond 1e\\+09 m"):
        certify(scene, Plan([0.0, 1.0], [[-1e200], [-5e199]], model))


# --------------------------------------------------------------------- gate: data of another model


def _certified_through_the_callers_wall(gate, data, model) -> bool:
    """``gate.decide`` at 1 m/s, then the caller steps ``model`` (5 substeps): True when the window was
    certified and the ball's centre (monotone within the window) crossed x = 0.07, where it touches the
    caller's wall (near face at 0.09); False when ``decide`` refused the data (InvalidInputError)."""
    try:
        report = gate.decide(data, np.array([1.0]))
    except InvalidInputError:
        return False
    x0 = float(data.qpos[0])
    data.ctrl[:] = report.applied_ctrl
    mujoco.mj_step(model, data, nstep=5)
    return report.verdict == Verdict.CERTIFIED and x0 < 0.07 < float(data.qpos[0])


def test_decide_refuses_the_data_of_an_edited_model_copy():
    """Domain randomisation by copies: the caller's model (the wall moved to x = 0.1) and its data,
    the gate on the original model. ca04081 checked nq / nv / nu only and certified the window of
    its own model; the motion under the caller's model went through the caller's wall."""
    from monitor import Gate

    model = mujoco.MjModel.from_xml_string(_WALL)
    edited = copy.deepcopy(model)
    edited.geom_pos[0] = [0.1, 0.0, 0.0]          # the caller's wall: near face at x = 0.09
    data = mujoco.MjData(edited)
    data.qpos[0] = 0.05
    gate = Gate(model, pairs=[("wall", "ball")], frame_skip=5, brake=False)
    assert not _certified_through_the_callers_wall(gate, data, edited)


def test_step_refuses_the_data_of_a_model_with_other_sizes():
    """ca04081: ``mujoco.FatalError`` (mj_copyData) for the data of a model with one more body."""
    from monitor import Gate

    model = mujoco.MjModel.from_xml_string(_WALL)
    ball = '<body name="ball">'
    post = '<body name="post" pos="0 1 0"><geom type="sphere" size="0.1"/></body>'
    bigger = mujoco.MjModel.from_xml_string(_WALL.replace(ball, post + ball))
    gate = Gate(model, pairs=[("wall", "ball")], frame_skip=5)
    with pytest.raises(InvalidInputError, match="another MjModel"):
        gate.step(mujoco.MjData(bigger), np.array([1.0]))


def test_a_gate_accepts_the_data_of_an_identical_model_copy():
    """The guard: a copy with the same bytes (a pickled gate and the original's data) still works."""
    from monitor import Gate

    model = mujoco.MjModel.from_xml_string(_WALL)
    data = mujoco.MjData(copy.deepcopy(model))
    gate = Gate(model, pairs=[("wall", "ball")], frame_skip=5)
    assert gate.step(data, np.array([0.1])).verdict == Verdict.CERTIFIED


# --------------------------------------------------------------------- SafetyGate: the action array


@pytest.mark.parametrize("commit", [True, False])
def test_an_env_step_that_scales_the_action_in_place_is_not_certified(commit):
    """An env whose ``step`` scales the action array in place (``action *= 6``) before simulating.

    SafetyGate's after-step checks compared ``data.ctrl`` with ``report.applied_ctrl``, the very
    array the env had just scaled: ca04081 (``commit=False``, or any env without the commit hook)
    reported ``certified`` while the ball ran at 6 m/s through the tunnel's wall. The wall's near
    face is at x = -0.015 for the ball's centre; the centre moves monotonically within a step."""
    from monitor.envs.tunnel_v0 import BALL_RADIUS, WALL_HALF_THICKNESS, TunnelEnv
    from monitor.gym_gate import SafetyGate

    class Scaled(TunnelEnv):
        def step(self, action):
            action *= 6.0
            return super().step(action)

    env = SafetyGate(Scaled(x0=-0.04), brake=False)
    env.commit = commit
    env.reset(seed=0)
    x0 = float(env.unwrapped.data.qpos[0])
    try:
        info = env.step(np.array([1.0]))[4]
    except InvalidInputError:
        return
    x1 = float(env.unwrapped.data.qpos[0])
    touch = -(WALL_HALF_THICKNESS + BALL_RADIUS)
    assert not (info["safety"]["verdict"] == "certified" and x0 < touch < x1), (x0, x1)


# --------------------------------------------------------------------- review: applied-motion records


def test_review_flags_an_applied_record_replaced_by_a_body_motion(tmp_path):
    """A gate logs joint-space plans; review checks that a replaced step's applied-motion record passes
    through the step's start state, but skipped the check when the RECORD was a body motion. A forged
    record (the ball 5 m away, where it never was: the oracle is the live state the test recorded)
    reviewed exit 0 with no finding on ca04081; the same forgery as a joint-space plan is CRITICAL."""
    from mcap_rewrite import rewrite

    from monitor import Gate, review
    from monitor.log import read_log, topics

    model = mujoco.MjModel.from_xml_string(_WALL)
    data = mujoco.MjData(model)
    data.qpos[0] = 0.2
    path = tmp_path / "run.mcap"
    with Gate(model, pairs=[("wall", "ball")], frame_skip=5, brake=False, log=path) as gate:
        report = gate.step(data, np.array([2.0]))      # blocked (the wall): the hold fallback ran
    assert report.replaced and float(data.qpos[0]) == 0.2
    acts = [a for a in read_log(path).topic(topics.ACTION) if a["replaced"]]
    j = acts[0]["applied_window"]

    def body_motion(topic, p):
        if topic == topics.PLAN and p["index"] == j:
            K = len(p["times"])
            pos = np.zeros((K, 2, 3))
            pos[:, 1, 0] = -5.0                         # not the run's x = 0.2
            quat = np.zeros((K, 2, 4))
            quat[..., 0] = 1.0
            return {"index": j, "kind": "bodymotion", "times": p["times"], "pos": pos.tolist(),
                    "quat": quat.tolist(), "interpolation": "lerp_slerp"}
        return p

    assert review.verify_exit_code(review.verify(read_log(path))) == 0
    rewrite(path, tmp_path / "forged.mcap", msg=body_motion)
    ver = review.verify(read_log(tmp_path / "forged.mcap"))
    assert review.verify_exit_code(ver) == 1, ver["findings"]
    assert any("does not pass through replaced step" in f["reason"] for f in ver["findings"])


def test_review_flags_body_motion_records_that_leave_a_body_motion_step():
    """The same check between body motions (a user's log): the record's poses at the step's start."""
    from monitor.review import _passes_through

    def bm(times, x):
        pos = np.zeros((len(times), 2, 3))
        pos[:, 1, 0] = x
        quat = np.zeros((len(times), 2, 4))
        quat[..., 0] = 1.0
        return {"kind": "bodymotion", "times": times, "pos": pos.tolist(), "quat": quat.tolist()}

    step = bm([0.0, 0.1], [0.2, 0.3])
    assert _passes_through([step], [bm([0.0, 0.1, 0.2], [0.2, 0.2, 0.2])], 0.0)
    assert not _passes_through([step], [bm([0.0, 0.1, 0.2], [0.7, 0.2, 0.2])], 0.0)
    assert not _passes_through([{"kind": "plan", "times": [0.0, 0.1], "qpos": [[0.2], [0.3]]}],
                               [bm([0.0, 0.1], [0.2, 0.2])], 0.0)


# --------------------------------------------------------------------- the pack and Plan subclasses


class _ShiftedPlan(Plan):
    """A Plan whose ball body runs 0.2 m further along x than its waypoints' FK (a valid trajectory:
    a constant offset leaves the motion bounds, which are relative to the midpoint pose, valid)."""

    def body_poses(self, times):
        pos, rot = super().body_poses(times)
        pos = pos.copy()
        pos[..., 1, 0] += 0.2
        return pos, rot

    def translation_segments(self, body):
        seg = super().translation_segments(body)
        if seg is None or body != 1:
            return seg
        t, o = seg
        o = np.array(o)
        o[:, 0] += 0.2
        return t, o


@pytest.mark.parametrize("method", ["auto", "toleranced", "extrusion"])
def test_a_plan_subclass_is_certified_by_its_own_motion(wall, method):
    """ca04081: once a plain Plan of the model had verified the motion pack's tree, a Plan subclass
    was packed from its waypoint arrays (its own ``body_poses`` ignored) and the compiled
    whole-shape stage certified it (toleranced); its own motion runs the ball from x = 0.2 to 0.3
    through the wall's face at 0.27 (the oracle: its ``body_poses``, continuity)."""
    model, scene = wall
    assert certify(scene, Plan([0.0, 1.0], [[0.0], [0.1]], model)).verdict == Verdict.CERTIFIED
    shifted = _ShiftedPlan([0.0, 1.0], [[0.0], [0.1]], model)
    x = shifted.body_poses(np.array([0.0, 1.0]))[0][:, 1, 0]
    assert x[0] < _WALL_X < x[1]
    assert certify(scene, shifted, method=method).verdict != Verdict.CERTIFIED


@pytest.mark.parametrize("method", ["auto", "toleranced", "extrusion"])
def test_a_plan_subclass_built_before_a_model_edit_keeps_its_motion(method):
    """ca04081: after an in-place model edit ``certify`` certifies ``plan.refreshed()``, which was a
    plain Plan of the subclass's waypoints: the shifted motion through the wall (violation before the
    edit) was ``certified`` after an edit that moves nothing (the slide joint's anchor)."""
    model = mujoco.MjModel.from_xml_string(_WALL)
    scene = Scene.from_model(model, pairs="all", allowed=None)
    shifted = _ShiftedPlan([0.0, 1.0], [[0.0], [0.1]], model)
    assert certify(scene, shifted, method=method).verdict != Verdict.CERTIFIED
    model.jnt_pos[0] += 0.1
    assert not shifted.is_current() and type(shifted.refreshed()) is _ShiftedPlan
    assert certify(scene, shifted, method=method).verdict != Verdict.CERTIFIED


def test_a_gate_copy_refuses_the_originals_data_after_the_original_model_is_edited():
    """A pickled gate stepping the original's data (the models are equal copies: accepted). After the
    ORIGINAL model is edited in place (the wall moved into the ball's path) the copy still certified
    windows of its own stale model: the once-per-MjData check had cached the data."""
    import pickle

    from monitor import Gate

    model = mujoco.MjModel.from_xml_string(_WALL)
    data = mujoco.MjData(model)
    data.qpos[0] = 0.05
    again = pickle.loads(pickle.dumps(Gate(model, pairs=[("wall", "ball")], frame_skip=5, brake=False)))
    assert again.decide(data, np.array([0.0])).verdict == Verdict.CERTIFIED
    model.geom_pos[0] = [0.1, 0.0, 0.0]            # the caller's wall: near face at x = 0.09
    assert not _certified_through_the_callers_wall(again, data, model)


# --------------------------------------------------------------------- fuzz (slow)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_gate_fuzz_with_edits_between_steps(seed):
    """docs/notes/redteam-10/gatefuzz.py: random model and data edits between Gate steps; every
    applied window the gate calls certified, replayed from a copy of the state (the motion that ran),
    keeps the exact gap above the margin."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "docs" / "notes" / "redteam-10" / "gatefuzz.py"
    spec = importlib.util.spec_from_file_location("rt10_gatefuzz", path)
    fuzz = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fuzz)
    counts = fuzz.main(seed, 80)
    assert counts["bad"] == 0 and counts["certified"] > 20, counts


@pytest.mark.parametrize("commit", [True, False])
def test_an_env_step_that_moves_the_state_after_simulating_is_refused(commit):
    """An env whose ``step`` moves the ball on by 6 cm after the simulation (a teleport). Without the
    commit hook the after-step check refuses it (the qpos is not the certified row); ca04081 skipped
    that check when the window was committed (the default on stock MujocoEnvs): ``certified`` while
    the ball jumped from -0.035 to +0.025 across the wall (its near face at -0.015 for the centre)."""
    from monitor.envs.tunnel_v0 import TunnelEnv
    from monitor.gym_gate import SafetyGate

    class Teleport(TunnelEnv):
        def step(self, action):
            out = super().step(action)
            self.data.qpos[0] += 0.06
            return out

    env = SafetyGate(Teleport(x0=-0.04), brake=False)
    env.commit = commit
    env.reset(seed=0)
    with pytest.raises(InvalidInputError, match="data.qpos"):
        env.step(np.array([0.5]))


# --------------------------------------------------------------------- window length


@pytest.mark.parametrize("where", ["nstep", "frame_skip", "setting"])
def test_a_window_of_a_billion_substeps_is_a_typed_error_before_any_simulation(where):
    """Red team 10's open item: ``nstep=10**9`` allocated (nstep + 1, 1 + nq) rows and simulated them
    before anything was certified (an out-of-memory crash or hours). Now InvalidInputError, and the
    data is untouched (nothing simulated)."""
    from monitor import Gate
    from monitor.gate import MAX_WINDOW_STEPS

    model = mujoco.MjModel.from_xml_string(_WALL)
    data = mujoco.MjData(model)
    big = 10**9
    with pytest.raises(InvalidInputError, match="more than one window may take"):
        if where == "frame_skip":
            Gate(model, pairs=[("wall", "ball")], frame_skip=big)
        gate = Gate(model, pairs=[("wall", "ball")], frame_skip=5)
        if where == "setting":
            gate.frame_skip = big
        gate.step(data, np.array([0.1]), nstep=big)
    assert data.time == 0.0
    gate = Gate(model, pairs=[("wall", "ball")], frame_skip=5)
    assert gate.step(data, np.array([0.1]), nstep=MAX_WINDOW_STEPS // 10_000).verdict == Verdict.CERTIFIED
