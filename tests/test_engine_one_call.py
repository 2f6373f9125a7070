"""The engine's per-window Python on the tunnel gate's route (issue 12, helper certpy).

* One ``window_kernel`` call for a window whose survivors all take the extrusion route
  (``engine._ONE_CALL``). Oracle: the two calls it replaces (the flag off), on the same inputs;
  whole certificates compared bit for bit (``to_dict()`` without the wall time).
* The first witness candidate without the others (``engine._earliest_candidate``). Oracle:
  the sorted candidate array the engine builds otherwise (``np.linspace`` per span), bit for bit,
  and ``_find_witness`` on that array for the witness.
* The moving / kernel flags of a new Plan taken from the scene's cache (``engine._plan_inputs``).
  Oracle: ``moving_bodies()`` and ``_body_flags`` computed afresh.

Seeded, no timings.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import mujoco
import numpy as np

import monitor
from monitor.certify import engine
from monitor.certify.engine import certify
from monitor.tolerances import DEFAULT

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _switch_cases import cert_key, on_and_off_counted, tunnel_gate_keys  # noqa: E402


def _calls_and_keys(run):
    """(certificate keys of ``run()``, window_kernel calls it made) with ``_ONE_CALL`` on, then off."""
    return on_and_off_counted(engine, "_ONE_CALL", run, engine, "_window_kernel")


def test_one_call_same_certificates_on_translating_cases():
    """60 seeded translating cases x (auto, extrusion) x (violation, deepen): identical, fewer calls."""
    from monitor.bench.cases import make_translating_cases

    cases = [(c.scene(), c.body_motion(), c.margin) for c in make_translating_cases(60, seed0=100)]

    def run():
        return [cert_key(certify(s, m, margin=mg, epsilon=1e-3, method=meth, ongoing=og))
                for s, m, mg in cases for meth in ("auto", "extrusion") for og in ("violation", "deepen")]

    on, off, n_on, n_off = _calls_and_keys(run)
    assert on == off
    verdicts = {k.split("'verdict': ")[1].split(",")[0] for k in on}
    assert {"'certified'", "'violation'"} <= verdicts
    assert n_off - n_on > 100, (n_on, n_off)     # the one-call path ran on many windows


def test_one_call_same_certificates_on_tunnel_gate():
    """60 tunnel gate steps (certified and violation windows): identical certificates and end state."""
    on, off, n_on, n_off = _calls_and_keys(lambda: tunnel_gate_keys(60))
    assert on == off
    assert n_on < n_off


def test_one_call_not_taken_under_a_test_budget():
    """A test-count budget keeps the chunked calls (same certificates either way)."""
    from monitor.bench.cases import make_translating_cases

    cases = [(c.scene(), c.body_motion(), c.margin) for c in make_translating_cases(12, seed0=300)]

    def run():
        return [cert_key(certify(s, m, margin=mg, epsilon=1e-3, budget={"tests": t}))
                for s, m, mg in cases for t in (0, 1, 3, 50)]

    on, off, n_on, n_off = _calls_and_keys(run)
    assert on == off and n_on == n_off


def _spans(rng):
    """Seeded (cands, spans) of _checked_result's kinds, edge cases included."""
    edge = [0.0, -0.0, 1e-300, -1e-300, 5e-324, 1e308, -1e308, np.inf, -np.inf, np.nan, 0.1, 0.3]
    for _ in range(400):
        spans = []
        for _ in range(int(rng.integers(0, 4))):
            a = float(rng.choice(edge)) if rng.random() < 0.2 else float(rng.uniform(-2, 2))
            r = rng.random()
            b = a if r < 0.2 else float(rng.choice(edge)) if r < 0.3 else a + float(rng.uniform(-0.1, 0.5))
            spans.append((a, b))
        cands = []
        if rng.random() < 0.7:
            cands.append(float(rng.choice(edge)) if rng.random() < 0.2
                         else spans[0][0] if spans and rng.random() < 0.3 else float(rng.uniform(-2, 2)))
        if cands or spans:
            yield cands, spans


