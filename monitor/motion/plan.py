r"""Joint-space plans: waypoints interpolated in joint space, poses by MuJoCo FK.

:class:`Plan` implements the :class:`monitor.motion.base.Trajectory` protocol for
a MuJoCo model and joint waypoints ``qpos`` (K, nq) at ``times`` (K,).

Interpolation (piecewise in time, breakpoints at the waypoints):
hinge and slide coordinates are lerped; a free joint lerps its position and
slerps its quaternion (shortest arc, about the body origin); a ball joint slerps
(shortest arc). Mocap bodies hold ``mocap_pos/mocap_quat`` over the window.

Poses come from ``mujoco.mj_kinematics`` on a private scratch ``MjData``; a live
``MjData`` is never read or written.

Derivation of the certified motion bound
----------------------------------------
Notation: for a rigid motion X(t) = (R(t), x(t)) and a point p of its body frame,
the deviation is delta_X(p) = ||X(t) p - X(m) p|| for t in [ta, tb], m the
midpoint. For any rigid motion and any reference point c,

    X(t)p - X(m)p = [X(t)c - X(m)c] + (R(t) - R(m)) (p - c),            (1)

and ||(R(t) - R(m)) v|| = ||(R(t)R(m)^T - I) R(m) v|| = chord(angle(R(t)R(m)^T)) ||v||.
So it suffices to bound (a) the displacement ``trans`` of the reference point and
(b) the rotation angle ``angle``; the contract of ``monitor.motion.base`` follows.

*Composition.* For X(t) = Y(t) Z(t) (Y, Z rigid), adding and subtracting Y(t)Z(m)p:

    delta_X(p) <= ||Z(t)p - Z(m)p|| + ||Y(t)q - Y(m)q||,  q = Z(m) p,        (2)

because Y(t) is an isometry. For rotations, the angle is a bi-invariant metric on
SO(3), so angle(R_Y(t)R_Z(t), R_Y(m)R_Z(m)) <= angle_Y + angle_Z.           (3)

*MuJoCo's chain.* For body b with parent P, ``mj_kinematics`` computes
X_Wb = X_WP * T0 * G_1(q_1) * ... * G_n(q_n), with T0 = (body_pos, body_quat)
constant and one rigid map G_k per joint of b in MuJoCo's order, acting in the
frame F_{k-1} left by the previous joints (``jnt_pos``/``jnt_axis`` are given in
that frame): hinge y -> s_k + Rot(a_k, q_k - q0_k)(y - s_k); slide
y -> y + a_k (q_k - q0_k); ball y -> s_k + R(q_k)(y - s_k). A free joint sets the
world pose directly from qpos (free joints only exist on children of the world).

*Joint deviations.* Over [ta, tb] the interpolated coordinate deviates from its
midpoint value by at most dq_k = max over the vertices {ta, tb, waypoints
inside} of |q_k(t) - q_k(m)| (|affine| is convex on each linear piece, so the
maximum over a piece is at an end). Rotations (ball and free quaternions) are
slerped: on a single segment the angle from the midpoint is the path length
(geodesic of length <= pi), across waypoints the triangle inequality adds the
exact angle at the waypoint and the path length beyond it
(:func:`monitor.motion._kinematics.rotation_deviation`).

*Own (local) motion.* Applying (2) repeatedly to T0 G_1 ... G_n (T0 is constant
and does not change deviations), with H_k = G_{k+1} ... G_n:

    delta_local(p) <= sum_k delta_{G_k}(H_k(m) p),

where the point is expressed in joint k's frame at the midpoint. The single-joint
deviations are exact-form: hinge chord(dq_k) * dist(y, axis line_k) (the axis is
invariant under G_k); slide dq_k ||a_k||; ball chord(Theta_k) ||y - s_k||.
We evaluate this at p = ref_b and carry y = H_k(m) ref_b backwards through the
joints (vectorised over the N sub-intervals); at the end z = T0 H_0(m) ref_b is
ref_b at the midpoint pose expressed in P's frame.

*Parent.* By (2) with Y = X_WP: delta_b(ref_b) <= delta_local(ref_b) + delta_P(z),
and the parent's own bound holds for its rigid extension:
delta_P(z) <= T_P + chord(Theta_P) ||z - ref_P||. Hence

    T_b     = sum_k delta_{G_k}(H_k(m) ref_b) + T_P + chord(Theta_P) ||z - ref_P||,
    Theta_b = Theta_P + sum_{hinge} dq_k + sum_{ball} Theta_k      (by (3), capped at pi).

A second valid bound for the same point skips the parent's ball: apply (2) all
the way up, i.e. carry z through the ancestors' joints and add their single-joint
deviations at the carried point (this avoids the triangle inequality
dist(z, axis) <= dist(ref_P, axis) + ||z - ref_P|| hidden in T_P + chord(Theta_P)...).
We take the minimum of the two (both are upper bounds); on random chains this
raised the median tightness of T from 0.54 to 0.70.

*Velocity bound.* On a sub-interval inside one segment every coordinate moves at
a constant rate, and a second-order (Taylor) bound built from the exact
reference-point velocity and body angular velocity at the midpoint is also valid
(derivation in :meth:`Plan._velocity_bound`); it is nearly exact for short
sub-intervals, which is where the checkers spend their subdivisions. The final
bounds are the minimum of all valid bounds.

A free body: T_b = max_t ||x(t) - x(m)|| + chord(Theta) ||ref_b|| by (1) about the
origin, Theta its slerp bound. Mocap and world-welded bodies: zero. A body whose
chain has no changing coordinate has bit-identical poses (the lerp is
``a + s (b - a)``) and gets exactly zero; likewise the angle of a body whose
chain has no changing hinge, ball or free-quaternion coordinate.

*Rounding.* Joint deviations are differences of numbers of size |q|, so dq_k is
padded by rel_pad * max|q| (angles and lengths alike); the path lengths by
rel_pad * (total path + 1). The results are then padded by
``Tolerances.pad(T)`` + scale_pad * scale (scale = coordinate magnitude of the
plan, covering the FK rounding of MuJoCo's poses) and angles by
rel_pad * Theta + abs_pad (radians).

*Reference points.* The bound grows with ||p - ref_b||, so ref_b is the centre of
the box around the bounding spheres of the body's geoms (``geom_pos`` +-
``geom_rbound``, planes count as their origin), or ``body_ipos`` when the body
has no geoms.
"""

