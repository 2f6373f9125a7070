r"""Joint-space plans: waypoints interpolated in joint space, poses by MuJoCo FK.

:class:`Plan` implements the :class:`monitor.motion.base.Trajectory` protocol for
a MuJoCo model and joint waypoints ``qpos`` (K, nq) at ``times`` (K,).

Interpolation (piecewise in time, breakpoints at the waypoints):
hinge and slide coordinates are lerped; a free joint lerps its position and
slerps its quaternion (shortest arc, about the body origin); a ball joint slerps
(shortest arc). Mocap bodies hold ``mocap_pos/mocap_quat`` over the window.

Poses come from ``mujoco.mj_kinematics`` on a scratch ``MjData`` private to the
calling thread (one per thread and model, shared by that thread's plans); a live
``MjData`` is never read or written.

Per-step cost. Everything derived from the model alone (joint/body topology, chains,
reference points, plain-numpy copies of the geometry) is computed once and cached
under the bytes of the model arrays it reads, so a model edited in place gets a
fresh structure. The waypoint FK and the rounding scale are computed on first use,
and small ``motion_bounds`` / ``body_poses`` queries are memoised per plan (pure
functions of their arguments). None of this changes a computed number.

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
Distances are invariant under rigid maps, so we evaluate them in world
coordinates: one vectorised FK at the N midpoints (numpy, MuJoCo's rules) gives
every joint's world anchor and axis, and y is the world reference point
X_Wb(m) ref_b; z denotes the same point, seen as a point of P's rigid extension.

*Parent.* By (2) with Y = X_WP: delta_b(ref_b) <= delta_local(ref_b) + delta_P(z),
and the parent's own bound holds for its rigid extension:
delta_P(z) <= T_P + chord(Theta_P) ||z - ref_P||. Hence

    T_b     = sum_k delta_{G_k}(H_k(m) ref_b) + T_P + chord(Theta_P) ||z - ref_P||,
    Theta_b = Theta_P + sum_{hinge} dq_k + sum_{ball} Theta_k      (by (3), capped at pi).

A second valid bound for the same point skips the parent's ball: apply (2) all
the way up, i.e. add the single-joint deviations of every ancestor joint at the
same world point (this avoids the triangle inequality
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

*The rounding scale* S (``Plan._scale``; the compiled pack's ``tol[3]``, the same
formula). With m the window's midpoint, x_b(m) body b's FK origin there, W_b its
whole-window translation bound computed with scale 0 and rho_b = ||ref_b||:

    S = (max_b (||x_b(m)|| + 2 rho_b + W_b) + max_b W_b + 3 max_b rho_b) * (1 + 2^-30).

(The factor covers the rounding of the computed terms: x_b(m) is a rounded FK origin and W_b
carries no FK-rounding pad at scale 0, so without it S fell 1-2 ulps below the former definition
and below a computed origin on a far static body whose child moves by a few ulps of its
distance; red team 16. 2^-30 is ~4e6 ulps, far above any FK chain's rounding.)
(a) S bounds every origin and reference point over the window: by (1) about the
reference point, ||x_b(t) - x_b(m)|| <= W_b + chord(Theta_b) rho_b <= W_b + 2 rho_b, so
||x_b(t)|| <= max_b (||x_b(m)|| + 2 rho_b + W_b) for every t, and
||x_b(t) + R_b(t) ref_b|| <= that + rho_b <= S. (b) S is at least the former
definition (FK at all K waypoints), max_{k,b} ||x_b(t_k)|| + max_b W_b + 3 max_b rho_b,
by (a) at t = t_k. (c) Every translation bound is a nondecreasing function of S and no angle depends on it: S
enters only through nonnegative multiples, rel_pad * S * coef_k of each rotational
chain term (coef_k >= 0), scale_pad * S in the chain and final pads (and in the zero
bound of a frozen base, ``kernel._bounds_core``), and rel_pad * 4 h sum|omega| * S in the
velocity bound (h >= 0); sums, minima and the parent's bound (by induction from the
root) keep that order. By (b) and (c), every bound with this S is at least the bound
with the former scale at the same sub-interval: pads only grow, never shrink. A NaN term
(overflowing coordinates) makes S = inf, not a NaN that a maximum or a comparison would
skip (the engine's compiled path refuses scales >= 1e9 m).
It costs one FK at m and the one whole-window bound instead of FK at all K waypoints.

*Reference points.* The bound grows with ||p - ref_b||, so ref_b is the centre of
the box around the bounding spheres of the body's geoms (``geom_pos`` +-
``geom_rbound``, planes count as their origin), or ``body_ipos`` when the body
has no geoms.
"""

from __future__ import annotations

import math
import threading
from bisect import bisect_right

import mujoco
import numpy as np

from monitor.certify.common import check_active_budget
from monitor.errors import InvalidInputError
from monitor.motion import _kinematics as K
from monitor.motion.base import MotionBounds, Sealed, WindowTimes, chord, sealed
from monitor.tolerances import DEFAULT, Tolerances

_FREE = int(mujoco.mjtJoint.mjJNT_FREE)
_BALL = int(mujoco.mjtJoint.mjJNT_BALL)
_SLIDE = int(mujoco.mjtJoint.mjJNT_SLIDE)
_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)
_SCALE_ROUND_UP = 1.0 + 2.0**-30
"""The rounding scale's factor for its own rounding (module docstring, "The rounding scale";
``monitor.motion.kernel.SCALE_ROUND_UP``, the same value: the compiled pack's scale)."""


def _ref_points(model: mujoco.MjModel) -> np.ndarray:
    """(nbody, 3) body-frame reference points near each body's geoms."""
    ref = np.array(model.body_ipos, dtype=np.float64)
    gb = np.asarray(model.geom_bodyid)
    if gb.size == 0:
        return ref
    r = np.asarray(model.geom_rbound, dtype=np.float64)[:, None]
    p = np.asarray(model.geom_pos, dtype=np.float64)
    lo = np.full_like(ref, np.inf)
    hi = np.full_like(ref, -np.inf)
    np.minimum.at(lo, gb, p - r)
    np.maximum.at(hi, gb, p + r)
    has = np.zeros(ref.shape[0], dtype=bool)
    has[gb] = True
    ref[has] = 0.5 * (lo[has] + hi[has])
    return ref


# Per-model structure (joint/body topology, plain-numpy copies of the geometry),
# cached under a key made of the bytes of EVERY model array it is derived from:
# a model edited in place (e.g. domain randomisation of body_pos) gets a new key.
_STRUCT_FIELDS = ("jnt_type", "jnt_qposadr", "jnt_bodyid", "jnt_pos", "jnt_axis", "qpos0",
                  "body_parentid", "body_mocapid", "body_jntadr", "body_jntnum", "body_pos",
                  "body_quat", "body_ipos", "geom_bodyid", "geom_pos", "geom_rbound")
