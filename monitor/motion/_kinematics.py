"""Numpy helpers shared by :class:`monitor.Plan` and :class:`monitor.BodyMotion`.

Quaternions are (w, x, y, z) as in MuJoCo. Everything here is vectorised over a
leading batch axis; nothing imports MuJoCo (``bodymotion`` must stay numpy-only).

The interpolants are piecewise in time with breakpoints at the waypoint times:

* scalars and vectors: ``a + s (b - a)`` with ``s = (t - t_i) / (t_{i+1} - t_i)``,
  which returns ``a`` bit-exactly when ``a == b`` (a joint that does not move
  produces bit-identical poses, so its motion bound can be exactly zero);
* quaternions: shortest-arc slerp. On segment i the rotation turns at constant
  angular speed about a fixed axis by ``phi_i`` (rad, <= pi) in total, so the
  rotation angle between any two times of the segment is ``phi_i |s - s'|``
  (a geodesic of length <= pi in SO(3) is minimising).

At a waypoint time the stored waypoint values are returned exactly.
"""

from __future__ import annotations

import operator

import numpy as np

from monitor.errors import InvalidInputError
from monitor.tolerances import Tolerances


def check_finite(name: str, arr: np.ndarray) -> None:
    """Raise InvalidInputError naming the first non-finite entry of ``arr``."""
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InvalidInputError(f"{name} has a non-finite value (NaN or inf) at index {idx}")


def as_float_array(name: str, value: object) -> np.ndarray:
    """``np.asarray(value, float64)`` that raises InvalidInputError instead of TypeError/ValueError."""
    try:
        return np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} is not a numeric array: {exc}") from exc


def check_times(times: object) -> np.ndarray:
    """Validate waypoint times: (K,), K >= 2, finite, strictly increasing (s)."""
    t = as_float_array("times", times)
    if t.ndim != 1:
        raise InvalidInputError(f"times must have shape (K,), got {t.shape}")
    if t.shape[0] < 2:
        raise InvalidInputError(f"a plan needs at least 2 waypoints, got {t.shape[0]}")
    check_finite("times", t)
    dt = np.diff(t)
    if (dt <= 0).any():
        i = int(np.argmax(dt <= 0)) + 1
        raise InvalidInputError(
            f"times must be strictly increasing: times[{i}] = {t[i]!r} <= times[{i - 1}] = {t[i - 1]!r}"
        )
    return t


def normalize_quats(name: str, q: np.ndarray, tol: Tolerances) -> np.ndarray:
    """Normalise quaternions (..., 4) whose norm is within ``tol.quat_norm_tol`` of 1.

    Raises:
        InvalidInputError: naming the first quaternion outside the tolerance.
    """
    n = np.linalg.norm(q, axis=-1)
    bad = np.abs(n - 1.0) > tol.quat_norm_tol
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InvalidInputError(
            f"{name}: quaternion at index {idx} has norm {n[idx]!r}, not 1 within "
            f"quat_norm_tol={tol.quat_norm_tol}"
        )
    return q / n[..., None]


def quat_to_mat(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of quaternions (..., 4) (normalised first)."""
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    out = np.empty(q.shape[:-1] + (3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - w * z)
    out[..., 0, 2] = 2 * (x * z + w * y)
    out[..., 1, 0] = 2 * (x * y + w * z)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - w * x)
    out[..., 2, 0] = 2 * (x * z - w * y)
    out[..., 2, 1] = 2 * (y * z + w * x)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def norm3(v: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis of (..., 3) arrays (cheaper than ``np.linalg.norm``)."""
    return np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1] + v[..., 2] * v[..., 2])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of broadcastable (..., 3) arrays (cheaper than ``np.cross`` for small batches)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a * b of quaternions (..., 4)."""
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack([aw * bw - ax * bx - ay * by - az * bz,
                     aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw], axis=-1)


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors v (..., 3) by unit quaternions q (..., 4)."""
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * cross(u, v)
    return v + w * t + cross(u, t)


