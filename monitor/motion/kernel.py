r"""Compiled forward kinematics and certified motion bounds over a :class:`MotionPack`.

numba, nopython, ``cache=True``; numpy and numba only (no MuJoCo). The arrays come
from :func:`monitor.motion.pack.pack_trajectory`, which packs a :class:`monitor.Plan`
(joint waypoints of a MuJoCo tree) or a :class:`monitor.BodyMotion` (every body a
free-joint child of the world) into one flat :class:`~monitor.motion.pack.MotionPack`.

What is computed is exactly what :mod:`monitor.motion.plan` derives (its module
docstring is THE contract and the derivation; the section names below refer to it):

* **Interpolation.** Piecewise in time, breakpoints at the waypoints. Scalar joint
  coordinates and free-joint positions: ``a + s (b - a)``; ball and free quaternions:
  shortest-arc slerp (``QuatTrack.interp`` of :mod:`monitor.motion._kinematics`, same
  formulas); at the last waypoint time the stored waypoint is returned exactly.
* **Forward kinematics.** MuJoCo's ``mj_kinematics`` rules: X_Wb = X_WP T0 G_1 ... G_n
  in quaternions; a free joint sets the world pose; mocap bodies (and the world) hold
  their packed pose. Equal to ``mj_kinematics`` up to a few ulp.
* **Motion bound** for body b on [ta, tb], midpoint m, w.r.t. ``ref_points[b]``:
  the minimum of (i) the *chain bound* (sum of single-joint deviations of every joint
  root -> b at the world reference point, "Own (local) motion"), (ii) the same through
  the parent's bound ("Parent"), and (iii) on sub-intervals inside one segment the
  second-order *velocity (Taylor) bound* (``Plan._velocity_bound``). Joint deviations
  are the maxima over the vertices {ta, tb, waypoints inside} ("Joint deviations");
  quaternion deviations the slerp path length, plus the exact waypoint angle across
  waypoints (``rotation_deviation``). An interval spanning several segments is thus
  bounded soundly without splitting (the vertex maxima cover every piece).
* **Rounding.** The same pads as ``Plan._bounds``: rel_pad/abs_pad/scale_pad with the
  plan's coordinate scale (computed ONCE at pack time, ``tol[3]``), joint-coordinate
  magnitude ``tol[4]`` and rotation path magnitude ``tol[5]``.
* **Never NaN.** A bound that comes out NaN (overflowing inputs) is returned as
  ``inf`` (translation) / ``pi`` (angle, always valid); callers treat inf as
  "cannot certify".

Compilation: every kernel is ``njit(cache=True, error_model="numpy")``: a division never
raises (no divisor can be 0 on valid packs; an overflow gives inf/NaN, and NaN bounds are
returned as inf/pi as above), which also drops the ZeroDivisionError branches from the code.
Helpers take plain arrays, not the pack: each compiled function taking the 25-array pack
costs about a second of cold compile, so only the entry points take it.
Cold-compile structure (issue 12 item 7, ``docs/notes/issue-12-coldstart.md``): no cfunc
wrapper anywhere and no CPython wrapper on what Python never calls (``no_*_wrapper``);
the thin wrappers :func:`body_bound` and :func:`tree_bounds` are ``inline="always"``
(numba inlines them into their compiled callers, so they are not a separate level: numba
re-optimises and re-emits the whole linked callee tree at every level). Do not inline the
small helpers: numba inlines per call site at the untyped-IR stage, which costs far more
compile time than a separate compile (measured 1.66x slower), and LLVM inlines them anyway.

Reference counting (issue 12, pair-window floor): :func:`_bounds_core` and
:func:`pair_bound` (the motion bound of every test of the window kernel's search, and
of its broad phase) are compiled with ``_nrt=False``: numba emits no NRT incref/decref in
them. With it, every array taken from the pack or a workspace tuple and every row view cost
an out-of-line atomic incref/decref pair: about 0.7 of 1.2 us per ``_bounds_core`` call and
1.1 of 1.7 us per ``pair_bound`` call on a two-body, two-waypoint motion
(docs/notes/issue-12-pairwindow-5.md). The arithmetic is unchanged (the same numbers, bit for
bit). Sound because neither function nor anything it calls allocates, returns or keeps an
array: they read and write arrays their caller owns, and views of them, during the call,
so no reference they would count can be the last one. Keep it that way: numba types the
callees a no-NRT function compiles on first use with its flags, so an allocation anywhere
below these two fails to compile (``_qpos_at`` therefore slerps straight into its output).
``_nrt`` is a private numba option (checked on numba 0.68): the decorators take it through
:data:`NO_NRT`, which is empty when an installed numba no longer has it (then NRT stays on:
slower, the same numbers).

Preconditions (not checked in the kernels, checked by the Python helpers):
``0 <= body < nbody``; ``t0 <= ta <= tb <= t1`` (the window).

Joint type codes are MuJoCo's: 0 free, 1 ball, 2 slide, 3 hinge.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from monitor._jit_cache import bind_caches, purge_if_changed

purge_if_changed()  # before any cached kernel of this package loads (see monitor._jit_cache)


def _no_nrt_option() -> dict[str, bool]:
    """``{"_nrt": False}`` when this numba has its private ``_nrt`` jit option, else ``{}``.

    Without it numba raises "Unrecognized options" at the first call of every function
    compiled with it; with ``{}`` they compile with reference counting on (slower only:
    they allocate nothing, see "Reference counting" above).
    """
    try:
        from numba.core.options import DefaultOptions
    except ImportError:
        return {}
    return {"_nrt": False} if hasattr(DefaultOptions, "_nrt") else {}


NO_NRT = _no_nrt_option()
"""Keyword options of the jit decorators that switch numba's reference counting off (see above)."""

_FREE = 0
_BALL = 1
_SLIDE = 2
_HINGE = 3

# Virtual joint kinds (as in plan.py): 0 hinge, 1 slide, 2 ball, 3 free translation, 4 free rotation.
_V_HINGE = 0
_V_SLIDE = 1
_V_BALL = 2
_V_FREE_T = 3
_V_FREE_R = 4

# Indices into MotionPack.tol.
TOL_REL = 0
TOL_ABS = 1
TOL_SCALE_PAD = 2
TOL_SCALE = 3
TOL_QMAG = 4
TOL_PATHMAG = 5

SCALE_ROUND_UP = 1.0 + 2.0**-30
"""Factor on the rounding scale (``batch(BATCH_SCALE)``; ``plan._SCALE_ROUND_UP``, the same value):
the midpoint origins and the scale-0 whole-window bounds are rounded (FK, norms, sums), so without
it the scale fell 1-2 ulps below the former definition and below a body's FK origin (red team 16:
31 of 4000 plans with a far static body and a child moving by ulps of its distance). 2**-30 is
~4e6 ulps, far above the rounding of any FK chain, and changes pads by ~1e-9 of scale_pad * S."""


