"""Reassignable and fixed settings of :class:`monitor.Gate` (red team 4 follow-up).

A setting a user reassigns after construction either acts from the next step
(validated when assigned, like ``margin``) or raises :class:`InvalidInputError`
naming it. The settings that decide WHAT is certified and that the log records as
the run's pair policy (``model``, ``pairs``, ``allowed``, ``hazards``, ``allow``) are
fixed: the scene is built from them once and ``review --verify`` re-derives the pair
set from the logged policy, so a silent change would make either the gate or the
log untruthful. Their list values are stored as tuples, so that an in-place edit
(``gate.hazards.append(...)``) fails loudly too.
"""

from __future__ import annotations

from collections.abc import Callable
from operator import attrgetter
from typing import Any

import numpy as np

from monitor.errors import InvalidInputError


def fixed_setting(name: str, doc: str, arg: str | None = None) -> property:
    """A read-only property over ``_<name>``: assignment raises InvalidInputError naming ``name``.

    ``arg``: the constructor argument that sets it (default ``name``), named in the message.
    """
    arg = name if arg is None else arg

    def refuse(self: Any, value: Any) -> None:
        cls = type(self).__name__
        raise InvalidInputError(f"{cls}.{name} cannot be reassigned after construction ({doc}); "
                                f"construct a new {cls}({arg}=...) instead")

    full_doc = f"{doc}. Fixed at construction (assignment raises InvalidInputError)."
    return property(attrgetter("_" + name), refuse, doc=full_doc)


def checked_setting(name: str, check: Callable[[Any, Any], Any], doc: str) -> property:
    """A property over ``_<name>`` whose setter stores ``check(self, value)`` (which raises on bad input)."""
    slot = "_" + name

    def put(self: Any, value: Any) -> None:
        self.__dict__[slot] = check(self, value)

    # a C getter (attrgetter): the per-step reads cost about what a plain attribute's did
    return property(attrgetter(slot), put, doc=f"{doc} Reassignable: validated, used from the next step.")


def frozen_items(value: Any) -> Any:
    """``pairs`` / ``allowed`` / ``hazards`` / ``allow`` with lists made tuples (pairs: tuples of tuples).

    Anything else (None, a string, a Path, an ACM, an array, a bad value the scene will
    reject with its own message) is returned as it is.
    """
    if not isinstance(value, (list, tuple)):
        return value
    return tuple(tuple(v) if isinstance(v, (list, tuple)) else v for v in value)


def check_flag(name: str) -> Callable[[Any, Any], bool]:
    """Validator of a boolean setting: a bool (or numpy bool, or the integers 0 / 1)."""
    def check(_owner: Any, value: Any) -> bool:
        if isinstance(value, (bool, np.bool_)) or (isinstance(value, (int, np.integer)) and value in (0, 1)):
            return bool(value)
        raise InvalidInputError(f"{name} must be True or False, got {value!r}")
    return check


def check_choice(name: str, choices: tuple[str, ...]) -> Callable[[Any, Any], str]:
    """Validator of a setting that is one of ``choices``."""
    def check(_owner: Any, value: Any) -> str:
        if not isinstance(value, str) or value not in choices:
            raise InvalidInputError(f"{name} must be one of {choices}, got {value!r}")
        return value
    return check


def check_reference(owner: Any, value: Any) -> np.ndarray | None:
    """``Gate.reference_qpos``: None or a finite (nq,) pose, and only before the scene is first built.

    The scene's allowed-contact matrix (``allowed="auto"``) is resolved at this pose and the log
    records it; once the scene was built a new pose would change neither (a rebuilt scene, after
    ``tolerances`` is reassigned, keeps the pose the first one used).
    """
    if owner.__dict__.get("_scene_builds", 0):
        raise InvalidInputError(
            "Gate.reference_qpos cannot be reassigned once the scene is built (the first decision): "
            "allowed='auto' was resolved at the first pose and the log records it; construct a new Gate")
    if value is None:
        return None
    nq = owner.model.nq
    try:
        ref = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidInputError(f"reference_qpos must be None or a ({nq},) array, got {value!r}") from e
    if ref.shape != (nq,) or not np.isfinite(ref).all():
        raise InvalidInputError(f"reference_qpos must be None or a finite ({nq},) array, got {value!r}")
    return ref


__all__ = ["fixed_setting", "checked_setting", "frozen_items", "check_flag", "check_choice",
           "check_reference"]
