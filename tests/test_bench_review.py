"""The bench's review suite: per-window cost of read_log + analyze + render_text (issue 16)."""

from __future__ import annotations

import json

from monitor.bench import SUITES
from monitor.bench import report as bench_report
from monitor.bench.suites import SUITE_FUNCS, BenchConfig, suite_review


def test_review_suite_smoke(tmp_path):
    lines: list[str] = []
    cfg = BenchConfig(quick=True, out=tmp_path, reps=2, log=lines.append, smoke=True)
    res = suite_review(cfg)
    assert res["windows"] == 50 and res["file_bytes"] > 0
    steps = {r["step"]: r for r in res["rows"]}
    assert set(steps) == {"write + close (once)", "read_log", "analyze", "render_text", "review (sum)"}
    parts = sum(steps[k]["seconds"] for k in ("read_log", "analyze", "render_text"))
    assert abs(steps["review (sum)"]["seconds"] - parts) <= 1e-12 * max(1.0, parts)
    for r in res["rows"]:
        assert r["seconds"] > 0 and abs(r["us_per_window"] - 1e6 * r["seconds"] / 50) < 1e-6
    assert any("[bench] review: 50 windows" in ln for ln in lines)
    assert "µs / window" in "\n".join(res["markdown"])
    json.dumps(res)  # JSON-serialisable like every suite
    assert not list(tmp_path.glob("*.mcap"))  # the scratch log is removed


def test_review_is_a_registered_suite(tmp_path):
    assert "review" in SUITES and SUITE_FUNCS["review"] is suite_review
    cfg = BenchConfig(quick=True, out=tmp_path, reps=1, log=lambda s: None, smoke=True)
    results = {"command": "x", "quick": True, "seed": 7, "reps": 1, "wall_seconds": 1.0,
               "machine": bench_report.machine_info(), "suites": {"review": suite_review(cfg)}}
    bench_report.write_markdown(tmp_path / "results.md", results)
    assert "## review" in (tmp_path / "results.md").read_text()
