"""Shared test fixtures (keep small)."""

from __future__ import annotations

from pathlib import Path

import pytest

ASSETS = Path(__file__).resolve().parent / "assets"
"""Folder of the test MJCF scenes (tests/assets/*.xml)."""


@pytest.fixture
def load_asset():
    """Return a loader ``name -> mujoco.MjModel`` for tests/assets/<name> (a fresh model per call)."""
    import mujoco

    def _load(name: str):
        return mujoco.MjModel.from_xml_path(str(ASSETS / name))

    return _load


def pytest_collection_modifyitems(config, items):
    """Skip ``@pytest.mark.slow`` tests unless a ``-m`` expression selects markers explicitly.

    ``pytest tests`` then stays CI-sized; ``pytest -m slow`` runs the sweeps.
    """
    if config.getoption("-m"):
        return
    skip = pytest.mark.skip(reason="slow sweep: run with -m slow (or python -m monitor bench)")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
