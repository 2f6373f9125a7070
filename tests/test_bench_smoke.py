"""Smoke tests of the benchmark harness (issue 7): oracle, peers, report, suites, CLI.

The oracle is checked against closed forms (axis-aligned boxes passing each other
at a known gap), and the exact LP against the sampling oracle; peers are checked
on an obvious collision and an obvious miss. No timings are asserted.
"""

from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

pytest.importorskip("mujoco")

from monitor.bench import oracle, report  # noqa: E402
from monitor.bench.cases import PairCase, ShapeSpec  # noqa: E402

IDQ = np.array([1.0, 0.0, 0.0, 0.0])


def slab_case(gap: float, *, turn: float = 0.0, both: bool = False, name: str = "slab") -> PairCase:
    """Box A (half 0.1, 0.08, 0.05) passes along x over box B (half 0.1) with y gap ``gap``.

    A rotates by ``turn`` rad about y (preserves y), so the min distance is exactly ``gap``.
    With ``both``, B moves along z by 0.01 (its top face stays at y = 0.1): still exact.
    """
    a, b = ShapeSpec.box([0.1, 0.08, 0.05]), ShapeSpec.box([0.1, 0.1, 0.1])
    y = 0.1 + 0.08 + gap
    pos = np.array([[[-0.6, y, 0.0], [0.6, y, 0.0]], [[0.0, 0.0, 0.0], [0.0, 0.0, 0.01 if both else 0.0]]])
    quat = np.tile(IDQ, (2, 2, 1))
    quat[0, 1] = [math.cos(turn / 2), 0.0, math.sin(turn / 2), 0.0]
    group = "rotating" if turn else "translating"
    return PairCase(name, group, "collide" if gap < 0 else "near", gap, (a, b), pos, quat, (True, both))


@pytest.fixture(scope="module")
def small_set():
    cases = [slab_case(-0.01, name="col"), slab_case(1e-3, name="near3"),
             slab_case(0.05, turn=1.0, name="rot"), slab_case(-1e-3, turn=0.5, both=True, name="rotcol")]
    return cases, [oracle.label(c) for c in cases]


def test_oracle_closed_form(small_set):
    cases, labels = small_set
    got = {c.name: lab for c, lab in zip(cases, labels)}
    assert got["col"].label == "collide" and got["rotcol"].label == "collide"
    for name, gap in (("near3", 1e-3), ("rot", 0.05)):
        lab = got[name]
        assert lab.label == "clear"
        assert 0.0 < lab.clearance_lower <= gap + 1e-9
        assert lab.distance_upper >= gap - 1e-6
    assert got["col"].lp is True and got["near3"].lp is False  # exact LP agrees on the translating cases


def test_lp_matches_sampling_on_random_translations():
    rng = np.random.default_rng(3)
    for _ in range(12):
        a = ShapeSpec.box(rng.uniform(0.05, 0.2, 3))
        pts = rng.normal(size=(10, 3)) * 0.1
        b = ShapeSpec.hull(pts)
        pos = np.zeros((2, 2, 3))
        pos[0, 0], pos[0, 1] = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
        quat = np.tile(IDQ, (2, 2, 1))
        case = PairCase("r", "translating", "near", 0.0, (a, b), pos, quat, (True, False))
        lab = oracle.label(case, resolution=1e-7)
        sampled = lab.hit_time is not None
        if lab.label != "near":
            assert sampled == oracle.lp_overlap(case)


def test_speed_bound_is_conservative():
    case = slab_case(0.01, turn=2.0)
    ts = np.linspace(0, 1, 2001)
    P, R = case.poses(ts)
    corners = case.shapes[0].vertices
    X = np.einsum("tij,nj->tni", R[:, 0], corners) + P[:, 0, None, :]
    speed = np.linalg.norm(np.diff(X, axis=0), axis=2).max() / (ts[1] - ts[0])
    assert speed <= case.speed_bounds()[0]


def test_peers_on_obvious_cases(small_set):
    from monitor.bench import peers

    cases, _ = small_set
    col, clear = cases[0], cases[2]
    for n in (10, 100):
        s = peers.MujocoSampler(n)
        assert s.query(s.prepare(col))[0] is True
        assert s.query(s.prepare(clear))[0] is False
    if peers.have_fcl():
        p = peers.FclPeer("CCDM_LINEAR", "CCDC_NAIVE")
        assert p.query(p.prepare(col))[0] is True
        assert p.query(p.prepare(clear))[0] is False
    if peers.have_ipctk():
        p = peers.IpctkPeer()
        assert p.applies(col)
        assert p.query(p.prepare(col))[0] is True
        assert p.query(p.prepare(clear))[0] is False


def test_captured_fds_sees_c_level_output():
    from monitor.bench.peers import captured_fds

    with captured_fds() as cap:
        os.write(1, b"hello-fd1 ")
        os.write(2, b"not supported")
    assert "hello-fd1" in cap[0] and "not supported" in cap[0]


