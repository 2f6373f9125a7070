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
