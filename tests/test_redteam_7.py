"""Red team 7: the last session's fast paths and the inputs at their edges.

Oracles are independent of ``monitor``'s checkers:

* where MuJoCo puts a geom: ``mj_forward``'s ``geom_xpos`` / ``geom_xmat`` on a fresh ``MjData``, and the
  exact sphere-box distance in closed form at those poses;
* a straight motion that crosses a wall: by continuity the ball's centre passes every point of its
  segment, including one inside the wall, so a "certified" window is a proven false certificate
  whatever the checker says about the sampled ends.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor import BodyMotion, Plan, Scene, certify
from monitor.certify import extrusion
from monitor.certify.types import Verdict
from monitor.errors import InvalidInputError

_WORLD_WALL = """
<mujoco>
  <worldbody>
    <geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0" euler="0 0 10"
          contype="0" conaffinity="0"/>
    <body name="ball">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="0.02" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>
"""


def _sphere_box_distance(model: mujoco.MjModel, data: mujoco.MjData, box: int, sphere: int) -> float:
    """Exact signed distance (m) of geoms ``box`` and ``sphere`` at ``data``'s poses (closed form)."""
    rot = data.geom_xmat[box].reshape(3, 3)
    c = rot.T @ (data.geom_xpos[sphere] - data.geom_xpos[box])
    half = model.geom_size[box]
    outside = np.linalg.norm(c - np.clip(c, -half, half))
    inside = -float(np.min(half - np.abs(c))) if outside == 0.0 else outside
    return float(inside - model.geom_size[sphere, 0])


@pytest.mark.parametrize("body_sf,geom_sf", [(0, 2), (0, 4), (3, 2)])
def test_a_world_geom_on_the_world_inertial_frame_is_where_mujoco_puts_it(body_sf, geom_sf):
    """``mj_kinematics`` puts the world's inertial frame at the origin whatever ``body_sameframe[0]``,
    ``body_ipos[0]`` and ``body_iquat[0]`` say; a world geom on that frame (``geom_sameframe``
    INERTIA / INERTIAROT, a hand edit) is there. The scene read ``body_ipos[0]`` and certified a ball
    that overlaps the wall where MuJoCo has it."""
    model = mujoco.MjModel.from_xml_string(_WORLD_WALL)
    model.body_sameframe[0] = body_sf
    model.body_ipos[0] = [0.3, 0.0, 0.0]
    q = np.array([0.9, 0.1, 0.3, -0.2])
    model.body_iquat[0] = q / np.linalg.norm(q)
    model.geom_sameframe[0] = geom_sf
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    scene = Scene.from_model(model, pairs="all", allowed=None)
    wall = scene.geom("wall").shape  # body frame of the world = world frame
    size = model.geom_size[0]
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * size
    mujoco_corners = corners @ data.geom_xmat[0].reshape(3, 3).T + data.geom_xpos[0]
    gap = np.linalg.norm(wall.points[:, None, :] - mujoco_corners[None], axis=2).min(axis=1).max()
    assert gap < 1e-12
    if geom_sf == 2:  # INERTIA: MuJoCo's wall is at the origin, the scene's was at body_ipos[0]
        # the ball's segment x in [0, 0.05] m starts inside MuJoCo's wall
        assert _sphere_box_distance(model, data, 0, 1) < 0.0
        cert = certify(scene, Plan([0.0, 1.0], [[0.0], [0.05]], model), margin=0.01)
        assert cert.verdict != Verdict.CERTIFIED


_FREE_BALL = """
<mujoco>
  <worldbody>
    <geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
    <body name="ball"><freejoint/><geom name="ball" type="sphere" size="0.02"/></body>
  </worldbody>
</mujoco>
"""
_SLIDE_BALL = """
<mujoco>
  <worldbody>
    <geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
    <body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.02"/>
    </body>
  </worldbody>
</mujoco>
"""
# (duration s, half-stroke m): the ball goes from x = -a to x = +a through the wall at x = 0.3 m
# in one segment whose velocity 2a / dt is not a float64 (subnormal durations, or a quotient or a
# difference beyond 1.8e308): the extrusion route divided by it and certified on NaN arithmetic.
_OVERFLOWING = [(1e-308, 1.0), (5e-324, 1.0), (1e-300, 5e9), (1.0, 9e307), (20.0, 9e307)]