def test_fcl_probe_classifies():
    from monitor.bench import peers

    if not peers.have_fcl():
        pytest.skip("python-fcl not installed")
    res = peers.probe_fcl(motions=("CCDM_LINEAR",), solvers=("CCDC_NAIVE", "CCDC_POLYNOMIAL_SOLVER"))
    assert res["CCDM_LINEAR|CCDC_NAIVE|box"]["status"] == "ok"
    assert res["CCDM_LINEAR|CCDC_POLYNOMIAL_SOLVER|box"]["status"] == "unsupported"


def test_report_files(tmp_path):
    rows = [{"checker": "toleranced", "group": "rotating", "epsilon": e, "us_median": 100 / e ** 0.2,
             "us_p95": 150 / e ** 0.2} for e in (1e-1, 1e-3)]
    report.plot_time_vs_epsilon(tmp_path / "a.png", rows, {"fcl": 10.0})
    pts = [{"checker": "toleranced", "clearance": c, "epsilon": 1e-3, "verdict": v}
           for c, v in ((1e-4, "uncertain"), (1e-2, "certified"), (1e-1, "certified"))]
    report.plot_uncertain(tmp_path / "b.png", pts)
    assert (tmp_path / "a.png").stat().st_size > 1000 and (tmp_path / "b.png").stat().st_size > 1000
    res = {"command": "x", "quick": True, "wall_seconds": 1.0, "machine": report.machine_info(),
           "suites": {"s": {"markdown": [report.table(rows, ["checker", "epsilon", "us_median"])],
                            "figures": ["a.png"], "value": float("nan")}, "t": {"skipped": "why"}}}
    report.write_json(tmp_path / "r.json", res)
    report.write_markdown(tmp_path / "r.md", res)
    back = json.loads((tmp_path / "r.json").read_text())
    assert back["suites"]["s"]["value"] is None and back["machine"]["cores_logical"] >= 1
    md = (tmp_path / "r.md").read_text()
    assert "Skipped: why" in md and "| toleranced |" in md


def test_peers_suite_on_small_set(small_set, tmp_path):
    from monitor.bench.suites import BenchConfig, suite_peers

    cases, labels = small_set
    cfg = BenchConfig(quick=True, out=tmp_path, reps=1, log=lambda s: None, smoke=True)
    cfg.shared["cases"], cfg.shared["labels"] = cases, labels
    res = suite_peers(cfg)
    if res.get("skipped"):
        pytest.skip(res["skipped"])
    rows = {(r["checker"], r["group"]): r for r in res["rows"]}
    ours = rows.get(("ours/toleranced eps=1e-3", "all"))
    if ours is not None:
        assert ours["misses"] == 0
    assert rows[("mujoco/N=1000", "all")]["misses"] == 0
    assert (tmp_path / "peers.png").exists()


def test_accuracy_suite_on_small_set(small_set, tmp_path):
    from monitor.bench import suites

    cases, labels = small_set
    cfg = suites.BenchConfig(quick=True, out=tmp_path, reps=1, log=lambda s: None, smoke=True)
    cfg.shared["cases"], cfg.shared["labels"] = cases, labels
    cfg.shared["skip_facets"] = True
    res = suites.suite_accuracy(cfg)
    for r in res["rows"]:
        assert r["false_negatives"] == 0, r
        assert r["errors"] == 0, r
    assert (tmp_path / "time_vs_epsilon.png").exists() and (tmp_path / "uncertain_vs_clearance.png").exists()


def test_cli_writes_results(tmp_path):
    from monitor.cli import main

    rc = main(["bench", "--quick", "--out", str(tmp_path), "--suite", "seeds"])
    res = json.loads((tmp_path / "results.json").read_text())
    assert "error" not in res["suites"]["seeds"], res["suites"]["seeds"].get("trace")
    assert rc == 0  # 1 means a suite raised
    assert "seeds" in res["suites"] and res["machine"]["cpu"]
    assert (tmp_path / "results.md").exists()