# ------------------------------------------------------------------ small helpers
@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _chord(a: float) -> float:
    """2 sin(min(a, pi) / 2)."""
    if a > math.pi:
        a = math.pi
    return 2.0 * math.sin(0.5 * a)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _sinc(x: float) -> float:
    """sin(x) / x (np.sinc(x / pi))."""
    if x == 0.0:
        return 1.0
    return math.sin(x) / x


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _norm3(x: float, y: float, z: float) -> float:
    return math.sqrt(x * x + y * y + z * z)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _search_right(times: np.ndarray, t: float) -> int:
    """Number of entries <= t (np.searchsorted side='right')."""
    lo = 0
    hi = times.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _search_left(times: np.ndarray, t: float) -> int:
    """Number of entries < t (np.searchsorted side='left')."""
    lo = 0
    hi = times.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if times[mid] < t:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _locate(times: np.ndarray, t: float) -> tuple[int, float, bool]:
    """(segment i, parameter s in [0, 1], at_end) as ``Segments.locate``."""
    K = times.shape[0]
    i = _search_right(times, t) - 1
    if i < 0:
        i = 0
    if i > K - 2:
        i = K - 2
    s = (t - times[i]) / (times[i + 1] - times[i])
    if s < 0.0:
        s = 0.0
    if s > 1.0:
        s = 1.0
    return i, s, t >= times[K - 1]


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _quat_mul(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    """Set out = a * b (Hamilton, MuJoCo's mju_mulQuat); out may alias a or b."""
    w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3]
    x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2]
    y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1]
    z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]
    out[0] = w
    out[1] = x
    out[2] = y
    out[3] = z


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _quat_normalize(q: np.ndarray) -> None:
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if n > 0.0:
        q[0] /= n
        q[1] /= n
        q[2] /= n
        q[3] /= n
    else:
        q[0] = 1.0
        q[1] = 0.0
        q[2] = 0.0
        q[3] = 0.0


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _quat_to_mat(q: np.ndarray, R: np.ndarray) -> None:
    """R (3, 3) of a unit quaternion q (w, x, y, z)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    R[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    R[0, 1] = 2.0 * (x * y - w * z)
    R[0, 2] = 2.0 * (x * z + w * y)
    R[1, 0] = 2.0 * (x * y + w * z)
    R[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    R[1, 2] = 2.0 * (y * z - w * x)
    R[2, 0] = 2.0 * (x * z - w * y)
    R[2, 1] = 2.0 * (y * z + w * x)
    R[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _quat_unit(w: float, x: float, y: float, z: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) / its norm, identity for a zero quaternion: :func:`_quat_normalize` on scalars."""
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if n > 0.0:
        return w / n, x / n, y / n, z / n
    return 1.0, 0.0, 0.0, 0.0


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _quat_mat9(w: float, x: float, y: float, z: float) -> tuple:
    """The 9 entries (row-major) of R for a unit quaternion (w, x, y, z).

    :func:`_quat_to_mat`'s expressions, on scalars (the FK's: no array views).
    """
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
            2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _rot_vec(q: np.ndarray, v: np.ndarray, out: np.ndarray) -> None:
    """Set out = R(q) v for a unit quaternion q (v and out (3,), may not alias)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    v0, v1, v2 = v[0], v[1], v[2]
    out[0] = (1.0 - 2.0 * (y * y + z * z)) * v0 + 2.0 * (x * y - w * z) * v1 + 2.0 * (x * z + w * y) * v2
    out[1] = 2.0 * (x * y + w * z) * v0 + (1.0 - 2.0 * (x * x + z * z)) * v1 + 2.0 * (y * z - w * x) * v2
    out[2] = 2.0 * (x * z - w * y) * v0 + 2.0 * (y * z + w * x) * v1 + (1.0 - 2.0 * (x * x + y * y)) * v2


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _quat_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Rotation angle (rad, [0, pi]) of R(a) R(b)^T, as ``_kinematics.quat_angle``."""
    d = 0.0
    s = 0.0
    for k in range(4):
        d += (a[k] - b[k]) ** 2
        s += (a[k] + b[k]) ** 2
    d = math.sqrt(d)
    s = math.sqrt(s)
    return 4.0 * math.atan2(min(d, s), max(d, s))


# ------------------------------------------------------------------ interpolation
@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _lerp_col(qpos: np.ndarray, c: int, i: int, s: float, at_end: bool) -> float:
    """Interpolated qpos column c at (segment i, parameter s)."""
    q = qpos
    if at_end:
        return q[q.shape[0] - 1, c]
    a = q[i, c]
    return a + s * (q[i + 1, c] - a)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _slerp(qpos: np.ndarray, qt_adr: np.ndarray, qt_same: np.ndarray, qt_half: np.ndarray,
           qt_target: np.ndarray, k: int, i: int, s: float, at_end: bool, out: np.ndarray, off: int) -> None:
    """Slerped quaternion of track k (not normalised) into out[off:off + 4], as ``QuatTrack.interp``.

    Reads only ``qpos`` and the track arrays (``out`` may be the qpos vector being filled).
    """
    adr = qt_adr[k]
    q = qpos
    if at_end:
        last = q.shape[0] - 1
        for c in range(4):
            out[off + c] = q[last, adr + c]
        return
    if qt_same[k, i] != 0 or s == 0.0:
        for c in range(4):
            out[off + c] = q[i, adr + c]
        return
    h = qt_half[k, i]
    den = _sinc(h)
    c0 = (1.0 - s) * _sinc((1.0 - s) * h) / den
    c1 = s * _sinc(s * h) / den
    for c in range(4):
        out[off + c] = c0 * q[i, adr + c] + c1 * qt_target[k, i, c]


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _qpos_at(qpos: np.ndarray, qt_adr: np.ndarray, qt_same: np.ndarray, qt_half: np.ndarray,
             qt_target: np.ndarray, i: int, s: float, at_end: bool, out: np.ndarray) -> None:
    """Interpolated qpos (nq,) at (segment i, parameter s).

    Allocates nothing (it is called from :func:`_bounds_core`, compiled without NRT: module
    docstring): each track's slerp is written straight into its four columns of ``out``
    (the same numbers the former scratch copy wrote there).
    """
    nq = qpos.shape[1]
    for c in range(nq):
        out[c] = _lerp_col(qpos, c, i, s, at_end)
    for k in range(qt_adr.shape[0]):
        _slerp(qpos, qt_adr, qt_same, qt_half, qt_target, k, i, s, at_end, out, qt_adr[k])


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _track_path(qt_cum: np.ndarray, qt_phi: np.ndarray, k: int, i: int, s: float) -> float:
    return qt_cum[k, i] + s * qt_phi[k, i]


