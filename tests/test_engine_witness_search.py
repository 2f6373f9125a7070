"""The engine's full whole-shape search on pairs the window kernel leaves open (issue 12, Arm).

A cylinder on a hinge swings a few millimetres into a post: the window kernel's certify-only
search stops at the sub-interval where contact begins (the polytope core's approximation
error hides the first midpoints' penetration), and the pair used to go to the Python
fat-feature checker (~1e5 row tests). ``engine._full_search`` now finds the witness with the
compiled search. Oracles: MuJoCo's signed distance sampled densely (the witness is a real
contact, nothing before ``earliest_time`` touches), and the Python pipeline of the same
engine (same verdict). Seeded geometry, no timings.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify import engine

_XML = """<mujoco><worldbody>
  <geom name="post" type="box" size="0.05 0.05 0.5" pos="0.5 0 0"/>
  <body name="b" pos="{dx} 0 0"><joint name="h" type="hinge" axis="0 0 1"/>
    <geom name="cyl" type="cylinder" size="0.04 0.03" pos="0.3 0 0" euler="{roll} 0 0"/></body>
</worldbody></mujoco>"""


def _setup(roll: float):
    m = mujoco.MjModel.from_xml_string(_XML.format(dx=0.11, roll=roll))
    scene = monitor.Scene.from_model(m, pairs="all")
    plan = monitor.Plan([0.0, 0.1], [[-1.0], [1.0]], m)
    return m, scene, plan


def _signed_distance(m, d, q: float) -> float:
    d.qpos[0] = q
    mujoco.mj_forward(m, d)
    fromto = np.zeros(6)
    return float(mujoco.mj_geomDistance(m, d, m.geom("cyl").id, m.geom("post").id, 0.1, fromto))


def _python_pipeline(monkeypatch, scene, plan, **kw):
    with monkeypatch.context() as mp:
        mp.setattr(engine, "_fast_inputs", lambda scene, plan: None)
        return monitor.certify(scene, plan, **kw)


@pytest.mark.parametrize("roll", [17.0, 35.0])
def test_a_shallow_collision_is_convicted_by_the_compiled_search(monkeypatch, roll):
    m, scene, plan = _setup(roll)
    cert = monitor.certify(scene, plan, method="toleranced")
    assert cert.verdict == "violation", cert.stats
    # decided by the compiled whole-shape search, not the Python fat-feature checker
    assert cert.stats["checker_mix"] == {"toleranced/whole-shape": 1}, cert.stats
    assert cert.stats["tests"] < 2000, cert.stats
    d = mujoco.MjData(m)
    q_of = lambda t: -1.0 + 2.0 * t / 0.1  # noqa: E731  (the plan's linear hinge angle)
    w = cert.witness
    assert 0.0 < w.time < 0.1 and _signed_distance(m, d, q_of(w.time)) < 0.0
    assert cert.earliest_time <= w.time
    # nothing touches before earliest_time (dense samples; the hinge moves 0.3 m * 20 rad/s,
    # 6 m/s * 0.1 s / 4000 = 0.15 mm between samples, against 1 mm clearance tolerance)
    ts = np.linspace(0.0, cert.earliest_time, 4000)
    assert min(_signed_distance(m, d, q_of(t)) for t in ts) > -1e-3
    assert cert.pairs[0].verdict == "violation" and cert.pairs[0].method == "toleranced"
    old = _python_pipeline(monkeypatch, scene, plan, method="toleranced")
    assert old.verdict == cert.verdict


def test_a_grazing_pair_it_cannot_convict_still_reaches_the_python_checker(monkeypatch):
    """roll 0: the contact is shallower than the cylinder's polytope error; no witness is
    confirmed, so the pair goes on to the fat-feature checker and ends as before."""
    _m, scene, plan = _setup(0.0)
    cert = monitor.certify(scene, plan, method="toleranced")
    assert cert.stats["checker_mix"] == {"toleranced": 1}, cert.stats
    assert cert.verdict != "certified"
    with monkeypatch.context() as mp:
        mp.setattr(engine, "_full_search", lambda *a, **k: 0)
        before = monitor.certify(scene, plan, method="toleranced")
    assert before.verdict == cert.verdict


def test_a_test_budget_leaves_the_pair_undecided_not_certified():
    _m, scene, plan = _setup(17.0)
    for n in (1, 10, 100, 300):
        cert = monitor.certify(scene, plan, method="toleranced", budget={"tests": n})
        assert cert.verdict in ("violation", "uncertain"), (n, cert.stats)


_MIXED_XML = """<mujoco><worldbody>
  <geom name="floor" type="plane" size="2 2 0.1"/>
  <geom name="post" type="box" size="0.05 0.05 0.5" pos="0.8 0 0"/>
  <body name="slider" pos="0 0.5 0.2"><joint name="s" type="slide" axis="1 0 0"/>
    <geom name="sb" type="box" size="0.05 0.05 0.05"/>
    <body name="spin" pos="0 0 0.2"><joint name="r" type="hinge" axis="0 0 1"/>
      <geom name="rb" type="box" size="0.1 0.02 0.02"/></body></body>
  <body name="free" pos="0 -0.5 0.3"><freejoint/><geom name="fb" type="sphere" size="0.05"/></body>
  <body name="still" pos="0.3 0.3 0.3"><joint name="z" type="slide" axis="0 0 1"/>
    <geom name="sg" type="sphere" size="0.05"/></body>
</worldbody></mujoco>"""


@pytest.mark.parametrize("seed", range(6))
def test_the_route_flags_agree_with_translation_segments(seed):
    """engine._translates (pack flags) == ``plan.translation_segments(b) is not None`` on every body
    of plans that slide, spin, fly free (with and without rotating) or hold still."""
    from monitor.certify import kernels as K

    m = mujoco.MjModel.from_xml_string(_MIXED_XML)
    rng = np.random.default_rng(seed)
    q = np.tile(m.qpos0, (3, 1))
    moves = rng.random(5) < 0.6
    if moves[0]:
        q[1:, 0] = [0.1, 0.3]
    if moves[1]:
        q[1:, 1] = [0.5, 1.0]
    if moves[2]:
        q[1:, 2:5] += [[0.1, 0.0, 0.0], [0.2, 0.1, 0.0]]
    if moves[3]:
        q[2, 5:9] = [np.cos(0.2), 0.0, 0.0, np.sin(0.2)]
    if moves[4]:
        q[1:, 9] = [0.0, 0.0]
    plan = monitor.Plan([0.0, 0.05, 0.1], q, m)
    mp = K.trajectory_pack(plan)
    assert mp is not None
    got = [engine._translates(plan, mp, b) for b in range(m.nbody)]
    assert got == [plan.translation_segments(b) is not None for b in range(m.nbody)], (moves, got)
