r"""Rational Bézier motions (Schröcker & Weber): the R^12 curve and a public SE(3) trajectory.

* :class:`RationalBezier`: a rational Bézier curve ``c(s) = sum_k B_k(s) w_k P_k / sum_k B_k(s) w_k``
  (s in [0, 1], Bernstein basis of degree n, POSITIVE weights) whose control points P_k are
  affine maps x -> L_k x + p_k (R^12 = 9 entries of L_k row-major + 3 of p_k), stored
  homogeneously as ``H_k = (w_k, w_k P_k)`` (n+1, 13). The toleranced checker
  (:mod:`monitor.certify.bezier`) subdivides it.
* :class:`RigidBezier`: a rational motion on SE(3) from a quaternion polynomial
  Q(s) = sum_k B^m_k(s) Q_k (degree m): R(s) = M(Q(s)) / |Q(s)|^2 (M the quadratic form of the
  unit-quaternion rotation matrix) and x(s) = sum_k B^{2m}_k w_k T_k / sum_k B^{2m}_k w_k with
  w_k the Bernstein coefficients of |Q|^2 (required > 0). Degree 2m in R^12.
* :class:`BezierMotion`: the :class:`monitor.motion.base.Trajectory` of a model whose bodies
  either follow a :class:`RigidBezier` over the window (s = (t - t0) / (t1 - t0)) or stay at a
  fixed pose. Usable with :func:`monitor.certify`.

Motion bound (derivation, body b, sub-interval [ta, tb] -> parameters [sa, sb], midpoint m).
Split the curve with de Casteljau at sa and sb: the sub-curve on [sa, sb] has homogeneous
control points that are convex combinations of the original ones, so its weights stay
positive. For a body point p, X(t)p - X(m)p = [y(t) - y(m)] + (R(t) - R(m))(p - r) with
r = ``ref_points[b]`` and y(t) = X(t) r.

* ``trans``: y(s) is itself a rational Bézier curve in R^3 (numerators M_k r + w_k T_k over
  the weights w_k of degree 2m), so y(t) lies in the convex hull of the sub-curve's
  dehomogenised control points Y_k and |y(t) - y(m)| <= max_k |Y_k - y(m)|.
* ``angle``: Q(t) = sum B_k Q'_k (sub-curve quaternion control points, B_k >= 0) lies in the
  convex cone of the Q'_k. If every Q'_k makes a 4-vector angle <= alpha < pi/2 with Q(m),
  so does Q(t) (that set is a convex cone), and the rotation angle of R(t) R(m)^T is
  2 min(angle(Q(t), Q(m)), pi - angle(...)) <= 2 alpha. Otherwise ``angle`` = pi.
  Then ||(R(t) - R(m))(p - r)|| <= chord(angle) ||p - r||: the contract of
  :mod:`monitor.motion.base`. Both bounds shrink linearly with tb - ta.

Rounding: de Casteljau uses convex combinations (error <= ~ n u max|H| per split); the
evaluation of body_poses sums positive Bernstein terms. ``trans`` is padded by
4 (n + 1) rel_pad (max_k |Y_k| + |y(m)| + |r| + 1) plus the usual pads, ``angle`` by
4 (m + 1) rel_pad max|Q| / min|Q'_k| (and set to pi when that is not small).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from math import comb

import numpy as np

from monitor.errors import InvalidInputError
from monitor.motion import _kinematics as K
from monitor.motion.base import MotionBounds, Sealed, WindowTimes, sealed
from monitor.tolerances import DEFAULT, Tolerances


@dataclass(frozen=True)
class RationalBezier:
    """Rational Bézier curve in R^12 with positive weights (homogeneous control points).

    Attributes:
        H: (n+1, 13) homogeneous control points (w_k, w_k * vec(L_k), w_k * p_k).
    """

    H: np.ndarray

    def __post_init__(self) -> None:
        H = np.asarray(self.H, float)
        if H.ndim != 2 or H.shape[1] != 13 or len(H) < 2:
            raise InvalidInputError(f"H must have shape (n+1, 13) with n >= 1, got {H.shape}")
        if not np.isfinite(H).all():
            raise InvalidInputError("Bezier control points must be finite")
        if not (H[:, 0] > 0).all():
            raise InvalidInputError(f"Bezier weights must be positive, got {H[:, 0]}")

    @classmethod
    def from_affine(cls, weights: np.ndarray, L: np.ndarray, p: np.ndarray) -> RationalBezier:
        """From weights (n+1,), linear parts (n+1, 3, 3) and translations (n+1, 3)."""
        w = np.asarray(weights, float)
        X = np.concatenate([np.asarray(L, float).reshape(len(w), 9), np.asarray(p, float)], axis=1)
        return cls(np.concatenate([w[:, None], w[:, None] * X], axis=1))

    @property
    def degree(self) -> int:
        """Polynomial degree n."""
        return len(self.H) - 1

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Affine maps at parameters t (T,): L (T, 3, 3), p (T, 3)."""
        t = np.atleast_1d(np.asarray(t, float))
        h = bernstein(self.degree, t) @ self.H
        x = h[:, 1:] / h[:, :1]
        return x[:, :9].reshape(-1, 3, 3), x[:, 9:]

    def affine_points(self) -> np.ndarray:
        """(n+1, 12) control points P_k (dehomogenised)."""
        return self.H[:, 1:] / self.H[:, :1]


