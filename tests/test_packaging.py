"""Packaging: the wheel ships every models/ scene (as monitor.models) and envs/ as monitor.envs,
an installed copy finds its scenes, and a source checkout finds models/ too."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SCENES = sorted(p.relative_to(REPO / "models") for p in (REPO / "models").glob("*/scene.xml"))
_IGNORE = shutil.ignore_patterns(".git", ".venv*", "build", "dist", "*.egg-info", "__pycache__", "logs",
                                 ".pytest_cache", ".ruff_cache", "bench_out", "*.mcap")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """Build a wheel from a copy of the working tree (never writes build files into the repo)."""
    tmp = tmp_path_factory.mktemp("pkg")
    src = tmp / "src"
    shutil.copytree(REPO, src, ignore=_IGNORE)
    cmd = [sys.executable, "-m", "pip", "wheel", ".", "--no-deps", "-q", "-w", str(tmp / "dist")]
    out = subprocess.run(cmd, cwd=src, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr
    (whl,) = (tmp / "dist").glob("monitor-*.whl")
    return whl


def test_wheel_contents(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    assert SCENES, "no models/*/scene.xml in the repository"
    for rel in SCENES:
        assert f"monitor/models/{rel.as_posix()}" in names
        # assets next to a scene (meshes) ship too
        for asset in (REPO / "models" / rel.parent).glob("*.stl"):
            assert f"monitor/models/{rel.parent.as_posix()}/{asset.name}" in names
    assert "monitor/envs/__init__.py" in names
    for py in (REPO / "envs").glob("*.py"):
        assert f"monitor/envs/{py.name}" in names
    assert not any(n.startswith("envs/") for n in names)  # no generic top-level package
    assert "monitor/__init__.py" in names and "monitor/scene.py" in names
    assert "monitor/geometry/polytope.py" in names


def test_installed_copy_finds_models(wheel, tmp_path):
    target = tmp_path / "site"
    out = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(target),
                          str(wheel)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    code = ("import monitor, monitor._paths as p; d = p.models_dir(); "
            "print(monitor.__file__); print(d); print(p.scene_path(sorted(x.parent.name for x in "
            "d.glob('*/scene.xml'))[0]))")
    env = dict(os.environ, PYTHONPATH=str(target))
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    mod_file, models, scene = run.stdout.strip().splitlines()
    assert Path(mod_file).is_relative_to(target)
    assert Path(models) == target / "monitor" / "models"
    assert Path(scene).is_file()
    for rel in SCENES:
        assert (Path(models) / rel).is_file()


def test_source_checkout_models_dir():
    name = SCENES[0].parent.name
    code = f"import monitor._paths as p; print(p.models_dir()); print(p.scene_path({name!r}))"
    run = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    models, scene = run.stdout.strip().splitlines()
    assert Path(models) == REPO / "models"
    assert Path(scene) == REPO / "models" / SCENES[0]