from __future__ import annotations

import mujoco
import numpy as np

from monitor.errors import InvalidInputError
from monitor.motion import _kinematics as K
from monitor.motion.base import MotionBounds, chord
from monitor.tolerances import DEFAULT, Tolerances

_FREE = int(mujoco.mjtJoint.mjJNT_FREE)
_BALL = int(mujoco.mjtJoint.mjJNT_BALL)
_SLIDE = int(mujoco.mjtJoint.mjJNT_SLIDE)
_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)


def _ref_points(model: mujoco.MjModel) -> np.ndarray:
    """(nbody, 3) body-frame reference points near each body's geoms."""
    ref = np.array(model.body_ipos, dtype=np.float64)
    for b in range(model.nbody):
        g = np.flatnonzero(model.geom_bodyid == b)
        if g.size == 0:
            continue
        r = np.asarray(model.geom_rbound[g])[:, None]
        p = np.asarray(model.geom_pos[g])
        lo = (p - r).min(axis=0)
        hi = (p + r).max(axis=0)
        ref[b] = 0.5 * (lo + hi)
    return ref


class Plan:
    """Joint waypoints of a MuJoCo model over a time window (Trajectory protocol).

    Args:
        times: (K,) strictly increasing waypoint times (s), K >= 2.
        qpos: (K, nq) joint positions at the waypoints. Ball and free
            quaternions are normalised when their norm is within
            ``tolerances.quat_norm_tol`` of 1.
        model: the ``mujoco.MjModel`` the plan is for.
        mocap_pos: (nmocap, 3) mocap positions held over the window
            (default: the model's, i.e. a fresh ``MjData``'s).
        mocap_quat: (nmocap, 4) mocap quaternions held over the window.
        tolerances: rounding pads and the quaternion norm tolerance.

    Raises:
        InvalidInputError: NaN/inf, wrong shapes, non-increasing times, fewer
            than 2 waypoints, non-unit quaternions, wrong nq, or ``model`` not an
            ``MjModel``; the message names the offending index.
    """

    _bound_kinds: tuple[str, ...] = ("chain", "velocity")
    """Which bounds to combine (min): the chain bound and, on single-segment
    sub-intervals, the velocity bound. Private; tests check each one alone."""

    def __init__(self, times: object, qpos: object, model: mujoco.MjModel, *,
                 mocap_pos: object = None, mocap_quat: object = None,
                 tolerances: Tolerances = DEFAULT):
        if not isinstance(model, mujoco.MjModel):
            raise InvalidInputError(f"model must be a mujoco.MjModel, got {type(model).__name__}")
        self._model = model
        self._tol = tolerances
        t = K.check_times(times)
        q = K.as_float_array("qpos", qpos)
        if q.ndim != 2 or q.shape[0] != t.shape[0]:
            raise InvalidInputError(
                f"qpos must have shape (K, nq) = ({t.shape[0]}, {model.nq}), got {q.shape}"
            )
        if q.shape[1] != model.nq:
            raise InvalidInputError(f"qpos has nq = {q.shape[1]} columns, the model has nq = {model.nq}")
        K.check_finite("qpos", q)

        nmocap = model.nmocap
        mocap_bodies = np.flatnonzero(np.asarray(model.body_mocapid) >= 0)
        mocap_bodies = mocap_bodies[np.argsort(np.asarray(model.body_mocapid)[mocap_bodies])]
        if mocap_pos is None:
            mp = np.array(model.body_pos[mocap_bodies], dtype=np.float64).reshape(nmocap, 3)
        else:
            mp = K.as_float_array("mocap_pos", mocap_pos)
            if mp.shape != (nmocap, 3):
                raise InvalidInputError(f"mocap_pos must have shape ({nmocap}, 3), got {mp.shape}")
            K.check_finite("mocap_pos", mp)
        if mocap_quat is None:
            mq = np.array(model.body_quat[mocap_bodies], dtype=np.float64).reshape(nmocap, 4)
        else:
            mq = K.as_float_array("mocap_quat", mocap_quat)
            if mq.shape != (nmocap, 4):
                raise InvalidInputError(f"mocap_quat must have shape ({nmocap}, 4), got {mq.shape}")
            K.check_finite("mocap_quat", mq)
        mq = K.normalize_quats("mocap_quat", mq, tolerances)

        # Joint structure.
        jtype = np.asarray(model.jnt_type)
        jadr = np.asarray(model.jnt_qposadr)
        self._quat_tracks: dict[int, K.QuatTrack] = {}
        for j in range(model.njnt):
            if jtype[j] in (_BALL, _FREE):
                a = jadr[j] + (3 if jtype[j] == _FREE else 0)
                name = model.joint(j).name or f"joint{j}"
                q[:, a:a + 4] = K.normalize_quats(f"qpos (joint {name!r}, qpos columns {a}..{a + 3})",
                                                  q[:, a:a + 4], tolerances)
        for j in range(model.njnt):
            if jtype[j] in (_BALL, _FREE):
                a = jadr[j] + (3 if jtype[j] == _FREE else 0)
                self._quat_tracks[j] = K.QuatTrack(q[:, a:a + 4])

        self._times = t
        self._qpos = q
        self._times.setflags(write=False)
        self._qpos.setflags(write=False)
        self._mocap_pos = mp
        self._mocap_quat = mq
        self._seg = K.Segments(t)
        # Linear columns: every qpos column that is not a quaternion component.
        lin = np.ones(model.nq, dtype=bool)
        for j, _ in self._quat_tracks.items():
            a = jadr[j] + (3 if jtype[j] == _FREE else 0)
            lin[a:a + 4] = False
        self._lin = lin

        self._scratch = mujoco.MjData(model)
        self._ref = _ref_points(model)
        self._ref.setflags(write=False)

        # Which qpos columns change anywhere in the window, per body chain.
        changes = np.any(q != q[0], axis=0)  # (nq,)
        parent = np.asarray(model.body_parentid)
        mocapid = np.asarray(model.body_mocapid)
        nbody = model.nbody
        self._jnt_of_body = [
            list(range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]))
            for b in range(nbody)
        ]
        # Plain-numpy copies of the joint and body geometry (MjModel attribute access is slow).
        axes = np.array(model.jnt_axis, dtype=np.float64).reshape(-1, 3)
        self._jnt = {
            "type": [int(x) for x in jtype],
            "adr": [int(x) for x in jadr],
            "pos": np.array(model.jnt_pos, dtype=np.float64).reshape(-1, 3),
            "axis": axes,
            "axis_norm": np.linalg.norm(axes, axis=-1),
            "qpos0": np.array(model.qpos0, dtype=np.float64),
        }
        self._body_pos = np.array(model.body_pos, dtype=np.float64)
        self._body_quat = np.array(model.body_quat, dtype=np.float64)
        self._parent = [int(x) for x in parent]
        qwidth = {_FREE: 7, _BALL: 4, _SLIDE: 1, _HINGE: 1}
        own_moving = np.zeros(nbody, dtype=bool)
        own_rot = np.zeros(nbody, dtype=bool)
        for b in range(nbody):
            for j in self._jnt_of_body[b]:
                cols = slice(jadr[j], jadr[j] + qwidth[int(jtype[j])])
                if changes[cols].any():
                    own_moving[b] = True
                    if jtype[j] == _HINGE or jtype[j] == _BALL:
                        own_rot[b] = True
                    if jtype[j] == _FREE and changes[jadr[j] + 3:jadr[j] + 7].any():
                        own_rot[b] = True
        moving = np.zeros(nbody, dtype=bool)
        rotating = np.zeros(nbody, dtype=bool)
        for b in range(1, nbody):
            if mocapid[b] >= 0:
                continue
            p = parent[b]
            moving[b] = own_moving[b] or moving[p]
            rotating[b] = own_rot[b] or rotating[p]
        self._moving = moving
        self._rotating = rotating
        self._moving.setflags(write=False)

        # Waypoint poses (for translation segments and the rounding scale).
        self._wp_pos, self._wp_mat = self._fk(q)
        self._magnitude = {
            "q": float(np.max(np.abs(q), initial=0.0)) + float(np.max(np.abs(model.qpos0), initial=0.0)),
            "path": max((float(tr.cum[-1]) for tr in self._quat_tracks.values()), default=0.0),
        }
        ref_norm = float(np.max(np.linalg.norm(self._ref, axis=-1), initial=0.0))
        self._scale = float(np.max(np.linalg.norm(self._wp_pos, axis=-1), initial=0.0)) + ref_norm
        whole = self._bounds(np.array([t[0]]), np.array([t[-1]]), scale=0.0)
        self._scale += float(np.max(whole[0], initial=0.0)) + 2.0 * ref_norm

    # ------------------------------------------------------------------ basics
    @property
    def model(self) -> mujoco.MjModel:
        """The MuJoCo model of the plan."""
        return self._model

    @property
    def times(self) -> np.ndarray:
        """(K,) waypoint times (s), read-only."""
        return self._times

    @property
    def qpos(self) -> np.ndarray:
        """(K, nq) waypoint joint positions (quaternions normalised), read-only."""
        return self._qpos

    @property
    def window(self) -> tuple[float, float]:
        """(t0, t1) the plan's time span (s)."""
        return float(self._times[0]), float(self._times[-1])

    @property
    def t0(self) -> float:
        """Window start (s)."""
        return float(self._times[0])

    @property
    def t1(self) -> float:
        """Window end (s)."""
        return float(self._times[-1])

    @property
    def nbody(self) -> int:
        """Number of bodies (world included)."""
        return int(self._model.nbody)

    @property
    def ref_points(self) -> np.ndarray:
        """(nbody, 3) body-frame reference points of the motion bounds (m)."""
        return self._ref

    @property
    def mocap_pos(self) -> np.ndarray:
        """(nmocap, 3) held mocap positions (m)."""
        return self._mocap_pos.copy()

    @property
    def mocap_quat(self) -> np.ndarray:
        """(nmocap, 4) held mocap quaternions."""
        return self._mocap_quat.copy()

    # ----------------------------------------------------------- interpolation
    def _qpos_many(self, t: np.ndarray, loc: tuple | None = None) -> np.ndarray:
        """Interpolated qpos (T, nq) at validated times (T,)."""
        i, s, at_end = self._seg.locate(t) if loc is None else loc
        out = K.lerp_values(self._qpos, i, s, at_end)
        jtype = self._model.jnt_type
        jadr = self._model.jnt_qposadr
        for j, track in self._quat_tracks.items():
            a = jadr[j] + (3 if jtype[j] == _FREE else 0)
            out[:, a:a + 4] = track.interp(i, s, at_end)
        return out

    def qpos_at(self, t: float | np.ndarray) -> np.ndarray:
        """Interpolated joint positions: (nq,) for a scalar t, (T, nq) for times (T,)."""
        scalar = np.ndim(t) == 0
        tt = K.check_times_in_window(t, self.window)
        out = self._qpos_many(tt)
        return out[0] if scalar else out

    def _fk(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World body poses for joint positions Q (T, nq) via mj_kinematics on scratch data."""
        m = self._model
        d = self._scratch
        T = Q.shape[0]
        pos = np.empty((T, m.nbody, 3))
        mat = np.empty((T, m.nbody, 3, 3))
        if m.nmocap:
            d.mocap_pos[:] = self._mocap_pos
            d.mocap_quat[:] = self._mocap_quat
        for k in range(T):
            d.qpos[:] = Q[k]
            mujoco.mj_kinematics(m, d)
            pos[k] = d.xpos
            mat[k] = d.xmat.reshape(m.nbody, 3, 3)
        return pos, mat

    def body_poses(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World poses at ``times`` (T,) in the window.

        Returns:
            positions (T, nbody, 3) m and rotations R_WB (T, nbody, 3, 3).
        """
        t = K.check_times_in_window(times, self.window)
        return self._fk(self._qpos_many(t))

    # ------------------------------------------------------------------ bounds
    def motion_bounds(self, t0: np.ndarray, t1: np.ndarray) -> MotionBounds:
        """Certified bounds for the sub-intervals [t0[i], t1[i]] (see module docstring).

        Args:
            t0: (N,) sub-interval starts (s), inside the window.
            t1: (N,) sub-interval ends (s), t1 >= t0, inside the window.

        Returns:
            MotionBounds with trans (N, nbody) m and angle (N, nbody) rad.
        """
        a, b = K.check_interval_arrays(t0, t1, self.window)
        trans = np.empty((a.shape[0], self.nbody))
        angle = np.empty((a.shape[0], self.nbody))
        for sl in K.interval_chunks(self._times, a, b, width=max(self._model.nq, 4)):
            trans[sl], angle[sl] = self._bounds(a[sl], b[sl], scale=self._scale)
        return MotionBounds(t0=a, t1=b, trans=trans, angle=angle)

    def _bounds(self, ta: np.ndarray, tb: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
        m = self._model
        tol = self._tol
        N = ta.shape[0]
        nbody = m.nbody
        trans = np.zeros((N, nbody))
        angle = np.zeros((N, nbody))
        if not self._moving.any() or N == 0:
            return trans, angle
        iv = K.IntervalVertices(self._seg, ta, tb)
        Qa = self._qpos_many(ta, iv.loc_a)
        Qb = self._qpos_many(tb, iv.loc_b)
        Qm = self._qpos_many(iv.tm, iv.loc_m)
        lin = self._lin
        dq = np.zeros((N, m.nq))
        dq[:, lin] = K.scalar_deviation(self._qpos[:, lin], Qa[:, lin], Qb[:, lin], Qm[:, lin], iv)
        dq += tol.rel_pad * self._magnitude["q"]

        J = self._jnt
        jtype = J["type"]
        jadr = J["adr"]
        qpos0 = J["qpos0"]
        ref = self._ref

        # Per joint, once: deviation bounds and the rigid map G_k at the midpoint.
        joint: dict[int, tuple] = {}
        for j, typ in enumerate(jtype):
            bj = int(m.jnt_bodyid[j])
            if not self._moving[bj]:
                continue
            a = jadr[j]
            if typ == _HINGE:
                axn = J["axis"][j] / J["axis_norm"][j]
                joint[j] = (typ, dq[:, a], axn, J["pos"][j], Qm[:, a] - qpos0[a])
            elif typ == _SLIDE:
                joint[j] = (typ, dq[:, a] * J["axis_norm"][j],
                            (Qm[:, a] - qpos0[a])[:, None] * J["axis"][j])
            else:
                off = 3 if typ == _FREE else 0
                track = self._quat_tracks[j]
                qm = Qm[:, a + off:a + off + 4]
                qm = qm / np.linalg.norm(qm, axis=-1, keepdims=True)
                th = K.rotation_deviation(track, qm, iv) + tol.rel_pad * (track.cum[-1] + 1.0)
                if typ == _BALL:
                    joint[j] = (typ, th, qm, J["pos"][j])
                else:
                    dx = K.vector_deviation(self._qpos[:, a:a + 3], Qa[:, a:a + 3], Qb[:, a:a + 3],
                                            Qm[:, a:a + 3], iv)
                    joint[j] = (typ, th, dx + tol.rel_pad * self._magnitude["q"], qm)

        def local(c: int, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
            """Own-joint bounds of body c at its points y (N, 3).

            Returns the displacement bound (N,), the own rotation bound (N,), and y
            expressed in the parent's frame at the midpoint (None after a free joint).
            """
            T = np.zeros(N)
            Th = np.zeros(N)
            for j in reversed(self._jnt_of_body[c]):
                info = joint[j]
                typ = info[0]
                if typ == _HINGE:
                    _, dqj, axn, s, ang = info
                    T += chord(dqj) * np.linalg.norm(K.cross(axn, y - s), axis=-1)
                    Th += dqj
                    y = s + K.axis_rotate(axn, ang, y - s)
                elif typ == _SLIDE:
                    T += info[1]
                    y = y + info[2]
                elif typ == _BALL:
                    _, th, qm, s = info
                    T += chord(th) * np.linalg.norm(y - s, axis=-1)
                    Th += th
                    y = s + K.quat_rotate(qm, y - s)
                else:  # free joint: world pose straight from qpos, about the body origin
                    _, th, dx, _ = info
                    return dx + chord(th) * np.linalg.norm(y, axis=-1), th, None
            return T, Th, self._body_pos[c] + K.quat_rotate(self._body_quat[c], y)

        velocity = self._velocity_setup(iv, Qm, joint) if "velocity" in self._bound_kinds else None

        for b in range(1, nbody):
            if not self._moving[b]:
                continue
            T, Th, z = local(b, np.broadcast_to(ref[b], (N, 3)).copy())
            P = self._parent[b]
            if z is not None and P != 0 and self._moving[P]:
                # (i) through the parent's bound (its rigid extension)
                T_rec = T + trans[:, P] + chord(angle[:, P]) * np.linalg.norm(z - ref[P], axis=-1)
                # (ii) carrying ref_b itself up through every ancestor's joints
                T_dir = T.copy()
                c = P
                while z is not None and c != 0 and self._moving[c]:
                    Tc, _, z = local(c, z)
                    T_dir += Tc
                    c = self._parent[c]
                T_dir = T_dir * (1.0 + tol.rel_pad) + tol.abs_pad + tol.scale_pad * scale
                T = np.minimum(T_rec, T_dir)
                Th = Th + angle[:, P]
            if velocity is not None:
                T2, Th2 = self._velocity_bound(b, velocity, joint)
                if "chain" not in self._bound_kinds:  # tests: the velocity bound on its own
                    T, Th = T2, Th2
                T = np.minimum(T, T2)
                Th = np.minimum(Th, Th2)
            if self._rotating[b]:
                Th = np.minimum(Th, np.pi)
                angle[:, b] = np.minimum(Th * (1.0 + tol.rel_pad) + tol.abs_pad, np.pi)
            # else: no rotational coordinate changes on the chain, so R_WB(t) is
            # computed from bit-identical inputs and the angle is exactly 0.
            trans[:, b] = T * (1.0 + tol.rel_pad) + tol.abs_pad + tol.scale_pad * scale
        return trans, angle

    def _velocity_setup(self, iv: K.IntervalVertices, Qm: np.ndarray, joint: dict) -> dict | None:
        """Per-joint constant rates (per unit segment parameter s) on single-segment sub-intervals.

        Returns None when no sub-interval lies within one segment.
        """
        N = iv.tm.shape[0]
        single = ~iv.valid.any(axis=1) if iv.C else np.ones(N, dtype=bool)
        if not single.any():
            return None
        i, s_m, _ = iv.loc_m
        s_a = np.where(iv.loc_a[0] == i, iv.loc_a[1], s_m)
        s_b = np.where(iv.loc_b[0] == i, iv.loc_b[1], 1.0)
        s_b = np.where(iv.loc_b[0] < i, s_m, s_b)
        h = np.maximum(np.maximum(s_b - s_m, s_m - s_a), 0.0)
        q = self._qpos
        J = self._jnt
        rate: dict[int, tuple] = {}
        for j, info in joint.items():
            typ = info[0]
            a = J["adr"][j]
            if typ in (_HINGE, _SLIDE):
                rate[j] = (q[i + 1, a] - q[i, a],)
            elif typ == _BALL:
                rate[j] = (self._quat_tracks[j].angular_velocity(i, np.ones(N)),)
            else:
                rate[j] = (q[i + 1, a:a + 3] - q[i, a:a + 3],
                           self._quat_tracks[j].angular_velocity(i, np.ones(N)))
        return {"single": single, "h": h, "rate": rate, "N": N}

    def _velocity_bound(self, b: int, vel: dict, joint: dict) -> tuple[np.ndarray, np.ndarray]:
        r"""Second-order bound on sub-intervals inside one segment (inf elsewhere).

        On one segment every coordinate moves at a constant rate in the segment
        parameter s (hinge/slide: b - a; ball/free: rotation about a fixed axis at
        rate phi_i, see ``QuatTrack.angular_velocity``), so the chain is a
        composition of screw motions at constant rates omega_k (hinges, balls, the
        free rotation about the body origin) and v_k (slides, the free position).
        The reference point p has velocity p' = sum_k J_k with
        J_k = omega_k a_k x (p - s_k) (or v_k a_k) and the body angular velocity is
        W = sum_k omega_k a_k, both computed exactly at the midpoint. With
        Omega_k = sum_{l < k} |omega_l| (joints nearer the root), the axes move as
        a_k' = W_{k-1} x a_k and the anchors as s_k' = sum_{l<k} J_l(s_k), so

            |J_k'| <= |omega_k| (2 Omega_k r_k + S_k)    (hinge-like),
            |J_k'| <= |v_k| Omega_k                      (slide-like),

        where S_k = sum_{l >= k} (|omega_l| r_l + |v_l|) bounds |p' - s_k' - W_{k-1} x (p - s_k)|
        and r_k >= |p - s_k| over the sub-interval: by rule (2) of the module
        docstring, r_k = |p(m) - s_k(m)| + sum_{l > k} e_l with
        e_l = chord(|omega_l| h) r_l(m) (or |v_l| h). Taylor with remainder gives

            |p(s) - p(s_m)| <= h |p'(s_m)| + h^2 / 2 * sum_k |J_k'|,
            angle(R(s) R(s_m)^T) <= h |W(s_m)| + h^2 / 2 * sum_k |omega_k| Omega_k,

        with h = max |s - s_m| over the sub-interval, computed from the very
        parameters s(ta), s(tb) that the interpolation uses (floating-point
        t -> s is monotone, so every pose the checkers evaluate lies in range).
        """
        N = vel["N"]
        h = vel["h"]
        rate = vel["rate"]
        J = self._jnt
        jtype = J["type"]
        tol = self._tol
        y = np.broadcast_to(self._ref[b], (N, 3)).copy()
        V = np.zeros((N, 3))
        W = np.zeros((N, 3))
        recs: list[tuple[bool, np.ndarray, np.ndarray]] = []  # (hinge-like, |rate|, r(m)), body first
        c = b
        done = False
        while not done and c != 0 and self._moving[c]:
            for j in reversed(self._jnt_of_body[c]):
                typ = jtype[j]
                info = joint[j]
                if typ == _HINGE:
                    _, _, axn, s, ang = info
                    r0 = np.linalg.norm(y - s, axis=-1)
                    y = s + K.axis_rotate(axn, ang, y - s)
                    V = K.axis_rotate(axn, ang, V)
                    W = K.axis_rotate(axn, ang, W)
                    wv = rate[j][0][:, None] * axn
                    V += K.cross(wv, y - s)
                    W += wv
                    recs.append((True, np.abs(rate[j][0]), r0))
                elif typ == _SLIDE:
                    y = y + info[2]
                    v = rate[j][0][:, None] * J["axis"][j]
                    V += v
                    recs.append((False, np.linalg.norm(v, axis=-1), np.zeros(N)))
                elif typ == _BALL:
                    _, _, qm, s = info
                    wv = rate[j][0]
                    r0 = np.linalg.norm(y - s, axis=-1)
                    y = s + K.quat_rotate(qm, y - s)
                    V = K.quat_rotate(qm, V)
                    W = K.quat_rotate(qm, W)
                    V += K.cross(wv, y - s)
                    W += wv
                    recs.append((True, np.linalg.norm(wv, axis=-1), r0))
                else:  # free: rotation about the body origin, then translation (world axes)
                    qmid = info[3]
                    dx_rate, wv = rate[j]
                    r0 = np.linalg.norm(y, axis=-1)
                    yr = K.quat_rotate(qmid, y)
                    V = K.quat_rotate(qmid, V)
                    W = K.quat_rotate(qmid, W)
                    V += K.cross(wv, yr)
                    W += wv
                    recs.append((True, np.linalg.norm(wv, axis=-1), r0))
                    V += dx_rate
                    recs.append((False, np.linalg.norm(dx_rate, axis=-1), np.zeros(N)))
                    done = True
            if not done:
                y = self._body_pos[c] + K.quat_rotate(self._body_quat[c], y)
                V = K.quat_rotate(self._body_quat[c], V)
                W = K.quat_rotate(self._body_quat[c], W)
                c = self._parent[c]
        # Second-order terms (recs are ordered from the body towards the root).
        n = len(recs)
        e_before = np.zeros(N)  # sum of e_l for joints nearer the body
        r_max = []
        for hinge, w, r0 in recs:
            r_max.append(r0 + e_before)
            e_before = e_before + (chord(w * h) * r0 if hinge else w * h)
        omega_after = np.zeros(N)  # Omega_k: sum of |omega| nearer the root
        Omegas = [None] * n
        for k in range(n - 1, -1, -1):
            Omegas[k] = omega_after.copy()
            if recs[k][0]:
                omega_after = omega_after + recs[k][1]
        A = np.zeros(N)
        AW = np.zeros(N)
        S = np.zeros(N)
        rsum = np.zeros(N)
        for k in range(n):
            hinge, w, _ = recs[k]
            S = S + (w * r_max[k] if hinge else w)
            if hinge:
                A += w * (2.0 * Omegas[k] * r_max[k] + S)
                AW += w * Omegas[k]
                rsum += r_max[k]
            else:
                A += w * Omegas[k]
        mag = self._magnitude["q"] + self._magnitude["path"] + 1.0
        T2 = h * np.linalg.norm(V, axis=-1) + 0.5 * h * h * A
        T2 = T2 + tol.rel_pad * (4.0 * h * S + mag * (rsum + n))
        Th2 = h * np.linalg.norm(W, axis=-1) + 0.5 * h * h * AW
        Th2 = Th2 + tol.rel_pad * (4.0 * h * omega_after + mag * n)
        single = vel["single"]
        return np.where(single, T2, np.inf), np.where(single, Th2, np.inf)

    # ------------------------------------------------------------ structure
    def moving_bodies(self) -> np.ndarray:
        """(nbody,) bool: True where some coordinate on the body's chain changes in the window."""
        return self._moving.copy()

    def translation_segments(self, body: int) -> tuple[np.ndarray, np.ndarray] | None:
        """Piecewise-linear origin path of ``body`` if its rotation is constant, else None.

        Returns:
            (breakpoints (k+1,) s, origins (k+1, 3) m): ``([t0, t1], [p, p])`` for a
            body that does not move; the waypoint times and FK origins when only
            slide joints and free-joint positions change along its chain.
        """
        b = int(body)
        if not 0 <= b < self.nbody:
            raise InvalidInputError(f"body index {body} out of range [0, {self.nbody})")
        if not self._moving[b]:
            p = self._wp_pos[0, b]
            return np.array([self.t0, self.t1]), np.stack([p, p])
        if self._rotating[b]:
            return None
        return self._times.copy(), self._wp_pos[:, b].copy()


__all__ = ["Plan"]
