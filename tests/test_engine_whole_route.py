"""engine._certify_fast: the whole-shape route from stage 0, and the rest of stage 1 in one call (issue 12).

Under ``method="auto"``, when no moving body of the motion translates (the Arm's hinges),
every survivor takes the compiled whole-shape stage as under ``"toleranced"``: stage 0 also
runs stage 1 (up to ``kernels.CALL_TESTS`` tests per call) and no route is computed
(``engine._no_extrusion_route``), and a window the kernel decided gets ``_kernel_decided``'s
certificate. Oracle: the same engine on the previous path (``_no_extrusion_route`` forced
False, ``_kernel_decided`` off): verdict, witness,
earliest time, clearance, stats but wall time, and every PairResult identical. A model with
a translating body checks that its pairs keep the extrusion route.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify import engine

ARM = Path(__file__).resolve().parents[1] / "models" / "arm" / "scene.xml"

_SLIDER = """<mujoco><worldbody>
  <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.6 0 0.5"/>
  <body name="cart" pos="0 0 0.5"><joint name="x" type="slide" axis="1 0 0"/>
    <geom name="box" type="box" size="0.1 0.1 0.1"/></body>
  <body name="arm" pos="0 0.4 0.5"><joint name="yaw" type="hinge" axis="0 0 1"/>
    <geom name="link" type="capsule" fromto="0 0 0 0.5 0 0" size="0.03"/></body>
</worldbody></mujoco>"""


def _key(cert):
    w = cert.witness
    stats = {k: v for k, v in cert.stats.items() if k != "wall_seconds"}
    return (str(cert.verdict), cert.earliest_time, cert.clearance, repr(stats), str(cert.method),
            None if w is None else (w.time, w.geoms, tuple(w.point.tolist()), w.distance),
            repr(cert.pairs))


@pytest.fixture(scope="module")
def arm():
    m = mujoco.MjModel.from_xml_path(str(ARM))
    return m, monitor.Scene.from_model(m)


def _arm_plan(m, moves: list[tuple[int, float]], n: int = 2, t1: float = 0.5):
    """n waypoints from qpos0, each joint (index, total change) moved linearly."""
    q = np.repeat(m.qpos0[None], n, axis=0)
    for j, d in moves:
        q[:, j] += np.linspace(0.0, d, n)
    return monitor.Plan(np.linspace(0.0, t1, n), q, m)


ARM_CASES = {
    "yaw through post_a": [(0, 1.0)],                       # violation, 10 survivors
    "yaw clear": [(0, 0.3)],                                # certified
    "pitch and elbow, 40 waypoints": [(1, 0.9), (2, -1.2)],  # a long window (sub-ranges)
    "all three, 12 waypoints": [(0, -0.8), (1, 0.5), (2, 0.7)],
}


def _oracle(monkeypatch, scene, plan, **kw):
    with monkeypatch.context() as mp:
        mp.setattr(engine, "_no_extrusion_route", lambda mpk, mov: False)
        mp.setattr(engine, "_kernel_decided", lambda *a, **k: None)
        return monitor.certify(scene, plan, **kw)


@pytest.mark.parametrize("name", sorted(ARM_CASES))
@pytest.mark.parametrize("method", ["auto", "toleranced"])
def test_the_arm_certificates_are_the_previous_paths(arm, monkeypatch, name, method):
    m, scene = arm
    n = 40 if "40" in name else 12 if "12" in name else 2
    plan = _arm_plan(m, ARM_CASES[name], n)
    calls = []
    real = engine._window_kernel

    def spy(*a):
        calls.append(a[7])        # stage
        return real(*a)

    monkeypatch.setattr(engine, "_window_kernel", spy)
    fast = monitor.certify(scene, plan, method=method, epsilon=1e-3)
    monkeypatch.undo()
    ref = _oracle(monkeypatch, scene, plan, method=method, epsilon=1e-3)
    assert _key(fast) == _key(ref), name
    # stage 0 runs stage 1 too; further calls only after kernels.CALL_TESTS tests each
    assert calls[0] == 0 and set(calls[1:]) <= {1}, (name, calls)


def test_the_cases_cover_verdicts_and_long_windows(arm):
    m, scene = arm
    verdicts, survivors = set(), []
    for name, moves in ARM_CASES.items():
        n = 40 if "40" in name else 12 if "12" in name else 2
        cert = monitor.certify(scene, _arm_plan(m, moves, n), epsilon=1e-3)
        verdicts.add(str(cert.verdict))
        survivors.append(cert.stats["pairs"] - cert.stats["pairs_culled"])
    assert verdicts == {"certified", "violation"}
    assert max(survivors) > 4      # more survivors than the old chunk of 4 per call


def test_a_translating_body_keeps_the_extrusion_route(monkeypatch):
    m = mujoco.MjModel.from_xml_string(_SLIDER)
    scene = monitor.Scene.from_model(m, pairs="all")
    q1 = m.qpos0.copy()
    q1[0] = 0.42          # the cart slides to 3 cm of the wall
    q1[1] = 0.6           # the arm turns
    plan = monitor.Plan([0.0, 0.3], [m.qpos0, q1], m)
    seen = []
    real = engine._no_extrusion_route

    def spy(mpk, mov):
        seen.append(real(mpk, mov))
        return seen[-1]

    monkeypatch.setattr(engine, "_no_extrusion_route", spy)
    cert = monitor.certify(scene, plan, epsilon=1e-3)
    assert seen == [False]
    assert "extrusion" in cert.stats["checker_mix"], cert.stats     # the cart-wall pair's checker
    monkeypatch.undo()
    assert _key(cert) == _key(_oracle(monkeypatch, scene, plan, epsilon=1e-3))
    # had it been routed whole-shape, the pair's checker would differ: the route matters here
    with monkeypatch.context() as mp:
        mp.setattr(engine, "_no_extrusion_route", lambda mpk, mov: True)
        forced = monitor.certify(scene, plan, epsilon=1e-3)
    assert "extrusion" not in forced.stats["checker_mix"]
