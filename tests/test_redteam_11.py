"""Red team 11: review's re-simulation of logged rollouts, the engine's whole-shape route.

Each test is a finding of ``docs/notes/redteam-11.md`` (it failed on 0453413) or a check that held.
Forgeries are made as ``tests/test_review_replay.py`` makes them (``mcap_rewrite.rewrite``, re-sealed).
"""

from __future__ import annotations

import pytest
from test_review_replay import _bounce_log, _edit_plan, _findings, _forge, _verify

from monitor.log import replay


@pytest.fixture(scope="module")
def bounce(tmp_path_factory):
    path = tmp_path_factory.mktemp("rt11") / "bounce.mcap"
    model, _ = _bounce_log(path)  # Gate (warn), 6 windows of 50 substeps, window 2 bounces off a wall
    return path, model


@pytest.mark.parametrize("substeps", [51, replay.MAX_SUBSTEPS])
def test_a_forged_substep_count_is_refused_before_it_is_simulated(bounce, tmp_path, monkeypatch, substeps):
    """A rollout whose substeps disagree with its logged rows (51 logged) is a critical finding without
    a re-simulation: on 0453413 review simulated up to MAX_SUBSTEPS (10**6) substeps per plan and kept
    (substeps, nstate) floats, seconds of mj_step and megabytes for every forged plan of a log."""
    path, _ = bounce
    dst = tmp_path / "huge.mcap"

    def more(o):
        o["rollout"]["segments"][0]["substeps"] = substeps

    _forge(path, dst, msg=_edit_plan(1, more))
    simulated = []
    real = replay.resimulate

    def counted(model, data, ro):
        simulated.append(ro.substeps - ro.rows_from + 1)
        assert ro.substeps <= 50, "review re-simulated a rollout longer than its logged rows"
        return real(model, data, ro)

    monkeypatch.setattr(replay, "resimulate", counted)
    code, ver = _verify(dst)
    assert code == 1 and simulated == [51] * 5  # the five genuine windows, not the forged one
    crit = _findings(ver, "critical")
    assert [k for k, _ in crit] == [1], crit
    assert f"51 logged row(s), the rollout makes {substeps + 1}" in crit[0][1]
