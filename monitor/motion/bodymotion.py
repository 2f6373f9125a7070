r"""Explicit per-body motions: world poses at waypoints, lerp + slerp or screw per body.

:class:`BodyMotion` implements the :class:`monitor.motion.base.Trajectory`
protocol without a MuJoCo model (numpy only). Two interpolations between
consecutive waypoint poses:

* ``"lerp_slerp"`` (default): each body's origin is lerped and its orientation
  slerped (shortest arc, about the body origin).
* ``"screw"``: the SE(3) geodesic, a constant world twist (screw linear
  interpolation, :mod:`monitor.motion._screw`). The orientation is the same
  slerp; the origin follows a helix about the screw axis instead of a line.

Motion bound (derivation). For body b on [ta, tb] with midpoint m, origin x(t),
rotation R(t) and reference point r = ``ref_points[b]`` (body frame): for any
body point p,

    X(t)p - X(m)p = [x(t) - x(m)] + (R(t) - R(m)) r + (R(t) - R(m)) (p - r),

and ||(R(t) - R(m)) v|| <= chord(angle(R(t) R(m)^T)) ||v||. So with
``angle`` >= max_t angle(R(t) R(m)^T) and
``trans`` = max_t ||x(t) - x(m)|| + chord(angle) ||r|| the contract holds.
max_t ||x(t) - x(m)|| is attained at a vertex (ta, tb or a waypoint inside: a
norm of an affine function is convex on each linear piece); the angle is the
slerp path length from m on the midpoint's segment and the exact waypoint angle
plus the path length beyond it on the others
(:func:`monitor.motion._kinematics.rotation_deviation`). With the default
reference point (the body origin) both are exact up to the vertex maximum.
Rounding: the position deviation is padded by rel_pad * max|x| (a difference
of numbers of that size), the angle by rel_pad * (path length + 1) and then
both by ``Tolerances.pad``-style terms as in :mod:`monitor.motion.plan`.
A body whose pose is identical at all waypoints gets exactly zero (lerp is
``a + s (b - a)`` and slerp of equal quaternions returns them bit-exactly).

Screw motion bound (derivation). The rotation is the slerp, so ``angle`` is the
same as above. For a body point p, X(t)p - X(m)p = [X(t)r - X(m)r] + (R(t) - R(m))(p - r)
with r = ``ref_points[b]``, and the second term is at most chord(angle) ||p - r||;
so ``trans`` only has to bound the displacement of the reference point's world
image y(t) = X(t) r. On one segment (constant twist (omega, v) per unit parameter,
duration h) y moves on a helix about the screw axis and, by
:func:`monitor.motion._screw.helix_span`, for a parameter span sigma

    |y(s0 + sigma) - y(s0)| = sigma sqrt(d^2 + (sinc(|omega| sigma / 2) P)^2)
                            = sqrt((|v_par| dt)^2 + (chord(|omega| dt) dist(y, axis))^2)

exactly (dt = sigma h; axial advance and chord of the circle are orthogonal), which
grows with sigma (|omega| sigma <= pi). So on the segment holding the midpoint m the
maximum over [ta, tb] is this expression at the larger of m - ta, tb - m (clipped
to the segment). For a piece of [ta, tb] beyond an interior waypoint w (towards the
end of [ta, tb]): |y(t) - y(m)| <= |y(w) - y(m)| + helix span from w to t, with the
first term computed from the exact waypoint pose. This is the same piece structure
as the rotation bound, and it is exact when [ta, tb] holds no waypoint. In the
contract's terms (per point p, using ||p - axis|| <= ||p - r|| + dist(y(m), axis)):
this ``trans`` is at most |v_par| h_half + chord(|omega| h_half) dist(y(m), axis),
with h_half = (tb - ta) / 2 inside one segment.
Rounding: the computed twist reproduces the end waypoint up to a few ulps of
max|x| + max|v| + max|r|; the implemented curve and the computed helix constants
deviate from the ideal helix by the same order, so ``trans`` is padded by
16 rel_pad (1 + pi) (max|x| + max|v| + max|r|) and then as for lerp_slerp.
"""

from __future__ import annotations

import numpy as np

from monitor.errors import InvalidInputError
from monitor.motion import _kinematics as K
from monitor.motion import _screw as S
from monitor.motion.base import MotionBounds, WindowTimes, chord
from monitor.tolerances import DEFAULT, Tolerances


