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