def bernstein(n: int, t: np.ndarray) -> np.ndarray:
    """(T, n+1) Bernstein basis of degree n at parameters t (T,)."""
    t = np.asarray(t, float)
    return np.stack([comb(n, k) * t**k * (1 - t) ** (n - k) for k in range(n + 1)], axis=-1)


def de_casteljau_half(H: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split homogeneous control points (..., n+1, d) at t = 1/2.

    Returns:
        left (..., n+1, d), right (..., n+1, d), and the curve point c(1/2) (..., d).
    """
    H = np.asarray(H, float)
    n = H.shape[-2] - 1
    left = [H[..., 0, :]]
    right = [H[..., n, :]]
    cur = H
    for _ in range(n):
        cur = 0.5 * (cur[..., :-1, :] + cur[..., 1:, :])
        left.append(cur[..., 0, :])
        right.append(cur[..., -1, :])
    return np.stack(left, axis=-2), np.stack(right[::-1], axis=-2), cur[..., 0, :]


def de_casteljau_sub(H: np.ndarray, sa: np.ndarray, sb: np.ndarray) -> np.ndarray:
    """Control points (N, n+1, d) of the sub-curves on [sa[i], sb[i]] of ONE curve H (n+1, d).

    Every step is a convex combination (0 <= sa <= sb <= 1), so positive weights stay positive.
    """
    H = np.asarray(H, float)
    n = H.shape[0] - 1
    N = sa.shape[0]

    def split(P: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tau = tau[:, None, None]
        left, right = [P[:, 0]], [P[:, n]]
        cur = P
        for _ in range(n):
            cur = (1.0 - tau) * cur[:, :-1] + tau * cur[:, 1:]
            left.append(cur[:, 0])
            right.append(cur[:, -1])
        return np.stack(left, axis=1), np.stack(right[::-1], axis=1)

    P = np.broadcast_to(H, (N,) + H.shape).copy()
    _, right = split(P, sa)                           # curve on [sa, 1]
    span = 1.0 - sa
    tau = np.where(span > 0.0, (sb - sa) / np.where(span > 0.0, span, 1.0), 0.0)
    left, _ = split(right, np.clip(tau, 0.0, 1.0))    # [sa, sb]
    return left


def bernstein_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bernstein coefficients of the product of two Bernstein polynomials (last axis = coeffs)."""
    n, m = a.shape[-1] - 1, b.shape[-1] - 1
    out = np.zeros(np.broadcast_shapes(a.shape[:-1], b.shape[:-1]) + (n + m + 1,))
    for i in range(n + 1):
        for j in range(m + 1):
            out[..., i + j] += comb(n, i) * comb(m, j) / comb(n + m, i + j) * a[..., i] * b[..., j]
    return out


def _rotation_form(Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bernstein coefficients of M(Q) (3, 3, 2m+1) and |Q|^2 (2m+1,) for Q (4, m+1)."""
    w, x, y, z = Q
    P = bernstein_product
    ww, xx, yy, zz = P(w, w), P(x, x), P(y, y), P(z, z)
    xy, xz, yz, wx, wy, wz = P(x, y), P(x, z), P(y, z), P(w, x), P(w, y), P(w, z)
    M = np.array([[ww + xx - yy - zz, 2 * (xy - wz), 2 * (xz + wy)],
                  [2 * (xy + wz), ww - xx + yy - zz, 2 * (yz - wx)],
                  [2 * (xz - wy), 2 * (yz + wx), ww - xx - yy + zz]])
    return M, ww + xx + yy + zz


class RigidBezier(Sealed):
    """Rational Bézier motion on SE(3) over s in [0, 1] (see the module docstring).

    Args:
        quat_ctrl: (m+1, 4) Bernstein coefficients (w, x, y, z) of the quaternion polynomial,
            m >= 1 (need not be unit).
        trans_ctrl: (2m+1, 3) translation control points (m) of the body origin.

    Raises:
        InvalidInputError: wrong shapes, NaN/inf, or a non-positive Bernstein coefficient of
            |Q|^2 (the weights; move the quaternion control points closer together).
    """

    def __init__(self, quat_ctrl: object, trans_ctrl: object):
        Q = K.as_float_array("quat_ctrl", quat_ctrl)
        T = K.as_float_array("trans_ctrl", trans_ctrl)
        if Q.ndim != 2 or Q.shape[1] != 4 or Q.shape[0] < 2:
            raise InvalidInputError(f"quat_ctrl must have shape (m+1, 4) with m >= 1, got {Q.shape}")
        m = Q.shape[0] - 1
        if T.shape != (2 * m + 1, 3):
            raise InvalidInputError(
                f"trans_ctrl must have shape ({2 * m + 1}, 3) for quat_ctrl of degree {m}, got {T.shape}")
        K.check_finite("quat_ctrl", Q)
        K.check_finite("trans_ctrl", T)
        M, W = _rotation_form(Q.T)
        if not (W > 0).all():
            raise InvalidInputError(
                f"quat_ctrl: the weights |Q|^2 have a non-positive Bernstein coefficient: {W}")
        Q, T, W = sealed(Q), sealed(T), sealed(W)   # read-only for good (the memos trust them)
        self._Q = Q
        self._T = T
        self._M = sealed(np.moveaxis(M, -1, 0))  # (2m+1, 3, 3)
        self._W = W

    @property
    def quat_ctrl(self) -> np.ndarray:
        """(m+1, 4) quaternion Bernstein coefficients."""
        return self._Q

    @property
    def trans_ctrl(self) -> np.ndarray:
        """(2m+1, 3) translation control points (m)."""
        return self._T

    @property
    def weights(self) -> np.ndarray:
        """(2m+1,) positive weights (Bernstein coefficients of |Q|^2)."""
        return self._W

    @property
    def degree(self) -> int:
        """Degree 2m of the motion in R^12."""
        return 2 * (self._Q.shape[0] - 1)

    def curve(self) -> RationalBezier:
        """The motion as a :class:`RationalBezier` in R^12 (for ``monitor.certify.bezier.check_bezier``)."""
        W = self._W
        H = np.concatenate([W[:, None], self._M.reshape(-1, 9), W[:, None] * self._T], axis=1)
        return RationalBezier(H)

    def ref_curve(self, r_B: np.ndarray) -> np.ndarray:
        """(2m+1, 4) homogeneous control points (w_k, M_k r + w_k T_k) of y(s) = X(s) r."""
        num = np.einsum("kij,j->ki", self._M, np.asarray(r_B, float)) + self._W[:, None] * self._T
        return np.concatenate([self._W[:, None], num], axis=1)

    def poses(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Origins (T, 3) m and unit quaternions (T, 4) at parameters s (T,) in [0, 1]."""
        s = np.asarray(s, float)
        m = self._Q.shape[0] - 1
        q = bernstein(m, s) @ self._Q
        q = q / np.linalg.norm(q, axis=-1, keepdims=True)
        B2 = bernstein(2 * m, s) * self._W
        x = (B2 @ self._T) / B2.sum(axis=-1, keepdims=True)
        return x, q


def quaternion_motion(quat_ctrl: np.ndarray, trans_ctrl: np.ndarray) -> RationalBezier:
    """Degree-2m rational motion in R^12 from a degree-m quaternion polynomial (see :class:`RigidBezier`).

    Args:
        quat_ctrl: (m+1, 4) quaternion Bernstein coefficients.
        trans_ctrl: (2m+1, 3) translation control points (m).
    """
    return RigidBezier(quat_ctrl, trans_ctrl).curve()


class BezierMotion(WindowTimes):
    """Bodies following rational Bézier motions over one window (Trajectory protocol).

    Args:
        window: (t0, t1) seconds, t0 < t1; s = (t - t0) / (t1 - t0).
        pos: (nbody, 3) world positions of the bodies that do not move (m); rows of moving
            bodies are ignored.
        quat: (nbody, 4) their world orientations (w, x, y, z), unit within tolerance.
        motions: {body index >= 1: RigidBezier} world pose of those bodies over the window.
        ref_points: optional (nbody, 3) body-frame reference points of the bounds.
        tolerances: rounding pads.

    Raises:
        InvalidInputError: bad window, shapes, body indices (the world body 0 cannot move),
            or a motion that is not a :class:`RigidBezier`.
    """

    def __init__(self, window: object, pos: object, quat: object, motions: Mapping[int, RigidBezier], *,
                 ref_points: object = None, tolerances: Tolerances = DEFAULT):
        t = K.check_times(window)
        if t.shape[0] != 2:
            raise InvalidInputError(f"window must be (t0, t1), got {t.shape[0]} values")
        p = K.as_float_array("pos", pos)
        q = K.as_float_array("quat", quat)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 1:
            raise InvalidInputError(f"pos must have shape (nbody, 3), got {p.shape}")
        nbody = p.shape[0]
        if q.shape != (nbody, 4):
            raise InvalidInputError(f"quat must have shape ({nbody}, 4), got {q.shape}")
        K.check_finite("pos", p)
        K.check_finite("quat", q)
        q = K.normalize_quats("quat", q[None], tolerances)[0]
        if not isinstance(motions, Mapping):
            raise InvalidInputError(
                f"motions must be a mapping body -> RigidBezier, got {type(motions).__name__}")
        mot: dict[int, RigidBezier] = {}
        for b, rb in motions.items():
            if isinstance(b, bool) or not isinstance(b, (int, np.integer)) or not 1 <= int(b) < nbody:
                raise InvalidInputError(f"motions: body index {b!r} must be an int in [1, {nbody})")
            if not isinstance(rb, RigidBezier):
                raise InvalidInputError(f"motions[{b}] must be a RigidBezier, got {type(rb).__name__}")
            mot[int(b)] = rb
        if ref_points is None:
            ref = np.zeros((nbody, 3))
        else:
            ref = K.as_float_array("ref_points", ref_points)
            if ref.shape != (nbody, 3):
                raise InvalidInputError(f"ref_points must have shape ({nbody}, 3), got {ref.shape}")
            K.check_finite("ref_points", ref)
        t, p, q, ref = (sealed(a) for a in (t, p, q, ref))  # read-only for good (the memos trust them)
        self._times = t
        self._pos = p
        self._quat = q
        self._ref = ref
        self._motions = mot
        self._tol = tolerances
        self._refH = {b: rb.ref_curve(ref[b]) for b, rb in mot.items()}
        self._moving = np.zeros(nbody, bool)
        self._moving[list(mot)] = True
        self._rot0 = K.quat_to_mat(q)

    def __repr__(self) -> str:
        return f"BezierMotion(window=({self.t0!r}, {self.t1!r}), moving bodies={sorted(self._motions)})"

    @property
    def nbody(self) -> int:
        """Number of bodies (world included)."""
        return int(self._pos.shape[0])

    @property
    def ref_points(self) -> np.ndarray:
        """(nbody, 3) body-frame reference points of the bounds (m)."""
        return self._ref

    @property
    def motions(self) -> dict[int, RigidBezier]:
        """{body: RigidBezier} (a copy of the mapping)."""
        return dict(self._motions)

    def _param(self, t: np.ndarray) -> np.ndarray:
        t0, t1 = self.window
        return np.clip((t - t0) / (t1 - t0), 0.0, 1.0)

    def body_poses(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World poses at ``times`` (T,): positions (T, nbody, 3) m, rotations (T, nbody, 3, 3)."""
        t = K.check_times_in_window(times, self.window)
        T = t.shape[0]
        pos = np.broadcast_to(self._pos, (T,) + self._pos.shape).copy()
        rot = np.broadcast_to(self._rot0, (T,) + self._rot0.shape).copy()
        s = self._param(t)
        for b, rb in self._motions.items():
            x, q = rb.poses(s)
            pos[:, b] = x
            rot[:, b] = K.quat_to_mat(q)
        return pos, rot

    def motion_bounds(self, t0: np.ndarray, t1: np.ndarray) -> MotionBounds:
        """Certified bounds for sub-intervals [t0[i], t1[i]] (see the module docstring).

        Returns:
            MotionBounds with trans (N, nbody) m and angle (N, nbody) rad.
        """
        ta, tb = K.check_interval_arrays(t0, t1, self.window)
        N = ta.shape[0]
        trans = np.zeros((N, self.nbody))
        angle = np.zeros((N, self.nbody))
        if N:
            sa, sb = self._param(ta), self._param(tb)
            sm = self._param(0.5 * (ta + tb))
            tol = self._tol
            for b, rb in self._motions.items():
                trans[:, b], angle[:, b] = self._body_bounds(b, rb, sa, sb, sm, tol)
        return MotionBounds(t0=ta, t1=tb, trans=trans, angle=angle)

    def _body_bounds(self, b: int, rb: RigidBezier, sa: np.ndarray, sb: np.ndarray, sm: np.ndarray,
                     tol: Tolerances) -> tuple[np.ndarray, np.ndarray]:
        r = self._ref[b]
        xm, qm = rb.poses(sm)
        ym = xm + np.einsum("nij,j->ni", K.quat_to_mat(qm), r)
        # translation of the reference point: convex hull of the sub-curve's control points
        Hs = de_casteljau_sub(self._refH[b], sa, sb)                 # (N, 2m+1, 4)
        Y = Hs[..., 1:] / Hs[..., :1]
        dev = np.linalg.norm(Y - ym[:, None, :], axis=-1).max(axis=1)
        n = rb.degree
        mag = np.abs(Y).max(axis=(1, 2)) + np.abs(ym).max(axis=1) + float(np.abs(r).max()) + 1.0
        trans = (dev + 4.0 * (n + 1) * tol.rel_pad * mag) * (1.0 + tol.rel_pad) + tol.abs_pad
        # rotation: cone of the sub-curve's quaternion control points
        Qs = de_casteljau_sub(rb.quat_ctrl, sa, sb)                    # (N, m+1, 4)
        nq = np.linalg.norm(Qs, axis=-1)
        safe = np.where(nq > 0.0, nq, 1.0)[..., None]
        u = Qs / safe
        half = 2.0 * np.arctan2(np.linalg.norm(u - qm[:, None, :], axis=-1),
                                np.linalg.norm(u + qm[:, None, :], axis=-1))   # 4-vector angles
        alpha = half.max(axis=1)
        qmag = float(np.abs(rb.quat_ctrl).max())
        err = 4.0 * (n + 1) * tol.rel_pad * qmag / np.maximum(nq.min(axis=1), 1e-300) + tol.abs_pad
        alpha = alpha * (1.0 + tol.rel_pad) + err
        ang = np.where((alpha < 0.5 * np.pi) & (nq.min(axis=1) > 0.0), 2.0 * alpha, np.pi)
        return trans, np.minimum(ang, np.pi)

    def moving_bodies(self) -> np.ndarray:
        """(nbody,) bool: True for the bodies that follow a motion."""
        return self._moving.copy()

    def translation_segments(self, body: int) -> tuple[np.ndarray, np.ndarray] | None:
        """Static bodies: ([t0, t1], [p, p]); bodies following a motion: None."""
        b = int(body)
        if not 0 <= b < self.nbody:
            raise InvalidInputError(f"body index {body} out of range [0, {self.nbody})")
        if self._moving[b]:
            return None
        p = self._pos[b]
        return np.array([self.t0, self.t1]), np.stack([p, p])


__all__ = ["BezierMotion", "RationalBezier", "RigidBezier", "bernstein", "bernstein_product",
           "de_casteljau_half", "de_casteljau_sub", "quaternion_motion"]
