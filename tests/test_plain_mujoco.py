"""The README's plain-MuJoCo example: 500 steps of ``Gate.step`` on models/tunnel, no gymnasium.

Independent check: the ball's x after every step, straight from MuJoCo's data.
The gate must keep the ball on its side of the wall (|x| >= wall half-width +
radius at every step state, and no change of side), while the same controller
without the gate tunnels through the wall (so the gate is not vacuous).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "plain_mujoco.py"


@pytest.fixture(scope="module")
def example():
    spec = importlib.util.spec_from_file_location("plain_mujoco_example", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_example_gates_500_steps(example, capsys):
    res = example.main(500)
    out = capsys.readouterr().out
    s = res["gated"]["summary"]
    assert s["windows"] == 500
    assert s["certified"] + s["violation"] + s["uncertain"] == 500
    assert s["replaced"] > 0 and s["certified"] > 0
    assert "500 gated steps: certified" in out and "wall crossings: gated 0" in out
    x_gated, x_free = res["gated"]["x"], res["ungated"]["x"]
    assert x_gated.shape == (500,)
    assert np.all(np.abs(x_gated) >= 0.005 + 0.01)  # never in contact at a step state
    assert np.all(x_gated < 0)  # starts at -0.32 and never gets past the wall
    assert example.crossings(x_gated) == 0
    assert example.crossings(x_free) >= 2  # MuJoCo alone tunnels through the wall


def test_example_does_not_import_gymnasium():
    import subprocess

    code = ("import runpy, sys; sys.argv = ['x', '--steps', '5']; "
            f"runpy.run_path({str(EXAMPLE)!r}, run_name='__main__'); "
            "print('gymnasium' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         cwd=EXAMPLE.parents[1], env={**__import__("os").environ,
                                                      "PYTHONPATH": str(EXAMPLE.parents[1])})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "False"
