"""monitor.rollouts on local processes: per-episode verdicts, logs, determinism across worker counts.

Scene: models/tunnel (a 1 cm ball on a slide joint, a 1 cm thick wall at x = 0),
cheap enough to gate hundreds of windows. Oracle for the verdicts: the ball-wall
clearance of a window is closed-form. The plan interpolates x linearly between
the two step states, so min |x| over the window is 0 if the states straddle the
wall and min(|x0|, |x1|) otherwise; the clearance is min |x| - 0.005 - 0.01.
"""

from __future__ import annotations

import json
import pickle
import sys

import numpy as np
import pytest

from monitor.errors import DependencyNotInstalled, InvalidInputError
from monitor.rollouts import RandomPolicy, RolloutSummary, rollouts

EPISODES, STEPS = 4, 30
WALL_HALF, BALL_R = 0.005, 0.01


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """4 seeded episodes in this process, with logs."""
    log_dir = tmp_path_factory.mktemp("roll1")
    return rollouts("tunnel", RandomPolicy(hold=5), episodes=EPISODES, steps=STEPS, seeds=10, workers=1,
                    log_dir=log_dir, progress=False)


def test_summary_table(serial: RolloutSummary):
    assert [e.episode for e in serial.episodes] == list(range(EPISODES))
    assert [e.seed for e in serial.episodes] == [10, 11, 12, 13]
    for e in serial.episodes:
        assert e.steps == STEPS
        assert e.certified + e.violation + e.uncertain == STEPS
        assert e.blocked >= e.violation  # block mode: every violation is replaced (uncertain too)
        assert e.certify_s > 0
    t = serial.totals()
    assert t["steps"] == EPISODES * STEPS
    assert t["violation"] > 0 and t["certified"] > 0  # the random policy does aim through the wall
    text = str(serial)
    assert "certified" in text and "total" in text and len(text.splitlines()) == EPISODES + 4
    d = json.loads(json.dumps(serial.to_dict()))
    assert [r["violation"] for r in d["episodes"]] == [e.violation for e in serial.episodes]


def test_one_log_per_episode_matches_summary_and_closed_form(serial: RolloutSummary):
    from monitor.log.reader import read_log

    for e in serial.episodes:
        assert e.log is not None and e.log.endswith(f"episode-{e.episode:04d}-seed{e.seed}.mcap")
        c = read_log(e.log)
        certs = c.certificates()
        # one window per step, plus the records of the motions that ran on replaced steps (h12ac: a
        # fresh fallback's window or the committed braking tail, marked "applied")
        steps = [x for x in certs if "applied" not in x]
        assert e.fallback_uncertified == 0  # then there is exactly one step window per step
        assert len(steps) == STEPS
        got = {v: sum(x["verdict"] == v for x in steps) for v in ("certified", "violation", "uncertain")}
        assert [got[v] for v in ("certified", "violation", "uncertain")] == [e.certified, e.violation,
                                                                             e.uncertain]
        plans = c.plans_by_index()
        for cert in certs:
            x = np.asarray(plans[int(cert["index"])]["qpos"], float)[:, 0]
            straddle = x.min() <= 0.0 <= x.max()
            clearance = (0.0 if straddle else np.abs(x).min()) - WALL_HALF - BALL_R
            if clearance < 0:
                assert cert["verdict"] == "violation", (cert["index"], x)
            elif clearance > 1e-3:  # epsilon: farther than the certification tolerance
                assert cert["verdict"] == "certified", (cert["index"], x)


def test_two_workers_same_verdicts(serial: RolloutSummary):
    par = rollouts("tunnel", RandomPolicy(hold=5), episodes=EPISODES, steps=STEPS, seeds=10, workers=2,
                   log_dir=None, progress=False)
    assert par.workers == 2 and par.log_dir is None
    assert par.counts() == serial.counts()
    assert [e.verdict_digest for e in par.episodes] == [e.verdict_digest for e in serial.episodes]
    assert all(e.log is None for e in par.episodes)


def test_gym_env_id():
    s = rollouts("monitor/Tunnel-v0", RandomPolicy(hold=3), episodes=1, steps=12, seeds=[5], log_dir=None,
                 progress=False)
    e = s.episodes[0]
    assert e.seed == 5 and 1 <= e.steps <= 12
    assert e.certified + e.violation + e.uncertain == e.steps


def _not_picklable_policy():
    return lambda data, rng: np.zeros(1)


def test_bad_input():
    with pytest.raises(InvalidInputError, match="picklable"):
        rollouts("tunnel", _not_picklable_policy(), episodes=1, steps=1, log_dir=None)
    with pytest.raises(InvalidInputError, match="one per episode"):
        rollouts("tunnel", episodes=2, steps=1, seeds=[1], log_dir=None)
    with pytest.raises(InvalidInputError, match="backend"):
        rollouts("tunnel", episodes=1, steps=1, backend="dask", log_dir=None)
    with pytest.raises(InvalidInputError, match="workers"):
        rollouts("tunnel", episodes=1, steps=1, workers=0, log_dir=None)
    with pytest.raises(InvalidInputError, match="episodes"):
        rollouts("tunnel", episodes=0, steps=1, log_dir=None)
    with pytest.raises(InvalidInputError, match="neither an MJCF file"):
        rollouts("no_such_scene", episodes=1, steps=1, log_dir=None)
    with pytest.raises(InvalidInputError, match="log_dir"):
        rollouts("tunnel", episodes=1, steps=1, log_dir=None, gate_kwargs={"log": "x.mcap"})


def test_random_policy_is_picklable_and_seeded():
    import mujoco

    from monitor._paths import scene_path

    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    a, b = RandomPolicy(hold=2), pickle.loads(pickle.dumps(RandomPolicy(hold=2)))
    a.reset(m, 0)
    b.reset(m, 0)
    ra, rb = np.random.default_rng(3), np.random.default_rng(3)
    seq_a = [a(None, ra) for _ in range(6)]
    seq_b = [b(None, rb) for _ in range(6)]
    assert np.array_equal(seq_a, seq_b)
    assert np.array_equal(seq_a[0], seq_a[1]) and not np.array_equal(seq_a[1], seq_a[2])
    assert all(-6 <= v[0] <= 6 for v in seq_a)


def test_ray_missing_raises_dependency_error(monkeypatch):
    from monitor.distributed import require_ray

    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ImportError
    with pytest.raises(DependencyNotInstalled, match=r"pip install"):
        require_ray()
    with pytest.raises(DependencyNotInstalled, match=r"monitor\[ray\]"):
        rollouts("tunnel", episodes=1, steps=1, backend="ray", log_dir=None)


def test_monitor_rollouts_callable_after_module_import():
    import importlib

    import monitor

    importlib.import_module("monitor.rollouts")
    assert callable(monitor.rollouts) and monitor.rollouts.RandomPolicy is RandomPolicy
    s = monitor.rollouts("tunnel", episodes=1, steps=2, log_dir=None, progress=False)
    assert isinstance(s, RolloutSummary) and s.episodes[0].steps == 2
