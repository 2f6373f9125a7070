"""Compilation never spends a window's budget (numba:compile events); ``monitor warmup`` compiles ahead."""

from __future__ import annotations

import subprocess
import sys
import time

import mujoco
import numpy as np
import pytest

import monitor
import monitor.warmup
from monitor.certify import engine, kernels
from monitor.certify.common import Budget, compile_seconds


def test_warmup_command_compiles_each_path_with_its_expected_verdict():
    r = subprocess.run([sys.executable, "-m", "monitor", "warmup"], capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    for case, verdict in (("rotating clear", "certified"), ("colliding swing", "violation"),
                          ("translating", "certified")):
        assert case in r.stdout and verdict in r.stdout.split(case)[1].splitlines()[0]
    assert "kernels ready" in r.stdout


def _slow_first_stage(monkeypatch, seconds: float, compile_event: bool) -> None:
    """Make the compiled stage's first call slow, as a cold numba compile is.

    With ``compile_event`` the delay is announced as numba announces a compile (the
    ``numba:compile`` event around it); without it, it is plain work.
    """
    from numba.core import event

    original = kernels.whole_shape_stage
    state = {"first": True}

    def slow(*args, **kwargs):
        if state["first"]:
            state["first"] = False
            if compile_event:
                with event.trigger_event("numba:compile", data={"dispatcher": None, "args": (),
                                                                "return_type": None}):
                    time.sleep(seconds)
            else:
                time.sleep(seconds)
        return original(*args, **kwargs)

    monkeypatch.setattr(kernels, "whole_shape_stage", slow)
    monkeypatch.setattr(engine, "_fast_inputs", lambda scene, plan: None)  # the Python stages run


def _clear_pass():
    m = mujoco.MjModel.from_xml_string(monitor.warmup._XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    return scene, monitor.Plan([0.0, 0.1], np.array([[-1.0, 0.0, -0.5], [-0.3, 0.0, -0.5]]), m)


@pytest.mark.parametrize("budget", [None, {"seconds": 0.3}], ids=["default", "explicit"])
def test_a_slow_first_compile_does_not_spend_the_budget(monkeypatch, budget):
    scene, plan = _clear_pass()
    monkeypatch.setattr(engine, "DEFAULT_BUDGET_SECONDS", 0.3)
    _slow_first_stage(monkeypatch, 0.6, compile_event=True)
    cert = monitor.certify(scene, plan, margin=0.001, budget=budget)
    assert cert.verdict == "certified", cert.stats


def test_plain_slow_work_spends_the_budget():
    """The control: the same delay without a compile event is work, and spends a 0.3 s budget."""
    scene, plan = _clear_pass()
    mp = pytest.MonkeyPatch()
    try:
        _slow_first_stage(mp, 0.6, compile_event=False)
        cert = monitor.certify(scene, plan, margin=0.001, budget={"seconds": 0.3})
    finally:
        mp.undo()
    assert cert.verdict == "uncertain" and cert.stats["budget_exhausted"], cert.stats


def test_budget_clock_excludes_compile_seconds():
    b = Budget(seconds=1.0)
    c0 = compile_seconds()
    from numba.core import event

    with event.trigger_event("numba:compile", data={"dispatcher": None, "args": (), "return_type": None}):
        with event.trigger_event("numba:compile", data={"dispatcher": None, "args": (), "return_type": None}):
            time.sleep(0.2)  # nested events (a kernel compiling its callees) count once
        time.sleep(0.1)
    assert 0.3 <= compile_seconds() - c0 < 0.6
    assert b.elapsed() < 0.25 and not b.exhausted


_COLD_SCRIPT = """
import sys, time, mujoco, numpy as np, monitor, monitor.warmup
m = mujoco.MjModel.from_xml_string(monitor.warmup._XML)
scene = monitor.Scene.from_model(m, pairs="all")
plan = monitor.Plan([0.0, 0.1], np.array([[-1.0, 0.0, -0.5], [-0.3, 0.0, -0.5]]), m)
t = time.perf_counter()
cert = monitor.certify(scene, plan, margin=0.001, budget={"seconds": 1.0})
print("RESULT", cert.verdict, time.perf_counter() - t, cert.stats["budget_exhausted"])
"""


@pytest.mark.slow
def test_a_real_cold_compile_inside_a_one_second_budget_is_certified(tmp_path):
    """Empty numba cache: the first call compiles for many seconds, yet its 1 s budget holds."""
    import os

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    r = subprocess.run([sys.executable, "-c", _COLD_SCRIPT], capture_output=True, text=True, timeout=900,
                       env=env)
    line = [x for x in r.stdout.splitlines() if x.startswith("RESULT")]
    assert line, r.stdout + r.stderr
    _, verdict, seconds, exhausted = line[-1].split()
    assert float(seconds) > 1.0  # it did compile (this is what made the first window uncertain before)
    assert verdict == "certified" and exhausted == "False", line


# Two processes add different signatures of one cached function at the same time. The hooks force
# the interleaving that breaks numba's unlocked index update (both read the empty index, A writes
# {A: 1}, B writes {B: 1} and data file 1, A writes data file 1), unless the save lock makes B wait.
_RACE_CHILD = r"""
import os, sys, time
role, sync, cache, locked, root = sys.argv[1:6]
sys.path.insert(0, root)
os.environ["NUMBA_CACHE_DIR"] = cache
from numba import njit
from numba.core import caching
import monitor.warmup as w
if locked == "1":
    assert w.serialise_cache_saves()
other = "B" if role == "A" else "A"
def signal(name):
    open(os.path.join(sync, name), "w").close()
def have(name):
    return os.path.exists(os.path.join(sync, name))
def wait(name):
    # until `name`, or the other process has been inside save() for 1 s without getting there
    # (it waits for the lock this process holds), or 60 s
    t_end, t_seen = time.monotonic() + 60, None
    while not have(name) and time.monotonic() < t_end:
        if t_seen is None and have(other + "_entered"):
            t_seen = time.monotonic()
        if t_seen is not None and time.monotonic() - t_seen > 1.0:
            return
        time.sleep(0.005)
C = caching.IndexDataCacheFile
save, load_index, save_index, save_data = C.save, C._load_index, C._save_index, C._save_data
state = {"in_save": False}
def h_save(self, key, data):
    state["in_save"] = True
    signal(role + "_entered")
    return save(self, key, data)
def h_load_index(self):
    out = load_index(self)
    if state["in_save"]:
        signal(role + "_loaded"); wait(other + "_loaded")
    return out
def h_save_index(self, overloads):
    if role == "B":
        wait("A_index")
    save_index(self, overloads)
    if role == "A":
        signal("A_index")
def h_save_data(self, name, data):
    if role == "A":
        wait("B_data")
    save_data(self, name, data)
    if role == "B":
        signal("B_data")
C.save, C._load_index, C._save_index, C._save_data = h_save, h_load_index, h_save_index, h_save_data
sys.path.insert(0, sync)
from kernel_mod import twice
signal(role + "_ready"); wait(other + "_ready")
twice(1 if role == "A" else 1.5)
"""

_RACE_KERNEL = """from numba import njit


@njit(cache=True)
def twice(x):
    return x + x
"""


def _index_against_data(cache_dir):
    """{signature in the index: signature stored in the data file it names} of the one cached function."""
    import pickle

    from numba.core import caching

    idx = list(cache_dir.rglob("*.nbi"))
    assert len(idx) == 1, idx
    cf = caching.IndexDataCacheFile(str(idx[0].parent), idx[0].name[:-4], None)
    with open(idx[0], "rb") as f:
        pickle.load(f)              # numba version
        _, overloads = pickle.loads(f.read())
    return {str(key[0]): str(tuple(cf._load_data(name)[3].args)) for key, name in overloads.items()}


@pytest.mark.parametrize("locked", [True, False], ids=["with-save-lock", "numba-alone-control"])
def test_concurrent_cache_saves_of_two_signatures(tmp_path, monkeypatch, locked):
    """With :func:`monitor.warmup.serialise_cache_saves` each index entry names its own data file.

    The control (numba alone, same forced interleaving) shows the hazard is real: the index
    names a data file that holds the other signature's machine code.
    """
    import os
    from pathlib import Path

    sync, cache = tmp_path / "sync", tmp_path / "cache"
    sync.mkdir()
    cache.mkdir()
    (sync / "kernel_mod.py").write_text(_RACE_KERNEL)
    root = str(Path(monitor.__file__).resolve().parent.parent)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    procs = [subprocess.Popen([sys.executable, "-c", _RACE_CHILD, role, str(sync), str(cache),
                               "1" if locked else "0", root], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True) for role in ("A", "B")]
    for p in procs:
        out, _ = p.communicate(timeout=300)
        assert p.returncode == 0, out
    monkeypatch.syspath_prepend(str(sync))   # the data files pickle references to kernel_mod
    entries = _index_against_data(cache)
    if locked:
        assert entries == {"(int64,)": "(int64,)", "(float64,)": "(float64,)"}, entries
    else:
        assert entries == {"(float64,)": "(int64,)"}, entries


def test_child_processes_report_and_a_failed_child_is_not_fatal(monkeypatch):
    """The children's plumbing (their own interpreter, this sys.path, one report line each), warm cache.

    An unknown task fails in its child: reported with its error, never raised. "motion" does not
    run here, so its signal is written before the children start and "geometry" does not wait
    for it (both tasks' own steps: the in-process test below).
    """
    monkeypatch.setattr(monitor.warmup, "_CHILD_TASKS", ("geometry", "no-such-task"))
    out = monitor.warmup._run_children(2)
    assert set(out) == {"geometry", "no-such-task"}
    good = out["geometry"]
    assert good["ok"] and good["error"] == "", good
    assert good["seconds"] > 0 and good["cpu"] > 0 and good["compiled"]["functions"] >= 0
    bad = out["no-such-task"]
    assert not bad["ok"] and "unknown warm-up task" in bad["error"], bad


def test_child_tasks_give_the_expected_verdicts_and_signal_each_step(tmp_path):
    """Both child tasks in this process (kernels already loaded): each certify case's verdict, the
    pair search's, and every signal file the other task waits for."""
    w = monitor.warmup
    for name in (w._SCENE_READY, w._LP_READY):  # as if "geometry" had run: "motion" does not wait
        (tmp_path / name).touch()
    expected = {"rotating clear": "certified", "colliding swing": "violation", "translating": "certified"}
    assert w._child_task("motion", str(tmp_path)) == expected
    assert (tmp_path / w._BATCH_READY).exists()
    for name in (w._SCENE_READY, w._LP_READY):
        (tmp_path / name).unlink()
    (tmp_path / "motion-exited").touch()  # never wait for cache entries here (an unwritable cache has none)
    assert w._child_task("geometry", str(tmp_path)) == {"pair search entry": "certified"}
    signals = {w._BATCH_READY, w._SCENE_READY, w._LP_READY, "motion-exited"}
    assert {p.name for p in tmp_path.iterdir()} == signals
    assert set(w._SIGNALS) == set(w._CHILD_TASKS)
    with pytest.raises(ValueError, match="unknown warm-up task"):
        w._child_task("no-such-task")


def test_warm_up_skips_the_children_when_the_cache_is_warm_and_checks_processes():
    """The session fixture filled the cache: children would only load, so none start."""
    assert monitor.warmup._children_cached()
    rep = monitor.warmup.warm_up("auto")
    assert rep["children"] == {} and rep["total_seconds"] >= 0
    assert rep["cases"]["rotating clear"][0] == "certified"
    for bad in (-1, 1.5, "two", True):
        with pytest.raises(monitor.errors.InvalidInputError, match="processes"):
            monitor.warmup.warm_up(bad)


@pytest.mark.slow
def test_parallel_warmup_from_an_empty_cache_compiles_each_function_once(tmp_path):
    """Empty numba cache, two children: every case has its verdict, the children compile every
    kernel and this process none; a later process compiles nothing and starts no child."""
    import os

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    cmd = [sys.executable, "-m", "monitor", "warmup", "--processes", "2"]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=1800, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "child motion" in r.stdout and "child geometry" in r.stdout and "failed" not in r.stdout, r.stdout
    assert "nothing compiled in this process" in r.stdout, r.stdout
    r2 = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
    assert r2.returncode == 0 and "nothing compiled" in r2.stdout and "child" not in r2.stdout, r2.stdout
