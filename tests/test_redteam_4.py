"""Red team 4: ``certified`` for a motion that collides, or a gate that runs another motion (rt4).

Every test here failed on the base commit 1c16a97 (see docs/notes/redteam-4.md) unless its
docstring says it is a guard. Oracles are independent of the checkers: a sphere on a slide
joint along x and a box wall that MuJoCo does not collide (contype 0, an explicitly monitored
pair); the distance of the ball to the wall is the closed form ``|x_wall - x| - half - r``,
evaluated on the live data after the step (the motion that actually ran; the ball moves
monotonically within one window, so sampling the segment between its end states suffices).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.envs.mujoco.mujoco_env import MujocoEnv

from monitor.errors import InvalidInputError
from monitor.gym_gate import SafetyGate

BALL_R, WALL_HALF = 0.01, 0.005

_SLIDE_XML = f"""<mujoco><option timestep="0.002" gravity="0 0 0"/><worldbody>
<geom name="wall" type="box" pos="{{wall_x}} 0 0" size="{WALL_HALF} 0.2 0.2" contype="0" conaffinity="0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/>
  <geom name="ball" type="sphere" size="{BALL_R}" mass="0.01" contype="0" conaffinity="0"/></body>
</worldbody><actuator><velocity name="vx" joint="x" kv="10" ctrlrange="-6 6"/></actuator></mujoco>"""


def _gap(x0: float, x1: float, wall_x: float) -> float:
    """Closed-form least distance (m) of the ball to the wall while x goes monotonically x0 -> x1."""
    lo, hi = min(x0, x1), max(x0, x1)
    nearest = min(max(wall_x, lo), hi)
    return abs(wall_x - nearest) - WALL_HALF - BALL_R


class _EditingEnv(MujocoEnv):
    """A user's env whose ``step`` edits the model (``edit``) and then simulates."""

    metadata = {"render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"], "render_fps": 100}

    def __init__(self, path: str, edit: str, v0: float = 0.0) -> None:
        self.edit, self.v0 = edit, v0
        MujocoEnv.__init__(self, path, 5,
                           observation_space=gym.spaces.Box(-np.inf, np.inf, shape=(2,), dtype=np.float64))

    def step(self, action):
        if self.edit == "geom_pos":   # a static obstacle moved onto the ball's path (moving obstacles)
            self.model.geom_pos[0, 0] = float(self.data.qpos[0]) + 0.01
        elif self.edit == "timestep":  # the env changes its integration step
            self.model.opt.timestep = 0.02
        self.do_simulation(action, self.frame_skip)
        return np.array([self.data.qpos[0], self.data.qvel[0]]), 0.0, False, False, {}

    def reset_model(self):
        self.set_state(np.zeros(1), np.array([self.v0]))
        return np.zeros(2)


def _env_path(tmp_path, wall_x: float) -> str:
    path = tmp_path / "slide_wall.xml"
    path.write_text(_SLIDE_XML.format(wall_x=wall_x))
    return str(path)


@pytest.mark.parametrize("commit", [True, False])
def test_env_step_moving_a_static_obstacle_is_not_certified(tmp_path, commit):
    """Base: the env's ``step`` moved the wall (``model.geom_pos``) onto the ball's path after the
    gate decided; the window ran through it (closed-form gap -0.0148 m) and was reported
    ``applied_verdict == "certified"`` (with the commit hook the scratch window was copied in;
    without it the qpos rows matched, since the wall does not act on the ball). Now refused:
    before the motion runs with the hook, right after it without."""
    env = SafetyGate(_EditingEnv(_env_path(tmp_path, 1.0), "geom_pos"), pairs=[("ball", "wall")])
    env.commit = commit
    env.reset(seed=0)
    d, m = env.unwrapped.data, env.unwrapped.model
    t0 = float(d.time)
    with pytest.raises(InvalidInputError, match="geom_pos"):
        for _ in range(2):
            x0 = float(d.qpos[0])
            info = env.step(np.array([2.0]))[4]
            gap = _gap(x0, float(d.qpos[0]), float(m.geom_pos[0, 0]))
            assert not (gap < 0.0 and info["safety"]["applied_verdict"] == "certified"), gap
    if commit:
        assert float(d.time) == t0  # refused before simulating anything
    env.close()