@pytest.mark.parametrize("dt,a", _OVERFLOWING)
@pytest.mark.parametrize("method", ["auto", "extrusion"])
def test_a_plan_through_a_wall_in_an_overflowing_segment_is_not_certified(dt, a, method):
    model = mujoco.MjModel.from_xml_string(_SLIDE_BALL)
    scene = Scene.from_model(model, pairs="all", allowed=None)
    plan = Plan([0.0, dt], [[-a], [a]], model)
    with np.errstate(all="ignore"):
        try:
            cert = certify(scene, plan, margin=0.0, method=method)
        except InvalidInputError:
            return  # a typed refusal is a correct answer
    assert cert.verdict != Verdict.CERTIFIED


@pytest.mark.parametrize("dt", [1e-308, 5e-324])
def test_a_body_motion_through_a_wall_in_a_subnormal_segment_is_not_certified(dt):
    model = mujoco.MjModel.from_xml_string(_FREE_BALL)
    scene = Scene.from_model(model, pairs="all", allowed=None)
    pos = np.zeros((2, 2, 3))
    pos[0, 1, 0], pos[1, 1, 0] = -1.0, 1.0
    quat = np.zeros((2, 2, 4))
    quat[..., 0] = 1.0
    motion = BodyMotion([0.0, dt], pos, quat)
    for method in ("auto", "extrusion"):
        with np.errstate(all="ignore"):
            try:
                cert = certify(scene, motion, margin=0.0, method=method)
            except InvalidInputError as exc:  # a typed refusal is a correct answer
                assert "overflows" in str(exc)
                continue
        assert cert.verdict != Verdict.CERTIFIED


