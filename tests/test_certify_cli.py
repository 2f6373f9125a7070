"""``python -m monitor certify PLANS.npz --model scene.xml``: layouts, verdicts, logs, errors.

Scene: models/arm (3 hinge joints, posts, shelf, floor). Oracle for the verdicts:
MuJoCo's own ``mj_geomDistance`` for every candidate pair, sampled densely along
the plan (linear in joint space). A negative sampled distance means the plan
collides; a minimum sampled distance larger than the Lipschitz gap between
samples (joint speed x lever arm x half the sample spacing) means it does not.
"""

from __future__ import annotations

import io
import json
import math
import os
import signal
import tracemalloc
import zipfile
from contextlib import contextmanager
from pathlib import Path

import mujoco
import numpy as np
import pytest

from monitor._paths import scene_path
from monitor.cli import main

T = np.linspace(0.0, 0.5, 6)


def _yaw(to: float, k: int = 6) -> np.ndarray:
    q = np.zeros((k, 3))
    q[:, 0] = np.linspace(0.0, to, k)
    return q


PLANS = {
    "clear": (T, _yaw(-0.3)),                                   # swings away from every obstacle
    "post": (T, _yaw(0.7)),                                     # sweeps through post_a
    "floor": (np.linspace(0, 0.3, 4), np.array([[0, 0, 0], [0, 0.5, 0], [0, 1.0, 0], [0, 1.5, 0.0]])),
}


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_path(str(scene_path("arm")))


def _per_plan_npz(path, names):
    arrays = {}
    for i, n in enumerate(names):
        arrays[f"plan{i}_times"], arrays[f"plan{i}_qpos"] = PLANS[n]
    np.savez(path, **arrays, names=np.array(names))
    return str(path)


def _oracle(model, cert_dict, times, qpos, n=401):
    """(min sampled distance over candidate pairs, Lipschitz gap between samples)."""
    d = mujoco.MjData(model)
    ids = [(model.geom(a).id, model.geom(b).id) for a, b in (p["geoms"] for p in cert_dict["pairs"])]
    ts = np.linspace(times[0], times[-1], n)
    best = np.inf
    for t in ts:
        d.qpos[:] = [np.interp(t, times, qpos[:, j]) for j in range(model.nq)]
        mujoco.mj_kinematics(model, d)
        for a, b in ids:
            best = min(best, mujoco.mj_geomDistance(model, d, a, b, 1.0, None))
    speed = np.max(np.abs(np.diff(qpos, axis=0)) / np.diff(times)[:, None])
    lever = 1.0  # m: every arm point is within 1 m of every joint axis
    return best, speed * lever * (ts[1] - ts[0]) / 2


