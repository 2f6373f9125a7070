"""Ray backend: the same seeds give the same verdicts as local processes; review --ray == review --verify.

One local Ray instance (num_cpus=2) is started for the whole module. Skipped
when the optional ``ray`` extra is not installed.
"""

from __future__ import annotations

import json
import shutil

import mujoco
import numpy as np
import pytest

ray = pytest.importorskip("ray", reason="optional 'ray' extra not installed: pip install 'monitor[ray]'")

from monitor._paths import scene_path  # noqa: E402
from monitor.cli import main  # noqa: E402
from monitor.rollouts import RandomPolicy, bench_rollouts, format_bench, rollouts  # noqa: E402

pytestmark = pytest.mark.ray


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield
    if started:
        ray.shutdown()


@pytest.fixture(scope="module")
def ray_logs(tmp_path_factory):
    """8 gated tunnel episodes run as Ray tasks, one log each."""
    d = tmp_path_factory.mktemp("raylogs")
    s = rollouts("tunnel", RandomPolicy(hold=3), episodes=8, steps=6, seeds=100, backend="ray", workers=2,
                 log_dir=d, progress=False)
    return d, s


def test_rollouts_local_and_ray_identical():
    # the local reference runs in this process: local 1 == 2 workers is test_rollouts.py's
    # test_two_workers_same_verdicts (a 2-process pool here cost ~7 s of CPU for its start-up alone)
    kw = dict(episodes=4, steps=25, seeds=7, log_dir=None, progress=False)
    local = rollouts("tunnel", RandomPolicy(hold=4), workers=1, backend="local", **kw)
    assert local.workers == 1
    on_ray = rollouts("tunnel", RandomPolicy(hold=4), workers=2, backend="ray", **kw)
    assert on_ray.backend == "ray"
    assert local.counts() == on_ray.counts()
    assert [e.verdict_digest for e in local.episodes] == [e.verdict_digest for e in on_ray.episodes]
    assert sum(c[1] for c in local.counts()) > 0  # there are violations to agree on


def test_gym_env_id_on_ray_same_as_local():
    kw = dict(episodes=2, steps=6, seeds=3, log_dir=None, progress=False)
    local = rollouts("monitor/Tunnel-v0", RandomPolicy(hold=2), workers=1, **kw)
    on_ray = rollouts("monitor/Tunnel-v0", RandomPolicy(hold=2), backend="ray", workers=2, **kw)
    assert local.counts() == on_ray.counts()
    assert [e.verdict_digest for e in local.episodes] == [e.verdict_digest for e in on_ray.episodes]


def test_ray_rollouts_write_one_log_per_episode(ray_logs):
    d, s = ray_logs
    names = sorted(p.name for p in d.glob("*.mcap"))
    assert names == [f"episode-{i:04d}-seed{100 + i}.mcap" for i in range(8)]
    assert [e.episode for e in s.episodes] == list(range(8))


def _review(capsys, *argv):
    code = main(["review", "--no-progress", *map(str, argv)])
    return code, capsys.readouterr().out


def _colliding_log(path):
    """A log whose single window claims 'certified' for a plan that crosses the wall."""
    from monitor.certify.engine import certify
    from monitor.log.writer import MonitorLog
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    xml = scene_path("tunnel")
    model = mujoco.MjModel.from_xml_path(str(xml))
    scene = Scene.from_model(model)
    clear = Plan(np.array([0.0, 0.01]), np.array([[-0.3], [-0.25]]), model=model)
    crossing = Plan(np.array([0.0, 0.01]), np.array([[-0.1], [0.1]]), model=model)
    cert = certify(scene, clear)
    assert cert.verdict == "certified"
    with MonitorLog(path, model=model, metadata={"margin": 0.0, "epsilon": 1e-3, "pairs": "mujoco"},
                    model_source=str(xml)) as log:
        log.write_window(0.0, crossing, cert)


def test_review_ray_matches_serial_verify(ray_logs, tmp_path, capsys):
    d, _ = ray_logs
    logs = tmp_path / "logs"
    shutil.copytree(d, logs)
    code_serial, out_serial = _review(capsys, "--verify", logs)
    code_ray, out_ray = _review(capsys, "--ray", logs)
    assert code_serial == code_ray == 0
    assert out_ray == out_serial
    assert out_serial.count("6 re-derived, 0 mismatch(es), 0 critical, 0 without plan, 0 error(s)") == 8
    assert "total over 8 logs" in out_serial
    _, js_serial = _review(capsys, "--verify", "--json", logs)
    _, js_ray = _review(capsys, "--ray", "--json", logs)
    assert json.loads(js_serial) == json.loads(js_ray)

    _colliding_log(logs / "z-bad.mcap")  # 9th log: a certified window whose plan collides
    code_serial, out_serial = _review(capsys, "--verify", logs)
    code_ray, out_ray = _review(capsys, "--ray", logs)
    assert code_serial == code_ray == 1
    assert out_ray == out_serial
    assert "1 re-derived, 1 mismatch(es), 1 critical" in out_serial and "[CRITICAL]" in out_serial


def test_verify_logs_returns_the_serial_verify_dicts(ray_logs):
    from monitor.distributed import verify_logs
    from monitor.log.reader import read_log
    from monitor.review import verify

    d, _ = ray_logs
    paths = sorted(str(p) for p in d.glob("*.mcap"))[:3]
    got = verify_logs(paths, backend="ray")
    assert got == [verify(read_log(p)) for p in paths]
    assert [v["checked"] for v in got] == [6, 6, 6]
    assert verify_logs([str(d / "missing.mcap")], backend="ray")[0]["error"]


def test_certify_cli_ray_backend_same_certificates(tmp_path, capsys):
    t = np.linspace(0.0, 0.05, 3)
    npz = tmp_path / "p.npz"
    qpos = np.array([[[-0.3], [-0.2], [-0.1]], [[-0.1], [0.0], [0.1]], [[0.3], [0.2], [0.1]]])
    np.savez(npz, times=t, qpos=qpos)
    outs = []
    for backend in ("local", "ray"):
        code = main(["certify", str(npz), "--model", "tunnel", "--json", "--backend", backend,
                     "--no-progress"])
        assert code == 1
        outs.append([{k: v for k, v in p.items() if k not in ("certify_us", "stats")}
                     for p in json.loads(capsys.readouterr().out)["plans"]])
    assert outs[0] == outs[1]
    assert [p["verdict"] for p in outs[0]] == ["certified", "violation", "certified"]


def test_bench_rollouts_rows():
    rows = bench_rollouts("tunnel", RandomPolicy(hold=3), episodes=2, steps=5,
                          configs=(("local", 1), ("ray", 2)), repeat=2)
    assert [(r["backend"], r["workers"]) for r in rows] == [("local", 1), ("ray", 2)]
    for r in rows:
        assert r["identical"] is True
        assert r["windows"] == 10 and r["episodes_per_min"] > 0
        assert len(r["runs_s"]) == 2 and r["warm_wall_s"] == min(r["runs_s"][1:])
    assert rows[1]["ray_init_s"] == 0.0  # the module's instance was reused
    assert "| ray | 2 | 2 x 5 |" in format_bench(rows)
