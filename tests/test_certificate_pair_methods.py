"""Certificate.pair_methods() equals the methods of the built pairs, without building them (issue 12).

Oracle: ``[str(p.method) for p in cert.pairs]`` (the PairResults themselves), read after
``pair_methods()`` so that the lazy path is the one under test. Cases: the tunnel gate (extrusion
route, rejections), the Arm gate (toleranced whole-shape stage, static pairs, violations), and
budget-limited calls (pairs left "budget").
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np

import monitor.envs  # noqa: F401  (registers monitor/Arm-v0)
from monitor._paths import scene_path
from monitor.certify.engine import certify
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate


def _check(cert, seen: dict) -> None:
    lazy = not isinstance(cert.__dict__.get("_pairs_store", ()), tuple)
    got = cert.pair_methods().tolist()
    assert got == [str(p.method) for p in cert.pairs]
    if lazy:
        for m in got:
            seen[m] = seen.get(m, 0) + 1


def test_arm_and_tunnel_gate_certificates():
    seen: dict = {}
    env = SafetyGate(gym.make("monitor/Arm-v0"))
    env.action_space.seed(3)
    env.reset(seed=0)
    for _ in range(30):
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        r = env.gate.last_report
        for c in (r.certificate, r.fallback_certificate):
            if c is not None:
                _check(c, seen)
        if term or trunc:
            env.reset(seed=1)
    env.close()
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m)
    rng = np.random.default_rng(1)
    for _ in range(60):
        r = gate.step(d, np.array([rng.uniform(-6.0, 6.0)]))
        for c in (r.certificate, r.fallback_certificate):
            if c is not None:
                _check(c, seen)
    # the lazy path met the kinds it maps (culled always; the Arm's narrow phase)
    assert seen.get("culled", 0) > 0 and seen.get("toleranced", 0) > 0, seen


def test_budget_limited_calls():
    """Test budgets leave pairs to the Python pipeline (its PairResults sit in the lazy source)."""
    seen: dict = {}
    env = gym.make("monitor/Arm-v0")
    env.reset(seed=0)
    gate = Gate(env.unwrapped.model)
    data = env.unwrapped.data
    plan = gate.predict(data, np.full(env.unwrapped.model.nu, 0.5), 10)
    from_python = 0
    for method in ("auto", "toleranced"):
        for tests in (0, 1, 3, None):
            c = certify(gate.scene, plan, margin=0.05, method=method,
                        budget={"seconds": 10.0, "tests": tests})
            src = c.__dict__.get("_pairs_store", ())
            from_python += 0 if isinstance(src, tuple) else len(src.results)
            _check(c, seen)
    env.close()
    assert from_python > 0 and seen.get("culled", 0) > 0, (from_python, seen)