class BodyMotion(WindowTimes):
    """Explicit world poses of every body at waypoint times (Trajectory protocol).

    Args:
        times: (K,) strictly increasing times (s), K >= 2.
        pos: (K, nbody, 3) world positions of the body origins (m).
        quat: (K, nbody, 4) world orientations (w, x, y, z); normalised when
            within ``tolerances.quat_norm_tol`` of unit norm.
        ref_points: optional (nbody, 3) body-frame reference points of the
            bounds (default: the body origins). Choose them near the geometry:
            the bound grows with the distance from them.
        tolerances: rounding pads and the quaternion norm tolerance.
        interpolation: ``"lerp_slerp"`` (default: lerp of the origin, slerp of the
            orientation) or ``"screw"`` (constant twist between waypoint poses, the
            SE(3) geodesic; see the module docstring).

    Raises:
        InvalidInputError: NaN/inf, wrong shapes, non-increasing times, fewer
            than 2 waypoints, non-unit quaternions, a moving world body
            (body 0), or an unknown ``interpolation``; the message names the
            offending index or argument.
    """

    INTERPOLATIONS = ("lerp_slerp", "screw")

    def __init__(self, times: object, pos: object, quat: object, *, ref_points: object = None,
                 tolerances: Tolerances = DEFAULT, interpolation: str = "lerp_slerp"):
        if not isinstance(interpolation, str) or interpolation not in self.INTERPOLATIONS:
            raise InvalidInputError(
                f"interpolation must be one of {self.INTERPOLATIONS}, got {interpolation!r}")
        t = K.check_times(times)
        p = K.as_float_array("pos", pos)
        q = K.as_float_array("quat", quat)
        if p.ndim != 3 or p.shape[0] != t.shape[0] or p.shape[2] != 3:
            raise InvalidInputError(f"pos must have shape (K, nbody, 3) with K = {t.shape[0]}, got {p.shape}")
        nbody = p.shape[1]
        if nbody < 1:
            raise InvalidInputError("pos must hold at least the world body (nbody >= 1)")
        if q.shape != (t.shape[0], nbody, 4):
            raise InvalidInputError(f"quat must have shape ({t.shape[0]}, {nbody}, 4), got {q.shape}")
        K.check_finite("pos", p)
        K.check_finite("quat", q)
        q = K.normalize_quats("quat", q, tolerances)
        if ref_points is None:
            ref = np.zeros((nbody, 3))
        else:
            ref = K.as_float_array("ref_points", ref_points)
            if ref.shape != (nbody, 3):
                raise InvalidInputError(f"ref_points must have shape ({nbody}, 3), got {ref.shape}")
            K.check_finite("ref_points", ref)
        moved0 = np.any(p[:, 0] != p[0, 0], axis=-1) | np.any(q[:, 0] != q[0, 0], axis=-1)
        if moved0.any():
            k = int(np.argmax(moved0))
            raise InvalidInputError(f"the world body (body 0) must be constant; it moves at waypoint {k}")
        self._tol = tolerances
        self._times = t
        self._pos = p
        self._quat = q
        self._ref = ref
        for arr in (t, p, q, ref):
            arr.setflags(write=False)
        self._seg = K.Segments(t)
        self._tracks = [K.QuatTrack(q[:, b]) for b in range(nbody)]
        pos_moves = np.any(p != p[0], axis=(0, 2))
        rot_moves = np.any(q != q[0], axis=(0, 2))
        self._moving = pos_moves | rot_moves
        self._rotating = rot_moves
        self._pos_mag = float(np.max(np.abs(p), initial=0.0))
        ref_norm = np.linalg.norm(ref, axis=-1)
        self._scale = float(np.max(np.linalg.norm(p, axis=-1), initial=0.0)) + 3.0 * float(
            np.max(ref_norm, initial=0.0))
        self._interp = interpolation
        if interpolation == "screw":
            self._init_screw()

    def _init_screw(self) -> None:
        """Per segment and rotating body: twist (omega, v) per unit parameter and helix constants."""
        p, ref = self._pos, self._ref
        Km1, nbody = p.shape[0] - 1, p.shape[1]
        self._omega = np.zeros((Km1, nbody, 3))
        self._v = np.zeros((Km1, nbody, 3))
        self._hx_d = np.zeros((Km1, nbody))
        self._hx_P = np.zeros((Km1, nbody))
        self._hx_th = np.zeros((Km1, nbody))
        # world image of each body's reference point at the waypoints (K, nbody, 3)
        self._ref_W = p + np.einsum("kbij,bj->kbi", K.quat_to_mat(self._quat), ref)
        seg = np.arange(Km1)
        for b in np.flatnonzero(self._rotating):
            om = self._tracks[b].angular_velocity(seg, np.ones(Km1))
            v = S.twist_translation(om, p[:-1, b], p[1:, b])
            d, P = S.helix_speeds(om, v, self._ref_W[:-1, b])
            self._omega[:, b], self._v[:, b] = om, v
            self._hx_d[:, b], self._hx_P[:, b] = d, P
            self._hx_th[:, b] = np.linalg.norm(om, axis=-1)
        vmag = float(np.max(np.abs(self._v), initial=0.0))
        refmag = float(np.max(np.abs(ref), initial=0.0))
        self._screw_pad = 16.0 * self._tol.rel_pad * (1.0 + np.pi) * (self._pos_mag + vmag + refmag)

    def __repr__(self) -> str:
        return (f"BodyMotion(K={self._times.shape[0]}, window=({self.t0!r}, {self.t1!r}), "
                f"moving bodies={int(self._moving.sum())}/{self.nbody}, interpolation={self._interp!r})")

    @property
    def interpolation(self) -> str:
        """``"lerp_slerp"`` or ``"screw"``."""
        return self._interp

    @property
    def pos(self) -> np.ndarray:
        """(K, nbody, 3) waypoint positions (m)."""
        return self._pos

    @property
    def quat(self) -> np.ndarray:
        """(K, nbody, 4) waypoint quaternions (normalised)."""
        return self._quat

    @property
    def nbody(self) -> int:
        """Number of bodies (world included)."""
        return int(self._pos.shape[1])

    @property
    def ref_points(self) -> np.ndarray:
        """(nbody, 3) body-frame reference points of the bounds (m)."""
        return self._ref

    def _poses(self, t: np.ndarray, loc: tuple | None = None) -> tuple[np.ndarray, np.ndarray]:
        i, s, at_end = self._seg.locate(t) if loc is None else loc
        pos = K.lerp_values(self._pos, i, s, at_end)
        quat = np.stack([tr.interp(i, s, at_end) for tr in self._tracks], axis=1)
        if self._interp == "screw":
            for b in np.flatnonzero(self._rotating):
                x = S.screw_point(self._omega[i, b], self._v[i, b], s, self._pos[i, b])
                x[s == 0.0] = self._pos[i[s == 0.0], b]
                x[at_end] = self._pos[-1, b]
                pos[:, b] = x
        return pos, quat

    def body_poses(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World poses at ``times`` (T,): positions (T, nbody, 3) m, rotations (T, nbody, 3, 3)."""
        t = K.check_times_in_window(times, self.window)
        pos, quat = self._poses(t)
        return pos, K.quat_to_mat(quat)

    def motion_bounds(self, t0: np.ndarray, t1: np.ndarray) -> MotionBounds:
        """Certified bounds for sub-intervals [t0[i], t1[i]] (see module docstring).

        Args:
            t0: (N,) sub-interval starts (s), inside the window.
            t1: (N,) sub-interval ends (s), inside the window, t1 >= t0.

        Returns:
            MotionBounds with trans (N, nbody) m and angle (N, nbody) rad.
        """
        ta, tb = K.check_interval_arrays(t0, t1, self.window)
        trans = np.empty((ta.shape[0], self.nbody))
        angle = np.empty((ta.shape[0], self.nbody))
        for sl in K.interval_chunks(self._times, ta, tb, width=4):
            trans[sl], angle[sl] = self._bounds(ta[sl], tb[sl])
        return MotionBounds(t0=ta, t1=tb, trans=trans, angle=angle)

    def _bounds(self, ta: np.ndarray, tb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tol = self._tol
        N = ta.shape[0]
        trans = np.zeros((N, self.nbody))
        angle = np.zeros((N, self.nbody))
        if N and self._moving.any():
            iv = K.IntervalVertices(self._seg, ta, tb)
            xa, _ = self._poses(ta, iv.loc_a)
            xb, _ = self._poses(tb, iv.loc_b)
            xm, qm = self._poses(iv.tm, iv.loc_m)
            for b in np.flatnonzero(self._moving):
                dx = K.vector_deviation(self._pos[:, b], xa[:, b], xb[:, b], xm[:, b], iv)
                dx = dx + tol.rel_pad * self._pos_mag
                if self._rotating[b]:
                    tr = self._tracks[b]
                    qmb = qm[:, b] / np.linalg.norm(qm[:, b], axis=-1, keepdims=True)
                    th = K.rotation_deviation(tr, qmb, iv) + tol.rel_pad * (tr.cum[-1] + 1.0)
                    th = np.minimum(th * (1.0 + tol.rel_pad) + tol.abs_pad, np.pi)
                else:
                    th = np.zeros(N)
                if self._interp == "screw" and self._rotating[b]:
                    T = self._screw_ref_deviation(b, xm[:, b], qm[:, b], iv) + self._screw_pad
                else:
                    T = dx + chord(th) * np.linalg.norm(self._ref[b])
                trans[:, b] = T * (1.0 + tol.rel_pad) + tol.abs_pad + tol.scale_pad * self._scale
                angle[:, b] = th
        return trans, angle

    def _screw_ref_deviation(self, b: int, xm: np.ndarray, qm: np.ndarray,
                             iv: K.IntervalVertices) -> np.ndarray:
        """Max over t in [ta, tb] of |y(t) - y(m)| (N,) for the helix pieces (module docstring)."""
        times = self._times
        h = np.diff(times)
        Km2 = times.shape[0] - 2
        d, P, th = self._hx_d[:, b], self._hx_P[:, b], self._hx_th[:, b]
        il, ir = iv.seg_left, iv.seg_right   # the segments left / right of m (one unless m is a waypoint)
        left = np.maximum(iv.tm - iv.near_left, 0.0) / h[il]
        right = np.maximum(iv.near_right - iv.tm, 0.0) / h[ir]
        dev = np.maximum(S.helix_span(d[il], P[il], th[il], left), S.helix_span(d[ir], P[ir], th[ir], right))
        if iv.C:
            ym = xm + np.einsum("nij,j->ni", K.quat_to_mat(qm), self._ref[b])
            d_w = np.linalg.norm(self._ref_W[iv.idx, b] - ym[:, None, :], axis=-1)
            t_w = times[iv.idx]
            is_left = t_w <= iv.tm[:, None]
            k = np.clip(np.where(is_left, iv.idx - 1, iv.idx), 0, Km2)
            sigma = np.abs(iv.outer_t - t_w) / h[k]
            w = d_w + S.helix_span(d[k], P[k], th[k], sigma)
            w = np.where(iv.valid, w, 0.0)
            dev = np.maximum(dev, w.max(axis=1))
        return dev

    def screw_arrays(self) -> tuple:
        """Flat arrays of a screw motion for the compiled bounds (``fat_kernels.screw_poses_bounds``).

        (times, pos, quat, target, half, phi, cum, same, moving, rotating, omega, v, hx_d,
        hx_P, hx_th, ref, ref_W, prm) with the per-body slerp tracks stacked on axis 1 and
        prm = (rel_pad, abs_pad, scale_pad, pos_mag, scale, screw_pad). Built once.

        Raises:
            InvalidInputError: the interpolation is not ``"screw"``.
        """
        if self._interp != "screw":
            raise InvalidInputError(f"screw_arrays: interpolation is {self._interp!r}, not 'screw'")
        hit = getattr(self, "_screw_flat", None)
        if hit is None:
            tr = self._tracks
            c = np.ascontiguousarray
            tol = self._tol
            hit = (c(self._times), c(self._pos), c(self._quat),
                   c(np.stack([t.target for t in tr], axis=1)), c(np.stack([t.half for t in tr], axis=1)),
                   c(np.stack([t.phi for t in tr], axis=1)), c(np.stack([t.cum for t in tr], axis=1)),
                   c(np.stack([t.same for t in tr], axis=1)), c(self._moving), c(self._rotating),
                   c(self._omega), c(self._v), c(self._hx_d), c(self._hx_P), c(self._hx_th), c(self._ref),
                   c(self._ref_W), np.array([tol.rel_pad, tol.abs_pad, tol.scale_pad, self._pos_mag,
                                             self._scale, self._screw_pad], float))
            self._screw_flat = hit
        return hit

    def moving_bodies(self) -> np.ndarray:
        """(nbody,) bool: True where the body's waypoint poses are not all identical."""
        return self._moving.copy()

    def translation_segments(self, body: int) -> tuple[np.ndarray, np.ndarray] | None:
        """Breakpoints (k+1,) s and origins (k+1, 3) m if the body only translates, else None."""
        b = int(body)
        if not 0 <= b < self.nbody:
            raise InvalidInputError(f"body index {body} out of range [0, {self.nbody})")
        if not self._moving[b]:
            p = self._pos[0, b]
            return np.array([self.t0, self.t1]), np.stack([p, p])
        if self._rotating[b]:
            return None
        return self._times.copy(), self._pos[:, b].copy()


__all__ = ["BodyMotion"]
