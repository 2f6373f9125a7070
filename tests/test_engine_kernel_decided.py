"""engine._kernel_decided and engine._window_kernel (issue 12, the pair-window floor).

When one ``window_kernel`` call decided every surviving pair (``method="toleranced"``, at most
``kernels.CALL_TESTS`` whole-shape tests), ``_certify_fast`` builds the certificate from the result rows
directly instead of running its general tail. Oracle: the general tail itself (the same
engine with ``_kernel_decided`` patched to return None): verdict, witness, earliest time,
clearance, stats and every PairResult must be identical. Scenes mix a moving pair (colliding,
grazing or clear), two free bodies the plan does not move (overlapping: a start-pose
violation; apart: a start-pose certificate) and culled pairs.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify import engine

_XML = """<mujoco><worldbody>
  <body name="a" pos="0 0 0"><freejoint/><geom name="ga" type="box" size="0.1 0.1 0.1"/></body>
  <body name="b" pos="{bx} 0 0"><freejoint/>
    <geom name="gb" type="box" size="0.1 0.1 0.1" euler="0 0 {yaw}"/></body>
  <body name="c" pos="0 2 0"><freejoint/><geom name="gc" type="capsule" size="0.05 0.1"/></body>
  <body name="d" pos="{dx} 2 0"><freejoint/><geom name="gd" type="box" size="0.1 0.1 0.1"/></body>
</worldbody></mujoco>"""


def _scene_plan(bx: float, yaw: float, dx: float, travel: float, spin: float):
    m = mujoco.MjModel.from_xml_string(_XML.format(bx=bx, yaw=yaw, dx=dx))
    scene = monitor.Scene.from_model(m, pairs="all")
    q0 = m.qpos0.copy()
    q1 = q0.copy()
    q1[0] += travel                         # body a slides along x towards b
    half = 0.5 * spin
    q1[3:7] = [np.cos(half), 0.0, 0.0, np.sin(half)]   # and turns about z
    plan = monitor.Plan([0.0, 0.2], np.stack([q0, q1]), m)
    return scene, plan


def _key(cert):
    w = cert.witness
    stats = {k: v for k, v in cert.stats.items() if k != "wall_seconds"}
    return (str(cert.verdict), cert.earliest_time, cert.clearance, repr(stats),
            None if w is None else (w.time, w.geoms, tuple(w.point.tolist()), w.distance),
            repr(cert.pairs))


CASES = {
    # moving pair collides; c-d overlap at t0 (start-pose violation of bodies the plan does not move)
    "collide+static-violation": (0.35, 10.0, 0.1, 0.45, 0.4),
    # moving pair collides; c-d 2 cm apart (start-pose certificate)
    "collide+static-clear": (0.35, 10.0, 0.17, 0.45, 0.4),
    # moving pair grazes past a few mm of clearance; c-d apart
    "near+static-clear": (0.35, 0.0, 0.17, 0.14, 0.0),
    # moving pair clear by centimetres; c-d overlap
    "clear+static-violation": (0.6, 0.0, 0.1, 0.2, 0.3),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_kernel_decided_certificate_is_the_general_tails(monkeypatch, name):
    scene, plan = _scene_plan(*CASES[name])
    calls = []
    real = engine._kernel_decided

    def spy(*a, **k):
        out = real(*a, **k)
        calls.append(out is not None)
        return out

    monkeypatch.setattr(engine, "_kernel_decided", spy)
    fast = monitor.certify(scene, plan, method="toleranced", epsilon=1e-3)
    assert calls == [True], (name, calls, fast.stats)        # the shortcut built this certificate
    monkeypatch.setattr(engine, "_kernel_decided", lambda *a, **k: None)
    general = monitor.certify(scene, plan, method="toleranced", epsilon=1e-3)
    assert _key(fast) == _key(general)
    assert fast.stats["pairs"] == 6 and fast.stats["pairs_culled"] >= 2


def test_the_cases_cover_every_kernel_decision():
    seen = set()
    for name in CASES:
        scene, plan = _scene_plan(*CASES[name])
        cert = monitor.certify(scene, plan, method="toleranced", epsilon=1e-3)
        for p in cert.pairs:
            seen.add((str(p.verdict), str(p.method)))
    assert {("violation", "static"), ("certified", "static"), ("violation", "toleranced"),
            ("certified", "toleranced"), ("certified", "culled")} <= seen, seen


# -- engine._window_kernel: the entry point called directly for known argument objects ---------------


def test_direct_calls_give_the_dispatchers_certificates():
    for name in sorted(CASES):
        scene, plan = _scene_plan(*CASES[name])
        engine._WK_DIRECT[0] = None
        ref = monitor.certify(scene, plan, method="toleranced", epsilon=1e-3)      # the dispatcher
        assert engine._WK_DIRECT[0] is not None and engine._WK_DIRECT[0][4] is not None
        again = monitor.certify(scene, plan, method="toleranced", epsilon=1e-3)    # the entry point
        assert _key(again) == _key(ref), name


def test_only_the_last_typed_objects_take_the_direct_call(monkeypatch):
    from monitor.certify import kernels as KS

    scene, plan = _scene_plan(*CASES["near+static-clear"])
    monitor.certify(scene, plan, method="toleranced")
    d = engine._WK_DIRECT[0]
    used = []
    poisoned = d[:2] + (lambda *a: used.append("direct") or 0,) + d[3:]
    monkeypatch.setattr(engine, "_WK_DIRECT", [poisoned])
    monitor.certify(scene, plan, method="toleranced")       # the recorded objects: the entry point runs
    assert used == ["direct"]
    used.clear()
    # another plan object (a new motion pack): the dispatcher, never the recorded entry point
    engine._WK_DIRECT[0] = poisoned
    scene2, plan2 = _scene_plan(*CASES["near+static-clear"])
    cert = monitor.certify(scene2, plan2, method="toleranced")
    assert used == [] and cert.stats["checker_mix"].get("toleranced/whole-shape") == 1
    # a replaced window_kernel is what runs, not the recorded entry point
    calls = []
    real = KS.window_kernel

    def wrapper(*a):
        calls.append(1)
        return real(*a)

    monkeypatch.setattr(KS, "window_kernel", wrapper)
    engine._WK_DIRECT[0] = poisoned
    monitor.certify(scene, plan, method="toleranced")
    assert used == [] and calls
