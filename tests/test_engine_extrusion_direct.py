"""The engine's direct certificate for all-extrusion-route windows (``engine._extrusion_decided``, issue 12).

Oracle: the general path it replaces (``engine._EXTRUSION_DIRECT = False``: ``_python_stages``
and ``_certify_fast``'s general tail), on the same inputs. The whole certificate must be the
same: ``to_dict()`` (verdict, earliest time, clearance, witness, every PairResult, stats with
``checker_mix`` / ``extrusion_stages`` / ``extrusion``) except ``wall_seconds``, bit for bit.
Cases: the seeded cross-check translating cases (clear, graze, collide, tunnel, start-inside;
moving and static partners; boxes, hulls, spheres, capsules, half-spaces) with methods auto and
extrusion, the ongoing-contact rule, test-count budgets that run out at every stage, and the
tunnel gate's steps.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from monitor.certify import engine
from monitor.certify.common import Budget
from monitor.certify.engine import certify

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _switch_cases import agv_scene_plan, on_and_off_counted, tunnel_gate_keys  # noqa: E402
from _switch_cases import cert_key as _key  # noqa: E402


def _both(run):
    """(direct path on, off) results of ``run()``, and how often the direct builder returned a certificate."""
    a, b, n_on, n_off = on_and_off_counted(engine, "_EXTRUSION_DIRECT", run, engine, "_extrusion_decided",
                                           lambda c: c is not None)
    return a, b, n_on + n_off


def test_same_certificates_on_translating_cases():
    """60 seeded cases x (auto, extrusion) x (plain, ongoing deepen): identical certificates."""
    from monitor.bench.cases import make_translating_cases

    n_direct, verdicts = 0, set()
    for case in make_translating_cases(60, seed0=100):
        scene, motion = case.scene(), case.body_motion()
        for method in ("auto", "extrusion"):
            for ongoing in ("violation", "deepen"):
                def run(scene=scene, motion=motion, margin=case.margin, method=method, ongoing=ongoing):
                    return certify(scene, motion, margin=margin, epsilon=1e-3, method=method, ongoing=ongoing)

                a, b, used = _both(run)
                assert _key(a) == _key(b), (case.name, method, ongoing)
                n_direct += used
                verdicts.add(str(a.verdict))
    assert n_direct > 100                      # the direct builder decided most of the 240 calls
    assert verdicts >= {"certified", "violation"}


@pytest.mark.parametrize("tests", [0, 1, 2, 3, 5])
def test_same_certificates_when_the_test_budget_runs_out(tests):
    """A test-count budget spent before, inside or after the compiled pass: identical certificates."""
    from monitor.bench.cases import make_translating_cases

    for case in make_translating_cases(12, seed0=200):
        scene, motion = case.scene(), case.body_motion()

        def run(scene=scene, motion=motion, margin=case.margin):
            return certify(scene, motion, margin=margin, method="auto", budget=Budget(tests=tests))

        a, b, _ = _both(run)
        assert _key(a) == _key(b), (case.name, tests)


def test_rotating_pair_and_extrusion_method_fall_back():
    """A rotating body is left to the general path: auto certifies it with the toleranced checker,
    method="extrusion" raises the same typed error either way."""
    from monitor.bench.cases import make_translating_cases
    from monitor.errors import InvalidInputError
    from monitor.motion.bodymotion import BodyMotion

    case = next(c for c in make_translating_cases(40, seed0=0) if not c.b_static and c.intent == "clear")
    scene, m = case.scene(), case.body_motion()
    quat = np.array(m.quat)
    quat[-1, 1] = [np.cos(0.2), 0.0, 0.0, np.sin(0.2)]   # body A turns by 0.4 rad over the window
    motion = BodyMotion(np.array(m.times), np.array(m.pos), quat)
    a, b, used = _both(lambda: certify(scene, motion, margin=case.margin, method="auto"))
    assert _key(a) == _key(b) and used == 0
    assert "extrusion" not in a.stats["checker_mix"]
    for on in (True, False):
        engine._EXTRUSION_DIRECT = on
        try:
            with pytest.raises(InvalidInputError, match="does not translate"):
                certify(scene, motion, margin=case.margin, method="extrusion")
        finally:
            engine._EXTRUSION_DIRECT = True


def test_tunnel_gate_same_certificates():
    """models/tunnel, plain Gate.step (the bench's workload): the same certificate at every step."""
    pytest.importorskip("mujoco")
    a, b, used = _both(tunnel_gate_keys)
    assert a == b
    assert used > 20
    assert any("'violation'" in k for k in a) and any("'certified'" in k for k in a)


@pytest.mark.parametrize(("name", "skewed"), [("straight", False), ("weaving", False), ("weaving", True)])
def test_agv_scenes_same_certificates(name, skewed):
    """Cameron's §5 AGV scenes (29 primitives, pairs="all": culled pairs, several survivors per window),
    whole plan and sub-windows, margins 0 and 5 mm: identical certificates."""
    pytest.importorskip("mujoco")
    import monitor

    scene, plan = agv_scene_plan(name, skewed)
    t = np.linspace(plan.t0, plan.t1, 5)
    n_direct, culled = 0, 0
    for window in [None] + list(zip(t[:-1], t[1:])):
        for margin in (0.0, 0.005):
            a, b, used = _both(lambda w=window, mg=margin: monitor.certify(scene, plan, margin=mg, window=w))
            assert _key(a) == _key(b), (window, margin)
            n_direct += used
            culled += a.stats["pairs_culled"] > 0 and "extrusion" in a.stats["checker_mix"]
    assert n_direct >= 5 and culled >= 5