def test_targets_suite_on_small_set(small_set, tmp_path):
    """The targets section (issue 12): one row per target, statuses consistent, in json, md and stdout.

    Smoke sizes only; nothing about the timings is asserted.
    """
    from monitor.bench import targets
    from monitor.bench.suites import SUITE_FUNCS, BenchConfig

    cases, labels = small_set
    cfg = BenchConfig(quick=True, out=tmp_path, reps=1, log=lambda s: None, smoke=True)
    cfg.shared["cases"], cfg.shared["labels"] = cases, labels
    res = SUITE_FUNCS["targets"](cfg)
    rows = {r["key"]: r for r in res["rows"]}
    assert list(rows) == [s.key for s in targets.TARGETS]  # every issue-12 target, in order
    assert res["errors"] == {}, res["errors"]
    for r in rows.values():
        for bound, status in (("target", "target_status"), ("floor", "floor_status")):
            if r[bound] is None:
                assert r[status] is None
            elif r["value"] is None:
                assert r[status] == "NOT MEASURED"
            elif r["value"] > r[bound]:
                assert r[status] == "MISSED"
            else:  # within the bound; MISSED only when an extra condition (e.g. 0 misses) failed
                assert r[status] in ("MET", "MISSED")
    # the targets and floors
    assert (rows["pair_windows"]["target"], rows["pair_windows"]["floor"]) == (3.0, 10.0)
    assert (rows["pusher"]["target"], rows["pusher"]["floor"]) == (3.0, 5.0)
    assert (rows["arm"]["target"], rows["arm"]["floor"]) == (5.0, 10.0)
    assert (rows["tunnel"]["target"], rows["tunnel"]["floor"]) == (3.0, 5.0)
    assert (rows["hand30"]["target"], rows["hand30"]["floor"]) == (10.0, 25.0)
    assert (rows["cold_start"]["target"], rows["cold_start"]["floor"]) == (10.0, 15.0)
    assert rows["sparse_seconds"]["target"] == 0.05 and rows["sparse_exponent"]["target"] == 1.2
    # measured in a smoke run: the tunnel gate against its mj_step loop, ours against fcl when installed
    tun = rows["tunnel"]
    assert tun["value"] is not None and tun["value"] == pytest.approx(tun["ours"] / tun["ref"])
    verdicts = res["tunnel"]["verdicts"]
    assert verdicts and sum(verdicts.values()) == res["tunnel"]["steps_gated"]
    pw = res["pair_windows"]
    from monitor.bench import peers

    if peers.have_fcl():
        assert pw["rows"][-1]["group"] == "all" and pw["rows"][-1]["n"] == len(cases)
        assert pw["rows"][-1]["ours_misses"] == 0  # oracle-collide cases never certified
        assert rows["pair_windows"]["value"] is not None
    else:
        assert rows["pair_windows"]["target_status"] == "NOT MEASURED"
    # report: summary table at the top of results.md, rows in results.json, stdout lines
    results = {"command": "x", "quick": True, "wall_seconds": 1.0, "machine": report.machine_info(),
               "suites": {"targets": res}, "targets": res["rows"]}
    report.write_json(tmp_path / "r.json", results)
    report.write_markdown(tmp_path / "r.md", results)
    md = (tmp_path / "r.md").read_text()
    assert md.index("## Targets (issue 12)") < md.index("## targets")
    assert "Gate.step on models/tunnel" in md and "≤ 3x:" in md
    back = json.loads((tmp_path / "r.json").read_text())
    assert [r["key"] for r in back["targets"]] == list(rows)
    lines = targets.summary_lines(res["rows"])
    assert len(lines) == len(rows) and any("floor <= 5x" in s for s in lines)


def test_target_status_rules():
    from monitor.bench.targets import SPECS, target_row

    spec = SPECS["pair_windows"]
    assert target_row(spec, 2.0)["target_status"] == "MET"
    five = target_row(spec, 5.0)
    assert five["target_status"] == "MISSED" and five["floor_status"] == "MET"
    assert target_row(spec, 2.0, ok=False)["floor_status"] == "MISSED"  # e.g. a miss: never MET
    assert target_row(spec, None)["floor_status"] == "NOT MEASURED"
    assert target_row(spec, float("nan"))["target_status"] == "NOT MEASURED"
    assert target_row(SPECS["sparse_seconds"], 0.01)["floor_status"] is None  # the issue sets no floor


def test_physics_floor_counts_the_tails_that_ran():
    """The floor is 1 + (tail substeps actually simulated per step) x (one loop substep) / ungated step."""
    from monitor.bench.targets import _floor

    tail = {"tail_substeps": 25, "tail_loop_s": 250e-6}  # 10 us per substep
    f = _floor(tail, 20e-6, 3.5)  # tails of 3.5 substeps per gated step on average
    assert f["physics_floor_ratio"] == pytest.approx(1 + 3.5 * 10e-6 / 20e-6)
    assert f["physics_floor_horizon_ratio"] == pytest.approx(1 + 250e-6 / 20e-6)
    assert "physics_floor_ratio" not in _floor(tail, 20e-6)  # no count: only the horizon bound
    assert _floor(None, 20e-6) == {}


def test_cli_lists_the_targets_suite():
    from monitor.commands.bench import SUITES

    assert SUITES[-1] == "targets"


def test_targets_take_ours_from_the_peers_suite_of_the_run(small_set, tmp_path):
    """Ours' per-case µs and verdicts come from the peers suite's entries, earliest times from run_ours."""
    from monitor.bench.suites import BenchConfig
    from monitor.bench.targets import _ours_per_case

    cases, labels = small_set
    cfg = BenchConfig(quick=True, out=tmp_path, reps=1, log=lambda s: None, smoke=True)
    entries = [
        {"case": c.name, "verdict": "violation" if lab.label == "collide" else "certified", "us": 100.0 + i}
        for i, (c, lab) in enumerate(zip(cases, labels))
    ]
    cfg.shared["suite_results"] = {"peers": {"entries": {"ours/toleranced eps=1e-3": entries}}}
    cfg.shared["ours"] = {(c.name, "toleranced", 1e-3): {"verdict": "x", "us": 1.0, "earliest_time": 0.25}
                          for c in cases}
    got, source = _ours_per_case(cfg, cases, labels)
    assert source == f"{len(cases)} from the peers suite"
    for i, c in enumerate(cases):
        assert got[c.name]["us"] == 100.0 + i and got[c.name]["earliest_time"] == 0.25
