"""Paths of the MJCF scenes used by the environments (source checkout or installed)."""

from __future__ import annotations

from pathlib import Path

from monitor._paths import scene_path


def scene(name: str) -> Path:
    """Path of ``models/<name>/scene.xml``; FileNotFoundError naming the scene if absent."""
    return scene_path(name)


__all__ = ["scene"]
