"""Red team 6: this session's gate shortcuts (zero-pair certificate, static fallback windows, brake steps).

Oracles are independent of ``monitor``'s checkers: the motion that actually ran, replayed substep by
substep from a copy of the state with the applied control (bit-identical end state asserted), and
the exact sphere-box distance in closed form at every substep (an exact value at a time of the
motion is an upper bound of its minimum over the window, so ``certified`` with such a value
<= margin is a proven false certificate); and the general path (the same gate with ``_certify``
wrapped by an instance attribute, which turns the shortcuts off: ``Gate._certify_is_own``).

Scene: a ball (r = 1 cm, slide joint along x, velocity servo) 5 cm from a thin wall (half-thickness
5 mm) with ``contype = conaffinity = 0`` (no physics contact: the ball rests where it is put),
checked with ``pairs="all"``, ``allowed=None``, ``ongoing="violation"`` (every pair keeps the full
margin). Proposals of 6 m/s into the wall are blocked; the fallback (zero velocity) keeps the ball at
rest, so every fallback window is one in which nothing moves (``Gate._certify_static``).
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
import pytest

from monitor.certify.types import Verdict
from monitor.gate import Gate

_XML = """
<mujoco>
  <option timestep="0.01" integrator="implicitfast" gravity="0 0 0"/>
  <worldbody>
    <body name="wall"><geom name="wall" type="box" size="0.005 0.2 0.2" contype="0" conaffinity="0"/></body>
    <body name="ball">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="0.01" mass="0.01"/>
    </body>
  </worldbody>
  <actuator><velocity name="vx" joint="x" kv="10" ctrlrange="-6 6"/></actuator>
</mujoco>
"""
MARGIN = 1e-3


def _sphere_box_distance(model: mujoco.MjModel, data: mujoco.MjData, box: int, sphere: int) -> float:
    """Exact signed distance (m) of geoms ``box`` and ``sphere`` at ``data``'s poses (closed form)."""
    rot = data.geom_xmat[box].reshape(3, 3)
    c = rot.T @ (data.geom_xpos[sphere] - data.geom_xpos[box])  # sphere centre in the box frame
    half = model.geom_size[box]
    outside = np.linalg.norm(c - np.clip(c, -half, half))
    inside = -float(np.min(half - np.abs(c))) if outside == 0.0 else outside
    return float(inside - model.geom_size[sphere, 0])


def _ran_distances(model: mujoco.MjModel, before: mujoco.MjData, after: mujoco.MjData,
                   ctrl: np.ndarray, nstep: int) -> list[float]:
    """Exact distances at every substep of the motion that ran (replayed from ``before``)."""
    d = copy.copy(before)
    d.ctrl[:] = ctrl
    mujoco.mj_forward(model, d)
    out = [_sphere_box_distance(model, d, 0, 1)]
    for _ in range(nstep):
        mujoco.mj_step(model, d)
        mujoco.mj_forward(model, d)
        out.append(_sphere_box_distance(model, d, 0, 1))
    assert d.qpos.tobytes() == after.qpos.tobytes() and d.time == after.time  # the motion that ran
    return out


def _edit(model: mujoco.MjModel, what: str) -> None:
    """Bring the wall onto the ball (an in-place model edit)."""
    if what == "body_pos":
        model.body_pos[model.body("wall").id, 0] = -0.05
    elif what == "geom_pos":  # with geom_sameframe 0, so that MuJoCo reads geom_pos
        model.geom_sameframe[0] = 0
        model.geom_pos[0, 0] = -0.05
    else:
        model.geom_size[0, 0] = 0.05


def _scene_and_editing_fallback(edit, at_call: int):
    """(model, data with the ball at rest 3.5 cm from the wall, fallback callable).

    The fallback returns zero velocity and calls ``edit(model)`` on its ``at_call``-th call (user
    code inside ``decide``, after its scene sync).
    """
    m = mujoco.MjModel.from_xml_string(_XML)
    d = mujoco.MjData(m)
    d.qpos[0] = -0.05
    calls = [0]

    def fallback(data: mujoco.MjData) -> np.ndarray:
        calls[0] += 1
        if calls[0] == at_call:
            edit(m)
        return np.zeros(1)

    return m, d, fallback


def _false_certificates(general: bool, what: str, steps: int = 3) -> tuple[list[str], int]:
    """Gate.step with a fallback callable that edits the model on its 2nd call.

    Returns (applied verdicts, number of steps whose applied window was certified although an
    exact distance of the motion that ran is <= margin).
    """
    m, d, fallback = _scene_and_editing_fallback(lambda model: _edit(model, what), 2)

    gate = Gate(m, pairs="all", margin=MARGIN, allowed=None, ongoing="violation", fallback=fallback)
    if general:
        own = gate._certify
        gate._certify = lambda plan: own(plan)  # the general path: no shortcut
    verdicts, false = [], 0
    for _ in range(steps):
        before = copy.copy(d)
        r = gate.step(d, np.array([6.0]))
        dist = _ran_distances(m, before, d, r.applied_ctrl, gate.frame_skip)
        verdicts.append(str(r.applied_verdict))
        false += r.applied_verdict == Verdict.CERTIFIED and min(dist) <= MARGIN
    return verdicts, false