_STRUCT_CACHE: dict[bytes, _ModelStructure] = {}
_STRUCT_CACHE_MAX = 16


class _ModelStructure(Sealed):
    """Everything :class:`Plan` derives from the model alone (read-only, shared)."""

    key: bytes = b""
    """:func:`_structure_key` of the arrays this structure was built from."""
    field_bytes: list[bytes] = []
    """Raw bytes of each ``_STRUCT_FIELDS`` array it was built from (for ``Plan.is_current``)."""

    def __init__(self, model: mujoco.MjModel):
        nbody = model.nbody
        jtype = np.asarray(model.jnt_type)
        jadr = np.asarray(model.jnt_qposadr)
        self.jtype_list = [int(x) for x in jtype]
        self.jadr_list = [int(x) for x in jadr]
        self.njnt = model.njnt
        self.nq = model.nq
        self.nbody = nbody
        self.nmocap = model.nmocap
        mocap_bodies = np.flatnonzero(np.asarray(model.body_mocapid) >= 0)
        mocap_bodies = mocap_bodies[np.argsort(np.asarray(model.body_mocapid)[mocap_bodies])]
        self.mocap_pos0 = np.array(model.body_pos[mocap_bodies], dtype=np.float64).reshape(self.nmocap, 3)
        self.mocap_quat0 = np.array(model.body_quat[mocap_bodies], dtype=np.float64).reshape(self.nmocap, 4)
        # (M,) mocap bodies b >= 1 in body order and their mocap ids (the pack check's rows)
        self.mocap_rows = np.flatnonzero(np.asarray(model.body_mocapid)[1:] >= 0) + 1
        self.mocap_ids = np.array(model.body_mocapid, dtype=np.int64)[self.mocap_rows]
        # (joint, first quaternion column, label) of every ball / free joint.
        self.quat_joints: list[tuple[int, int, str]] = []
        for j in range(model.njnt):
            if jtype[j] in (_BALL, _FREE):
                a = int(jadr[j]) + (3 if jtype[j] == _FREE else 0)
                name = model.joint(j).name or f"joint{j}"
                self.quat_joints.append((j, a, f"qpos (joint {name!r}, qpos columns {a}..{a + 3})"))
        lin = np.ones(model.nq, dtype=bool)
        for _, a, _ in self.quat_joints:
            lin[a:a + 4] = False
        # (4 * nquat,) qpos columns of every ball / free quaternion, joint by joint
        self.quat_cols = np.array([a + c for _, a, _ in self.quat_joints for c in range(4)], dtype=np.int64)
        self.lin = lin
        self.parent = [int(x) for x in model.body_parentid]
        self.mocap = [int(x) >= 0 for x in model.body_mocapid]
        self.jnt_of_body = [
            list(range(int(model.body_jntadr[b]), int(model.body_jntadr[b]) + int(model.body_jntnum[b])))
            for b in range(nbody)
        ]
        axes = np.array(model.jnt_axis, dtype=np.float64).reshape(-1, 3)
        self.jnt = {
            "type": self.jtype_list,
            "adr": self.jadr_list,
            "pos": np.array(model.jnt_pos, dtype=np.float64).reshape(-1, 3),
            "axis": axes,
            "axis_norm": np.linalg.norm(axes, axis=-1),
            "qpos0": np.array(model.qpos0, dtype=np.float64),
        }
        self.qpos0_mag = float(np.max(np.abs(self.jnt["qpos0"]), initial=0.0))
        self.body_pos = np.array(model.body_pos, dtype=np.float64)
        self.body_quat = np.array(model.body_quat, dtype=np.float64)
        self.body_mat = K.quat_to_mat(self.body_quat)
        qwidth = {_FREE: 7, _BALL: 4, _SLIDE: 1, _HINGE: 1}
        # Per body, per own joint: (all columns, rotational columns or None).
        self.body_cols: list[list[tuple[slice, slice | None]]] = []
        for b in range(nbody):
            cols = []
            for j in self.jnt_of_body[b]:
                typ, a = self.jtype_list[j], self.jadr_list[j]
                whole = slice(a, a + qwidth[typ])
                if typ in (_HINGE, _BALL):
                    rot = whole
                elif typ == _FREE:
                    rot = slice(a + 3, a + 7)
                else:
                    rot = None
                cols.append((whole, rot))
            self.body_cols.append(cols)
        vkind, vbody = [], []
        self.first_v: dict[int, int] = {}
        for j in range(model.njnt):
            self.first_v[j] = len(vkind)
            kinds = {_HINGE: [0], _SLIDE: [1], _BALL: [2], _FREE: [3, 4]}[self.jtype_list[j]]
            for kd in kinds:
                vkind.append(kd)
                vbody.append(int(model.jnt_bodyid[j]))
        self.vkind = np.array(vkind, dtype=np.int64)
        self.own_v = [[v for v in range(len(vkind)) if vbody[v] == b] for b in range(nbody)]
        # (nbody, nq) masks of each body's own joint columns / rotational columns.
        self.own_cols = np.zeros((nbody, model.nq), dtype=bool)
        self.own_rot_cols = np.zeros((nbody, model.nq), dtype=bool)
        for b in range(1, nbody):
            if self.mocap[b]:
                continue
            for whole, rot in self.body_cols[b]:
                self.own_cols[b, whole] = True
                if rot is not None:
                    self.own_rot_cols[b, rot] = True
        # Bodies by tree depth (non-mocap, world excluded) with their parents: for the
        # vectorised moving/rotating propagation in Plan._setup. Mocap bodies stay
        # False (fixed frames), and so does the world.
        depth = np.zeros(nbody, dtype=np.int64)
        for b in range(1, nbody):
            depth[b] = depth[self.parent[b]] + 1  # MuJoCo orders parents before children
        par = np.asarray(self.parent, dtype=np.int64)
        not_mocap = ~np.asarray(self.mocap, dtype=bool)
        self.levels: list[tuple[np.ndarray, np.ndarray]] = []
        for lev in range(1, int(depth.max(initial=0)) + 1):
            bodies = np.flatnonzero((depth == lev) & not_mocap)
            if bodies.size:
                self.levels.append((bodies, par[bodies]))
        # Small trees: (nbody, nq) counts of the qpos columns of each body's chain (its own
        # joints and its ancestors' up to the world or a mocap body), so that "moves" is one
        # matrix-vector product with the (nq,) changed-columns mask.
        self.chain_cols: np.ndarray | None = None
        self.chain_rot_cols: np.ndarray | None = None
        self.chain_both_cols: np.ndarray | None = None
        if nbody * model.nq <= 1 << 16:
            cc = np.zeros((nbody, model.nq), dtype=np.int64)
            cr = np.zeros((nbody, model.nq), dtype=np.int64)
            for b in range(1, nbody):
                if not self.mocap[b]:
                    cc[b] = self.own_cols[b] | (cc[self.parent[b]] > 0)
                    cr[b] = self.own_rot_cols[b] | (cr[self.parent[b]] > 0)
            self.chain_cols, self.chain_rot_cols = cc, cr
            self.chain_both_cols = np.concatenate([cc, cr])  # (2 nbody, nq): one product for both
        # Chains (virtual joints root -> body over the moving bodies) per moving pattern.
        self.chains: dict[bytes, tuple[list[np.ndarray], list[int]]] = {}
        # (moving, rotating, chains) per pattern of changing qpos columns (_flags_and_chains).
        self.flag_cache: dict[bytes, tuple] = {}
        # over bytes, never writable again: Plan.ref_points hands ``ref`` out, and the motion packs
        # and memos derived from it are cached per structure
        self.ref = sealed(_ref_points(model))
        self.ref_norms = sealed(np.linalg.norm(self.ref, axis=-1))   # (nbody,) |ref_b| (m)
        self.ref_norm = float(np.max(self.ref_norms, initial=0.0))
        for arr in (self.mocap_pos0, self.mocap_quat0, self.mocap_rows, self.mocap_ids, self.quat_cols,
                    self.lin, self.body_pos, self.body_quat, self.body_mat, self.vkind, *self.jnt.values()):
            if isinstance(arr, np.ndarray):
                arr.setflags(write=False)