def _run(capsys, *argv):
    code = main(["certify", *map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_verdicts_against_dense_mujoco_distance(tmp_path, capsys, model):
    names = ["clear", "post", "floor"]
    code, out, err = _run(capsys, _per_plan_npz(tmp_path / "p.npz", names), "--model", "arm", "--json",
                          "--margin", "0.0")
    assert code == 1, err  # some plan is not certified
    res = json.loads(out)
    assert [p["name"] for p in res["plans"]] == names
    seen = set()
    for name, p in zip(names, res["plans"]):
        dist, gap = _oracle(model, p, *PLANS[name])
        if dist < 0:
            assert p["verdict"] == "violation", name
            seen.add("collides")
        elif dist > gap:
            assert p["verdict"] == "certified", (name, dist, gap)
            seen.add("clear")
    assert seen == {"collides", "clear"}  # the oracle decided both kinds
    assert res["counts"]["violation"] >= 2


def test_stacked_layout_gives_the_same_certificates(tmp_path, capsys):
    per = _per_plan_npz(tmp_path / "per.npz", ["clear", "post"])
    st = tmp_path / "st.npz"
    np.savez(st, times=T, qpos=np.stack([PLANS["clear"][1], PLANS["post"][1]]))
    _, out1, _ = _run(capsys, per, "--model", "arm", "--json")
    _, out2, _ = _run(capsys, st, "--model", str(scene_path("arm")), "--json")
    a, b = json.loads(out1)["plans"], json.loads(out2)["plans"]
    for x, y in zip(a, b):
        for k in ("verdict", "window", "clearance", "earliest_time", "witness"):
            assert x[k] == y[k]
    assert [p["name"] for p in b] == ["plan0", "plan1"]


def test_all_certified_exit_0_text_output(tmp_path, capsys):
    code, out, _ = _run(capsys, _per_plan_npz(tmp_path / "c.npz", ["clear"]), "--model", "arm")
    assert code == 0
    assert "certified 1, violation 0, uncertain 0" in out
    assert sum(" clear " in line for line in out.splitlines()) == 1


def test_log_reverifies_with_review(tmp_path, capsys):
    log = tmp_path / "plans.mcap"
    code, _, err = _run(capsys, _per_plan_npz(tmp_path / "p.npz", ["clear", "post"]), "--model", "arm",
                        "--log", log, "--margin", "0.002")
    assert code == 1 and log.stat().st_size > 0, err
    code = main(["review", "--verify", str(log)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "windows 2: certified 1, violation 1" in out
    assert "2 re-derived, 0 mismatch(es), 0 critical" in out


def test_two_local_workers_same_result(tmp_path, capsys):
    npz = _per_plan_npz(tmp_path / "p.npz", ["clear", "post"])
    _, out1, _ = _run(capsys, npz, "--model", "arm", "--json")
    _, out2, _ = _run(capsys, npz, "--model", "arm", "--json", "--workers", "2")

    def strip(out):
        drop = ("certify_us", "stats")  # wall times
        return [{k: v for k, v in p.items() if k not in drop} for p in json.loads(out)["plans"]]

    assert strip(out1) == strip(out2)


@pytest.mark.parametrize("arrays, needle", [
    ({"plan0_times": T}, "plan0_qpos is missing"),
    ({"plan0_times": T, "plan0_qpos": _yaw(0.1), "plan2_times": T, "plan2_qpos": _yaw(0.1)}, "gaps"),
    ({"plan0_times": T, "plan0_qpos": _yaw(0.1), "plan0_qpso": _yaw(0.1)}, "unknown key"),
    ({"plan0_times": T, "plan0_qpos": _yaw(0.1), "qpos": _yaw(0.1)[None]}, "mixes"),
    ({"plan0_times": T, "plan0_qpos": np.zeros((6, 4))}, "plan 'plan0'"),
    ({"times": T[:5], "qpos": _yaw(0.1)[None]}, "stacked times"),
    ({"times": T, "qpos": np.zeros(6)}, "stacked qpos"),
    ({"plan0_times": T, "plan0_qpos": _yaw(0.1), "names": np.array(["a", "b"])}, "names"),
    ({"plan0_times": T[::-1], "plan0_qpos": _yaw(0.1)}, "plan 'plan0'"),
    ({}, "no plans"),
])
def test_bad_npz_exit_2_with_message(tmp_path, capsys, arrays, needle):
    p = tmp_path / "bad.npz"
    np.savez(p, **arrays)
    code, out, err = _run(capsys, p, "--model", "arm")
    assert code == 2
    assert needle in err and "Traceback" not in err


def test_bad_files_exit_2(tmp_path, capsys):
    junk = tmp_path / "junk.npz"
    junk.write_bytes(np.random.default_rng(0).bytes(200))
    code, _, err = _run(capsys, junk, "--model", "arm")
    assert code == 2 and "not a readable .npz" in err
    ok = _per_plan_npz(tmp_path / "p.npz", ["clear"])
    code, _, err = _run(capsys, ok, "--model", "no_such_scene")
    assert code == 2 and "no such MJCF file" in err
    bad_xml = tmp_path / "bad.xml"
    bad_xml.write_text("<mujoco><worldbody><geom type='nonsense'/></worldbody></mujoco>")
    code, _, err = _run(capsys, ok, "--model", bad_xml)
    assert code == 2 and "does not load" in err
    code, _, err = _run(capsys, ok, "--model", "arm", "--epsilon", "0")
    assert code == 2 and "--epsilon" in err


# --------------------------------------------------------------------------- hostile .npz files (issue 15)


@contextmanager
def _bounded(seconds: int, mem_bytes: int):
    """Hang guard (SIGALRM) and a tracemalloc bound on Python-side allocations."""
    def boom(*_):
        raise TimeoutError(f"took longer than {seconds} s")

    old = signal.signal(signal.SIGALRM, boom)
    signal.alarm(seconds)
    tracemalloc.start()
    try:
        yield
        peak = tracemalloc.get_traced_memory()[1]
        assert peak < mem_bytes, f"peak allocation {peak / 2**20:.1f} MiB"
    finally:
        tracemalloc.stop()
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _npy_member(shape, dtype="<f8", data=b"") -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": dtype, "fortran_order": False, "shape": shape})
    return buf.getvalue() + data


def _zip(path, members: dict[str, bytes], compression=zipfile.ZIP_STORED):
    with zipfile.ZipFile(path, "w", compression=compression) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return path


def _hostile(tmp_path, kind):
    good = Path(_per_plan_npz(tmp_path / "good.npz", ["clear"]))
    raw = good.read_bytes()
    p = tmp_path / f"{kind}.npz"
    if kind == "truncated":
        p.write_bytes(raw[: len(raw) // 2])
    elif kind == "bad-crc":
        data = bytearray(raw)
        i = data.index(b"\x93NUMPY") + 130  # after the 128-byte .npy header: the first member's data
        data[i] ^= 0xFF
        p.write_bytes(bytes(data))
    elif kind == "npy":
        p = tmp_path / "plans.npy"
        np.save(p, np.zeros((6, 3)))
    elif kind == "structured":
        np.savez(p, plan0_times=np.zeros(6, dtype=[("t", "f8")]), plan0_qpos=_yaw(0.1))
    elif kind == "2e9-rows":
        _zip(p, {"plan0_times.npy": _npy_member((2_000_000_000,)),
                 "plan0_qpos.npy": _npy_member((2_000_000_000, 3))})
    elif kind == "lying-header":
        _zip(p, {"plan0_times.npy": _npy_member((6,), data=T.tobytes()[:40]),
                 "plan0_qpos.npy": _npy_member((6, 3), data=_yaw(0.1).tobytes())})
    elif kind == "20M-waypoints":  # consistent headers, deflated zeros: ~0.5 MB on disk, 640 MB of data
        n = 20_000_000
        with zipfile.ZipFile(p, "w", compression=zipfile.ZIP_DEFLATED) as z:
            for name, shape in (("plan0_times.npy", (n,)), ("plan0_qpos.npy", (n, 3))):
                with z.open(name, "w", force_zip64=True) as m:
                    m.write(_npy_member(shape))
                    block = bytes(1 << 22)
                    left = math.prod(shape) * 8
                    while left:
                        m.write(block[:min(left, len(block))])
                        left -= min(left, len(block))
    elif kind == "huge-index":
        np.savez(p, plan0_times=T, plan0_qpos=_yaw(0.1), plan999999999999_times=T,
                 plan999999999999_qpos=_yaw(0.1))
    elif kind == "leading-zero":
        np.savez(p, plan0_times=T, plan0_qpos=_yaw(0.1), plan00_times=T, plan00_qpos=_yaw(0.2))
    elif kind == "object":
        _zip(p, {"plan0_times.npy": _npy_member((6,), dtype="|O"), "plan0_qpos.npy": _npy_member((6, 3))})
    elif kind == "fifo":
        p = tmp_path / "fifo.npz"
        os.mkfifo(p)
    return p


HOSTILE = {
    "truncated": "not a readable .npz file",
    "bad-crc": "Bad CRC-32",
    "npy": "is a single .npy array, not an .npz library",
    "structured": "has dtype [('t', '<f8')]; expected integers or floats",
    "2e9-rows": "header claims shape (2000000000,) (16000000000 bytes) but the member holds 0 bytes",
    "lying-header": "header claims shape (6,) (48 bytes) but the member holds 40 bytes",
    "20M-waypoints": "has 20000000 waypoints, more than the limit 100000 per plan",
    "huge-index": "unknown key(s) ['plan999999999999_qpos', 'plan999999999999_times']",
    "leading-zero": "unknown key(s) ['plan00_qpos', 'plan00_times']",
    "object": "has dtype object; expected integers or floats",
    "fifo": "not a regular file",
}


@pytest.mark.parametrize("kind", sorted(HOSTILE))
def test_hostile_npz_one_clear_line_bounded(tmp_path, capsys, kind):
    """Each crafted file: exit 2, one 'error:' line naming the problem, no traceback, within
    20 s and 64 MiB of Python allocations (the 2e9-row header once allocated 44.7 GiB, the
    20 M-waypoint file reached 23.6 GB RSS, the huge index hung)."""
    p = _hostile(tmp_path, kind)
    with _bounded(20, 64 * 2**20):
        code, out, err = _run(capsys, p, "--model", "arm")
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert HOSTILE[kind] in lines[0] and "Traceback" not in err


def test_waypoint_limits_are_the_documented_ones():
    from monitor.commands import certify as cli

    doc = cli.__doc__
    limits = (cli.MAX_PLANS, cli.MAX_WAYPOINTS_PER_PLAN, cli.MAX_WAYPOINTS_TOTAL)
    assert limits == (100_000, 100_000, 1_000_000)
    assert "100 000 waypoints per" in doc and "1 000 000 waypoints in total" in doc


def test_text_output_keeps_the_sign_of_an_infinite_clearance(tmp_path, capsys):
    p = _per_plan_npz(tmp_path / "p.npz", ["post"])
    code, out, _ = _run(capsys, p, "--model", "arm")
    assert code == 1
    row = next(line for line in out.splitlines() if line.strip().startswith("0 "))
    assert " -inf " in row and " inf " not in row.replace("-inf", "")