def test_earliest_candidate_is_the_first_of_the_sorted_candidates():
    rng = np.random.default_rng(7)
    sure = unsure = 0
    for cands, spans in _spans(rng):
        for k in (1, 2, 9):
            tol = dataclasses.replace(DEFAULT, witness_candidates=k)
            with np.errstate(all="ignore"):
                want = engine._candidate_times(list(cands), spans, tol)
            got = engine._earliest_candidate(list(cands), spans)
            if got is None:
                unsure += 1
                continue
            sure += 1
            assert np.array([got]).tobytes() == want[:1].tobytes(), (cands, spans, got, want[:1])
    assert sure > 500 and unsure > 50, (sure, unsure)


_XML = """<mujoco><worldbody>
  <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.6 0 0"/>
  <body name="b"><joint name="s" type="slide" axis="1 0 0"/><joint name="h" type="hinge" axis="0 0 1"/>
    <geom name="arm" type="capsule" size="0.03 0.1" pos="0.2 0 0" euler="0 90 0"/>
  </body>
</worldbody></mujoco>"""


def _wkey(w):
    return None if w is None else (w.time, w.geoms, np.asarray(w.point).tobytes(), w.distance)


def test_witness_of_spans_equals_the_witness_of_all_candidates():
    """The witness (or None) of the lazy search equals ``_find_witness`` on every candidate."""
    from monitor.certify.common import Budget

    m = mujoco.MjModel.from_xml_string(_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    ga, gb = scene.geom("arm"), scene.geom("wall")
    kinds = set()
    for seed in range(4):
        rng = np.random.default_rng(seed)
        K = int(rng.integers(2, 5))
        q = np.tile(np.array(m.qpos0), (K, 1))
        q[:, 0] = np.linspace(0.0, 0.4, K)      # towards the wall: clear at t0, inside it at t1
        q[:, 1] = rng.uniform(-0.4, 0.4, K)
        plan = monitor.Plan(np.cumsum(rng.uniform(0.02, 0.1, K)), q, m)
        t0, t1 = plan.window
        for _ in range(30):
            a = float(rng.uniform(t0, t1))
            b = float(rng.uniform(a, t1)) if rng.random() < 0.8 else a
            spans = [(a, b)] + ([(t0, float(rng.uniform(t0, t1)))] if rng.random() < 0.3 else [])
            cands = [float(rng.uniform(t0, t1))] if rng.random() < 0.6 else []
            margin = float(rng.choice([0.0, 0.05, 0.2, 0.5]))
            times = engine._candidate_times(list(cands), spans, DEFAULT)
            want = engine._find_witness(plan, ga, gb, times, margin, DEFAULT, Budget())
            got = engine._find_witness_of(plan, ga, gb, list(cands), spans, margin, DEFAULT, Budget())
            assert _wkey(got) == _wkey(want)
            first = engine._earliest_candidate(list(cands), spans)
            assert first == times[0]
            kinds.add("none" if want is None else "first" if want.time == first else "later")
    assert kinds == {"none", "first", "later"}, kinds


def test_plan_flags_from_the_scene_cache_equal_fresh_ones():
    """Plans of alternating moving patterns on one scene: cached flags equal the fresh ones."""
    m = mujoco.MjModel.from_xml_string(_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    KS = engine._kernels()
    hits = 0
    for i in range(12):
        q = np.tile(np.array(m.qpos0), (3, 1))
        if i % 3 != 2:
            q[:, 0] = np.linspace(0.0, 0.1 * (i + 1), 3)    # moving (i % 3 == 2: nothing moves)
        plan = monitor.Plan(np.array([0.0, 0.05, 0.1]) + i, q, m)
        mp, memo = KS.trajectory_pack_memo(plan)
        cached = scene._hot.get("plan_moving")
        hits += cached is not None and cached[0] is plan._moving
        moving, fixed, mov, prm = engine._plan_inputs(scene, plan, memo, plan.t0, plan.t1, 0.01, 1e-3,
                                                      DEFAULT, KS)
        want_moving = np.asarray(plan.moving_bodies(), bool)
        want_fixed = (np.asarray(scene.body_static, bool) & ~want_moving).astype(np.int64)
        assert moving.tobytes() == want_moving.tobytes() and not moving.flags.writeable
        assert fixed.tobytes() == want_fixed.tobytes()
        assert mov.tobytes() == want_moving.astype(np.int64).tobytes()
        assert prm[0] == plan.t0 and prm[1] == plan.t1 and prm[2] == 0.01
    assert hits >= 4, hits
