"""The two certifiers cross-check (issue 14, item 3).

On seeded translating pair-windows (every shape kind the extrusion checker takes: box and
hull polytopes, spheres, capsules, and a static plane; piecewise-constant velocities; intents
clear, grazing, colliding, tunnelling and start-inside; margin 0 or 1 cm),
``monitor.certify(..., method="toleranced")`` and ``method="extrusion"`` must never
contradict: never ``certified`` by one and ``violation`` by the other. Every disagreement
(one certifies or finds a violation, the other is ``uncertain``) is labelled by an
independent oracle (dense time sampling of the exact static distance with the exact
Lipschitz margin |v_A - v_B| per segment, plus the exact space-time LP for polytope and
plane pairs at margin 0) and must not be a certified collision. The counts and the reasons
are printed (``pytest -s``).

Speed: both certifiers on one case take ~30 ms on this shared machine (an extrusion
violation ~60 ms), so 1000 cases do not fit the fast suite: ``test_crosscheck_fast`` runs
250 cases, ``test_crosscheck_1000`` (slow) the 1000-case acceptance run (a superset).
"""

from __future__ import annotations

import numpy as np
import pytest

from monitor.bench.cases import (
    XCHECK_INTENTS,
    XCHECK_KINDS_A,
    XCHECK_KINDS_B,
    TranslatingCase,
    make_translating_case,
    make_translating_cases,
)
from monitor.bench.oracle import translating_label, translating_lp
from monitor.bench.suites import crosscheck_case, crosscheck_summary
from monitor.geometry.polytope import box_polytope, sphere_shape

N_FAST = 250
N_FULL = 1000


def _run(n: int) -> list[dict]:
    cases = make_translating_cases(n, seed0=0)
    entries = []
    for case in cases:
        e = crosscheck_case(case)
        vt, ve = e["toleranced"]["verdict"], e["extrusion"]["verdict"]
        if case.intent == "start-inside":  # a body starting inside another is a violation, for both
            assert vt == ve == "violation", (case.name, vt, ve)
        if case.intent == "tunnel":  # the inner points meet: a collision, whatever the end poses
            assert "certified" not in (vt, ve), (case.name, vt, ve)
        if "certified" in (vt, ve) and case.margin == 0.0 and all(
                s.kind in ("polytope", "halfspace") for s in case.shapes):
            assert not translating_lp(case), (case.name, vt, ve)  # exact LP: no interior overlap
        entries.append(e)
    return entries


def _check(entries: list[dict]) -> None:
    s = crosscheck_summary(entries)
    print(f"\ncross-check over {s['n']} translating cases, intents {s['intents']}")
    print("verdict pairs (toleranced/extrusion):", s["verdict_pairs"])
    print(f"contradictions {s['contradictions']}, false negatives {s['false_negatives']}, "
          f"agree {s['agree']}; toleranced certified & extrusion uncertain {s['tol_cert_ext_uncertain']}, "
          f"extrusion certified & toleranced uncertain {s['ext_cert_tol_uncertain']}, "
          f"toleranced violation & extrusion uncertain {s['tol_viol_ext_uncertain']}, "
          f"extrusion violation & toleranced uncertain {s['ext_viol_tol_uncertain']}")
    for reason, count in s["reasons"].items():
        print(f"  {count:5d}  {reason}")
    bad = [e for e in entries if e["contradiction"]]
    assert not bad, [(e["case"], e["toleranced"], e["extrusion"], e["oracle"]) for e in bad[:5]]
    fn = [e for e in entries if e["false_negative"]]
    assert not fn, [(e["case"], e["oracle"]) for e in fn[:5]]
    # every disagreement got an oracle label; the set exercises both outcomes of both checkers
    assert all(e["oracle"] is not None for e in entries if e["disagreement"])
    pairs = s["verdict_pairs"]
    assert pairs.get("certified/certified", 0) >= 0.2 * len(entries)
    assert pairs.get("violation/violation", 0) >= 0.2 * len(entries)
    kinds = {e["kinds"] for e in entries}
    assert {k.split("-")[0] for k in kinds} == set(XCHECK_KINDS_A)
    assert {k.split("-")[1] for k in kinds} == set(XCHECK_KINDS_B)
    assert set(s["intents"]) == set(XCHECK_INTENTS)


def test_crosscheck_fast():
    _check(_run(N_FAST))


@pytest.mark.slow
def test_crosscheck_1000():
    _check(_run(N_FULL))