# ------------------------------------------------------------------ forward kinematics
@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _fk(body_parent: np.ndarray, body_mocap: np.ndarray, body_pos: np.ndarray, body_quat: np.ndarray,
        body_jntadr: np.ndarray, body_jntnum: np.ndarray, jnt_type: np.ndarray, jnt_qposadr: np.ndarray,
        jnt_pos: np.ndarray, jnt_axis: np.ndarray, jnt_axis_norm: np.ndarray, qpos0: np.ndarray,
        q: np.ndarray, need: np.ndarray, xpos: np.ndarray, xquat: np.ndarray, xmat: np.ndarray,
        janchor: np.ndarray, jaxis: np.ndarray, jframe: np.ndarray, tmp3: np.ndarray,
        qloc: np.ndarray) -> None:
    """MuJoCo's mj_kinematics for the bodies with need[b] != 0 (their ancestors must be needed too).

    Args:
        q: (nq,) joint positions.
        need: (nbody,) int mask.
        xpos, xquat, xmat: (nbody, 3), (nbody, 4), (nbody, 3, 3) outputs (world).
        janchor, jaxis: (njnt, 3) world joint anchors and (unnormalised) axes, before each joint acts.
        jframe: (njnt, 4) world orientation of the frame each joint acts in (before the joint).
        tmp3, qloc: (>= 3,), (4,) scratch (no longer written: kept in the signature, which
            every caller passes).

    Written on scalars (issue 12, Arm tail: the former version passed row views such as
    ``xquat[b]`` to ``_quat_mul`` / ``_rot_vec`` / ``_quat_normalize`` / ``_quat_to_mat`` and
    took ~2x as long): each pose is carried in locals and stored once. The expressions are
    those helpers' own, term for term in their order (no fastmath, so no reassociation or
    contraction): the same floats in every output, bit for bit (checked on random trees
    with every joint type and mocap bodies against the former version,
    tests/test_motion_kernel.py).
    """
    nbody = xpos.shape[0]
    for b in range(nbody):
        if need[b] == 0:
            continue
        ja = body_jntadr[b]
        jn = body_jntnum[b]
        if b == 0 or body_mocap[b] != 0:
            px, py, pz = body_pos[b, 0], body_pos[b, 1], body_pos[b, 2]
            w, x, y, z = body_quat[b, 0], body_quat[b, 1], body_quat[b, 2], body_quat[b, 3]
        elif jn >= 1 and jnt_type[ja] == _FREE:
            adr = jnt_qposadr[ja]
            px, py, pz = q[adr], q[adr + 1], q[adr + 2]
            janchor[ja, 0] = px
            janchor[ja, 1] = py
            janchor[ja, 2] = pz
            jaxis[ja, 0] = jnt_axis[ja, 0]
            jaxis[ja, 1] = jnt_axis[ja, 1]
            jaxis[ja, 2] = jnt_axis[ja, 2]
            w, x, y, z = q[adr + 3], q[adr + 4], q[adr + 5], q[adr + 6]
            jframe[ja, 0] = 1.0
            jframe[ja, 1] = 0.0
            jframe[ja, 2] = 0.0
            jframe[ja, 3] = 0.0
        else:
            p = body_parent[b]
            bp0, bp1, bp2 = body_pos[b, 0], body_pos[b, 1], body_pos[b, 2]
            px = xpos[p, 0] + (xmat[p, 0, 0] * bp0 + xmat[p, 0, 1] * bp1 + xmat[p, 0, 2] * bp2)
            py = xpos[p, 1] + (xmat[p, 1, 0] * bp0 + xmat[p, 1, 1] * bp1 + xmat[p, 1, 2] * bp2)
            pz = xpos[p, 2] + (xmat[p, 2, 0] * bp0 + xmat[p, 2, 1] * bp1 + xmat[p, 2, 2] * bp2)
            a0, a1, a2, a3 = xquat[p, 0], xquat[p, 1], xquat[p, 2], xquat[p, 3]
            c0, c1, c2, c3 = body_quat[b, 0], body_quat[b, 1], body_quat[b, 2], body_quat[b, 3]
            w = a0 * c0 - a1 * c1 - a2 * c2 - a3 * c3
            x = a0 * c1 + a1 * c0 + a2 * c3 - a3 * c2
            y = a0 * c2 - a1 * c3 + a2 * c0 + a3 * c1
            z = a0 * c3 + a1 * c2 - a2 * c1 + a3 * c0
            for j in range(ja, ja + jn):
                typ = jnt_type[j]
                adr = jnt_qposadr[j]
                jframe[j, 0] = w
                jframe[j, 1] = x
                jframe[j, 2] = y
                jframe[j, 3] = z
                # _rot_vec(quaternion, v) = R v, R's entries as _rot_vec / _quat_to_mat write them
                r00, r01, r02, r10, r11, r12, r20, r21, r22 = _quat_mat9(w, x, y, z)
                v0, v1, v2 = jnt_pos[j, 0], jnt_pos[j, 1], jnt_pos[j, 2]
                ax = px + (r00 * v0 + r01 * v1 + r02 * v2)
                ay = py + (r10 * v0 + r11 * v1 + r12 * v2)
                az = pz + (r20 * v0 + r21 * v1 + r22 * v2)
                janchor[j, 0] = ax
                janchor[j, 1] = ay
                janchor[j, 2] = az
                v0, v1, v2 = jnt_axis[j, 0], jnt_axis[j, 1], jnt_axis[j, 2]
                jx0 = r00 * v0 + r01 * v1 + r02 * v2
                jx1 = r10 * v0 + r11 * v1 + r12 * v2
                jx2 = r20 * v0 + r21 * v1 + r22 * v2
                jaxis[j, 0] = jx0
                jaxis[j, 1] = jx1
                jaxis[j, 2] = jx2
                if typ == _SLIDE:
                    d = q[adr] - qpos0[adr]
                    px += jx0 * d
                    py += jx1 * d
                    pz += jx2 * d
                    continue
                if typ == _BALL:
                    l0, l1, l2, l3 = _quat_unit(q[adr], q[adr + 1], q[adr + 2], q[adr + 3])
                else:  # hinge
                    ang = q[adr] - qpos0[adr]
                    n = jnt_axis_norm[j]
                    if ang == 0.0:
                        l0, l1, l2, l3 = 1.0, 0.0, 0.0, 0.0
                    else:
                        sh = math.sin(0.5 * ang)
                        l0 = math.cos(0.5 * ang)
                        l1 = sh * jnt_axis[j, 0] / n
                        l2 = sh * jnt_axis[j, 1] / n
                        l3 = sh * jnt_axis[j, 2] / n
                nw = w * l0 - x * l1 - y * l2 - z * l3
                nx = w * l1 + x * l0 + y * l3 - z * l2
                ny = w * l2 - x * l3 + y * l0 + z * l1
                nz = w * l3 + x * l2 - y * l1 + z * l0
                w, x, y, z = nw, nx, ny, nz
                v0, v1, v2 = jnt_pos[j, 0], jnt_pos[j, 1], jnt_pos[j, 2]
                r00, r01, r02, r10, r11, r12, r20, r21, r22 = _quat_mat9(w, x, y, z)
                px = ax - (r00 * v0 + r01 * v1 + r02 * v2)
                py = ay - (r10 * v0 + r11 * v1 + r12 * v2)
                pz = az - (r20 * v0 + r21 * v1 + r22 * v2)
        w, x, y, z = _quat_unit(w, x, y, z)
        xpos[b, 0] = px
        xpos[b, 1] = py
        xpos[b, 2] = pz
        xquat[b, 0] = w
        xquat[b, 1] = x
        xquat[b, 2] = y
        xquat[b, 3] = z
        (xmat[b, 0, 0], xmat[b, 0, 1], xmat[b, 0, 2], xmat[b, 1, 0], xmat[b, 1, 1], xmat[b, 1, 2],
         xmat[b, 2, 0], xmat[b, 2, 1], xmat[b, 2, 2]) = _quat_mat9(w, x, y, z)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True, **NO_NRT)