@pytest.mark.parametrize("dt", [1e-308, 5e-324])
def test_the_extrusion_checker_refuses_an_overflowing_velocity(dt):
    """The public checker (``extrusion.check_pairs``) on the same motion: a typed error, never certified."""
    model = mujoco.MjModel.from_xml_string(_FREE_BALL)
    scene = Scene.from_model(model, pairs="all", allowed=None)
    pair = extrusion.TranslatingPair(
        name=("wall", "ball"), shape_a=scene.geom("wall").shape, R_a=np.eye(3), times_a=[0.0, dt],
        origins_a=[[0.0, 0.0, 0.0]] * 2, shape_b=scene.geom("ball").shape, R_b=np.eye(3),
        times_b=[0.0, dt], origins_b=[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    with np.errstate(all="ignore"), pytest.raises(InvalidInputError, match="overflows"):
        extrusion.check_pairs([pair], (0.0, dt), 0.0)


class _OwnSegments:
    """A duck-typed Trajectory (a BodyMotion's poses) whose ``translation_segments`` are its own."""

    def __init__(self, motion: BodyMotion):
        self._m = motion

    def __getattr__(self, name):
        return getattr(self._m, name)

    def translation_segments(self, body: int):
        m = self._m
        if not m.moving_bodies()[body]:
            return np.array([m.t0, m.t1]), np.repeat(m._pos[:1, body], 2, axis=0)
        return m.times.copy(), m._pos[:, body].copy()


@pytest.mark.parametrize("obstacle", ['type="plane" size="1 1 0.1" zaxis="-1 0 0"',
                                      'type="box" size="0.01 0.2 0.2"'])
def test_any_trajectory_with_an_overflowing_segment_is_refused_by_the_extrusion_route(obstacle):
    """The check sits where the extrusion route takes segments (the compiled swept pass declines, the
    Python checker refuses), so a Trajectory of the user's own is covered too: with a plane the compiled
    half-space kernel certified the crossing by itself."""
    model = mujoco.MjModel.from_xml_string(
        f'<mujoco><worldbody><geom name="wall" pos="0.3 0 0" {obstacle}/><body name="ball"><freejoint/>'
        '<geom name="ball" type="ellipsoid" size="0.02 0.03 0.04"/></body></worldbody></mujoco>')
    scene = Scene.from_model(model, pairs="all", allowed=None)
    pos = np.zeros((2, 2, 3))
    pos[0, 1, 0], pos[1, 1, 0] = -1.0, 1.0
    quat = np.zeros((2, 2, 4))
    quat[..., 0] = 1.0
    motion = _OwnSegments(BodyMotion([0.0, 5e-324], pos, quat))
    for method in ("auto", "extrusion"):
        with np.errstate(all="ignore"), pytest.raises(InvalidInputError, match="overflows"):
            certify(scene, motion, margin=0.0, method=method)


def test_normal_fast_segments_still_take_the_extrusion_route():
    """The refusal is about overflow only: a 1e-300 s segment of 2 m (velocity 2e300 m/s) is a float64
    constant-velocity segment, and the exact checker still finds the crossing."""
    model = mujoco.MjModel.from_xml_string(_SLIDE_BALL)
    scene = Scene.from_model(model, pairs="all", allowed=None)
    plan = Plan([0.0, 1e-300], [[-1.0], [1.0]], model)
    assert plan.translation_segments(1) is not None
    cert = certify(scene, plan, margin=0.0, method="extrusion")
    assert cert.verdict == Verdict.VIOLATION


_TUNNEL = """
<mujoco>
  <option timestep="0.01" integrator="implicitfast" gravity="0 0 0"/>
  <worldbody>
    <body name="wall" pos="-0.05 0 0">
      <geom name="wall" type="box" size="0.005 0.2 0.2" contype="0" conaffinity="0"/>
    </body>
    <body name="ball">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="0.01" mass="0.01" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
  <actuator><velocity name="vx" joint="x" kv="10" ctrlrange="-6 6"/></actuator>
</mujoco>
"""


def test_a_cast_that_edits_the_model_during_the_tail_rollout_does_not_leave_a_stale_proposal_certificate():
    """On the two-call path ``decide`` certifies the proposal, THEN rolls out its braking tail, calling
    ``cast`` (user code) on every brake control. A ``cast`` that moves the wall into the proposal's path
    left the proposal certified on the model before the edit, and the proposal ran through the wall
    (the log then recorded the edit before the proposal's record: ``review --verify`` flagged it).
    Oracle: the motion that ran, replayed from a copy of the state on the edited model, with the exact
    sphere-box distance at every substep."""
    import copy

    from monitor.gate import Gate

    model = mujoco.MjModel.from_xml_string(_TUNNEL)
    data = mujoco.MjData(model)
    wall = model.body("wall").id
    gate = Gate(model, margin=1e-3, pairs="all", allowed=None, ongoing="violation", frame_skip=5)
    armed = [False]

    def cast(c):
        if armed[0]:  # the wall moves onto the proposal's path (past the tail's start)
            model.body_pos[wall, 0] = 0.02
            armed[0] = False
        return np.asarray(c, dtype=np.float64)

    first = gate.decide(data, np.array([-6.0]), cast=cast)   # into the wall: blocked -> two calls next
    assert first.replaced
    data.ctrl[:] = first.applied_ctrl
    mujoco.mj_step(model, data, nstep=5)
    armed[0] = True
    before = copy.copy(data)
    report = gate.decide(data, np.array([6.0]), cast=cast)
    assert not armed[0] and model.body_pos[wall, 0] == 0.02  # the edit happened inside decide
    applied_certified = report.fallback_certified if report.replaced else report.certificate.certified
    replay = copy.copy(before)
    replay.ctrl[:] = report.applied_ctrl
    xs = [float(replay.qpos[0])]
    for _ in range(5):
        mujoco.mj_step(model, replay)
        xs.append(float(replay.qpos[0]))
    # the certified motion interpolates the substeps linearly; on each piece the point nearest the
    # wall's plane x = 0.02 is a point of it: its exact distance bounds the piece's minimum from above
    probe = mujoco.MjData(model)
    dists = []
    for x0, x1 in zip(xs, xs[1:]):
        probe.qpos[0] = min(max(0.02, min(x0, x1)), max(x0, x1))
        mujoco.mj_forward(model, probe)
        dists.append(_sphere_box_distance(model, probe, 0, 1))
    assert not (applied_certified and min(dists) <= 1e-3), (report.replaced, xs, dists)
    assert report.replaced  # the proposal crosses the wall as it is now


_BALL_ON_PLANE = """
<mujoco>
  <worldbody>
    <body name="S">
      <joint name="sz" type="slide" axis="0 0 1"/><geom name="s" type="sphere" size="0.03"/>
    </body>
    <body name="P"><geom name="plane" type="plane" size="1 1 0.1"/></body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("penetration_tol", [1e13, 1e16])
def test_a_huge_penetration_tol_does_not_overstate_the_clearance(penetration_tol):
    """The ongoing rule shifts the plane by ``penetration_tol`` and subtracts it from the clearance again;
    for 1e13 m and more that subtraction's rounding exceeded every pad and the claimed clearance (a lower
    bound of the distance) was above the true one (0.0 m claimed for -0.03 m at 1e16). Closed form: the
    sphere (r = 3 cm, centre z) above the plane z = 0 is at z - 0.03, least at the lower end."""
    model = mujoco.MjModel.from_xml_string(_BALL_ON_PLANE)
    scene = Scene.from_model(model, pairs=[("s", "plane")])
    plan = Plan([0.0, 1.0], [[0.02], [0.0]], model)
    true_least = 0.0 - 0.03
    try:
        cert = certify(scene, plan, margin=0.0, ongoing="deepen", penetration_tol=penetration_tol)
    except InvalidInputError as exc:
        assert "penetration_tol" in str(exc)
        return
    assert cert.clearance <= true_least


def test_the_penetration_tol_bound_is_the_same_for_certify_and_the_gate():
    from monitor.certify.ongoing import MAX_PENETRATION_TOL
    from monitor.certify.request import CertifyRequest
    from monitor.gate import Gate

    CertifyRequest(ongoing="deepen", penetration_tol=MAX_PENETRATION_TOL)
    with pytest.raises(InvalidInputError, match="penetration_tol"):
        CertifyRequest(ongoing="deepen", penetration_tol=np.nextafter(MAX_PENETRATION_TOL, np.inf))
    model = mujoco.MjModel.from_xml_string(_BALL_ON_PLANE)
    with pytest.raises(InvalidInputError, match="penetration_tol"):
        Gate(model, ongoing="deepen", penetration_tol=2 * MAX_PENETRATION_TOL)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(2))
def test_fuzz_crossing_motions_with_extreme_segments_are_never_certified(seed):
    """Random one-segment crossings of the wall (x from -a to +a, |a| >= 0.4 m) with durations from
    subnormal to 1 s and strokes up to the float64 limit, as Plans (slide) and BodyMotions (free body),
    every method: a typed error or a verdict other than certified (continuity oracle as above)."""
    rng = np.random.default_rng(seed)
    slide = mujoco.MjModel.from_xml_string(_SLIDE_BALL)
    free = mujoco.MjModel.from_xml_string(_FREE_BALL)
    scenes = [Scene.from_model(m, pairs="all", allowed=None) for m in (slide, free)]
    for _ in range(30):
        dt = float(10.0 ** rng.uniform(-323.5, 0.0))
        a = float(10.0 ** rng.uniform(np.log10(0.4), 308.2))
        if not (dt > 0.0 and np.isfinite(a)):
            continue
        pos = np.zeros((2, 2, 3))
        pos[0, 1, 0], pos[1, 1, 0] = -a, a
        quat = np.zeros((2, 2, 4))
        quat[..., 0] = 1.0
        try:
            motions = ((scenes[0], Plan([0.0, dt], [[-a], [a]], slide)),
                       (scenes[1], BodyMotion([0.0, dt], pos, quat)))
        except InvalidInputError:
            continue
        for scene, motion in motions:
            for method in ("auto", "toleranced", "extrusion"):
                with np.errstate(all="ignore"):
                    try:
                        cert = certify(scene, motion, margin=0.0, method=method)
                    except InvalidInputError:
                        continue
                assert cert.verdict != Verdict.CERTIFIED, (dt, a, type(motion).__name__, method)
