"""Locate the shipped MJCF scenes, both in a source checkout and in an installed copy."""

from __future__ import annotations

from pathlib import Path


def models_dir() -> Path:
    """Folder holding ``<scene>/scene.xml``.

    The installed ``monitor.models`` package data, or the repository's top-level
    ``models/`` when running from a checkout.
    """
    try:
        import monitor.models as _m  # installed (package-dir maps models/ -> monitor.models)

        return Path(_m.__file__).resolve().parent
    except ImportError:
        return Path(__file__).resolve().parents[1] / "models"


def scene_path(name: str) -> Path:
    """Path of ``models/<name>/scene.xml``; raises FileNotFoundError naming the scene."""
    p = models_dir() / name / "scene.xml"
    if not p.is_file():
        raise FileNotFoundError(f"no scene {name!r}: expected {p}")
    return p
