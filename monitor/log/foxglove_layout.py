"""The Foxglove layout shipped with monitor logs (``monitor/log/foxglove_layout.json``).

Built with ``foxglove.layouts`` (foxglove-sdk >= 0.30), Foxglove's own layout
builder, so the JSON follows the SDK's layout format (``version: 1``):

* left: a 3-D panel (fixed frame ``world``) showing ``/monitor/scene`` (the geoms) and
  ``/monitor/markers`` (witness markers), posed by ``/monitor/tf``;
* right, top: a Plot of ``/monitor/certificate.clearance`` (the certified lower bound,
  ``null`` = unknown, so gaps) and ``/monitor/certificate.margin``;
* right, middle: the verdict state over time (State Transitions of
  ``/monitor/certificate.verdict``: certified green, uncertain orange, violation red);
* right, bottom: the ``/monitor/log`` panel (``foxglove.Log``: violations, uncertain
  windows, blocked actions).

Caveat: the layout is generated and parsed in tests, never opened in the Foxglove app.
Regenerate with ``python -m monitor.log.foxglove_layout > monitor/log/foxglove_layout.json``.
"""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

from monitor.certify.types import Verdict
from monitor.log import topics

LAYOUT_FILE = "foxglove_layout.json"

VERDICT_COLORS = {Verdict.CERTIFIED: "#2ca02c", Verdict.UNCERTAIN: "#ff7f0e", Verdict.VIOLATION: "#d62728"}


def build_layout() -> Any:
    """The layout as a ``foxglove.layouts.Layout`` (needs foxglove-sdk)."""
    import foxglove.layouts as fl

    three_d = fl.ThreeDeePanel(title="scene and witness markers", config=fl.ThreeDeeConfig(
        follow_tf="world", fixed_frame="world",
        topics={topics.SCENE: fl.BaseRendererSceneUpdateTopicSettings(visible=True),
                topics.MARKERS: fl.BaseRendererSceneUpdateTopicSettings(visible=True)}))
    plot = fl.PlotPanel(title="clearance and margin (m)", config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=f"{topics.CERTIFICATE}.clearance", timestamp_method="receiveTime"),
               fl.PlotSeries(value=f"{topics.CERTIFICATE}.margin", timestamp_method="receiveTime")],
        show_legend=True, y_axis_label="m"))
    states = fl.StateTransitionsPanel(title="verdict", config=fl.StateTransitionsConfig(paths=[
        fl.StateTransitionsSeries(
            value=f"{topics.CERTIFICATE}.verdict", label="verdict", timestamp_method="receiveTime",
            custom_states=fl.StateTransitionsDiscreteCustomStates(states=[
                fl.StateTransitionsDiscreteCustomState(value=v, label=v, color=c)
                for v, c in VERDICT_COLORS.items()]))]))
    log = fl.LogPanel(title="violations, uncertain windows, blocked actions",
                      config=fl.LogConfig(topic_to_render=topics.LOG))
    right = fl.SplitContainer(direction="column", items=[
        fl.SplitItem(proportion=2, content=plot), fl.SplitItem(proportion=1, content=states),
        fl.SplitItem(proportion=2, content=log)])
    return fl.Layout(content=fl.SplitContainer(direction="row", items=[
        fl.SplitItem(proportion=3, content=three_d), fl.SplitItem(proportion=2, content=right)]))


def layout_json() -> str:
    """The layout JSON text (generated; needs foxglove-sdk)."""
    return json.dumps(json.loads(build_layout().to_json()), indent=1) + "\n"


def shipped_layout() -> dict[str, Any]:
    """The shipped layout file, parsed (no foxglove-sdk needed)."""
    text = resources.files("monitor.log").joinpath(LAYOUT_FILE).read_text(encoding="utf-8")
    return json.loads(text)


if __name__ == "__main__":
    print(layout_json(), end="")
