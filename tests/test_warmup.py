"""Compilation never spends a window's default budget (monitor.warmup, ``monitor warmup``)."""

from __future__ import annotations

import subprocess
import sys
import time

import mujoco
import numpy as np

import monitor
import monitor.warmup
from monitor.certify import engine, kernels


def test_warmup_command_compiles_each_path_with_its_expected_verdict():
    r = subprocess.run([sys.executable, "-m", "monitor", "warmup"], capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    for case, verdict in (("rotating clear", "certified"), ("colliding swing", "violation"),
                          ("translating", "certified")):
        assert case in r.stdout and verdict in r.stdout.split(case)[1].splitlines()[0]
    assert "kernels ready" in r.stdout


def _slow_first_stage(monkeypatch, seconds: float) -> None:
    """Make the compiled stage's first call slow, as a cold numba compile is."""
    original = kernels.whole_shape_stage
    state = {"first": True}

    def slow(*args, **kwargs):
        if state["first"]:
            state["first"] = False
            time.sleep(seconds)
        return original(*args, **kwargs)

    monkeypatch.setattr(kernels, "whole_shape_stage", slow)


def _clear_pass():
    m = mujoco.MjModel.from_xml_string(monitor.warmup._XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    return scene, monitor.Plan([0.0, 0.1], np.array([[-1.0, 0.0, -0.5], [-0.3, 0.0, -0.5]]), m)


def test_a_slow_first_compile_does_not_make_the_default_budget_window_uncertain(monkeypatch):
    scene, plan = _clear_pass()
    monkeypatch.setattr(engine, "DEFAULT_BUDGET_SECONDS", 0.3)
    monkeypatch.setattr(monitor.warmup, "_REPORT", None)  # a fresh process: nothing compiled yet
    _slow_first_stage(monkeypatch, 0.6)
    cert = monitor.certify(scene, plan, margin=0.001)  # default budget: warm-up runs before its clock
    assert cert.verdict == "certified", cert.stats


def test_without_the_warmup_the_same_window_would_be_uncertain(monkeypatch):
    """The control: the same slow first call inside an explicit budget spends it (why warm-up exists)."""
    scene, plan = _clear_pass()
    _slow_first_stage(monkeypatch, 0.6)
    cert = monitor.certify(scene, plan, margin=0.001, budget={"seconds": 0.3})
    assert cert.verdict == "uncertain" and cert.stats["budget_exhausted"], cert.stats