def test_env_step_changing_the_timestep_is_detected_without_commit(tmp_path):
    """Base: with ``commit=False`` (the setting the docs recommend for envs that edit dynamics in
    ``step``) an env that sets ``opt.timestep`` 10x larger inside ``step`` ran 0.1 s instead of the
    certified 0.01 s: the ball went from x = 0 to 0.5 m, through the wall at 0.1 m (closed-form gap
    < 0), ``applied_verdict == "certified"`` (``data.time`` was not a row of the certified window and
    the check returned). Now InvalidInputError after the step, never silent."""
    env = SafetyGate(_EditingEnv(_env_path(tmp_path, 0.1), "timestep", v0=5.0), pairs=[("ball", "wall")])
    env.commit = False
    env.reset(seed=0)
    d = env.unwrapped.data
    x0 = float(d.qpos[0])
    with pytest.raises(InvalidInputError, match="substep time"):
        info = env.step(np.array([5.0]))[4]
        assert not (_gap(x0, float(d.qpos[0]), 0.1) < 0 and info["safety"]["applied_verdict"] == "certified")
    assert _gap(x0, float(d.qpos[0]), 0.1) < 0.0  # the oracle: the motion that ran went through the wall
    env.close()


def test_timestep_edit_with_commit_runs_the_certified_window(tmp_path):
    """Guard (passes on base): with the commit hook the certified window is copied in, so a
    timestep edit inside ``step`` does not change the motion of that step (the ball stays clear)."""
    env = SafetyGate(_EditingEnv(_env_path(tmp_path, 0.1), "timestep", v0=5.0), pairs=[("ball", "wall")])
    env.reset(seed=0)
    d = env.unwrapped.data
    x0 = float(d.qpos[0])
    info = env.step(np.array([5.0]))[4]
    assert info["safety"]["applied_verdict"] == "certified"
    assert _gap(x0, float(d.qpos[0]), 0.1) > 0.0
    env.close()


# --------------------------------------------------------------------------- geom frames (geom_sameframe)
_SAMEFRAME_XML = """<mujoco><worldbody>
<geom name="wall" type="sphere" size="0.05"/>
<geom name="obs" type="sphere" size="0.05" pos="0.3 0.25 0"/>
<body name="b" pos="0 -0.5 0"><freejoint/>
  <geom name="ball" type="capsule" size="0.05 0.02" pos="0.3 0 0" euler="0 90 0"/></body>
</worldbody></mujoco>"""


def _mujoco_gap(m, qpos, cap: int, sph: int) -> float:
    """Closed-form distance (m) of a capsule and a sphere geom where MuJoCo's own kinematics put them."""
    import mujoco

    d = mujoco.MjData(m)
    d.qpos[:] = qpos
    mujoco.mj_kinematics(m, d)
    c, axis, half = d.geom_xpos[cap], d.geom_xmat[cap].reshape(3, 3)[:, 2], m.geom_size[cap, 1]
    s = d.geom_xpos[sph]
    u = float(np.clip(np.dot(s - c, axis), -half, half))   # nearest point of the capsule's segment
    return float(np.linalg.norm(s - (c + u * axis)) - m.geom_size[cap, 0] - m.geom_size[sph, 0])


@pytest.mark.parametrize("edit", ["body_ipos", "geom_pos"])
def test_geom_frame_follows_mujoco_geom_sameframe(edit):
    """Base: the Scene placed every geom at ``geom_pos``/``geom_quat`` in its body frame, but MuJoCo
    places a geom whose frame the compiler found equal to its body's inertial frame (``geom_sameframe``
    INERTIA: any single-geom body with inertia from the geom) at ``body_ipos``/``body_iquat``, and one at
    its body's frame (BODY) at the body frame, ignoring ``geom_pos``. Centre-of-mass randomisation
    (``body_ipos``) moved the ball onto the obstacle in MuJoCo (closed-form distance -0.05 m on MuJoCo's
    own geom_xpos) and ``certify`` said certified (it saw the ball 0.2 m away); a ``geom_pos`` edit of a
    world geom at the origin moved nothing in MuJoCo, yet the Scene moved the wall out of the ball's path."""
    import mujoco

    from monitor import Plan, Scene, certify

    m = mujoco.MjModel.from_xml_string(_SAMEFRAME_XML)
    ball, wall, obs = m.geom("ball").id, m.geom("wall").id, m.geom("obs").id
    q0 = np.array(m.qpos0)
    q1 = q0.copy()
    if edit == "body_ipos":
        assert int(m.geom_sameframe[ball]) == int(mujoco.mjtSameFrame.mjSAMEFRAME_INERTIA)  # set-up
        m.body_ipos[m.body("b").id] = (0.3, 0.2, 0.0)      # the COM 0.2 m along y (randomised)
        q0[:3], q1[:3] = (0.0, 0.0, 0.0), (0.002, 0.0, 0.0)
        other, pairs = obs, [("ball", "obs")]
    else:
        assert int(m.geom_sameframe[wall]) == int(mujoco.mjtSameFrame.mjSAMEFRAME_BODY)  # set-up
        m.geom_pos[wall] = (2.0, 0.0, 0.0)                   # MuJoCo keeps the wall at the origin
        q0[:3], q1[:3] = (-0.3, 0.0, 0.0), (-0.3, 0.0, 0.0)
        q1[0] += 0.002
        other, pairs = wall, [("ball", "wall")]
    # the oracle: MuJoCo's own geom positions; the ball translates 2 mm, so the distance along the
    # segment is within 1 mm of its value at either end (Lipschitz margin)
    gap = min(_mujoco_gap(m, q, ball, other) for q in (q0, q1))
    assert gap + 0.001 < 0.0
    cert = certify(Scene.from_model(m, pairs=pairs), Plan([0.0, 0.1], [q0, q1], m), margin=0.0)
    assert cert.verdict != "certified", (edit, gap, cert.clearance)