# FK scratch data: one ``MjData`` per (thread, model), shared by that thread's plans of
# the model. ``_fk`` writes every input of ``mj_kinematics`` (qpos, mocap) before each
# call and copies the outputs out, so sharing within a thread is exact; no two
# threads share one (creating an ``MjData`` costs ~0.1-1 ms, more than a small plan).
_FK_POOL = threading.local()
_FK_POOL_MAX = 8


def _fk_data(model: mujoco.MjModel) -> mujoco.MjData:
    """The calling thread's scratch ``MjData`` for ``model``."""
    pool = getattr(_FK_POOL, "data", None)
    if pool is None:
        pool = _FK_POOL.data = {}
    hit = pool.get(id(model))
    if hit is not None and hit[0] is model:
        return hit[1]
    if len(pool) >= _FK_POOL_MAX:
        pool.pop(next(iter(pool)))
    d = mujoco.MjData(model)
    pool[id(model)] = (model, d)  # the model reference keeps id(model) unique
    return d


def _structure_key(model: mujoco.MjModel) -> bytes:
    """Bytes of every model array :class:`_ModelStructure` reads (its cache key).

    Read through the cached views of :func:`_field_views` (the same buffers as
    ``getattr(model, field)``, without building 16 new views per plan); the sizes'
    prefix is cached with them (an MjModel's sizes never change).
    """
    hit = _VIEWS.get(id(model))
    if hit is None or hit[0] is not model:
        _field_views(model)
        hit = _VIEWS[id(model)]
    return b"|".join([hit[2]] + [v.tobytes() for v in hit[1]])


_VIEWS: dict[int, tuple[mujoco.MjModel, list[np.ndarray], bytes]] = {}
_VIEWS_MAX = 16


def _field_views(model: mujoco.MjModel) -> list[np.ndarray]:
    """Views of ``model``'s ``_STRUCT_FIELDS`` arrays, cached per model object.

    Attribute access on an MjModel builds a new view each time; the buffers never move.
    """
    hit = _VIEWS.get(id(model))
    if hit is not None and hit[0] is model:
        return hit[1]
    if len(_VIEWS) >= _VIEWS_MAX:
        _VIEWS.pop(next(iter(_VIEWS)))
    views = [getattr(model, f) for f in _STRUCT_FIELDS]
    sizes = (model.nq, model.nv, model.njnt, model.nbody, model.nmocap, model.ngeom)
    _VIEWS[id(model)] = (model, views, repr(sizes).encode())  # the model reference keeps id(model) unique
    return views


def _normalized(q: np.ndarray, tol: Tolerances) -> np.ndarray | None:
    """``q / |q|`` for quaternions (..., 4) whose norms are all within ``tol.quat_norm_tol`` of 1, else None.

    The same arithmetic as :func:`monitor.motion._kinematics.normalize_quats` (``np.linalg.norm``
    of a real vector is ``sqrt(add.reduce(x * x))``), so the same bits; None (also for a NaN)
    sends the caller to ``normalize_quats``, which raises with the message naming the index.
    """
    n = np.sqrt(np.add.reduce(q * q, axis=-1))
    if not (np.abs(n - 1.0) <= tol.quat_norm_tol).all():
        return None
    return q / n[..., None]


_LAST_MOCAP: list[tuple | None] = [None]
"""[(input bytes, shape, quat_norm_tol, normalised (nmocap, 4))] of the last :func:`_normalized_mocap`."""


def _normalized_mocap(mq: np.ndarray, tol: Tolerances) -> np.ndarray:
    """Held mocap quaternions (nmocap, 4) as a Plan keeps them: ``_normalized``, else its error.

    A gate builds several Plans per step (window, braking tail, both joined) holding the same
    mocap poses, usually the same for a whole episode: the last result is kept and handed out
    as a fresh copy when the input has the same bytes and shape and the tolerance is the same
    (``_normalized`` is a function of those alone, and a result is only kept when it succeeded).
    Else: ``_normalized``, and ``normalize_quats`` (which raises naming the quaternion) when a
    norm is out of tolerance.
    """
    key = mq.tobytes()
    last = _LAST_MOCAP[0]
    if last is not None and last[0] == key and last[1] == mq.shape and last[2] == tol.quat_norm_tol:
        return last[3].copy()
    n = _normalized(mq, tol)
    if n is None:
        return K.normalize_quats("mocap_quat", mq, tol)
    _LAST_MOCAP[0] = (key, mq.shape, tol.quat_norm_tol, n.copy())
    return n


_LAST_STRUCT: dict[int, tuple[mujoco.MjModel, _ModelStructure]] = {}
"""Per model object, the structure :func:`_structure` returned last (a hint: checked by its key)."""


