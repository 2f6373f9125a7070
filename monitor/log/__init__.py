"""MCAP certificate logs: writing (:class:`MonitorLog`) and crash-tolerant reading (:func:`read_log`).

Topic names and JSON schemas: :mod:`monitor.log.topics`. Foxglove 3-D review
messages: :mod:`monitor.log.foxglove_scene` (optional, needs foxglove-sdk).
Tamper evidence: :mod:`monitor.log.digest` (unkeyed seal); authenticity: :mod:`monitor.log.sign`
(HMAC-SHA256 checkpoints, ``MonitorLog(key=...)`` or ``$MONITOR_LOG_KEY_FILE``).
"""

from __future__ import annotations

from monitor.log.reader import LogContents, load_model, read_log
from monitor.log.writer import MAX_MESSAGES_PER_WINDOW, MonitorLog, default_path, export_model

__all__ = ["MonitorLog", "LogContents", "read_log", "load_model", "export_model", "default_path",
           "MAX_MESSAGES_PER_WINDOW"]