def test_geom_frame_within_the_compilers_tolerance():
    """Base, on an UNEDITED model: MuJoCo's compiler treats a geom frame within ~1e-6 m / ~2e-6 rad of
    the body's inertial frame as the same (``geom_sameframe`` INERTIA) and places the geom there. A
    box whose explicit ``<inertial pos>`` is 9e-7 m off its ``pos`` sits 9e-7 m from where the Scene
    put it: a sphere overlapping MuJoCo's box by 1e-7 m (closed form on MuJoCo's geom_xpos/geom_xmat)
    was certified at margin 0 with clearance ~6.8e-7 m."""
    import mujoco

    from monitor import Plan, Scene, certify

    r, half, off = 0.05, np.array([0.1, 0.05, 0.05]), 9e-7
    u = np.array([np.cos(np.pi / 6), np.sin(np.pi / 6), 0.0])          # the box's local +x in the world
    s = np.array([0.3 + off, 0.0, 0.0]) + u * (half[0] + r - 1e-7)    # 1e-7 m into MuJoCo's box
    xml = (f'<mujoco><worldbody><geom name="obs" type="sphere" size="{r}" '
           f'pos="{float(s[0])!r} {float(s[1])!r} 0"/><body name="b"><freejoint/>'
           f'<inertial pos="{0.3 + off!r} 0 0" euler="0 0 30" mass="1" diaginertia=".1 .2 .3"/>'
           '<geom name="box" type="box" size=".1 .05 .05" pos=".3 0 0" euler="0 0 30"/>'
           '</body></worldbody></mujoco>')
    m = mujoco.MjModel.from_xml_string(xml)
    box, obs = m.geom("box").id, m.geom("obs").id
    assert int(m.geom_sameframe[box]) == int(mujoco.mjtSameFrame.mjSAMEFRAME_INERTIA)  # set-up
    q0 = np.array(m.qpos0)
    q1 = q0.copy()
    q1[2] += 1e-3    # along the box face: the distance is constant over the motion
    for q in (q0, q1):   # the oracle: MuJoCo's own box pose, closed-form sphere-box distance
        d = mujoco.MjData(m)
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        local = d.geom_xmat[box].reshape(3, 3).T @ (d.geom_xpos[obs] - d.geom_xpos[box])
        dist = np.linalg.norm(local - np.clip(local, -half, half)) - r
        assert dist < -5e-8
    cert = certify(Scene.from_model(m, pairs=[("box", "obs")]), Plan([0.0, 0.1], [q0, q1], m), margin=0.0)
    assert cert.verdict != "certified", cert.clearance