@pytest.mark.parametrize("what", ["body_pos", "geom_pos", "geom_size"])
def test_a_fallback_that_edits_the_model_is_certified_against_the_edited_model(what):
    """Finding 1: the static shortcut (body_pos: also vs the general path) and the reuse cache
    (geom_pos / geom_size: the general path too) answered from the context of decide's own scene
    sync, before the fallback callable moved the wall onto the ball: ``certified`` for a window in
    which ball and wall overlap. Fails on da1cfd7 (1 false certificate per run)."""
    fast, false_fast = _false_certificates(False, what)
    slow, false_slow = _false_certificates(True, what)
    assert fast[0] == Verdict.CERTIFIED  # the first fallback window (before the edit) is clear
    assert false_fast == 0 and false_slow == 0
    assert fast == slow == ["certified", "violation", "violation"]


def test_a_predictor_that_edits_the_model_does_not_reuse_stale_pair_results():
    """Finding 1 through ``decide(predict=...)``: an adapter's predictor that grows the wall onto the
    resting ball; the fixed pair's cached result (same body poses) was reused under the old scene
    version. Fails on da1cfd7 (``certified``, clearance 3.5 cm)."""
    m = mujoco.MjModel.from_xml_string(_XML)
    d = mujoco.MjData(m)
    d.qpos[0] = -0.05
    gate = Gate(m, pairs="all", margin=MARGIN, allowed=None, ongoing="violation")
    calls = [0]

    def predict(ctrl):
        calls[0] += 1
        if calls[0] == 2:
            _edit(m, "geom_size")
        return gate.predict(d, ctrl, 1)

    verdicts = [gate.decide(d, np.zeros(1), predict=predict).verdict for _ in range(2)]
    mujoco.mj_forward(m, d)
    assert _sphere_box_distance(m, d, 0, 1) < 0.0  # the oracle: they overlap after the edit
    assert verdicts == [Verdict.CERTIFIED, Verdict.VIOLATION]


def test_a_pair_added_between_steps_ends_the_zero_pair_certificate():
    """Held (guard): a zero-pair gate whose model gains a candidate pair in place (contype) certifies
    that pair from the next step (decide syncs before ``_certify_nothing`` decides)."""
    m = mujoco.MjModel.from_xml_string(_XML)
    d = mujoco.MjData(m)
    d.qpos[0] = -0.05
    with pytest.warns(UserWarning):
        gate = Gate(m, margin=MARGIN, allowed=None, ongoing="violation")  # pairs="mujoco": none
        r0 = gate.step(d, np.array([6.0]))
    assert r0.certificate.stats["nothing_checked"] and r0.verdict == Verdict.CERTIFIED
    m.geom_contype[0] = m.geom_conaffinity[0] = 1
    before = copy.copy(d)
    r1 = gate.step(d, np.array([6.0]))
    assert len(r1.certificate.pairs) == 1 and not r1.certificate.stats.get("nothing_checked")
    dist = _ran_distances(m, before, d, r1.applied_ctrl, gate.frame_skip)
    assert not (r1.applied_verdict == Verdict.CERTIFIED and min(dist) <= MARGIN)


def test_a_geom_on_the_inertial_frame_is_where_mujoco_puts_it():
    """Finding 2 (fixed in ``scene.geom_frame`` by the lead): ``geom_sameframe`` edited to INERTIA on a
    body whose ``body_sameframe`` is BODY, then ``body_ipos`` moved away: MuJoCo keeps the wall at the body
    origin (``xipos = xpos``), the scene moves it with ``body_ipos``; the gate certifies the ball
    through the wall. Fails on da1cfd7 too."""
    m = mujoco.MjModel.from_xml_string(_XML)
    d = mujoco.MjData(m)
    d.qpos[0] = -0.05
    gate = Gate(m, pairs="all", margin=MARGIN, allowed=None, ongoing="violation")
    assert m.body_sameframe[m.body("wall").id] == mujoco.mjtSameFrame.mjSAMEFRAME_BODY
    m.geom_sameframe[0] = mujoco.mjtSameFrame.mjSAMEFRAME_INERTIA
    m.body_ipos[m.body("wall").id, 0] = 0.3
    false = 0
    for _ in range(3):
        before = copy.copy(d)
        r = gate.step(d, np.array([6.0]))
        dist = _ran_distances(m, before, d, r.applied_ctrl, gate.frame_skip)
        false += r.applied_verdict == Verdict.CERTIFIED and min(dist) <= MARGIN
    assert false == 0