def mark_ancestors(body_parent: np.ndarray, body: int, need: np.ndarray, value: int) -> None:
    """need[c] = value for body and every ancestor (world included); 2: a frozen base (_bounds_core)."""
    c = body
    while True:
        need[c] = value
        if c == 0:
            break
        c = body_parent[c]


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _ancestors(body_parent: np.ndarray, body: int, need: np.ndarray) -> None:
    """need[c] = 1 for body and every ancestor (world included), 0 elsewhere."""
    need[:] = 0
    mark_ancestors(body_parent, body, need, 1)


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True)
def body_pose(mp, body: int, t: float, p_W_out: np.ndarray, R_WB_out: np.ndarray) -> None:
    """World pose of ``body`` at time ``t``: origin p_W_out (3,) m and rotation R_WB_out (3, 3).

    The float scratch is one array carved into C-contiguous views (two allocations instead of
    ten; the views have the types of the former arrays, so ``_fk`` keeps one specialisation;
    issue 12, kernel cost: ``window_kernel`` calls this once per body of its surviving pairs
    per call, for their start poses).
    """
    nbody = mp.body_parent.shape[0]
    njnt = mp.jnt_type.shape[0]
    nq = mp.qpos.shape[1]
    need = np.empty(nbody, dtype=np.int64)
    _ancestors(mp.body_parent, body, need)
    buf = np.empty(nq + 16 * nbody + 10 * njnt + 8)
    o = nq
    q = buf[0:o]
    xpos = buf[o:o + 3 * nbody].reshape((nbody, 3))
    o += 3 * nbody
    xquat = buf[o:o + 4 * nbody].reshape((nbody, 4))
    o += 4 * nbody
    xmat = buf[o:o + 9 * nbody].reshape((nbody, 3, 3))
    o += 9 * nbody
    ja = buf[o:o + 3 * njnt].reshape((njnt, 3))
    o += 3 * njnt
    jx = buf[o:o + 3 * njnt].reshape((njnt, 3))
    o += 3 * njnt
    jf = buf[o:o + 4 * njnt].reshape((njnt, 4))
    o += 4 * njnt
    i, s, at_end = _locate(mp.times, t)
    _qpos_at(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, i, s, at_end, q)
    _fk(mp.body_parent, mp.body_mocap, mp.body_pos, mp.body_quat, mp.body_jntadr, mp.body_jntnum, mp.jnt_type,
        mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis, mp.jnt_axis_norm, mp.qpos0,
        q, need, xpos, xquat, xmat, ja, jx, jf, buf[o:o + 4], buf[o + 4:o + 8])
    for r in range(3):
        p_W_out[r] = xpos[body, r]
        for c in range(3):
            R_WB_out[r, c] = xmat[body, r, c]


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True)
def tree_poses(mp, t: float, p_W_out: np.ndarray, R_WB_out: np.ndarray) -> None:
    """World poses of every body at time ``t``: p_W_out (nbody, 3), R_WB_out (nbody, 3, 3)."""
    nbody = mp.body_parent.shape[0]
    njnt = mp.jnt_type.shape[0]
    need = np.ones(nbody, dtype=np.int64)
    q = np.empty(mp.qpos.shape[1])
    i, s, at_end = _locate(mp.times, t)
    _qpos_at(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, i, s, at_end, q)
    xquat = np.empty((nbody, 4))
    ja = np.empty((njnt, 3))
    jx = np.empty((njnt, 3))
    jf = np.empty((njnt, 4))
    _fk(mp.body_parent, mp.body_mocap, mp.body_pos, mp.body_quat, mp.body_jntadr, mp.body_jntnum, mp.jnt_type,
        mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis, mp.jnt_axis_norm, mp.qpos0,
        q, need, p_W_out, xquat, R_WB_out, ja, jx, jf, np.empty(4), np.empty(4))


# ------------------------------------------------------------------ joint deviations
@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _col_dev(qpos: np.ndarray, c: int, qm_c: float, la, lb, lo: int, hi: int) -> float:
    """Maximum over the vertices of |q_c(t) - q_c(m)| (scalar_deviation)."""
    va = _lerp_col(qpos, c, la[0], la[1], la[2])
    vb = _lerp_col(qpos, c, lb[0], lb[1], lb[2])
    dev = max(abs(va - qm_c), abs(vb - qm_c))
    for w in range(lo, hi):
        d = abs(qpos[w, c] - qm_c)
        if d > dev:
            dev = d
    return dev


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _vec_dev(qpos: np.ndarray, adr: int, qm: np.ndarray, la, lb, lo: int, hi: int) -> float:
    """Maximum over the vertices of ||x(t) - x(m)|| for qpos columns adr..adr+2 (vector_deviation)."""
    da = 0.0
    db = 0.0
    for c in range(3):
        da += (_lerp_col(qpos, adr + c, la[0], la[1], la[2]) - qm[adr + c]) ** 2
        db += (_lerp_col(qpos, adr + c, lb[0], lb[1], lb[2]) - qm[adr + c]) ** 2
    dev = max(math.sqrt(da), math.sqrt(db))
    for w in range(lo, hi):
        d = 0.0
        for c in range(3):
            d += (qpos[w, adr + c] - qm[adr + c]) ** 2
        d = math.sqrt(d)
        if d > dev:
            dev = d
    return dev


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _rot_dev(times: np.ndarray, qpos: np.ndarray, qt_adr: np.ndarray, qt_cum: np.ndarray, qt_phi: np.ndarray,
             k: int, qm_unit: np.ndarray, ta: float, tb: float, tm: float, lm, lo: int, hi: int) -> float:
    """Bound on the rotation angle of track k from the midpoint over [ta, tb] (rotation_deviation)."""
    K = times.shape[0]
    s_m = _track_path(qt_cum, qt_phi, k, lm[0], lm[1])
    # the waypoints strictly before / after m (not the segment of m: on a sub-interval one ulp
    # long m rounds to tb, and tb's own segment would leave [ta, m] out)
    near_left = min(max(times[max(_search_left(times, tm) - 1, 0)], ta), tm)
    near_right = max(min(times[min(_search_right(times, tm), K - 1)], tb), tm)
    i_l, s_l, _ = _locate(times, near_left)
    i_r, s_r, _ = _locate(times, near_right)
    dev = max(abs(s_m - _track_path(qt_cum, qt_phi, k, i_l, s_l)),
              abs(_track_path(qt_cum, qt_phi, k, i_r, s_r) - s_m))
    adr = qt_adr[k]
    for w in range(lo, hi):
        d_w = _quat_angle(qpos[w, adr:adr + 4], qm_unit)
        if times[w] <= tm:
            outer = max(times[max(w - 1, 0)], ta)
        else:
            outer = min(times[min(w + 1, K - 1)], tb)
        i_o, s_o, _ = _locate(times, outer)
        v = d_w + abs(_track_path(qt_cum, qt_phi, k, i_o, s_o) - qt_cum[k, w])
        if v > dev:
            dev = v
    return min(dev, math.pi)


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _track_omega(qpos: np.ndarray, qt_adr: np.ndarray, qt_target: np.ndarray, qt_phi: np.ndarray, k: int,
                 seg: int, out: np.ndarray) -> None:
    """Angular velocity (3,) per unit segment parameter of track k on segment seg.

    ``QuatTrack.angular_velocity`` with dt = 1, in the frame the quaternions map into.
    """
    adr = qt_adr[k]
    a = qpos[seg, adr:adr + 4]
    b = qt_target[k, seg]
    # vector part of b * conj(a)
    vx = -b[0] * a[1] + b[1] * a[0] - b[2] * a[3] + b[3] * a[2]
    vy = -b[0] * a[2] + b[1] * a[3] + b[2] * a[0] - b[3] * a[1]
    vz = -b[0] * a[3] - b[1] * a[2] + b[2] * a[1] + b[3] * a[0]
    sc = 2.0 / _sinc(0.5 * qt_phi[k, seg])
    out[0] = vx * sc
    out[1] = vy * sc
    out[2] = vz * sc