def _structure(model: mujoco.MjModel) -> _ModelStructure:
    """The (cached) :class:`_ModelStructure` of ``model``'s current arrays.

    The key is built from the model's bytes on every call; the structure returned last for
    this model object is taken when its key is equal (one bytes comparison instead of
    hashing the key for the cache lookup), else the cache decides as before.
    """
    key = _structure_key(model)
    last = _LAST_STRUCT.get(id(model))
    if last is not None and last[0] is model and last[1].key == key:
        return last[1]
    st = _STRUCT_CACHE.get(key)
    if st is None:
        st = _ModelStructure(model)
        st.key = key
        st.field_bytes = [v.tobytes() for v in _field_views(model)]
        if len(_STRUCT_CACHE) >= _STRUCT_CACHE_MAX:
            _STRUCT_CACHE.pop(next(iter(_STRUCT_CACHE)))
        _STRUCT_CACHE[key] = st
    if len(_LAST_STRUCT) >= _VIEWS_MAX and id(model) not in _LAST_STRUCT:
        _LAST_STRUCT.pop(next(iter(_LAST_STRUCT)))
    _LAST_STRUCT[id(model)] = (model, st)  # the model reference keeps id(model) unique
    return st


def _flags_and_chains(st: _ModelStructure, changes: np.ndarray) -> tuple:
    """(moving, rotating, (chain_v, own_count)) of a plan whose changing qpos columns are ``changes``.

    Which qpos columns change anywhere in the window, per body chain: a body moves (rotates)
    when one of its own joints or of its ancestors' (up to the world or a mocap body, which is
    a fixed frame) changes. Small trees: one product for both flags; else propagated one tree
    depth at a time (st.levels: the non-mocap bodies of each depth), no loop over bodies.
    Chains (virtual joints root -> body over the moving bodies) are cached per moving pattern.
    A pure function of the structure and ``changes`` (:meth:`Plan._setup` caches it per
    ``changes`` in ``st.flag_cache``); the flag arrays are read-only (shared by plans).
    """
    nbody = st.nbody
    parent = st.parent
    if st.chain_cols is not None:  # small trees: one product for both (all False if nothing changes)
        both = (st.chain_both_cols @ changes.view(np.uint8)) > 0
        moving, rotating = both[:nbody], both[nbody:]
    else:
        moving = np.zeros(nbody, dtype=bool)
        rotating = np.zeros(nbody, dtype=bool)
        if changes.any():
            own_moving = (st.own_cols & changes).any(axis=1)
            own_rot = (st.own_rot_cols & changes).any(axis=1)
            for bodies, parents in st.levels:
                moving[bodies] = own_moving[bodies] | moving[parents]
                rotating[bodies] = own_rot[bodies] | rotating[parents]
    # sealed over bytes (once per pattern: the result is cached per structure): the engine keys its
    # per-scene flag cache on the identity of a Plan's ``_moving``, so it must never change
    moving = sealed(moving)
    rotating = sealed(rotating)
    key = moving.tobytes()
    chains = st.chains.get(key)
    if chains is None:
        own_v = st.own_v
        chain_v: list[np.ndarray] = []
        own_count: list[int] = []
        for b in range(nbody):
            chain: list[int] = []
            c = b
            while c != 0 and moving[c]:
                chain = own_v[c] + chain
                c = parent[c]
            arr = np.array(chain, dtype=np.int64)
            arr.setflags(write=False)
            chain_v.append(arr)
            own_count.append(len(own_v[b]) if moving[b] else 0)
        chains = (chain_v, own_count)
        if len(st.chains) < 64:
            st.chains[key] = chains
    return moving, rotating, chains


