"""Topic names, schema names and JSON schemas of a monitor MCAP log (one place).

Every JSON topic has a JSON schema in ``monitor/log/schemas/<file>.json`` that is
registered exactly once per log. Foxglove topics use the protobuf schemas of
``foxglove.messages`` (registered only when foxglove-sdk is installed).

Timestamps (format version 2, :data:`FORMAT_VERSION`):

* ``log_time`` is the **wall clock** (Unix ns) of the window, strictly increasing through
  the file (a window whose clock reading is not later than the previous window's gets
  the previous value + 1 ns). All messages of one window share it. Foxglove plays the
  file on this clock, so two episodes never interleave.
* ``publish_time`` is the **simulation time** (ns) of the window start within its
  episode (``round(sim_time * 1e9)``); it restarts at each episode.
* Every JSON payload carries ``index`` (window, 0-based, over the whole file),
  ``episode`` (0-based; the writer starts a new episode whenever ``sim_time`` goes
  back, e.g. after ``env.reset()``, or on :meth:`MonitorLog.new_episode`), ``sim_time``
  (s) and ``wall_time`` (Unix s).
* Foxglove ``timestamp`` fields (scene, transforms, markers, log) equal ``log_time``.

Unknown values are JSON ``null`` (never a huge finite number): a clearance of ``null``
means "no lower bound known" (read back as -inf).

Version 1 logs (written before this change) used sim time for ``log_time`` and
``publish_time``, had no ``episode`` field and stored metadata values as JSON text.
Version 3 adds the plan payload's ``source`` and ``rollout`` (:data:`ROLLOUTS_KEY`); a version 2
log reads as before (review notes that its rows cannot be re-simulated).
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
LOG = "/monitor/log"
"""foxglove.Log (JSON encoding, no foxglove-sdk needed): one line per violation, uncertain
window or blocked (replaced) action; level error for violations, warning otherwise."""

SIGNATURE = "/monitor/signature"
"""Signed checkpoints (:mod:`monitor.log.sign`; only in a log written with a key): one when the log
opens, one after every window and a final one at close, each an HMAC-SHA256 over every record
before it. Not a :data:`JSON_TOPICS` entry: registered (schema ``monitor.Signature``) only when signing."""
SIGNATURE_SCHEMA = ("monitor.Signature", "signature.json")

FORMAT_VERSION = 3
"""Stored as ``format_version`` in the ``monitor.run`` metadata (absent = version 1)."""

JSON_TOPICS: dict[str, tuple[str, str]] = {
    CERTIFICATE: ("monitor.Certificate", "certificate.json"),
    VIOLATION: ("monitor.Violation", "violation.json"),
    PLAN: ("monitor.Plan", "plan.json"),
    ACTION: ("monitor.Action", "action.json"),
    LOG: ("foxglove.Log", "foxglove_log.json"),
}
"""topic -> (schema name, schema file in ``monitor/log/schemas``)."""

FOXGLOVE_TOPICS: tuple[str, ...] = (SCENE, MARKERS, TRANSFORMS)

METADATA_RUN = "monitor.run"
"""Metadata record: versions, margin, epsilon, pair policy, predictor, ... (JSON values)."""
METADATA_MODEL = "monitor.model"
"""Metadata record: attachment names and fingerprints of the logged model."""
METADATA_FINALISE = "monitor.finalise"
"""Metadata record added when a journal is rewritten into an indexed file (source, bytes dropped)."""
METADATA_REQUEST = "monitor.request"
"""Metadata record, one per distinct :class:`~monitor.certify.request.CertifyRequest` a log's
certificates answer (``{"id": int, "request": CertifyRequest.to_json() with window None}``),
written before the first certificate that names it; each certificate payload carries
``"request_id"``. Id 0 may instead be the ``monitor.run`` record's ``"request"`` (a gate logs its
request at open): then no ``monitor.request`` record repeats it."""
METADATA_MODEL_EDIT = "monitor.model_edit"
"""Metadata record, one per in-place model edit a gate saw during the run (domain randomisation,
tuning), written before the first window certified on the edited model:
``{"window": i, "fields": {name: {"shape": [...], "values": [...]}}, "disableflags": int}`` with
``i`` the index of that window and, for every :data:`monitor.scene.SYNC_FIELDS` array (everything a
certificate depends on) that differs from the model as last attached or recorded, its full new
value (row-major). ``review --verify`` applies the records in order to the attached model, so each
window is re-derived on the model as it was certified. A gate writes ``"model_edits": "logged"``
(:data:`MODEL_EDITS_KEY`) in the run metadata. Format 3 (a gate that logs rollouts,
:data:`ROLLOUTS_KEY`): the records also hold every other changed array a re-simulation depends on
(:func:`monitor.log.replay.model_fields`: masses, gains, damping, ...) and, under ``"options"``
(``{name: value}``), every changed ``model.opt`` field but ``disableflags``."""
MODEL_EDITS_KEY = "model_edits"
"""``monitor.run`` key a gate writes (value ``"logged"``): every in-place model edit the gate certified
on is in a :data:`METADATA_MODEL_EDIT` record."""
APPLIED_MOTIONS_KEY = "applied_motions"
"""``monitor.run`` key a gate writes (value ``"logged"``) when every replaced action of its log names
the record of the motion actually applied: the action payload's ``applied_window`` is the index of a
window whose certificate payload has ``"applied": {"kind": "fallback" | "brake_tail", "covered_by": i}``
(a certified or uncertified fallback: its own window, ``covered_by`` = itself; the committed brake:
the braking tail's plan and certificate, written once per committed tail, ``covered_by`` = the
accepted window certified with it). Logs without the key (older gates) log the applied motion only
when it is not certified."""
ROLLOUTS_KEY = "rollouts"
"""``monitor.run`` key a gate writes (value ``"logged"``): every plan payload of its windows says
where its rows come from, ``"source": "rollout" | "user"``, and a ``"rollout"`` plan (the gate's
own MuJoCo rollout: proposals, fallbacks, braking tails) carries the integration state it started
from and the control of every substep, from which ``review --verify`` re-simulates its rows bit
for bit on the attached model (:mod:`monitor.log.replay`). A plan of such a log without
``source`` was stripped of it."""
METADATA_JSON_KEYS = "_json_keys"
"""Metadata key (version 2) listing, comma-separated, the keys whose values are JSON text;
every other value is a plain string stored as is (no JSON inside JSON)."""

ATTACHMENT_XML = "model.xml"
ATTACHMENT_MJB = "model.mjb"
ASSET_PREFIX = "assets/"
"""Mesh assets are attached as ``assets/<file name referenced by model.xml>``."""

LIBRARY = "monitor-log"
PROFILE = ""


@cache
def schema_text(topic: str) -> str:
    """The JSON schema (text) registered for a JSON ``topic``."""
    _, fname = SIGNATURE_SCHEMA if topic == SIGNATURE else JSON_TOPICS[topic]
    return resources.files("monitor.log").joinpath("schemas", fname).read_text(encoding="utf-8")


def schema(topic: str) -> dict[str, Any]:
    """The JSON schema (parsed) registered for a JSON ``topic``."""
    return json.loads(schema_text(topic))


__all__ = [
    "CERTIFICATE", "VIOLATION", "PLAN", "ACTION", "SCENE", "MARKERS", "TRANSFORMS", "LOG", "JSON_TOPICS",
    "SIGNATURE", "FORMAT_VERSION", "APPLIED_MOTIONS_KEY", "ROLLOUTS_KEY",
    "METADATA_MODEL_EDIT", "MODEL_EDITS_KEY", "METADATA_FINALISE", "METADATA_JSON_KEYS", "METADATA_REQUEST",
    "FOXGLOVE_TOPICS", "METADATA_RUN", "METADATA_MODEL", "ATTACHMENT_XML", "ATTACHMENT_MJB",
    "ASSET_PREFIX", "schema", "schema_text",
]