# ------------------------------------------------------------------ bounds
@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _velocity_bound(chain: np.ndarray, vkind: np.ndarray, vrate: np.ndarray, D: np.ndarray,
                    r0: np.ndarray, suffix: np.ndarray, rmax: np.ndarray, h: float, rel: float, qmag: float,
                    pathmag: float, scale: float) -> tuple[float, float]:
    """Second-order (Taylor) bound (T2 m, Th2 rad) for one chain: ``Plan._velocity_bound``, same pads.

    chain (L,) virtual joints root first; D (L, 3) reference point minus anchors, r0 (L,) their norms;
    suffix, rmax: (>= L,) scratch.
    """
    L = chain.shape[0]
    Vx = 0.0
    Vy = 0.0
    Vz = 0.0
    Wx = 0.0
    Wy = 0.0
    Wz = 0.0
    acc = 0.0
    for li in range(L - 1, -1, -1):  # suffix sums of e (joints nearer the body)
        v = chain[li]
        kd = vkind[v]
        rot = kd == _V_HINGE or kd == _V_BALL or kd == _V_FREE_R
        wabs = _norm3(vrate[v, 0], vrate[v, 1], vrate[v, 2])
        suffix[li] = acc
        if rot:
            e = _chord(wabs * h) * r0[li]
        else:
            e = wabs * h
        acc += e
    S_acc = 0.0
    S0 = 0.0
    sum_rmax = 0.0
    for li in range(L - 1, -1, -1):
        v = chain[li]
        kd = vkind[v]
        rot = kd == _V_HINGE or kd == _V_BALL or kd == _V_FREE_R
        wabs = _norm3(vrate[v, 0], vrate[v, 1], vrate[v, 2])
        rm = (r0[li] if rot else 0.0) + suffix[li]
        rmax[li] = rm
        sum_rmax += rm
        S_acc += wabs * rm if rot else wabs
        suffix[li] = S_acc  # now S_k
    if L > 0:
        S0 = suffix[0]
    Omega = 0.0
    A = 0.0
    AW = 0.0
    wrot_sum = 0.0
    for li in range(L):
        v = chain[li]
        kd = vkind[v]
        rot = kd == _V_HINGE or kd == _V_BALL or kd == _V_FREE_R
        w0, w1, w2 = vrate[v, 0], vrate[v, 1], vrate[v, 2]
        wabs = _norm3(w0, w1, w2)
        if rot:
            Vx += w1 * D[li, 2] - w2 * D[li, 1]
            Vy += w2 * D[li, 0] - w0 * D[li, 2]
            Vz += w0 * D[li, 1] - w1 * D[li, 0]
            Wx += w0
            Wy += w1
            Wz += w2
            A += wabs * (2.0 * Omega * rmax[li] + suffix[li])
            AW += wabs * Omega
            Omega += wabs
            wrot_sum += wabs
        else:
            Vx += w0
            Vy += w1
            Vz += w2
            A += wabs * Omega
    mag = qmag + pathmag + 1.0
    T2 = h * _norm3(Vx, Vy, Vz) + 0.5 * h * h * A
    Th2 = h * _norm3(Wx, Wy, Wz) + 0.5 * h * h * AW
    if L > 0:
        T2 += rel * (4.0 * h * S0 + mag * (sum_rmax + L) + 4.0 * h * wrot_sum * scale)
        Th2 += rel * (4.0 * h * wrot_sum + mag * L)
    return T2, Th2

