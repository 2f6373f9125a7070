"""Typed exception hierarchy for `monitor`.

Every error raised on bad input is a subclass of :class:`MonitorError`, and the
message names the offending item (index, geom, field) so that a user can act on
it without reading a traceback.
"""

from __future__ import annotations


class MonitorError(Exception):
    """Base class of every error raised by `monitor`."""


class InvalidInputError(MonitorError, ValueError):
    """An argument has the wrong shape, dtype, range or contents (NaN, inf, ...)."""


class ModelMismatchError(InvalidInputError):
    """A plan, scene or log refers to a different MuJoCo model than expected."""


class UnsupportedGeometryError(MonitorError):
    """A geom type (e.g. hfield, sdf) that the checkers cannot represent soundly."""


class LogFormatError(MonitorError):
    """An MCAP log is truncated, corrupt, not MCAP, or lacks the monitor schema."""


class LogKeyError(InvalidInputError):
    """A log signing key (or key file) is unusable: missing or unreadable file, empty, too short."""


class DependencyNotInstalled(MonitorError, ImportError):
    """An optional dependency is missing; the message names the extra to install."""


__all__ = [
    "MonitorError",
    "InvalidInputError",
    "ModelMismatchError",
    "UnsupportedGeometryError",
    "LogFormatError",
    "LogKeyError",
    "DependencyNotInstalled",
]
