"""The shipped Foxglove layout: parses, has the promised panels, and points at real topics and fields."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from monitor.log import read_log, topics
from monitor.log.foxglove_layout import LAYOUT_FILE, VERDICT_COLORS, shipped_layout

REPO = Path(__file__).resolve().parents[1]


def _panels(node):
    if node.get("type") == "panel":
        yield node
    for item in node.get("items", []):
        yield from _panels(item["content"])


def test_shipped_layout_parses_and_has_the_panels():
    lay = shipped_layout()
    assert lay["version"] == 1
    panels = {p["panelType"]: p for p in _panels(lay["content"])}
    assert set(panels) == {"ThreeDee", "Plot", "StateTransitions", "Log"}
    assert panels["Log"]["config"]["topicToRender"] == topics.LOG
    three = panels["ThreeDee"]["config"]
    assert three["fixedFrame"] == "world"
    assert {topics.SCENE, topics.MARKERS} <= set(three["topics"])
    plot = [s["value"] for s in panels["Plot"]["config"]["paths"]]
    assert plot == [f"{topics.CERTIFICATE}.clearance", f"{topics.CERTIFICATE}.margin"]
    (series,) = panels["StateTransitions"]["config"]["paths"]
    assert series["value"] == f"{topics.CERTIFICATE}.verdict"
    assert {s["value"] for s in series["customStates"]["states"]} == set(VERDICT_COLORS)


def test_layout_fields_exist_in_schema_and_in_a_log(tmp_path):
    """Every topic.field the layout plots is in the JSON schema and in real payloads."""
    from test_log_format import write_two_episodes

    lay = shipped_layout()
    refs = []
    for p in _panels(lay["content"]):
        for s in p["config"].get("paths", []):
            topic, fld = s["value"].rsplit(".", 1)
            refs.append((topic, fld))
        refs += [(t, None) for t in p["config"].get("topics", {})]
        if p["config"].get("topicToRender"):
            refs.append((p["config"]["topicToRender"], None))
    path = tmp_path / "l.mcap"
    write_two_episodes(path)
    c = read_log(path)
    for topic, fld in refs:
        assert c.counts.get(topic, 0) > 0, topic
        if fld is not None:
            assert fld in topics.schema(topic)["properties"], (topic, fld)
            assert all(fld in m for m in c.topic(topic))
    assert (topics.LOG, None) in refs


def test_shipped_file_is_the_generated_layout():
    pytest.importorskip("foxglove.layouts")
    from monitor.log.foxglove_layout import layout_json

    shipped = (REPO / "monitor" / "log" / LAYOUT_FILE).read_text(encoding="utf-8")
    assert json.loads(shipped) == json.loads(layout_json())