@njit(cache=True, error_model="numpy", no_cpython_wrapper=True, no_cfunc_wrapper=True, **NO_NRT)
def _bounds_core(mp, ta: float, tb: float, need: np.ndarray, xpos: np.ndarray, xmat: np.ndarray,
                 trans: np.ndarray, angle: np.ndarray, ws) -> None:
    """Poses at m = (ta + tb) / 2 and bounds over [ta, tb] for the bodies with need[b] != 0.

    ``need`` must be closed under ancestors. Fills xpos (nbody, 3), xmat (nbody, 3, 3),
    trans (nbody,) m and angle (nbody,) rad for those bodies (0 for static ones).
    ``need[b] == 2`` marks a *frozen base* (issue 12, hand30): a body and all its ancestors
    (closed under ancestors) held at their poses at m. Their bounds are 0 and the chains of
    the other bodies stop at them, so a body below the base gets the bound of its motion
    *relative to the base*: of the motion X_WC(m) X_WC(t)^-1 X_Wb(t) (C the deepest frozen
    body; C itself gets the pads of a zero bound, ``abs_pad + scale_pad scale`` and ``abs_pad``
    rad when it rotates), a chain rooted at a fixed frame, to which the chain, parent and velocity bounds
    apply as to a chain rooted at the world (the same joints' coordinates, anchors and axes
    at m; the rigid map X_WC(m) X_WC(t)^-1 is the identity at m). Poses (xpos, xmat) are
    the world poses at m in every case. With no 2 in ``need`` the numbers are the absolute
    bounds, bit for bit as before.
    ``ws``: the scratch arrays of :func:`bounds_workspace` (contents on entry do not matter:
    the arrays that must start at zero are zeroed here), so a caller that evaluates many
    sub-intervals allocates them once (issue 12, long windows: the ~20 allocations were
    about half of a bound's cost). The results are the same numbers as with fresh arrays.

    Compiled without numba's reference counting (module docstring, "Reference counting").
    """
    rel = mp.tol[TOL_REL]
    abs_pad = mp.tol[TOL_ABS]
    scale_pad = mp.tol[TOL_SCALE_PAD]
    scale = mp.tol[TOL_SCALE]
    qmag = mp.tol[TOL_QMAG]
    pathmag = mp.tol[TOL_PATHMAG]
    times = mp.times
    nbody = xpos.shape[0]

    tm = 0.5 * (ta + tb)
    la = _locate(times, ta)
    lb = _locate(times, tb)
    lm = _locate(times, tm)
    lo = _search_right(times, ta)
    hi = _search_left(times, tb)
    (qm, xquat, janchor, jaxis, jframe, vkind, vanchor, vaxis, vcoef, vang, vrate, qu, om, chain, stack,
     p_ref, D, r0, suffix, rmax) = ws
    _qpos_at(mp.qpos, mp.qt_adr, mp.qt_same, mp.qt_half, mp.qt_target, lm[0], lm[1], lm[2], qm)
    _fk(mp.body_parent, mp.body_mocap, mp.body_pos, mp.body_quat, mp.body_jntadr, mp.body_jntnum, mp.jnt_type,
        mp.jnt_qposadr, mp.jnt_pos, mp.jnt_axis, mp.jnt_axis_norm, mp.qpos0,
        qm, need, xpos, xquat, xmat, janchor, jaxis, jframe, om, qu)   # (om, qu: scratch until set below)

    # Single-segment sub-interval: the velocity bound applies.
    seg = lm[0]
    b_next = lb[0] == seg + 1 and lb[1] == 0.0
    single = la[0] == seg and (lb[0] == seg or b_next) and hi <= lo
    h = 0.0
    if single:
        s_b = 1.0 if b_next else lb[1]
        h = max(max(s_b - lm[1], lm[1] - la[1]), 0.0)

    # Virtual joints (2 slots per joint: [2j] translation / single, [2j+1] free rotation).
    # (the slots of joints that are not set below must read 0, as fresh np.zeros)
    vanchor[:] = 0.0
    vaxis[:] = 0.0
    vcoef[:] = 0.0
    vang[:] = 0.0
    vrate[:] = 0.0
    for b in range(1, nbody):
        if need[b] != 1 or mp.body_moving[b] == 0:   # (need 2: a frozen base, see the docstring)
            continue
        for j in range(mp.body_jntadr[b], mp.body_jntadr[b] + mp.body_jntnum[b]):
            typ = mp.jnt_type[j]
            adr = mp.jnt_qposadr[j]
            v = 2 * j
            if typ == _FREE or typ == _BALL:
                k = mp.jnt_track[j]
                qa = adr + 3 if typ == _FREE else adr
                for c in range(4):
                    qu[c] = qm[qa + c]
                _quat_normalize(qu)
                th = _rot_dev(times, mp.qpos, mp.qt_adr, mp.qt_cum, mp.qt_phi, k, qu, ta, tb, tm, lm, lo, hi)
                th += rel * (mp.qt_cum[k, times.shape[0] - 1] + 1.0)
                if single:
                    _track_omega(mp.qpos, mp.qt_adr, mp.qt_target, mp.qt_phi, k, seg, om)
                if typ == _FREE:
                    dx = _vec_dev(mp.qpos, adr, qm, la, lb, lo, hi) + rel * qmag
                    vkind[v] = _V_FREE_T
                    vcoef[v] = dx
                    vkind[v + 1] = _V_FREE_R
                    for c in range(3):
                        vanchor[v + 1, c] = xpos[b, c]
                    vcoef[v + 1] = _chord(th)
                    vang[v + 1] = th
                    if single:
                        for c in range(3):
                            vrate[v, c] = mp.qpos[seg + 1, adr + c] - mp.qpos[seg, adr + c]
                            vrate[v + 1, c] = om[c]
                else:
                    vkind[v] = _V_BALL
                    for c in range(3):
                        vanchor[v, c] = janchor[j, c]
                    vcoef[v] = _chord(th)
                    vang[v] = th
                    if single:
                        _rot_vec(jframe[j], om[:3], vrate[v])
            else:
                dq = _col_dev(mp.qpos, adr, qm[adr], la, lb, lo, hi) + rel * qmag
                rate = (mp.qpos[seg + 1, adr] - mp.qpos[seg, adr]) if single else 0.0
                if typ == _HINGE:
                    n = mp.jnt_axis_norm[j]
                    vkind[v] = _V_HINGE
                    for c in range(3):
                        vanchor[v, c] = janchor[j, c]
                        vaxis[v, c] = jaxis[j, c] / n
                        vrate[v, c] = rate * vaxis[v, c]
                    vcoef[v] = _chord(dq)
                    vang[v] = dq
                else:  # slide
                    vkind[v] = _V_SLIDE
                    vcoef[v] = dq * mp.jnt_axis_norm[j]
                    for c in range(3):
                        vrate[v, c] = rate * jaxis[j, c]

    # Per body: chain root -> body over the moving bodies.
    for b in range(nbody):
        if need[b] == 0:
            continue
        for r in range(3):
            rp = mp.ref_points[b]
            p_ref[b, r] = xpos[b, r] + (xmat[b, r, 0] * rp[0] + xmat[b, r, 1] * rp[1] + xmat[b, r, 2] * rp[2])
        if b == 0 or mp.body_moving[b] == 0:
            trans[b] = 0.0
            angle[b] = 0.0
            continue
        if need[b] == 2:
            # a frozen base: no motion relative to itself; the pads of a zero bound (below)
            # still cover the rounding of its computed pose at m, as for any moving body
            angle[b] = abs_pad if mp.body_rotating[b] != 0 else 0.0
            trans[b] = abs_pad + scale_pad * scale
            continue
        # Ancestors (moving, below a frozen base) root-first.
        ns = 0
        c = b
        while c != 0 and mp.body_moving[c] != 0 and need[c] != 2:
            stack[ns] = c
            ns += 1
            c = mp.body_parent[c]
        L = 0
        own_start = 0
        for si in range(ns - 1, -1, -1):
            cb = stack[si]
            if cb == b:
                own_start = L
            for j in range(mp.body_jntadr[cb], mp.body_jntadr[cb] + mp.body_jntnum[cb]):
                chain[L] = 2 * j
                L += 1
                if mp.jnt_type[j] == _FREE:
                    chain[L] = 2 * j + 1
                    L += 1
        # Chain terms at the world reference point.
        T_dir = 0.0
        T_own = 0.0
        Th = 0.0
        for li in range(L):
            v = chain[li]
            kd = vkind[v]
            dx = p_ref[b, 0] - vanchor[v, 0]
            dy = p_ref[b, 1] - vanchor[v, 1]
            dz = p_ref[b, 2] - vanchor[v, 2]
            D[li, 0] = dx
            D[li, 1] = dy
            D[li, 2] = dz
            dist = _norm3(dx, dy, dz)
            r0[li] = dist
            if kd == _V_HINGE:
                ax = vaxis[v]
                lever = _norm3(ax[1] * dz - ax[2] * dy, ax[2] * dx - ax[0] * dz, ax[0] * dy - ax[1] * dx)
            elif kd == _V_BALL or kd == _V_FREE_R:
                lever = dist
            else:
                lever = 1.0
            term = vcoef[v] * lever
            if kd != _V_SLIDE and kd != _V_FREE_T:
                term += rel * scale * vcoef[v]
            T_dir += term
            if li >= own_start:
                T_own += term
                Th += vang[v]
        P = mp.body_parent[b]
        T = T_dir
        if P != 0 and mp.body_moving[P] != 0 and own_start > 0:
            dpx = p_ref[b, 0] - p_ref[P, 0]
            dpy = p_ref[b, 1] - p_ref[P, 1]
            dpz = p_ref[b, 2] - p_ref[P, 2]
            T_rec = T_own + trans[P] + _chord(angle[P]) * _norm3(dpx, dpy, dpz)
            T_dir = T_dir * (1.0 + rel) + abs_pad + scale_pad * scale
            T = min(T_rec, T_dir)
            Th = Th + angle[P]
        if single:
            T2, Th2 = _velocity_bound(chain[:L], vkind, vrate, D, r0, suffix, rmax, h, rel, qmag, pathmag,
                                      scale)
            T = min(T, T2)
            Th = min(Th, Th2)
        if mp.body_rotating[b] != 0:
            Th = min(Th, math.pi)
            a_out = min(Th * (1.0 + rel) + abs_pad, math.pi)
            if not (a_out >= 0.0):  # NaN
                a_out = math.pi
            angle[b] = a_out
        else:
            angle[b] = 0.0
        t_out = T * (1.0 + rel) + abs_pad + scale_pad * scale
        if not (t_out >= 0.0):  # NaN
            t_out = math.inf
        trans[b] = t_out


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True, inline="always")
def bounds_workspace(mp):
    """Scratch arrays of :func:`_bounds_core` for the pack ``mp`` (a tuple; see there)."""
    nbody = mp.body_parent.shape[0]
    njnt = mp.jnt_type.shape[0]
    nq = mp.qpos.shape[1]
    nv = 2 * njnt
    return (np.empty(nq), np.empty((nbody, 4)), np.empty((njnt, 3)), np.empty((njnt, 3)), np.empty((njnt, 4)),
            np.empty(nv, dtype=np.int64), np.zeros((nv, 3)), np.zeros((nv, 3)), np.zeros(nv), np.zeros(nv),
            np.zeros((nv, 3)), np.empty(4), np.empty(4), np.empty(nv, dtype=np.int64),
            np.empty(nbody, dtype=np.int64), np.empty((nbody, 3)), np.empty((nv, 3)), np.empty(nv),
            np.empty(nv), np.empty(nv))


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True, inline="always")
def pair_workspace(mp):
    """Scratch of :func:`pair_bound`: (need, xpos, xmat, trans, angle, :func:`bounds_workspace`)."""
    nbody = mp.body_parent.shape[0]
    return (np.empty(nbody, dtype=np.int64), np.empty((nbody, 3)), np.empty((nbody, 3, 3)), np.zeros(nbody),
            np.zeros(nbody), bounds_workspace(mp))


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True, **NO_NRT)
def pair_bound(mp, ba: int, bb: int, ta: float, tb: float, pA_out: np.ndarray, RA_out: np.ndarray,
               pB_out: np.ndarray, RB_out: np.ndarray, pws,
               relative: int) -> tuple[float, float, float, float]:
    """:func:`body_bound` of two bodies in ONE pass over the union of their chains.

    Returns (trans_a m, angle_a rad, trans_b, angle_b) and writes each body's pose at
    m = (ta + tb) / 2 into (pA_out, RA_out) / (pB_out, RB_out). A body index < 0 is
    skipped: (0, 0) and its outputs left as they are (the caller's constant pose of a body
    the motion does not move). ``pws``: :func:`pair_workspace` (allocated once per caller).

    Same numbers as two :func:`body_bound` calls: in :func:`_bounds_core` a body's pose and
    bound depend only on its own ancestors (FK root first, the chain terms, the parent's
    bound), never on which other bodies are in ``need``; the union is closed under ancestors.

    ``relative != 0`` (issue 12, hand30): when both bodies are given and their deepest common
    ancestor C is not the world and moves, C and its ancestors are frozen at their poses at m
    (:func:`_bounds_core`, ``need == 2``: C's own bound is then just the rounding pads of a zero
    bound) and the bounds are those of the motion relative to C,
    ``X_WC(m) X_WC(t)^-1 X_Wb(t)`` (C = ba or bb itself when one is the other's ancestor). That
    map applies ONE rigid transform per time to both bodies, so the distance of any two points
    of theirs at t is the one of the mapped points: a lower bound on the distance of the pair
    from these bounds holds for the real motion (only distances of the pair may be derived from
    them, not world positions). The poses written are the world poses at m, as before.
    ``relative == 0``, or no such C: the absolute bounds (two ``body_bound`` calls' numbers).

    Compiled without reference counting (module docstring) and NOT inlined into its callers:
    numba's IR inlining binds the inlined parameters to new variables, and in a caller with
    reference counting each binding of ``mp`` and ``pws`` (25 arrays each) costs an
    incref/decref pair per array, about 0.5 us per call at K = 2; a plain call borrows them.
    """
    need, xpos, xmat, trans, angle, ws = pws
    need[:] = 0
    base = 0                  # the deepest common ancestor: the first body of bb's path already marked
    for body in (ba, bb):
        if body >= 0:
            c = body
            while True:
                if need[c] != 0:
                    base = c
                    break
                need[c] = 1
                if c == 0:
                    break
                c = mp.body_parent[c]
    if relative != 0 and ba >= 0 and bb >= 0 and base != 0 and mp.body_moving[base] != 0:
        mark_ancestors(mp.body_parent, base, need, 2)
    _bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, ws)
    TA, angA, TB, angB = 0.0, 0.0, 0.0, 0.0
    if ba >= 0:
        TA, angA = trans[ba], angle[ba]
        for r in range(3):
            pA_out[r] = xpos[ba, r]
            for c in range(3):
                RA_out[r, c] = xmat[ba, r, c]
    if bb >= 0:
        TB, angB = trans[bb], angle[bb]
        for r in range(3):
            pB_out[r] = xpos[bb, r]
            for c in range(3):
                RB_out[r, c] = xmat[bb, r, c]
    return TA, angA, TB, angB


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True, inline="always")
def body_bound(mp, body: int, ta: float, tb: float, p_W_out: np.ndarray,
               R_WB_out: np.ndarray) -> tuple[float, float]:
    """Pose of ``body`` at m = (ta + tb) / 2 and its certified (trans m, angle rad) over [ta, tb].

    The motion-bound contract of :mod:`monitor.motion.base` w.r.t. ``mp.ref_points[body]``.
    Outputs: p_W_out (3,), R_WB_out (3, 3).
    """
    nbody = mp.body_parent.shape[0]
    need = np.empty(nbody, dtype=np.int64)
    _ancestors(mp.body_parent, body, need)
    xpos = np.empty((nbody, 3))
    xmat = np.empty((nbody, 3, 3))
    trans = np.zeros(nbody)
    angle = np.zeros(nbody)
    _bounds_core(mp, ta, tb, need, xpos, xmat, trans, angle, bounds_workspace(mp))
    for r in range(3):
        p_W_out[r] = xpos[body, r]
        for c in range(3):
            R_WB_out[r, c] = xmat[body, r, c]
    return trans[body], angle[body]


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True, inline="always")
def tree_bounds(mp, ta: float, tb: float, p_W_out: np.ndarray, R_WB_out: np.ndarray,
                trans_out: np.ndarray, angle_out: np.ndarray) -> None:
    """Poses at m = (ta + tb) / 2 and certified bounds over [ta, tb] of every body, in one pass.

    Outputs: p_W_out (nbody, 3), R_WB_out (nbody, 3, 3), trans_out (nbody,) m, angle_out (nbody,) rad.
    """
    nbody = mp.body_parent.shape[0]
    need = np.ones(nbody, dtype=np.int64)
    _bounds_core(mp, ta, tb, need, p_W_out, R_WB_out, trans_out, angle_out, bounds_workspace(mp))


