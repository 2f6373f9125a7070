"""The trajectory protocol that both checkers and the broad phase consume.

A *trajectory* gives, for a time window, the world pose of every body at any
time and a **certified** bound on how far body points can move. Two concrete
trajectories exist: :class:`monitor.Plan` (joint waypoints, interpolated in
joint space) and :class:`monitor.BodyMotion` (explicit per-body poses).

Motion bound contract (the one thing every checker trusts):

    For body b and sub-interval [ta, tb], with m = (ta + tb) / 2 and X_WB(t)
    the body pose, for EVERY point p fixed in body b's frame (including points
    of the rigid extension of the body, i.e. anywhere in space):

        || X_WB(t) p - X_WB(m) p ||  <=  trans[b] + chord(angle[b]) * || p - ref_points[b] ||

    for all t in [ta, tb], where chord(a) = 2 sin(min(a, pi) / 2) <= a.
    ``angle[b]`` bounds the rotation angle of R_WB(t) R_WB(m)^T, and ``trans[b]``
    bounds the displacement of the reference point ``ref_points[b]`` (body frame).
    Both are rounding padded upwards.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np


def chord(angle: np.ndarray | float) -> np.ndarray:
    """Chord length 2 sin(min(a, pi)/2) of a rotation by ``angle`` (rad) at unit radius."""
    a = np.minimum(np.asarray(angle, dtype=np.float64), np.pi)
    return 2.0 * np.sin(0.5 * a)


@dataclass(frozen=True)
class MotionBounds:
    """Certified deviation bounds for N sub-intervals and all bodies.

    Attributes:
        t0: (N,) sub-interval starts (s).
        t1: (N,) sub-interval ends (s).
        trans: (N, nbody) bound (m) on the displacement of each body's reference
            point from its pose at the sub-interval midpoint.
        angle: (N, nbody) bound (rad) on the rotation angle from the midpoint pose.
    """

    t0: np.ndarray
    t1: np.ndarray
    trans: np.ndarray
    angle: np.ndarray

    def displacement(self, body: int, points_B: np.ndarray, ref_B: np.ndarray) -> np.ndarray:
        """Bound (N, n) on displacement of body-frame points (n, 3) of ``body``."""
        r = np.linalg.norm(np.asarray(points_B, float) - ref_B, axis=-1)
        return self.trans[:, body, None] + chord(self.angle[:, body])[:, None] * r[None, :]


@runtime_checkable
class Trajectory(Protocol):
    """What a checker needs from a planned motion. Times are seconds."""

    @property
    def t0(self) -> float:
        """Window start (s)."""

    @property
    def t1(self) -> float:
        """Window end (s)."""

    @property
    def nbody(self) -> int:
        """Number of bodies (MuJoCo ``model.nbody``, world included)."""

    @property
    def ref_points(self) -> np.ndarray:
        """(nbody, 3) body-frame reference point of each body used by the bounds."""

    def body_poses(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World poses at ``times`` (T,): positions (T, nbody, 3) and rotations (T, nbody, 3, 3)."""

    def motion_bounds(self, t0: np.ndarray, t1: np.ndarray) -> MotionBounds:
        """Certified bounds for sub-intervals [t0[i], t1[i]] (each within the window)."""

    def moving_bodies(self) -> np.ndarray:
        """(nbody,) bool: True where the body's pose changes anywhere in the window."""

    def translation_segments(self, body: int) -> tuple[np.ndarray, np.ndarray] | None:
        """Piecewise-constant-velocity translation of ``body``, or None.

        If the body's rotation is constant over the window and its origin moves
        linearly between breakpoints, return ``(breakpoints (k+1,) s, origins (k+1, 3) m)``:
        the world position of the body origin at each breakpoint (first = t0,
        last = t1). Static bodies return ``([t0, t1], [p, p])``. Otherwise None.
        """


def sealed(arr: np.ndarray) -> np.ndarray:
    """``arr``'s values, read-only for good: a read-only array over an immutable ``bytes`` copy.

    The waypoints a trajectory exposes (``times``, ``qpos``, ``pos``, ...) cannot be edited
    after the engine cached what it derived from them (the motion pack, the per-scene call
    memo). numpy lets an array that owns its memory turn ``WRITEABLE`` back on, and a read-only
    view's ``.base`` hands out that owner (red team 10: ``plan.qpos.base.setflags(write=True)``
    then edits the plan a memo answered for); an array over a ``bytes`` object refuses
    (``ValueError``), and so does every view of it. The copy also leaves the caller's array
    alone (its writeable flag included).

    Args:
        arr: any ndarray (the trajectory's own, just validated).

    Returns:
        a read-only C-contiguous array, same dtype, shape and values: ``arr`` itself when it is
        already one over ``bytes`` (nothing can edit it), else a copy.
    """
    base = arr
    while isinstance(base, np.ndarray):
        base = base.base
    if isinstance(base, bytes) and not arr.flags.writeable and arr.flags.c_contiguous:
        return arr
    return np.frombuffer(arr.tobytes(), dtype=arr.dtype).reshape(arr.shape)


class Sealed:
    """Mixin: a pickle / ``copy.deepcopy`` round trip keeps the sealed arrays sealed.

    Unpickled arrays are writable, so a copy of a trajectory could be edited while it still
    carries the caches derived from the original's waypoints (red team 10: a copy edited
    through a wall was certified from the copied waypoint poses). The attributes that were
    read-only arrays are :func:`sealed` again when the copy is restored.
    """

    def __getstate__(self) -> dict:
        """The instance dict and the names of its read-only array attributes."""
        state = dict(self.__dict__)
        state["_sealed_names"] = tuple(k for k, v in state.items()
                                       if isinstance(v, np.ndarray) and not v.flags.writeable)
        return state

    def __setstate__(self, state: dict) -> None:
        """Restore ``state``, sealing the arrays that were read-only in the original."""
        state = dict(state)
        for k in state.pop("_sealed_names", ()):
            state[k] = sealed(np.asarray(state[k]))
        self.__dict__.update(state)


class WindowTimes(Sealed):
    """Mixin for trajectories whose waypoint times are stored in ``self._times`` (K,) seconds."""

    _times: np.ndarray

    @property
    def times(self) -> np.ndarray:
        """(K,) waypoint times (s), read-only."""
        return self._times

    @property
    def window(self) -> tuple[float, float]:
        """(t0, t1) the time span (s)."""
        return float(self._times[0]), float(self._times[-1])

    @property
    def t0(self) -> float:
        """Window start (s)."""
        return float(self._times[0])

    @property
    def t1(self) -> float:
        """Window end (s)."""
        return float(self._times[-1])


__all__ = ["MotionBounds", "Trajectory", "WindowTimes", "chord"]