class Plan(WindowTimes):
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
        st = _structure(model)
        t = K.check_times(times)
        q = K.as_float_array("qpos", qpos)
        if q.ndim != 2 or q.shape[0] != t.shape[0]:
            raise InvalidInputError(
                f"qpos must have shape (K, nq) = ({t.shape[0]}, {model.nq}), got {q.shape}"
            )
        if q.shape[1] != model.nq:
            raise InvalidInputError(f"qpos has nq = {q.shape[1]} columns, the model has nq = {model.nq}")
        K.check_finite("qpos", q)

        nmocap = st.nmocap
        if mocap_pos is None:
            mp = st.mocap_pos0.copy()
        else:
            mp = K.as_float_array("mocap_pos", mocap_pos)
            if mp.shape != (nmocap, 3):
                raise InvalidInputError(f"mocap_pos must have shape ({nmocap}, 3), got {mp.shape}")
            K.check_finite("mocap_pos", mp)
        if mocap_quat is None:
            mq = st.mocap_quat0.copy()
        else:
            mq = K.as_float_array("mocap_quat", mocap_quat)
            if mq.shape != (nmocap, 4):
                raise InvalidInputError(f"mocap_quat must have shape ({nmocap}, 4), got {mq.shape}")
            K.check_finite("mocap_quat", mq)
        self._setup(model, st, t, q, mp, mq, tolerances)

    @classmethod
    def _trusted(cls, times: np.ndarray, qpos: np.ndarray, model: mujoco.MjModel, *,
                 mocap_pos: np.ndarray, mocap_quat: np.ndarray,
                 tolerances: Tolerances = DEFAULT) -> Plan:
        """Fast constructor for the gate's own rollouts (internal).

        Skips only the checks that hold by construction for arrays the caller
        just made: dtype float64, shapes (K,) / (K, nq) / (nmocap, 3|4), fresh
        (owned, not aliased) arrays. Finiteness, strictly increasing times and the
        quaternion norms are still checked (a diverging simulation can produce
        NaN), and the quaternions are normalised exactly as in ``__init__``, so
        the plan is bit-identical to ``Plan(times, qpos, model, ...)``.
        """
        st = _structure(model)
        self = cls.__new__(cls)
        if times.shape[0] < 2:
            raise InvalidInputError(f"a plan needs at least 2 waypoints, got {times.shape[0]}")
        # strictly increasing with finite ends <=> finite and strictly increasing (NaN fails '>')
        if not ((times[1:] > times[:-1]).all() and -math.inf < times[0] and times[-1] < math.inf):
            K.check_times(times)  # raises with the precise message
        qabs = float(np.abs(qpos).max(initial=0.0))   # NaN / inf -> not < inf (max propagates NaN)
        if not qabs < math.inf:
            K.check_finite("qpos", qpos)
        if mocap_pos.size and not (np.isfinite(mocap_pos).all() and np.isfinite(mocap_quat).all()):
            K.check_finite("mocap_pos", mocap_pos)
            K.check_finite("mocap_quat", mocap_quat)
        self._setup(model, st, times, qpos, mocap_pos, mocap_quat, tolerances, qabs)
        return self

    def _setup(self, model: mujoco.MjModel, st: _ModelStructure, t: np.ndarray, q: np.ndarray,
               mp: np.ndarray, mq: np.ndarray, tolerances: Tolerances, qabs: float | None = None) -> None:
        """Shared tail of the constructors: validated, owned float64 arrays in.

        ``qabs``: ``max |q|`` of the given ``q`` when the caller has it (used only when no
        quaternion is normalised here, i.e. ``q`` is not changed).
        """
        self._model = model
        self._tol = tolerances
        self._st = st
        if mq.size:  # (0, 4) when the model has no mocap body: nothing to normalise
            mq = _normalized_mocap(mq, tolerances)

        # Joint structure.
        self._quat_tracks: dict[int, K.QuatTrack] = {}
        if st.quat_joints:
            # every ball / free quaternion at once (the same arithmetic per quaternion as
            # normalize_quats); a norm out of tolerance: per joint, for the message naming it
            cols = st.quat_cols
            Kq = q.shape[0]
            n = _normalized(q[:, cols].reshape(Kq, -1, 4), tolerances)
            if n is None:
                for _, a, label in st.quat_joints:
                    q[:, a:a + 4] = K.normalize_quats(label, q[:, a:a + 4], tolerances)
            else:
                q[:, cols] = n.reshape(Kq, -1)
            qabs = None
            for j, a, _ in st.quat_joints:
                self._quat_tracks[j] = K.QuatTrack(q[:, a:a + 4])

        self._times = t = sealed(t)   # no setflags(write=True) later: the pack and call memos trust them
        self._qpos = q = sealed(q)
        self._mocap_pos = mp
        self._mocap_quat = mq
        self._seg = K.Segments(t)
        self._tlist = t.tolist()   # the waypoint times as Python floats (_times_ok, _locate)
        self._lin = st.lin
        self._ref = st.ref
        self._jnt_of_body = st.jnt_of_body
        self._jnt = st.jnt
        self._body_pos = st.body_pos
        self._body_quat = st.body_quat
        self._body_mat = st.body_mat
        self._parent = st.parent

        # Which qpos columns change anywhere in the window, per body chain: a body moves
        # (rotates) when one of its own joints or of its ancestors' (up to the world or a
        # mocap body, which is a fixed frame) changes. Propagated one tree depth at a
        # time (st.levels: the non-mocap bodies of each depth), no loop over bodies.
        changes = (q != q[0]).any(axis=0)  # (nq,)
        ckey = changes.tobytes()
        hit = st.flag_cache.get(ckey)   # the flags and chains are a function of (structure, changes)
        if hit is None:
            hit = _flags_and_chains(st, changes)
            if len(st.flag_cache) < 256:
                st.flag_cache[ckey] = hit
        self._moving, self._rotating, chains = hit

        # Virtual joints: one per hinge/slide/ball, two per free joint (translation
        # then rotation about the body origin). kind: 0 hinge, 1 slide, 2 ball,
        # 3 free translation, 4 free rotation. Chains run root -> body over the
        # moving bodies only (a mocap or static ancestor is a constant frame).
        self._vkind = st.vkind
        self._first_v = st.first_v
        self._chain_v, self._own_count = chains

        self._magnitude = {
            "q": (float(np.abs(q).max(initial=0.0)) if qabs is None else qabs) + st.qpos0_mag,
            "path": max((float(tr.cum[-1]) for tr in self._quat_tracks.values()), default=0.0),
        }
        # Waypoint poses (for translation segments and the rounding scale) and the
        # rounding scale are computed on first use (see ``_wp_pos`` / ``_scale``).
        self._wp_cache: tuple[np.ndarray, np.ndarray] | None = None
        self._wp0_cache: tuple[np.ndarray, np.ndarray] | None = None
        self._scale_cache: float | None = None
        self._mb_cache: dict[bytes, MotionBounds] = {}
        self._pose_cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    @property
    def _scratch(self) -> mujoco.MjData:
        """Scratch ``MjData`` for FK (the calling thread's, see ``_fk_data``)."""
        return _fk_data(self._model)

    @property
    def _wp_pos(self) -> np.ndarray:
        """(K, nbody, 3) FK origins at the waypoints (m)."""
        if self._wp_cache is None:
            self._wp_cache = self._fk(self._qpos)
        return self._wp_cache[0]

    @property
    def _wp_mat(self) -> np.ndarray:
        """(K, nbody, 3, 3) FK rotations at the waypoints."""
        if self._wp_cache is None:
            self._wp_cache = self._fk(self._qpos)
        return self._wp_cache[1]

    @property
    def _wp0(self) -> tuple[np.ndarray, np.ndarray]:
        """FK at the first waypoint: origins (nbody, 3) m and rotations (nbody, 3, 3).

        Row 0 of ``_wp_pos`` / ``_wp_mat`` (the same ``mj_kinematics`` call on the same qpos
        row and mocap poses: the same numbers), without the FK at the other waypoints.
        """
        if self._wp_cache is not None:
            return self._wp_cache[0][0], self._wp_cache[1][0]
        if self._wp0_cache is None:
            pos, mat = self._fk(self._qpos[:1])
            self._wp0_cache = (pos[0], mat[0])
        return self._wp0_cache

    @property
    def _scale(self) -> float:
        """Coordinate magnitude of the plan (m), for the rounding pads of the bounds.

        ``S = (max_b (|x_b(m)| + 2 |ref_b| + W_b) + max_b W_b + 3 max_b |ref_b|) * (1 + 2**-30)``
        with m the window's midpoint, x_b(m) the FK origin there and W_b body b's whole-window bound
        computed with scale 0 (module docstring, "Rounding"); ``inf`` if a term is NaN.
        The compiled pack computes the same formula (``batch(BATCH_SCALE)``).
        """
        if self._scale_cache is None:
            ta, tb = self._times[:1].copy(), self._times[-1:].copy()
            whole = self._bounds(ta, tb, scale=0.0, kinds=Plan._bound_kinds)[0][0]   # (nbody,)
            x_m = self._fk(self._qpos_many(0.5 * (ta + tb)))[0][0]                  # (nbody, 3)
            rho = self._st.ref_norms
            per_body = np.linalg.norm(x_m, axis=-1) + 2.0 * rho + whole
            scale = (float(np.max(per_body, initial=0.0)) + float(np.max(whole, initial=0.0))
                     + 3.0 * self._st.ref_norm) * _SCALE_ROUND_UP
            self._scale_cache = scale if scale == scale else math.inf
        return self._scale_cache

    # ------------------------------------------------------------------ basics
    def __repr__(self) -> str:
        return (f"Plan(K={self._times.shape[0]}, window=({self.t0!r}, {self.t1!r}), nq={self._model.nq}, "
                f"moving bodies={int(self._moving.sum())}/{self.nbody})")

    @property
    def model(self) -> mujoco.MjModel:
        """The MuJoCo model of the plan."""
        return self._model

    def is_current(self) -> bool:
        """True if the model arrays frozen at construction still equal the live model's.

        The motion bounds use joint frames, body offsets and reference points copied from
        the model when the plan was built, while the poses come from ``mj_kinematics`` on
        the live model; after an in-place edit of those arrays (``body_pos``, ``jnt_axis``,
        ``geom_pos``, ...) the two disagree. :func:`monitor.certify` then certifies
        :meth:`refreshed` instead.
        """
        # one join of the field bytes and one compare (the key holds the sizes and every
        # field's bytes; same answer as comparing field by field, at about half the cost)
        return _structure_key(self._model) == self._st.key

    def refreshed(self) -> Plan:
        """The same waypoints (times, qpos, held mocap poses) rebuilt on the live model.

        Of the same class: a subclass's own attributes are kept and its overrides (``body_poses``,
        ``motion_bounds``, ...) still define the motion (a plain ``Plan`` here certified the
        waypoints' motion instead of the subclass's after a model edit; red team 10).
        """
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new._setup(self._model, _structure(self._model), self._times.copy(), self._qpos.copy(),
                   self._mocap_pos.copy(), self._mocap_quat.copy(), self._tol)
        return new

    @property
    def qpos(self) -> np.ndarray:
        """(K, nq) waypoint joint positions (quaternions normalised), read-only."""
        return self._qpos

    @property
    def nbody(self) -> int:
        """Number of bodies (world included)."""
        return self._st.nbody  # an MjModel's sizes never change

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
    def _times_ok(self, times: object) -> np.ndarray:
        """``K.check_times_in_window(times, self.window)``: the same (T,) values, or its error.

        A small float64 (T,) array whose every entry lies in the window (NaN and inf do
        not) is checked on Python floats and copied (what the full check returns: a float64
        copy); anything else takes the full check, which raises the error naming the entry.
        Issue 12 (tunnel gate): the full check is ~10 numpy calls per ``body_poses`` query.
        """
        if (type(times) is np.ndarray and times.dtype == np.float64 and times.ndim == 1
                and 0 < times.shape[0] <= 64):
            tl = self._tlist
            w0, w1 = tl[0], tl[-1]
            for x in times.tolist():
                if not (w0 <= x <= w1):
                    break
            else:
                return times.copy()
        return K.check_times_in_window(times, self.window)

    def _locate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``self._seg.locate(t)`` (segment index, local parameter, at_end) for validated times (T,).

        Up to 16 times on Python floats with the same arithmetic as
        :meth:`monitor.motion._kinematics.Segments.locate` (``bisect_right`` is
        ``searchsorted(side="right")``; the same clips, the same IEEE division; NaN stays NaN
        as in ``np.clip``), so the values are bit-identical; more times: ``Segments.locate``.
        """
        if t.shape[0] > 16:
            return self._seg.locate(t)
        tl = self._tlist
        last = len(tl) - 2
        t_end = tl[-1]
        ii, ss, ee = [], [], []
        for x in t.tolist():
            i = bisect_right(tl, x) - 1
            i = 0 if i < 0 else last if i > last else i
            lo = tl[i]
            s = (x - lo) / (tl[i + 1] - lo)
            ii.append(i)
            ss.append(0.0 if s < 0.0 else 1.0 if s > 1.0 else s)
            ee.append(x >= t_end)
        return np.array(ii, np.int64), np.array(ss, np.float64), np.array(ee, bool)

    def _qpos_many(self, t: np.ndarray, loc: tuple | None = None) -> np.ndarray:
        """Interpolated qpos (T, nq) at validated times (T,)."""
        i, s, at_end = self._locate(t) if loc is None else loc
        out = K.lerp_values(self._qpos, i, s, at_end)
        for j, a, _ in self._st.quat_joints:
            out[:, a:a + 4] = self._quat_tracks[j].interp(i, s, at_end)
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
        nbody = m.nbody
        pos = np.empty((T, nbody, 3))
        mat = np.empty((T, nbody, 3, 3))
        if m.nmocap:
            d.mocap_pos[:] = self._mocap_pos
            d.mocap_quat[:] = self._mocap_quat
        # the scratch's arrays once (each attribute read makes a new view of the same buffer)
        qpos, xpos, xmat = d.qpos, d.xpos, d.xmat
        mat9 = mat.reshape(T, nbody, 9)
        kin = mujoco.mj_kinematics
        for k in range(T):
            if not k % 16:
                check_active_budget()
            qpos[:] = Q[k]
            kin(m, d)
            pos[k] = xpos
            mat9[k] = xmat
        return pos, mat

    def body_poses(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World poses at ``times`` (T,) in the window.

        Returns:
            positions (T, nbody, 3) m and rotations R_WB (T, nbody, 3, 3).
        """
        t = self._times_ok(times)
        # Small queries are memoised (several broad-phase stages ask for the same
        # sub-interval midpoints); the poses are a pure function of the times.
        key = t.tobytes() if t.shape[0] <= 64 else None
        hit = self._pose_cache.get(key) if key is not None else None
        if hit is not None:
            return hit[0].copy(), hit[1].copy()
        pos, mat = self._fk(self._qpos_many(t))
        if key is not None and len(self._pose_cache) < 64:
            self._pose_cache[key] = (pos.copy(), mat.copy())
        return pos, mat

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
        # Small queries (e.g. the whole window, asked by several broad-phase
        # stages) are memoised; the bounds are a pure function of the intervals.
        key = (repr(self._bound_kinds).encode() + a.tobytes() + b"|" + b.tobytes()
               if a.shape[0] <= 64 else None)
        hit = self._mb_cache.get(key) if key is not None else None
        if hit is not None:
            return MotionBounds(t0=a, t1=b, trans=hit.trans.copy(), angle=hit.angle.copy())
        trans = np.empty((a.shape[0], self.nbody))
        angle = np.empty((a.shape[0], self.nbody))
        for sl in K.interval_chunks(self._times, a, b, width=max(self._model.nq, 4)):
            trans[sl], angle[sl] = self._bounds(a[sl], b[sl], scale=self._scale)
        out = MotionBounds(t0=a, t1=b, trans=trans, angle=angle)
        if key is not None and len(self._mb_cache) < 64:
            self._mb_cache[key] = MotionBounds(t0=a.copy(), t1=b.copy(), trans=trans.copy(),
                                               angle=angle.copy())
        return out

    def _bounds(self, ta: np.ndarray, tb: np.ndarray, scale: float,
                kinds: tuple[str, ...] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Bounds (N, nbody) for validated sub-intervals; see the module docstring.

        ``kinds`` overrides ``_bound_kinds`` (the rounding scale always uses the defaults).
        """
        kinds = self._bound_kinds if kinds is None else kinds
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
        qmag = self._magnitude["q"]
        dq = np.zeros((N, m.nq))
        dq[:, lin] = K.scalar_deviation(self._qpos[:, lin], Qa[:, lin], Qb[:, lin], Qm[:, lin], iv)
        dq += tol.rel_pad * qmag

        # Single-segment sub-intervals: rates per unit segment parameter s, and the
        # half-width h in s of every sub-interval (from the parameters the
        # interpolation itself computes; t -> s is monotone in floating point).
        # A sub-interval is "single" when ta and tb lie in the midpoint's segment
        # (tb may be its end waypoint, located in the next segment with s = 0).
        use_velocity = "velocity" in kinds
        seg = iv.loc_m[0]
        b_next = (iv.loc_b[0] == seg + 1) & (iv.loc_b[1] == 0.0)
        single = (iv.loc_a[0] == seg) & ((iv.loc_b[0] == seg) | b_next)
        if iv.C:
            single &= ~iv.valid.any(axis=1)
        use_velocity = use_velocity and bool(single.any())
        if use_velocity:
            s_m = iv.loc_m[1]
            s_b = np.where(b_next, 1.0, iv.loc_b[1])
            h = np.maximum(np.maximum(s_b - s_m, s_m - iv.loc_a[1]), 0.0)
            dqs = self._qpos[seg + 1] - self._qpos[seg]  # (N, nq) per unit s

        # Virtual joints at the midpoint, in world coordinates (numpy FK, MuJoCo's rules).
        nv = self._vkind.shape[0]
        # Joint-major layout: gathering a chain copies contiguous (N, ...) slabs.
        anchor = np.zeros((nv, N, 3))
        axis = np.zeros((nv, N, 3))
        coef = np.zeros((nv, N))
        vang = np.zeros((nv, N))
        rate = np.zeros((nv, N, 3))
        J = self._jnt
        jtype = J["type"]
        jadr = J["adr"]
        qpos0 = J["qpos0"]
        frames: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        p_ref: dict[int, np.ndarray] = {}

        def frame(c: int) -> tuple[np.ndarray, np.ndarray]:
            if c in frames:
                return frames[c]
            wp_pos, wp_mat = self._wp0
            return wp_mat[c][None], wp_pos[c][None]  # constant frame (its pose at every time)

        for b in range(1, nbody):
            if not self._moving[b]:
                continue
            check_active_budget()  # a certify budget bounds this stage too (1000-link chains)
            js = self._jnt_of_body[b]
            if js and jtype[js[0]] == _FREE:
                j = js[0]
                a = jadr[j]
                track = self._quat_tracks[j]
                qm = Qm[:, a + 3:a + 7]
                qm = qm / np.linalg.norm(qm, axis=-1, keepdims=True)
                th = K.rotation_deviation(track, qm, iv) + tol.rel_pad * (track.cum[-1] + 1.0)
                dx = K.vector_deviation(self._qpos[:, a:a + 3], Qa[:, a:a + 3], Qb[:, a:a + 3],
                                        Qm[:, a:a + 3], iv) + tol.rel_pad * qmag
                x = Qm[:, a:a + 3].copy()
                R = K.quat_to_mat(qm)
                vt, vr = self._first_v[j], self._first_v[j] + 1
                coef[vt] = dx
                anchor[vr] = x
                coef[vr] = chord(th)
                vang[vr] = th
                if use_velocity:
                    rate[vt] = dqs[:, a:a + 3]
                    rate[vr] = track.angular_velocity(seg, np.ones(N))
            else:
                R_P, x_P = frame(self._parent[b])
                R = R_P @ self._body_mat[b]
                x = x_P + np.einsum("...ij,j->...i", R_P, self._body_pos[b])
                R = np.broadcast_to(R, (N, 3, 3))
                x = np.broadcast_to(x, (N, 3))
                for j in js:
                    v = self._first_v[j]
                    a = jadr[j]
                    typ = jtype[j]
                    axis_w = np.einsum("nij,j->ni", R, J["axis"][j])
                    anchor_w = x + np.einsum("nij,j->ni", R, J["pos"][j])
                    if typ == _HINGE:
                        unit_w = axis_w / J["axis_norm"][j]
                        anchor[v] = anchor_w
                        axis[v] = unit_w
                        coef[v] = chord(dq[:, a])
                        vang[v] = dq[:, a]
                        if use_velocity:
                            rate[v] = dqs[:, a, None] * unit_w
                        R = R @ K.axis_angle_mat(J["axis"][j] / J["axis_norm"][j], Qm[:, a] - qpos0[a])
                        x = anchor_w - np.einsum("nij,j->ni", R, J["pos"][j])
                    elif typ == _SLIDE:
                        coef[v] = dq[:, a] * J["axis_norm"][j]
                        if use_velocity:
                            rate[v] = dqs[:, a, None] * axis_w
                        x = x + axis_w * (Qm[:, a] - qpos0[a])[:, None]
                    else:  # ball
                        track = self._quat_tracks[j]
                        qm = Qm[:, a:a + 4]
                        qm = qm / np.linalg.norm(qm, axis=-1, keepdims=True)
                        th = K.rotation_deviation(track, qm, iv) + tol.rel_pad * (track.cum[-1] + 1.0)
                        anchor[v] = anchor_w
                        coef[v] = chord(th)
                        vang[v] = th
                        if use_velocity:
                            w_loc = track.angular_velocity(seg, np.ones(N))
                            rate[v] = np.einsum("nij,nj->ni", R, w_loc)
                        R = R @ K.quat_to_mat(qm)
                        x = anchor_w - np.einsum("nij,j->ni", R, J["pos"][j])
            frames[b] = (R, x)
            p_ref[b] = x + np.einsum("nij,j->ni", R, self._ref[b])

        vk = self._vkind
        for b in range(1, nbody):
            if not self._moving[b]:
                continue
            check_active_budget()
            ch = self._chain_v[b]
            kind = vk[ch]
            own = self._own_count[b]
            p = p_ref[b]
            D = p[None] - anchor[ch]  # (L, N, 3)
            dist_pt = K.norm3(D)
            lever = np.where(((kind == 2) | (kind == 4))[:, None], dist_pt, 1.0)
            hinge = np.flatnonzero(kind == 0)
            if hinge.size:
                lever[hinge] = K.norm3(K.cross(axis[ch[hinge]], D[hinge]))
            term = coef[ch] * lever  # single-joint deviation bounds at the reference point
            # The levers are differences of world points of size ~scale: absolute rounding.
            rot_lever = ((kind != 1) & (kind != 3))[:, None]
            term = term + tol.rel_pad * scale * np.where(rot_lever, coef[ch], 0.0)
            T_dir = term.sum(axis=0)
            T_own = term[len(ch) - own:].sum(axis=0)
            Th = vang[ch[len(ch) - own:]].sum(axis=0)
            P = self._parent[b]
            T = T_dir
            if P != 0 and self._moving[P] and own < len(ch):
                # Through the parent's bound (valid for its rigid extension).
                T_rec = T_own + trans[:, P] + chord(angle[:, P]) * np.linalg.norm(p - p_ref[P], axis=-1)
                T_dir = T_dir * (1.0 + tol.rel_pad) + tol.abs_pad + tol.scale_pad * scale
                T = np.minimum(T_rec, T_dir)
                Th = Th + angle[:, P]
            if use_velocity:
                T2, Th2 = self._velocity_bound(kind, rate[ch], D, dist_pt, h, qmag, scale)
                T2 = np.where(single, T2, np.inf)
                Th2 = np.where(single, Th2, np.inf)
                if "chain" not in kinds:  # tests: the velocity bound on its own
                    T, Th = T2, Th2
                T = np.minimum(T, T2)
                Th = np.minimum(Th, Th2)
            elif "chain" not in kinds:
                T = np.full(N, np.inf)
                Th = np.full(N, np.inf)
            if self._rotating[b]:
                Th = np.minimum(Th, np.pi)
                angle[:, b] = np.minimum(Th * (1.0 + tol.rel_pad) + tol.abs_pad, np.pi)
            # else: no rotational coordinate changes on the chain, so R_WB(t) is
            # computed from bit-identical inputs and the angle is exactly 0.
            trans[:, b] = T * (1.0 + tol.rel_pad) + tol.abs_pad + tol.scale_pad * scale
        return trans, angle

    def _velocity_bound(self, kind: np.ndarray, w: np.ndarray, D: np.ndarray, r0: np.ndarray,
                        h: np.ndarray, qmag: float, scale: float) -> tuple[np.ndarray, np.ndarray]:
        r"""Second-order bound for one body on sub-intervals inside one segment.

        On one segment every coordinate moves at a constant rate in the segment
        parameter s (hinge/slide: b - a; ball/free: rotation about a fixed axis at
        rate phi_i, see ``QuatTrack.angular_velocity``), so the chain is a
        composition of screw motions at constant rates: rotations omega_k a_k about
        anchors s_k (hinges, balls, the free rotation about the body origin) and
        translations v_k (slides, the free position). At the midpoint the
        reference point p has velocity p' = sum_k J_k, J_k = omega_k a_k x (p - s_k)
        (or v_k), and the body angular velocity is W = sum_k omega_k a_k (exact).
        With Omega_k = sum_{l < k} |omega_l| (joints nearer the root), the axes move as
        a_k' = W_{k-1} x a_k and the anchors as s_k' = sum_{l<k} J_l(s_k), hence
        p' - s_k' = W_{k-1} x (p - s_k) + sum_{l >= k} J_l(p) and

            |J_k'| <= |omega_k| (2 Omega_k r_k + S_k)  (rotations),  |J_k'| <= |v_k| Omega_k  (translations),

        with S_k = sum_{l >= k} (|omega_l| r_l + |v_l|) and r_k >= |p - s_k| over the
        sub-interval: by rule (2) of the module docstring applied to the joints
        beyond k, r_k = |p(m) - s_k(m)| + sum_{l > k} e_l, e_l = chord(|omega_l| h) r_l(m)
        (or |v_l| h). Taylor's theorem with the remainder bound gives

            |p(s) - p(s_m)| <= h |p'(s_m)| + h^2 / 2 * sum_k |J_k'|,
            angle(R(s) R(s_m)^T) <= h |W(s_m)| + h^2 / 2 * sum_k |omega_k| Omega_k,

        h = max |s - s_m| over the sub-interval.

        Args:
            kind: (L,) virtual joint kinds of the chain, root first.
            w: (L, N, 3) rates (world): rotation vectors for rotations, velocities for translations.
            D: (L, N, 3) reference point minus anchor (world, midpoint).
            r0: (L, N) ||D||.
            h: (N,) half-width in the segment parameter.
            qmag: magnitude of the joint coordinates (rounding pad).
            scale: coordinate magnitude of the plan (m): D carries absolute rounding ~u * scale.

        Returns:
            (T2 (N,), Th2 (N,)), rounding padded.
        """
        tol = self._tol
        rot = ((kind == 0) | (kind == 2) | (kind == 4))[:, None]  # (L, 1)
        wabs = K.norm3(w)  # (L, N)
        V = np.where(rot[..., None], K.cross(w, D), w).sum(axis=0)
        W = np.where(rot[..., None], w, 0.0).sum(axis=0)
        r0 = np.where(rot, r0, 0.0)
        e = np.where(rot, chord(wabs * h) * r0, wabs * h)
        suffix_e = np.cumsum(e[::-1], axis=0)[::-1] - e  # joints nearer the body
        r_max = r0 + suffix_e
        w_rot = np.where(rot, wabs, 0.0)
        Omega = np.cumsum(w_rot, axis=0) - w_rot  # joints nearer the root
        S = np.cumsum(np.where(rot, wabs * r_max, wabs)[::-1], axis=0)[::-1]
        A = np.where(rot, wabs * (2.0 * Omega * r_max + S), wabs * Omega).sum(axis=0)
        AW = (w_rot * Omega).sum(axis=0)
        n = kind.shape[0]
        mag = qmag + self._magnitude["path"] + 1.0
        T2 = h * K.norm3(V) + 0.5 * h * h * A
        Th2 = h * K.norm3(W) + 0.5 * h * h * AW
        if n:
            T2 = T2 + tol.rel_pad * (4.0 * h * S[0] + mag * (r_max.sum(axis=0) + n)
                                     + 4.0 * h * w_rot.sum(axis=0) * scale)
            Th2 = Th2 + tol.rel_pad * (4.0 * h * w_rot.sum(axis=0) + mag * n)
        return T2, Th2

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
            # = np.array([t0, t1]), np.stack([p, p]) (fresh float64 arrays), in fewer numpy calls
            return self._times[[0, -1]], p[None].repeat(2, 0)
        if self._rotating[b]:
            return None
        return self._times.copy(), self._wp_pos[:, b].copy()


__all__ = ["Plan"]
