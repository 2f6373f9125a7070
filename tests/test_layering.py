"""Layering: the algorithmic core never imports mujoco, gymnasium or mcap (docs/design.md)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FORBIDDEN = ("mujoco", "gymnasium", "mcap")

_PROBE = r"""
import importlib, importlib.util, json, pkgutil, sys
mods = ["monitor.certify", "monitor.geometry", "monitor.motion.base"]
for pkg in ("monitor.certify", "monitor.geometry"):  # every submodule, so later files are covered too
    p = importlib.import_module(pkg)
    mods += [m.name for m in pkgutil.iter_modules(p.__path__, pkg + ".")]
for extra in ("monitor.motion.metric", "monitor.motion.bodymotion"):
    if importlib.util.find_spec(extra) is not None:
        mods.append(extra)
loaded = {}
for m in mods:
    before = set(sys.modules)
    importlib.import_module(m)
    loaded[m] = sorted(set(sys.modules) - before)
print(json.dumps(loaded))
"""


def test_core_does_not_import_mujoco_gymnasium_mcap():
    out = subprocess.run([sys.executable, "-c", _PROBE], cwd=REPO, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    loaded = json.loads(out.stdout.strip().splitlines()[-1])
    assert "monitor.geometry.polytope" in loaded and "monitor.motion.base" in loaded
    culprits = {m: [x for x in new if x.split(".")[0] in FORBIDDEN] for m, new in loaded.items()}
    culprits = {m: v for m, v in culprits.items() if v}
    assert not culprits, f"modules pulling in forbidden packages: {culprits}"


def test_probe_detects_a_forbidden_import():
    """The check itself works: importing monitor.scene does load mujoco."""
    code = "import sys, monitor.scene; print('mujoco' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "True"
