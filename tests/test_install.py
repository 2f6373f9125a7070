"""Install without surprises: a wheel build prints no setuptools warnings from this project,
declares the dependencies the code needs, and ``import monitor.envs`` registers the env ids.

The fast test builds a wheel (pip, build isolation) and greps its verbose log; the slow
test installs the project into a fresh venv with its dependencies.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
_IGNORE = shutil.ignore_patterns(".git", ".venv*", "build", "dist", "*.egg-info", "__pycache__", "logs",
                                 ".pytest_cache", ".ruff_cache", "bench_out", "*.mcap")

PROJECT_WARNING = re.compile(
    r"would be ignored|absent from the `packages`|BuildBackendWarning|SetuptoolsDeprecationWarning"
    r"|Installing '[^']+' as data is deprecated|package_data|(?i:warning).*\b(monitor|envs|models)\b")
"""Lines that are setuptools complaints about this project's configuration."""


def project_warnings(log: str) -> list[str]:
    """Lines of a pip/setuptools log that warn about this project."""
    return [ln for ln in log.splitlines() if PROJECT_WARNING.search(ln)]


def test_warning_filter_catches_the_old_warnings():
    old = ("  /tmp/x/setuptools/command/build_py.py:215: BuildBackendWarning: Package 'monitor.models.arm' "
           "is absent from the `packages` configuration.\n"
           "  WARNING: Location 'file:///opt/pypi-more/simple/wheel/' is ignored: it is neither a file nor a "
           "directory.\n  warning: build_py: byte-compiling is disabled, skipping.\n")
    assert project_warnings(old) == [old.splitlines()[0]]


def _copy(tmp: Path) -> Path:
    src = tmp / "src"
    shutil.copytree(REPO, src, ignore=_IGNORE)
    return src


@pytest.fixture(scope="module")
def wheel_build(tmp_path_factory) -> tuple[Path, str]:
    tmp = tmp_path_factory.mktemp("wheel")
    src = _copy(tmp)
    cmd = [sys.executable, "-m", "pip", "wheel", ".", "--no-deps", "-v", "-w", str(tmp / "dist")]
    r = subprocess.run(cmd, cwd=src, capture_output=True, text=True, timeout=600)
    log = r.stdout + r.stderr
    assert r.returncode == 0, log[-3000:]
    (whl,) = (tmp / "dist").glob("monitor-*.whl")
    return whl, log


def test_wheel_build_prints_no_project_warnings(wheel_build):
    _, log = wheel_build
    assert project_warnings(log) == []


def test_wheel_layout_and_dependencies(wheel_build):
    whl, _ = wheel_build
    z = zipfile.ZipFile(whl)
    names = set(z.namelist())
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith((".dist-info", ".data"))}
    assert tops == {"monitor"}  # no top-level envs/ or models/
    assert "monitor/envs/__init__.py" in names and "monitor/envs/arm_v0.py" in names
    assert "monitor/log/foxglove_layout.json" in names
    for schema in (REPO / "monitor" / "log" / "schemas").glob("*.json"):
        assert f"monitor/log/schemas/{schema.name}" in names
    for d in (REPO / "models").iterdir():
        if d.is_dir() and not d.name.startswith((".", "_")):
            assert f"monitor/models/{d.name}/scene.xml" in names, d.name
    meta = next(z.read(n).decode() for n in names if n.endswith(".dist-info/METADATA"))
    reqs = [ln.split(":", 1)[1].strip() for ln in meta.splitlines() if ln.startswith("Requires-Dist:")]
    core = [r for r in reqs if "extra ==" not in r]
    assert any(r.startswith("gymnasium[mujoco]") for r in core)
    assert not any(r.startswith("imageio") for r in reqs)
    assert not any(r.startswith("matplotlib") for r in core)  # an extra: report / bench
    assert any(r.startswith("matplotlib") and "extra == \"report\"" in r for r in reqs)
    assert any(r.startswith("trimesh") for r in core)


def test_import_monitor_envs_registers_ids_and_import_envs_is_gone(wheel_build, tmp_path):
    whl, _ = wheel_build
    target = tmp_path / "site"
    r = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(target),
                        str(whl)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert not (target / "envs").exists()  # the wheel installs no top-level envs package
    code = ("import gymnasium as gym, monitor.envs, monitor\n"
            "ids = [i for i in gym.registry if i.startswith('monitor/')]\n"
            "print(sorted(ids)); print(gym.registry['monitor/Arm-v0'].entry_point)\n"
            "print(monitor.envs.__file__)")
    env = dict(os.environ, PYTHONPATH=str(target))
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    ids, entry, where = run.stdout.strip().splitlines()
    assert ids == "['monitor/AGV-v0', 'monitor/Arm-v0', 'monitor/Tunnel-v0']"
    assert entry == "monitor.envs.arm_v0:ArmEnv"
    assert Path(where).is_relative_to(target)


@pytest.mark.slow
def test_pip_install_into_fresh_venv_is_clean(tmp_path):
    """``pip install .`` (with dependencies) into a new venv: no warnings from this project."""
    src = _copy(tmp_path)
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    py = env_dir / "bin" / "python"
    r = subprocess.run([str(py), "-m", "pip", "install", "-v", "."], cwd=src, capture_output=True, text=True,
                       timeout=1800)
    log = r.stdout + r.stderr
    assert r.returncode == 0, log[-3000:]
    assert project_warnings(log) == []
    run = subprocess.run([str(py), "-c", "import monitor.envs, monitor; print(monitor.__version__)"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