def test_a_fallback_that_removes_a_pair_splits_the_reuse_over_the_live_pairs():
    """Finding 1, pair list: a fallback callable drops the first pair; the fallback's certificate is
    about the live pairs (da1cfd7: it still named the dropped pair, answered from the cache under
    the old scene). Also guards the fix's re-split in ``_split_reuse`` (a split over the old pair
    list wrote its keys against the new certificate's pairs: IndexError). General path."""
    xml = _XML.replace('<body name="wall">', '<body name="back" pos="-0.3 0 0"><geom name="back" type="box" '
                       'size="0.005 0.2 0.2"/></body>\n    <body name="wall">', 1)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qpos[0] = -0.05
    back = m.geom("back").id
    calls = [0]

    def fallback(data: mujoco.MjData) -> np.ndarray:
        calls[0] += 1
        if calls[0] == 2:
            m.geom_contype[back] = m.geom_conaffinity[back] = 0  # the pair (back, ball) leaves
        return np.zeros(1)

    gate = Gate(m, pairs="mujoco", margin=MARGIN, allowed=None, ongoing="violation", fallback=fallback)
    wall = m.geom("wall").id
    m.geom_contype[wall] = m.geom_conaffinity[wall] = 1  # a "mujoco" pair here (the ball rests 3.5 cm off)
    own = gate._certify
    gate._certify = lambda plan: own(plan)
    names = []
    for _ in range(3):
        r = gate.step(d, np.array([6.0]))
        names.append([p.geoms for p in r.fallback_certificate.pairs])
        assert r.applied_verdict == Verdict.CERTIFIED
    assert names == [[("back", "ball"), ("wall", "ball")], [("wall", "ball")], [("wall", "ball")]]


@pytest.mark.parametrize("wall_x", [-0.05, 0.5])  # onto the ball / away from it
def test_a_fallback_callable_edit_is_logged_at_the_fallbacks_window(tmp_path, wall_x):
    """Finding 1, log: the edit a fallback callable makes is noted before the fallback's record (the
    window certified on it), not before the proposal's (certified before it) nor a step late. Review
    re-derives every window on the model it was certified on: no CRITICAL (on da1cfd7 the edit was
    noted a step late, so the falsely certified fallback re-derived on the old model and agreed;
    noted at the proposal, moving the wall away made review report a false verdict flip)."""
    from monitor import review
    from monitor.log import read_log

    def move_wall(model: mujoco.MjModel) -> None:
        model.body_pos[model.body("wall").id, 0] = wall_x

    m, d, fallback = _scene_and_editing_fallback(move_wall, 3)

    path = tmp_path / "edit.mcap"
    with Gate(m, pairs="all", margin=MARGIN, allowed=None, ongoing="violation", fallback=fallback,
              log=str(path)) as gate:
        verdicts = [str(gate.step(d, np.array([6.0])).applied_verdict) for _ in range(4)]
    assert verdicts[:2] == ["certified", "certified"]
    assert verdicts[2] == ("violation" if wall_x < 0 else "certified")
    ver = review.verify(read_log(path))
    assert ver["critical"] == 0, ver
    assert any("first at window 5" in str(n) for n in ver["notes"]), ver["notes"]  # step 2's fallback


_SAMEFRAME_XML = """<mujoco><worldbody><body name="b" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2">
<joint type="hinge" axis="0 1 0"/><inertial pos="0.05 -0.02 0.01" quat="0.8 0.2 -0.1 0.3" mass="1"
 diaginertia="1 2 3"/><geom type="box" size=".1 .1 .1" pos="-.03 .04 .02" quat="0.7 0.1 0.5 -0.2"/>
</body></worldbody></mujoco>"""


@pytest.mark.parametrize("body_sf", [0, 1, 3])  # the values MuJoCo's compiler sets for a body
def test_geom_frame_matches_mj_kinematics_for_every_sameframe_combination(body_sf):
    """Oracle: MuJoCo's own geom_xpos / geom_xmat after mj_kinematics, for each geom_sameframe 0..4 on a
    rotated hinged body with an offset, rotated inertial frame (4 of these 15 combinations were wrong)."""
    from monitor.scene import geom_frame

    m = mujoco.MjModel.from_xml_string(_SAMEFRAME_XML)
    d = mujoco.MjData(m)
    d.qpos[0] = 0.4
    m.body_sameframe[1] = body_sf
    for geom_sf in range(5):
        m.geom_sameframe[0] = geom_sf
        mujoco.mj_kinematics(m, d)
        R_WB, p_WB = d.xmat[1].reshape(3, 3), d.xpos[1]
        R_BG, p_BG = geom_frame(m, 0)
        np.testing.assert_allclose(R_WB @ R_BG, d.geom_xmat[0].reshape(3, 3), atol=1e-12,
                                   err_msg=str(geom_sf))
        np.testing.assert_allclose(p_WB + R_WB @ p_BG, d.geom_xpos[0], atol=1e-12, err_msg=str(geom_sf))


def test_a_body_sameframe_the_compiler_never_sets_is_refused_by_name():
    from monitor.errors import UnsupportedGeometryError
    from monitor.scene import geom_frame

    m = mujoco.MjModel.from_xml_string(_SAMEFRAME_XML)
    m.body_sameframe[1] = mujoco.mjtSameFrame.mjSAMEFRAME_INERTIA
    m.geom_sameframe[0] = mujoco.mjtSameFrame.mjSAMEFRAME_INERTIA
    with pytest.raises(UnsupportedGeometryError, match="body_sameframe"):
        geom_frame(m, 0)
