"""Topic names, schema names and JSON schemas of a monitor MCAP log (one place).

Every JSON topic has a JSON schema in ``monitor/log/schemas/<file>.json`` that is
registered exactly once per log. Foxglove topics use the protobuf schemas of
``foxglove.messages`` (registered only when foxglove-sdk is installed).

Timestamps: a message's MCAP ``log_time`` and ``publish_time`` are the simulation
time in integer nanoseconds (``sim_time_ns``); the wall clock (Unix seconds) is a
field of the JSON payload.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from typing import Any

CERTIFICATE = "/monitor/certificate"
"""Every window: verdict, window, pairs, checker, clearance, stats (full certificate)."""
VIOLATION = "/monitor/violation"
"""Every window whose verdict is "violation" or "uncertain", with its witness."""
PLAN = "/monitor/plan"
"""The plan that was certified: times (K,), qpos (K, nq), mocap poses."""
ACTION = "/monitor/action"
"""Proposed action, applied action and whether the gate replaced it."""
SCENE = "/monitor/scene"
"""foxglove.SceneUpdate: the geoms, once, in their body frames (a topic of its own so that
Foxglove's seek back-fill, which replays the last message per topic, always finds it)."""
MARKERS = "/monitor/markers"
"""foxglove.SceneUpdate: witness markers of violation / uncertain windows."""
TRANSFORMS = "/monitor/tf"
"""foxglove.FrameTransforms: world -> body poses at each window start."""

JSON_TOPICS: dict[str, tuple[str, str]] = {
    CERTIFICATE: ("monitor.Certificate", "certificate.json"),
    VIOLATION: ("monitor.Violation", "violation.json"),
    PLAN: ("monitor.Plan", "plan.json"),
    ACTION: ("monitor.Action", "action.json"),
}
"""topic -> (schema name, schema file in ``monitor/log/schemas``)."""

FOXGLOVE_TOPICS: tuple[str, ...] = (SCENE, MARKERS, TRANSFORMS)

METADATA_RUN = "monitor.run"
"""Metadata record: versions, margin, epsilon, pair policy, predictor, ... (JSON values)."""
METADATA_MODEL = "monitor.model"
"""Metadata record: attachment names and fingerprints of the logged model."""

ATTACHMENT_XML = "model.xml"
ATTACHMENT_MJB = "model.mjb"
ASSET_PREFIX = "assets/"
"""Mesh assets are attached as ``assets/<file name referenced by model.xml>``."""

LIBRARY = "monitor-log"
PROFILE = ""


@cache
def schema_text(topic: str) -> str:
    """The JSON schema (text) registered for a JSON ``topic``."""
    _, fname = JSON_TOPICS[topic]
    return resources.files("monitor.log").joinpath("schemas", fname).read_text(encoding="utf-8")


def schema(topic: str) -> dict[str, Any]:
    """The JSON schema (parsed) registered for a JSON ``topic``."""
    return json.loads(schema_text(topic))


__all__ = [
    "CERTIFICATE", "VIOLATION", "PLAN", "ACTION", "SCENE", "MARKERS", "TRANSFORMS", "JSON_TOPICS",
    "FOXGLOVE_TOPICS", "METADATA_RUN", "METADATA_MODEL", "ATTACHMENT_XML", "ATTACHMENT_MJB",
    "ASSET_PREFIX", "schema", "schema_text",
]