BATCH_BOUNDS = 0
BATCH_POSES = 1
BATCH_SCALE = 2


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True)
def batch(mp, mode: int, t0: np.ndarray, t1: np.ndarray, pos: np.ndarray, rot: np.ndarray,
          trans: np.ndarray, angle: np.ndarray) -> float:
    """Batched entry point of the Python helpers (one compiled function for all three modes).

    Each compiled function that takes the 25-array pack costs about a second of cold
    compile, so the helpers share this one.

    * ``BATCH_BOUNDS``: tree_bounds for N sub-intervals [t0[n], t1[n]]: pos (N, nbody, 3),
      rot (N, nbody, 3, 3), trans/angle (N, nbody). Returns 0.
    * ``BATCH_POSES``: tree_poses at the N times t0: pos, rot. Returns 0.
    * ``BATCH_SCALE``: the rounding scale of the trajectory (m), as ``Plan._scale``: from the
      whole-window bounds computed with scale 0 and the poses at the window's midpoint,
      ``(max_b (|x_b(m)| + 2 |ref_b| + W_b) + max_b W_b + 3 max_b |ref_b|) * SCALE_ROUND_UP`` (no FK
      at the waypoints; ``inf`` if a term is NaN). ``mp.tol[3]`` must be 0 when this is called.
      pos/rot/trans/angle: (1, nbody, ...) scratch; on return they hold the whole-window
      poses at the midpoint and bounds.
    """
    if mode == BATCH_BOUNDS:
        for n in range(t0.shape[0]):
            tree_bounds(mp, t0[n], t1[n], pos[n], rot[n], trans[n], angle[n])
        return 0.0
    if mode == BATCH_POSES:
        for n in range(t0.shape[0]):
            tree_poses(mp, t0[n], pos[n], rot[n])
        return 0.0
    # The scale from ONE whole-window pass (issue 12, packscale): with m the window's midpoint,
    # W_b / A_b body b's whole-window bounds (computed here with scale 0) and rho_b = |ref_b|,
    # every origin satisfies |x_b(t)| <= |x_b(m)| + W_b + chord(A_b) rho_b <= |x_b(m)| + W_b + 2 rho_b
    # (rule (1) of plan.py about the reference point), so
    #     S = max_b (|x_b(m)| + 2 rho_b + W_b) + max_b W_b + 3 max_b rho_b
    # is >= the former definition (max over waypoints and bodies of |x_b(t_k)|, + max W + 3 max rho)
    # and every pad grows with S (plan.py, "Rounding"). No FK at the K waypoints.
    nbody = mp.body_parent.shape[0]
    K = mp.times.shape[0]
    tree_bounds(mp, mp.times[0], mp.times[K - 1], pos[0], rot[0], trans[0], angle[0])
    ref_norm = 0.0
    whole = 0.0
    body = 0.0
    for b in range(nbody):
        rho = _norm3(mp.ref_points[b, 0], mp.ref_points[b, 1], mp.ref_points[b, 2])
        if rho > ref_norm:
            ref_norm = rho
        w = trans[0, b]
        if w > whole:
            whole = w
        v = _norm3(pos[0, b, 0], pos[0, b, 1], pos[0, b, 2]) + 2.0 * rho + w
        if v > body:
            body = v
        elif v != v:               # NaN (overflowing coordinates): no finite scale
            body = math.inf
    scale = (body + whole + 3.0 * ref_norm) * SCALE_ROUND_UP    # (rounding: see SCALE_ROUND_UP)
    return scale if scale == scale else math.inf