# --------------------------------------------------------------------------- extrusion: a span one ulp long
@pytest.mark.parametrize("swept_first", [True, False])
@pytest.mark.parametrize("s0", [1.0, 1.7e9])
def test_extrusion_span_one_ulp_long_uses_its_own_segment(monkeypatch, swept_first, s0):
    """Base: on a span one ulp long the extrusion checkers (the compiled first pass and the Python
    checker) picked the segment by the span's midpoint, which rounds to ``s0`` (ties to even) and so
    took the PREVIOUS segment's velocity. A piecewise-linear plan whose waypoints ``s0`` and
    ``nextafter(s0)`` are 0.5 m apart (e.g. two trajectories concatenated at a rounded time) moves a
    sphere straight through another (closed-form least distance -0.02 m on that segment) and was
    certified with clearance 0.23 m. Now the span's own segment (``searchsorted(s0, side="right")``)."""
    import mujoco

    from monitor import Scene, certify
    from monitor.certify import engine
    from monitor.motion.bodymotion import BodyMotion

    monkeypatch.setattr(engine, "_SWEPT_FIRST", swept_first)
    r = 0.01
    m = mujoco.MjModel.from_xml_string(
        f'<mujoco><worldbody><geom name="B" type="sphere" size="{r}"/><body name="a" mocap="true">'
        f'<geom name="A" type="sphere" size="{r}"/></body></worldbody></mujoco>')
    s1 = float(np.nextafter(s0, 2.0 * s0))
    assert 0.5 * (s0 + s1) == s0  # set-up: the midpoint rounds to the span's start
    jump = np.array([0.0, -0.5, 0.0])
    p0 = -0.5 * jump                                  # the segment [p0, p0 + jump] passes B's centre
    times = np.array([s0 - 1.0, s0, s1, s0 + 1.0])
    pos = np.zeros((4, 2, 3))
    pos[:, 1] = [p0 - (0.0, 0.0, 1.0), p0, p0 + jump, p0 + jump + (0.0, 0.0, 1.0)]
    quat = np.zeros((4, 2, 4))
    quat[..., 0] = 1.0
    # the oracle: closed-form distance of B's centre (the origin) to the segment, minus the radii
    u = np.clip(-p0 @ jump / (jump @ jump), 0.0, 1.0)
    assert np.linalg.norm(p0 + u * jump) - 2 * r < -0.01
    cert = certify(Scene.from_model(m, pairs=[("A", "B")]), BodyMotion(times, pos, quat), margin=0.0,
                   method="extrusion")
    assert cert.verdict != "certified", cert.clearance


# ---------------------------------------------------------- motion bounds: a sub-interval one ulp long
def _qz(angle: float) -> list[float]:
    return [float(np.cos(angle / 2)), 0.0, 0.0, float(np.sin(angle / 2))]


@pytest.mark.parametrize("motion", ["lerp_slerp", "screw", "free_joint_plan"])
def test_rotation_bound_of_a_sub_interval_one_ulp_long(motion):
    """Base: the rotation bound of a sub-interval ``[s0, s1]`` one ulp long took the segment of its
    midpoint, which rounds to ``s1`` (here ``s0 = nextafter(1.7e9)``, odd mantissa), i.e. the segment
    AFTER the interval, so a body turning 90 degrees between the waypoints ``s0`` and ``s1`` got the
    bound 0 (compiled ``_rot_dev`` and ``screw_poses_bounds``, Python ``IntervalVertices``). A 1 m rod
    sweeping through a sphere was certified (auto and toleranced). Closed-form oracle: at 45 degrees
    (on the slerp and on the screw motion about the fixed origin) the sphere's centre is on the rod."""
    import mujoco

    from monitor import Plan, Scene, certify
    from monitor.motion.bodymotion import BodyMotion

    s0 = float(np.nextafter(1.7e9, 2e9))
    s1 = float(np.nextafter(s0, 2e9))
    assert 0.5 * (s0 + s1) == s1  # set-up: the midpoint rounds to the interval's end
    joint = "<freejoint/>" if motion == "free_joint_plan" else ""
    body = f'<body name="a"{"" if joint else " mocap=" + chr(34) + "true" + chr(34)}>{joint}'
    m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><geom name="B" type="sphere" size="0.01" pos="0.35 0.35 0"/>'
        f'{body}<geom name="A" type="box" size="0.5 0.01 0.01" pos="0.5 0 0"/></body></worldbody></mujoco>')
    times = np.array([s0 - 1.0, s0, s1, s0 + 1.0])
    angles = [0.0, 0.0, np.pi / 2, np.pi / 2]
    if motion == "free_joint_plan":
        plan = Plan(times, [[0.0, 0.0, 0.0, *_qz(a)] for a in angles], m)
    else:
        quat = np.zeros((4, 2, 4))
        quat[..., 0] = 1.0
        quat[:, 1] = [_qz(a) for a in angles]
        plan = BodyMotion(times, np.zeros((4, 2, 3)), quat, interpolation=motion)
    # the oracle: the rod at 45 degrees (box frame: centre 0.5 m along its axis), closed-form sphere-box
    c = 0.5 * np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0])
    R = np.array([[np.cos(np.pi / 4), -np.sin(np.pi / 4), 0.0], [np.sin(np.pi / 4), np.cos(np.pi / 4), 0.0],
                  [0.0, 0.0, 1.0]])
    local = R.T @ (np.array([0.35, 0.35, 0.0]) - c)
    half = np.array([0.5, 0.01, 0.01])
    assert np.linalg.norm(local - np.clip(local, -half, half)) - 0.01 <= 0.0 and np.all(np.abs(local) < half)
    scene = Scene.from_model(m, pairs=[("A", "B")])
    for method in ("auto", "toleranced"):
        cert = certify(scene, plan, margin=0.0, method=method)
        assert cert.verdict != "certified", (motion, method, cert.clearance)