def axis_rotate(axis: np.ndarray, angle: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rodrigues rotation of v (N, 3) about the unit ``axis`` (3,) by ``angle`` (N,) rad."""
    c = np.cos(angle)[:, None]
    s = np.sin(angle)[:, None]
    return v * c + cross(axis, v) * s + (v @ axis)[:, None] * axis * (1.0 - c)


def axis_angle_mat(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) about the unit ``axis`` (3,) by ``angle`` (N,) rad (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s = np.sin(angle)[:, None, None]
    c = np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def quat_angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angle (rad, in [0, pi]) of R(a) R(b)^T for unit quaternions (..., 4).

    Uses ``4 atan2(min(|a-b|, |a+b|), max(...))``, accurate for tiny angles too.
    """
    d = np.linalg.norm(a - b, axis=-1)
    s = np.linalg.norm(a + b, axis=-1)
    return 4.0 * np.arctan2(np.minimum(d, s), np.maximum(d, s))


def finite_velocities(times: list[float], points: np.ndarray) -> bool:
    """True when every segment velocity ``(points[k+1] - points[k]) / (times[k+1] - times[k])`` is finite.

    ``times``: the K strictly increasing waypoint times (s) as Python floats; ``points`` (K, ...) finite.
    False when a difference or a quotient overflows float64: a segment a few ulp of the smallest
    normal long (1e-308 s), or coordinates near the float64 limit. The extrusion checker divides
    exactly so; an infinite velocity turns its tests into NaN, which certified such motions (red team 7).
    """
    dt_min = min(map(operator.sub, times[1:], times[:-1]))
    # in Python floats: a few numpy reductions cost ~15 us per certify call in place (tunnel window)
    m = max(map(abs, points.ravel().tolist()))
    if m <= 1e307 and m <= dt_min * 1e307:  # (the first: dt_min * 1e307 overflows to inf beyond ~18 s)
        return True   # every |difference| <= 2 max|point| <= 2e307, / min duration <= 2e307
    t = np.asarray(times, dtype=np.float64)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        d = (points[1:] - points[:-1]).reshape(t.shape[0] - 1, -1)
        v = d / (t[1:] - t[:-1])[:, None]
    return bool(np.isfinite(v).all())


class Segments:
    """Locates times on the piecewise grid ``times`` (K,)."""

    def __init__(self, times: np.ndarray):
        self.times = times
        self.K = times.shape[0]

    def locate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Segment index i (T,), local parameter s in [0, 1] (T,), and ``at_end`` mask.

        ``at_end`` marks t == times[-1], where callers return the last waypoint exactly.
        """
        i = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, self.K - 2)
        t_lo = self.times[i]
        t_hi = self.times[i + 1]
        s = np.clip((t - t_lo) / (t_hi - t_lo), 0.0, 1.0)
        at_end = t >= self.times[-1]
        return i, s, at_end


def lerp_values(values: np.ndarray, i: np.ndarray, s: np.ndarray, at_end: np.ndarray) -> np.ndarray:
    """Piecewise-linear values (T, ...) from waypoint values (K, ...)."""
    a = values[i]
    b = values[i + 1]
    shape = (-1,) + (1,) * (values.ndim - 1)
    out = a + s.reshape(shape) * (b - a)
    out[at_end] = values[-1]
    return out


class QuatTrack:
    """Shortest-arc slerp through unit waypoint quaternions (K, 4).

    Attributes:
        q: (K, 4) waypoint quaternions as given (normalised).
        target: (K-1, 4) end quaternion of each segment, sign-aligned with its start.
        half: (K-1,) angle between the 4-vectors of each segment (rad, <= pi/2).
        phi: (K-1,) rotation angle of each segment (rad, = 2 * half <= pi).
        cum: (K,) cumulative rotation path length at the waypoints (rad).
    """

    def __init__(self, q: np.ndarray):
        self.q = q
        a = q[:-1]
        b = q[1:].copy()
        flip = np.einsum("ij,ij->i", a, b) < 0
        b[flip] *= -1.0
        self.target = b
        self.half = 2.0 * np.arctan2(np.linalg.norm(b - a, axis=-1), np.linalg.norm(b + a, axis=-1))
        self.phi = 2.0 * self.half
        self.cum = np.concatenate([[0.0], np.cumsum(self.phi)])
        self.same = np.all(a == b, axis=-1)

    def interp(self, i: np.ndarray, s: np.ndarray, at_end: np.ndarray) -> np.ndarray:
        """Slerped quaternions (T, 4) on segments i at local parameters s."""
        a = self.q[i]
        b = self.target[i]
        h = self.half[i]
        den = np.sinc(h / np.pi)
        c0 = (1.0 - s) * np.sinc((1.0 - s) * h / np.pi) / den
        c1 = s * np.sinc(s * h / np.pi) / den
        out = c0[:, None] * a + c1[:, None] * b
        exact = self.same[i] | (s == 0.0)
        out[exact] = a[exact]
        out[at_end] = self.q[-1]
        return out

    def angular_velocity(self, i: np.ndarray, dt: np.ndarray) -> np.ndarray:
        """Constant angular velocity (N, 3) rad/s on segments i, in the frame the quaternions map into.

        Slerp is R(s) = Rot(a_i, s phi_i) R_i with a_i the axis of R_{i+1} R_i^T, i.e.
        a rotation about a fixed axis at constant rate phi_i / dt_i. The vector part
        of q_{i+1} q_i^* is sin(phi_i / 2) a_i; dividing by sinc keeps tiny angles exact.
        """
        d = quat_mul(self.target[i], self.q[i] * np.array([1.0, -1.0, -1.0, -1.0]))
        # ``target`` is sign-aligned with q_i, so d = (cos(phi/2), sin(phi/2) a_i) with
        # phi in [0, pi]: the vector part already has the right sign. Never re-sign it by
        # d[0]: at a half turn d[0] ~ 0 and rounding can make it negative, which would
        # reverse the angular velocity (a false negative found by the red-team tests).
        vec = d[:, 1:]
        scale = 2.0 / np.sinc(self.phi[i] / (2.0 * np.pi)) / dt
        return vec * scale[:, None]

    def path(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """Cumulative rotation path length (rad) at (segment, parameter) (T,)."""
        return self.cum[i] + s * self.phi[i]


class IntervalVertices:
    """Vertices of the piecewise interpolants inside sub-intervals [ta, tb].

    For each of N sub-intervals: the midpoint m = (ta + tb) / 2 and the waypoint
    indices strictly inside (ta, tb), gathered into a padded (N, C) array.
    """

    def __init__(self, seg: Segments, ta: np.ndarray, tb: np.ndarray):
        times = seg.times
        self.ta = ta
        self.tb = tb
        self.tm = 0.5 * (ta + tb)
        self.loc_a = seg.locate(ta)
        self.loc_b = seg.locate(tb)
        self.loc_m = seg.locate(self.tm)
        lo = np.searchsorted(times, ta, side="right")
        hi = np.searchsorted(times, tb, side="left")
        count = np.maximum(hi - lo, 0)
        C = int(count.max()) if count.size else 0
        self.C = C
        idx = lo[:, None] + np.arange(C)[None, :]
        self.valid = np.arange(C)[None, :] < count[:, None]
        self.idx = np.clip(idx, 0, seg.K - 1)
        # Outer neighbour of each interior waypoint (away from the midpoint),
        # clipped to the sub-interval: for the path-length bound of rotations.
        t_w = times[self.idx]
        left = t_w <= self.tm[:, None]
        prev_t = times[np.clip(self.idx - 1, 0, seg.K - 1)]
        next_t = times[np.clip(self.idx + 1, 0, seg.K - 1)]
        self.outer_t = np.where(left, np.maximum(prev_t, ta[:, None]), np.minimum(next_t, tb[:, None]))
        # Nearest vertex on each side of the midpoint: the waypoints strictly before / after m
        # (on a sub-interval one ulp long m rounds to tb; tb's segment would leave [ta, m] out).
        jl = np.clip(np.searchsorted(times, self.tm, side="left") - 1, 0, seg.K - 1)
        jr = np.clip(np.searchsorted(times, self.tm, side="right"), 0, seg.K - 1)
        self.near_left = np.minimum(np.maximum(times[jl], ta), self.tm)
        self.near_right = np.maximum(np.minimum(times[jr], tb), self.tm)
        self.seg_left = np.minimum(jl, seg.K - 2)                 # segment of [near_left, m]
        self.seg_right = np.clip(jr - 1, 0, seg.K - 2)            # segment of [m, near_right]
        self.seg = seg


def scalar_deviation(values: np.ndarray, va: np.ndarray, vb: np.ndarray, vm: np.ndarray,
                     iv: IntervalVertices) -> np.ndarray:
    """Max over t in [ta, tb] of |v(t) - v(m)| for piecewise-linear columns.

    Args:
        values: (K, c) waypoint values.
        va, vb, vm: (N, c) values at ta, tb and the midpoint.
        iv: the sub-intervals.

    Returns:
        (N, c). Exact (up to rounding): |v(t) - v(m)| is convex on each piece, so
        its maximum is at a vertex (ta, tb or a waypoint inside).
    """
    dev = np.maximum(np.abs(va - vm), np.abs(vb - vm))
    if iv.C:
        w = np.abs(values[iv.idx] - vm[:, None, :])
        w = np.where(iv.valid[:, :, None], w, 0.0)
        dev = np.maximum(dev, w.max(axis=1))
    return dev


def vector_deviation(values: np.ndarray, va: np.ndarray, vb: np.ndarray, vm: np.ndarray,
                     iv: IntervalVertices) -> np.ndarray:
    """Max over t in [ta, tb] of ||x(t) - x(m)|| for a piecewise-linear (K, 3) path.

    Returns:
        (N,). Exact up to rounding (norm of an affine function is convex per piece).
    """
    dev = np.maximum(np.linalg.norm(va - vm, axis=-1), np.linalg.norm(vb - vm, axis=-1))
    if iv.C:
        w = np.linalg.norm(values[iv.idx] - vm[:, None, :], axis=-1)
        w = np.where(iv.valid, w, 0.0)
        dev = np.maximum(dev, w.max(axis=1))
    return dev


def rotation_deviation(track: QuatTrack, qm: np.ndarray, iv: IntervalVertices) -> np.ndarray:
    """Bound (N,) on the rotation angle between R(t) and R(m) over t in [ta, tb].

    Pieces of the path between consecutive vertices: on the piece containing m
    the angle is exactly the path length from m (single geodesic). On a piece
    starting at an interior waypoint w (towards the sub-interval end), the
    triangle inequality gives angle(R(t), R(m)) <= angle(R(w), R(m)) + path(w, t),
    with the first term computed exactly from the quaternions. Exact when the
    sub-interval holds no waypoint.

    Args:
        track: the slerp track.
        qm: (N, 4) unit quaternions at the midpoints.
        iv: the sub-intervals.
    """
    seg = iv.seg
    s_m = track.path(iv.loc_m[0], iv.loc_m[1])
    s_l = track.path(*seg.locate(iv.near_left)[:2])
    s_r = track.path(*seg.locate(iv.near_right)[:2])
    dev = np.maximum(np.abs(s_m - s_l), np.abs(s_r - s_m))
    if iv.C:
        d_w = quat_angle(track.q[iv.idx], qm[:, None, :])
        i_o, s_o, _ = seg.locate(iv.outer_t.ravel())
        s_outer = track.path(i_o, s_o).reshape(iv.outer_t.shape)
        w = d_w + np.abs(s_outer - track.cum[iv.idx])
        w = np.where(iv.valid, w, 0.0)
        dev = np.maximum(dev, w.max(axis=1))
    return np.minimum(dev, np.pi)


def check_interval_arrays(t0: object, t1: object,
                          window: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Validate sub-interval bounds (N,) against the trajectory window."""
    a = np.atleast_1d(as_float_array("t0", t0))
    b = np.atleast_1d(as_float_array("t1", t1))
    if a.ndim != 1 or a.shape != b.shape:
        raise InvalidInputError(f"t0 and t1 must both have shape (N,), got {a.shape} and {b.shape}")
    check_finite("t0", a)
    check_finite("t1", b)
    bad = (a > b) | (a < window[0]) | (b > window[1])
    if bad.any():
        i = int(np.argmax(bad))
        raise InvalidInputError(
            f"sub-interval {i} = [{a[i]!r}, {b[i]!r}] is empty or outside the window {window}"
        )
    return a, b


def check_times_in_window(times: object, window: tuple[float, float]) -> np.ndarray:
    """Validate query times (T,) (or a scalar) inside the window; returns (T,)."""
    t = np.atleast_1d(as_float_array("times", times))
    if t.ndim != 1:
        raise InvalidInputError(f"query times must have shape (T,), got {t.shape}")
    check_finite("times", t)
    bad = (t < window[0]) | (t > window[1])
    if bad.any():
        i = int(np.argmax(bad))
        raise InvalidInputError(f"query time {i} = {t[i]!r} is outside the window {window}")
    return t


def interval_chunks(times: np.ndarray, ta: np.ndarray, tb: np.ndarray, width: int,
                    budget: int = 4_000_000) -> list[slice]:
    """Split N sub-intervals into consecutive chunks whose vertex gathers stay small.

    The gathered arrays of :class:`IntervalVertices` have N * C * width entries
    (C = most waypoints inside one sub-interval of the chunk); each chunk keeps
    that under ``budget`` (about 32 MB of float64).
    """
    n = ta.shape[0]
    count = np.maximum(np.searchsorted(times, tb, side="left") - np.searchsorted(times, ta, side="right"), 0)
    per = (count + 1) * max(int(width), 1)
    if n == 0 or int(per.max()) * n <= budget:
        return [slice(0, n)]
    out = []
    start = 0
    while start < n:
        stop = start + 1
        worst = int(per[start])
        while stop < n and max(worst, int(per[stop])) * (stop + 1 - start) <= budget:
            worst = max(worst, int(per[stop]))
            stop += 1
        out.append(slice(start, stop))
        start = stop
    return out