@njit(cache=True, error_model="numpy", no_cfunc_wrapper=True)
def derive(qpos: np.ndarray, body_parent: np.ndarray, body_mocap: np.ndarray, body_jntadr: np.ndarray,
           body_jntnum: np.ndarray, jnt_type: np.ndarray, jnt_qposadr: np.ndarray, moving: np.ndarray,
           rotating: np.ndarray, tol: np.ndarray) -> None:
    """Per-trajectory flags and joint magnitude of a pack (outputs: moving, rotating, tol[4]).

    (nbody,) int flags: some (rotational) coordinate on the body's chain changes in the
    window (mocap bodies and the world never move); tol[4] = max |qpos|. The quaternion
    tracks are NOT derived here: they are copied from the trajectory's own ``QuatTrack``
    objects (the slerp branch is decided by the sign of a dot product that can be +-0 by
    rounding at a half turn; only the very same arithmetic picks the same arc).
    """
    K = qpos.shape[0]
    nq = qpos.shape[1]
    qmag = 0.0
    for k in range(K):
        for c in range(nq):
            v = abs(qpos[k, c])
            if v > qmag:
                qmag = v
    tol[TOL_QMAG] = qmag
    nbody = body_parent.shape[0]
    moving[0] = 0
    rotating[0] = 0
    for b in range(1, nbody):
        moving[b] = 0
        rotating[b] = 0
        if body_mocap[b] != 0:
            continue
        mv = moving[body_parent[b]]
        rt = rotating[body_parent[b]]
        for j in range(body_jntadr[b], body_jntadr[b] + body_jntnum[b]):
            typ = jnt_type[j]
            adr = jnt_qposadr[j]
            width = 7 if typ == _FREE else (4 if typ == _BALL else 1)
            rot_from = 3 if typ == _FREE else (width if typ == _SLIDE else 0)
            for c in range(width):
                ch = False
                for k in range(1, K):
                    if qpos[k, adr + c] != qpos[0, adr + c]:
                        ch = True
                        break
                if ch:
                    mv = 1
                    if c >= rot_from:
                        rt = 1
        moving[b] = mv
        rotating[b] = rt


bind_caches(globals())  # numba ignores caches written under other kernel sources (see monitor._jit_cache)