# ----------------------------------------------------------------------------- the oracle itself
def _two_spheres(gap: float, margin: float = 0.0) -> TranslatingCase:
    """Sphere A (r 0.1) passes sphere B (r 0.05, static at the origin) along x at height
    0.15 + gap, in two segments (the bend at x = 0.2): exact minimum distance ``gap`` at x = 0."""
    eye = np.stack([np.eye(3)] * 2)
    h = 0.15 + gap
    origins = np.zeros((3, 2, 3))
    origins[:, 0] = [[-0.6, h, 0.0], [0.2, h, 0.0], [0.5, h + 0.4, 0.0]]
    return TranslatingCase("spheres", "graze", ("sphere", "sphere"), margin,
                           (sphere_shape(0.1), sphere_shape(0.05)), eye, np.array([0.0, 0.5, 1.0]),
                           origins, True)


@pytest.mark.parametrize("gap", [1e-2, 1e-4, -1e-4, -1e-2])
def test_translating_label_closed_form(gap):
    lab = translating_label(_two_spheres(gap))
    if gap > 0:
        assert lab.label == "clear"
        assert 0.0 < lab.clearance_lower <= gap + 1e-12
        assert lab.distance_upper >= gap - 1e-9
    else:
        assert lab.label == "collide"
        assert lab.distance_upper < 0
    # the margin shifts the label: a 1e-2 gap is a collision of a 2e-2 margin band
    if gap == 1e-2:
        assert translating_label(_two_spheres(gap, margin=2e-2)).label == "collide"


def test_translating_lp_boxes_closed_form():
    """Box A (half 0.1) passes box B (half 0.1) along x at y offset 0.2 + gap: overlap iff gap < 0."""
    eye = np.stack([np.eye(3)] * 2)
    for gap, expect in ((1e-6, False), (0.0, False), (-1e-6, True), (-0.05, True)):
        origins = np.zeros((2, 2, 3))
        origins[:, 0] = [[-1.0, 0.2 + gap, 0.0], [1.0, 0.2 + gap, 0.0]]
        case = TranslatingCase("boxes", "graze", ("box", "box"), 0.0,
                               (box_polytope(np.full(3, 0.1)), box_polytope(np.full(3, 0.1))), eye,
                               np.array([0.0, 1.0]), origins, True)
        assert translating_lp(case) is expect, gap


def test_translating_cases_are_seeded():
    a, b = make_translating_case(17), make_translating_case(17)
    assert a.name == b.name and np.array_equal(a.origins, b.origins)
    assert np.array_equal(a.shapes[0].points, b.shapes[0].points)
    assert make_translating_case(18).name != a.name or not np.array_equal(
        make_translating_case(18).origins, a.origins)


def test_crosscheck_bench_row(tmp_path):
    """The bench row (smoke size): counts, reasons and the markdown table; 0 contradictions."""
    from monitor.bench.suites import BenchConfig, _same_case_crosscheck, suite_crosscheck

    cfg = BenchConfig(quick=True, out=tmp_path, reps=1, log=lambda s: None, smoke=True)
    res = suite_crosscheck(cfg)
    summ = res["summary"]
    assert summ["n"] == 12 and summ["contradictions"] == 0 and summ["false_negatives"] == 0
    assert sum(summ["verdict_pairs"].values()) == 12
    assert "| n | contradictions |" in "\n".join(res["markdown"])
    # the same-case comparison inside suite_accuracy counts a contradiction when there is one
    per_case = [{"case": "a", "checker": "extrusion", "epsilon": None, "verdict": "violation"},
                {"case": "a", "checker": "toleranced", "epsilon": 1e-3, "verdict": "certified"},
                {"case": "b", "checker": "extrusion", "epsilon": None, "verdict": "certified"},
                {"case": "b", "checker": "toleranced", "epsilon": 1e-3, "verdict": "uncertain"}]
    (row,) = _same_case_crosscheck(per_case)
    assert row["contradictions"] == 1 and row["ext_cert_tol_uncertain"] == 1 and row["agree"] == 0


def test_crosscheck_detects_a_contradiction(monkeypatch):
    """The harness can fail: an extrusion checker that certified everything would be caught."""
    from types import SimpleNamespace

    import monitor.certify.engine as engine

    real = engine.certify

    def lying(scene, plan, *args, method="auto", **kw):
        cert = real(scene, plan, *args, method=method, **kw)
        if method != "extrusion":
            return cert
        pair = SimpleNamespace(method="extrusion", note="", tests=0)
        return SimpleNamespace(verdict="certified", pairs=(pair,), clearance=1.0)

    monkeypatch.setattr(engine, "certify", lying)
    case = next(c for c in (make_translating_case(s) for s in range(40)) if c.intent == "start-inside")
    e = crosscheck_case(case)
    assert e["toleranced"]["verdict"] == "violation" and e["extrusion"]["verdict"] == "certified"
    assert e["contradiction"] and e["false_negative"] and e["reason"].startswith("CONTRADICTION")
    with pytest.raises(AssertionError):
        _check([e] * 10)
