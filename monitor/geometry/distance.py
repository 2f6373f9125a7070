"""Exact static distance / overlap test between two posed :class:`ConvexShape` objects.

Used to confirm violation witnesses (both checkers), for the start-pose overlap
test of the engine, and as the test oracle. The contract is **rigour**:

    lower <= true signed distance <= upper

where the signed distance is the Euclidean distance of the two solids when
they are apart and minus the penetration depth when they overlap (the length
of the shortest translation separating them), for the poses given as float64
(the shapes are the exact images of their body-frame points under x -> R x + p).
Both bounds are rounding padded (``Tolerances.rel_pad`` / ``abs_pad``; see
:mod:`monitor.geometry._gjk`).

How the bounds are obtained (cores = point / segment / polytope; the solid is
the core swept by the radius, so ``dist = core_dist - radius_a - radius_b``):

* ``upper`` always comes from actual points: the closest points GJK found
  (a convex combination of core vertices), or, when the cores overlap, a proof
  that the Minkowski difference ``A - B`` contains a ball ``B(0, r)`` (then the
  penetration depth is ``>= r``):
  - the GJK tetrahedron around the origin (certified in-radius);
  - EPA grown from it, whose triangle surface is verified after the fact
    (closed and consistently oriented, every face plane certified at positive
    distance from the origin, solid angles summing to 4 pi); this converges to
    the penetration depth (see :func:`monitor.geometry._gjk._epa_inradius`);
  - a common point ``x`` with ``B(x, d_A)`` in core A and ``B(x, d_B)`` in core
    B (``r = d_A + d_B``): the deepest point of a point / segment core in a
    polytope, and, for two polytopes when nothing else proved ``upper < 0`` (or
    with ``tight_overlap=True``), an LP (scipy HiGHS) maximising ``d_A + d_B``,
    re-checked in float64 with padding against the H-representation.
* ``lower`` comes from a direction n: ``dist >= -h_{A-B}(n) / |n|`` for every n
  (support function of the Minkowski difference). Separated cores use the GJK
  direction (tight to ~1e-12 relative, with fall-backs for sliver simplices);
  overlapping cores use EPA's face normals and, when those have not converged,
  the separating-axis candidates (face normals, edge x edge), which give the
  exact penetration depth for polytope pairs.

Depth certificates measure depth with a polytope's face normals. Once per
shape (cached), the normals are checked against the facets of the vertex hull
(scipy qhull); their angular defect becomes a depth pad (``_depth_pad``), and a
flat or normal-less polytope gets no depth certificate at all (its ``upper``
stays at the common-point bound, ~ +1e-12). The separated-case bounds and
``lower`` never use the normals' completeness.

Half-spaces: closed form (min over core vertices of the plane's signed
distance). Two half-spaces: antiparallel normals give ``-(b_1 + b_2)``; any
other pair intersects with infinite depth (``-inf``).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from monitor.errors import InvalidInputError
from monitor.geometry import _gjk
from monitor.geometry.shapes import ConvexShape
from monitor.tolerances import DEFAULT, Tolerances

_EPS_REL = 1e-14
"""GJK stops when the duality gap |v|^2 - v.w <= _EPS_REL |v|^2, i.e. when the
separating-axis lower bound is within ~_EPS_REL/2 relative of the closest-point
distance (plus rounding). Bounds stay rigorous whatever the value."""

_MAX_ITER = 200
"""GJK iteration cap (typical: < 10 for boxes, < 30 for 100-vertex hulls); a
capped run still returns rigorous (looser) bounds."""

_MAX_EDGE_PAIRS = 2_000_000
"""Work cap (edge pairs x vertices, ~1 ns each) on the edge x edge separating-axis
candidates of the overlap lower bound, used only when EPA did not converge.
Beyond it only face normals are used: still a valid, looser bound."""

_KINDS = ("sphere", "capsule", "polytope", "halfspace")

_MAX_COORD = 1e9
"""Largest accepted |coordinate| (m) of a pose translation or a body-frame point.
Beyond it the input is not physical (float64 spacing at 1e9 m is 1.2e-7 m) and
the kernels' squares / triple products could overflow, so it is rejected with
:class:`~monitor.errors.InvalidInputError` rather than answered with bounds that
rounding has made meaningless."""

_MAX_ROT = 2.0
"""Largest accepted |entry| of a rotation matrix (a rotation has entries <= 1;
this only rejects garbage, not slightly non-orthogonal matrices)."""



@dataclass(frozen=True)
class DistanceResult:
    """Result of :func:`shape_distance`.

    Attributes:
        distance: best estimate of the signed distance, metres (negative =
            penetration); always within [lower, upper].
        lower: rigorous lower bound on the signed distance, metres.
        upper: rigorous upper bound on the signed distance, metres.
        p_a: (3,) world point on/in A: closest point on A's surface when apart,
            a common point of both solids when the cores overlap.
        p_b: (3,) world point on/in B (equal to ``p_a`` for overlapping cores).
    """

    distance: float
    lower: float
    upper: float
    p_a: np.ndarray
    p_b: np.ndarray

    @property
    def overlapping(self) -> bool:
        """True when the solids certainly overlap (upper < 0)."""
        return self.upper < 0.0


# --------------------------------------------------------------------------- input checks


class _Core:
    """Validated kernel arrays of one shape (cached per shape object)."""

    __slots__ = ("P", "E", "N", "code", "radius", "offset", "dpad")

    def __init__(self, P, E, N, code, radius, offset=0.0, dpad=0.0):
        self.P, self.E, self.N, self.code, self.radius, self.offset = P, E, N, code, radius, offset
        self.dpad = dpad


_CORE_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""Shape -> _Core. ConvexShape is frozen (identity hashed); its arrays are
treated as immutable, like everywhere else in monitor."""


def _core(shape: ConvexShape, name: str) -> _Core:
    """Validate ``shape`` once and return its contiguous kernel arrays."""
    try:
        return _CORE_CACHE[shape]
    except (KeyError, TypeError):
        pass
    if not isinstance(shape, ConvexShape):
        raise InvalidInputError(f"{name}: expected a ConvexShape, got {type(shape).__name__}")
    if shape.kind not in _KINDS:
        raise InvalidInputError(f"{name}: unknown shape kind {shape.kind!r}")
    P = shape.points
    if not isinstance(P, np.ndarray) or P.ndim != 2 or P.shape[1] != 3 or len(P) < 1:
        raise InvalidInputError(f"{name}.points: expected (n>=1, 3), got {np.shape(P)}")
    if not np.isfinite(P).all():
        raise InvalidInputError(f"{name}.points: not finite")
    if np.abs(P).max() > _MAX_COORD:
        raise InvalidInputError(f"{name}.points: a coordinate is beyond {_MAX_COORD:g} m")
    r = float(shape.radius)
    if not np.isfinite(r) or r < 0.0:
        raise InvalidInputError(f"{name}.radius must be finite and >= 0, got {shape.radius!r}")
    P = np.ascontiguousarray(P, dtype=np.float64)
    E = np.zeros((0, 2), np.int64)
    N = np.zeros((0, 3))
    if shape.kind == "sphere":
        code = _gjk.KIND_POINT
        P = P[:1].copy()
    elif shape.kind == "capsule":
        if len(P) != 2:
            raise InvalidInputError(f"{name}: a capsule core needs 2 points, got {len(P)}")
        code = _gjk.KIND_SEGMENT
        E = np.array([[0, 1]], dtype=np.int64)
    elif shape.kind == "polytope":
        code = _gjk.KIND_POLYTOPE
        E = np.ascontiguousarray(np.asarray(shape.edges, dtype=np.int64).reshape(-1, 2))
        N = np.ascontiguousarray(np.asarray(shape.normals, dtype=np.float64).reshape(-1, 3))
        if len(E) and (E.min() < 0 or E.max() >= len(P)):
            raise InvalidInputError(f"{name}.edges: vertex index out of range [0, {len(P)})")
        if not np.isfinite(N).all():
            raise InvalidInputError(f"{name}.normals: not finite")
    else:
        code = -1
        N = np.ascontiguousarray(np.asarray(shape.normals, dtype=np.float64))
        off = np.asarray(shape.offsets, dtype=np.float64)
        if N.shape != (1, 3) or off.shape != (1,) or not (np.isfinite(N).all() and np.isfinite(off).all()):
            raise InvalidInputError(f"{name}: a half-space needs finite normals (1, 3) and offsets (1,)")
        if not np.linalg.norm(N[0]) > 0.0:
            raise InvalidInputError(f"{name}: half-space normal is zero")
    off0 = float(shape.offsets[0]) if code < 0 else 0.0
    dpad = _depth_pad(P, N) if code == _gjk.KIND_POLYTOPE else 0.0
    core = _Core(P, E, N, code, r, off0, dpad)
    try:
        _CORE_CACHE[shape] = core
    except TypeError:
        pass
    return core


def _depth_pad(P: np.ndarray, N: np.ndarray) -> float:
    """Completeness defect (m) of a polytope's face normals, or inf.

    Depth certificates (negative ``upper``) measure depth with the face normals:
    ``depth_N(x) = min_i (h_V(n_i) - n_i . x) / |n_i|``. If every facet normal m
    of the vertex hull (qhull) has a given normal n within angle theta, then
    ``{x : n_i . x <= h_V(n_i)}`` violates each hull facet by at most
    ``2 theta R`` (R = max vertex distance from the centroid, coordinates centred),
    so ``depth_hull >= depth_N - 2 theta R``. Returns that defect (plus a rounding
    pad), or inf when the hull is flat / the normals are missing: then no depth is
    certified (upper stays at the common-point bound).
    """
    from scipy.spatial import ConvexHull, QhullError

    if len(N) == 0 or len(P) < 4:
        return math.inf
    c = P.mean(axis=0)
    Q = P - c
    try:
        M = ConvexHull(Q).equations[:, :3]
    except (QhullError, ValueError):
        return math.inf
    Nn = N / np.linalg.norm(N, axis=1)[:, None]
    sin = np.linalg.norm(np.cross(M[:, None, :], Nn[None, :, :]), axis=2)
    sin = np.where(M @ Nn.T > 0.0, sin, np.inf)
    theta = float(sin.min(axis=1).max())
    R = float(np.sqrt((Q**2).sum(axis=1).max()))
    return 2.0 * theta * R * (1.0 + 1e-6) + 64 * 2.0**-52 * R


def _check_pose(X, name: str) -> tuple[np.ndarray, np.ndarray]:
    try:
        R, p = X
        R = np.ascontiguousarray(R, dtype=np.float64)
        p = np.ascontiguousarray(p, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name}: expected a pose (R (3, 3), p (3,))") from None
    if R.shape != (3, 3) or p.shape != (3,):
        raise InvalidInputError(f"{name}: expected R (3, 3) and p (3,), got {R.shape} and {p.shape}")
    # The common case on 12 Python floats (~1 us instead of six numpy reductions, issue 12): every
    # entry within its bound (so finite: NaN and inf fail the comparison) passes the checks below;
    # anything else takes them and their messages.
    x, y, z = p.tolist()
    if -_MAX_COORD <= x <= _MAX_COORD and -_MAX_COORD <= y <= _MAX_COORD and -_MAX_COORD <= z <= _MAX_COORD:
        r = R.ravel().tolist()
        if min(r) >= -_MAX_ROT and max(r) <= _MAX_ROT and all(v == v for v in r):
            return R, p
    # any NaN / inf entry makes the sum non-finite
    if not math.isfinite(R.sum() + p.sum()):
        raise InvalidInputError(f"{name}: pose is not finite")
    if max(p.max(), -p.min()) > _MAX_COORD or max(R.max(), -R.min()) > _MAX_ROT:
        raise InvalidInputError(f"{name}: translation beyond {_MAX_COORD:g} m or rotation entry beyond "
                                f"{_MAX_ROT:g}: p={p.tolist()}, max |R_ij|={float(np.abs(R).max()):g}")
    return R, p


# --------------------------------------------------------------------------- overlap depth (LP)


def _depth_lp(shape_a: ConvexShape, Ra, pa, shape_b: ConvexShape, Rb, pb, x0: np.ndarray,
              scale: float, tol: Tolerances) -> tuple[float, np.ndarray] | None:
    """Certified lower bound on the cores' penetration depth by LP (frame shifted by ``pa``).

    Maximises ``d_A + d_B`` (each polytope depth >= a small tau) over points x with
    ``B(x, d_A)`` in core A and ``B(x, d_B)`` in core B; a point / segment core
    has depth 0 and x must lie on it. The LP is posed in local, scaled
    coordinates ``x = x0 + scale * y`` around a common point ``x0`` so that HiGHS'
    absolute tolerances (~1e-9) are relative to the expected depth. The optimum is
    then re-checked in float64 with rounding pads against the H-representation
    (offsets recomputed as the max over the posed vertices).

    Args:
        x0: (3,) approximate common point (relative frame).
        scale: metres, > 0, the expected depth (e.g. the SAT estimate).

    Returns:
        (depth, x): depth > 0 certified, x (3,) the common point (relative frame);
        or None when no positive depth could be certified.
    """
    from scipy.optimize import linprog

    L = float(scale)
    x0 = np.asarray(x0, dtype=np.float64)
    d = pb - pa
    cores = []
    S = float(np.abs(x0).max())
    for shape, R, t in ((shape_a, Ra, np.zeros(3)), (shape_b, Rb, d)):
        V = shape.points @ R.T + t
        S = max(S, float(np.abs(V).max()))
        if shape.kind == "polytope":
            N = np.asarray(shape.normals, dtype=np.float64) @ R.T
            nrm = np.linalg.norm(N, axis=1)
            b = (N @ V.T).max(axis=1)
            cores.append(("poly", V, N, nrm, b))
        elif shape.kind == "capsule" and np.any(V[1] != V[0]):
            cores.append(("seg", V, None, None, None))
        else:
            cores.append(("pt", V[:1], None, None, None))
    pad = 2.0 * tol.rel_pad * S + tol.abs_pad
    # anchor x0 on a lower-dimensional core (the GJK point is on it only up to rounding)
    seg_t0 = None
    for c in cores:
        if c[0] == "pt":
            x0 = c[1][0].copy()
        elif c[0] == "seg":
            V = c[1]
            e = V[1] - V[0]
            seg_t0 = float(np.clip((x0 - V[0]) @ e / (e @ e), 0.0, 1.0))
            x0 = V[0] + seg_t0 * e
    # variables: y (3) [x = x0 + L y], then s (poly) / u (seg), then the balance m
    nvar = 3
    cols = []
    for c in cores:
        cols.append(nvar)
        if c[0] in ("poly", "seg"):
            nvar += 1
    cost = np.zeros(nvar)
    bounds: list[tuple[float | None, float | None]] = [(None, None)] * 3 + [(0.0, None)] * (nvar - 3)
    A_ub, b_ub, A_eq, b_eq = [], [], [], []
    for c, j in zip(cores, cols):
        if c[0] == "poly":
            _, V, N, nrm, b = c
            rows = np.zeros((len(N), nvar))
            rows[:, :3] = N
            rows[:, j] = nrm
            A_ub.append(rows)
            b_ub.append((b - N @ x0) / L)
            cost[j] = -1.0
        elif c[0] == "seg":
            V = c[1]
            e = V[1] - V[0]
            le = float(np.linalg.norm(e))
            rows = np.zeros((3, nvar))
            rows[:, :3] = np.eye(3)
            rows[:, j] = -e / le
            A_eq.append(rows)
            b_eq.append(np.zeros(3))
            bounds[j] = (-seg_t0 * le / L, (1.0 - seg_t0) * le / L)
        else:
            rows = np.zeros((3, nvar))
            rows[:, :3] = np.eye(3)
            A_eq.append(rows)
            b_eq.append(np.zeros(3))
    # Each polytope depth must be >= tau: the plain optimum often puts all the depth
    # on one body (a point on A's boundary deep in B), and a depth of exactly 0
    # cannot be certified after padding. tau = 1 % of the expected depth costs at
    # most that much of the bound; a smaller tau is tried if it is infeasible.
    s_cols = [j for c, j in zip(cores, cols) if c[0] == "poly"]
    res = None
    for tau in (0.01, 100.0 * pad / L):
        for j in s_cols:
            bounds[j] = (tau, None)
        res = linprog(cost,
                      A_ub=np.vstack(A_ub) if A_ub else None, b_ub=np.concatenate(b_ub) if b_ub else None,
                      A_eq=np.vstack(A_eq) if A_eq else None, b_eq=np.concatenate(b_eq) if b_eq else None,
                      bounds=bounds, method="highs")
        if res.status == 0 and res.x is not None:
            break
    if res is None or res.status != 0 or res.x is None:
        return None
    y = np.asarray(res.x)
    x = x0 + L * y[:3]
    for c, j in zip(cores, cols):
        if c[0] == "seg":
            V = c[1]
            e = V[1] - V[0]
            t = float(np.clip(seg_t0 + L * y[j] / float(np.linalg.norm(e)), 0.0, 1.0))
            x = V[0] + t * e
        elif c[0] == "pt":
            x = c[1][0].copy()
    depth = 0.0
    for c, shape in zip(cores, (shape_a, shape_b)):
        if c[0] == "poly":
            _, V, N, nrm, b = c
            dc = float(((b - N @ x) / nrm).min()) - pad - _core(shape, "shape").dpad
            if dc < 0.0:
                return None
            depth += dc
        else:
            # x lies on the point / segment up to the rounding of its construction
            depth -= pad
    if depth <= 0.0:
        return None
    return depth, x


# --------------------------------------------------------------------------- half-spaces


def _halfspace_pair(shape_a, Ra, pa, shape_b, Rb, pb, tol):
    """Both shapes are half-spaces: antiparallel -> finite, else -inf."""
    na = Ra @ shape_a.normals[0]
    nb = Rb @ shape_b.normals[0]
    na_len, nb_len = np.linalg.norm(na), np.linalg.norm(nb)
    ua, ub = na / na_len, nb / nb_len
    ba = (shape_a.offsets[0] + na @ pa) / na_len
    bb = (shape_b.offsets[0] + nb @ pb) / nb_len
    cross = np.linalg.norm(np.cross(ua, ub))
    if cross > 0.0 or ua @ ub > 0.0:
        # non-parallel (or same direction): the intersection is unbounded in depth
        q = np.zeros(3)
        return DistanceResult(-np.inf, -np.inf, -np.inf, q, q.copy())
    # u_b = -u_a: slab {x: -bb <= u_a.x <= ba}; empty iff ba < -bb: gap = -bb - ba
    dist = -(ba + bb)
    pad = tol.pad(abs(ba) + abs(bb) + np.abs(pa).max() + np.abs(pb).max())
    p_a = ua * ba
    p_b = ua * (-bb)
    return DistanceResult(float(dist), float(dist - pad), float(dist + pad), p_a, p_b)


# --------------------------------------------------------------------------- public API


def shape_distance(shape_a: ConvexShape, X_a, shape_b: ConvexShape, X_b, *,
                   tolerances: Tolerances = DEFAULT, tight_overlap: bool = False) -> DistanceResult:
    """Rigorous signed distance bounds between two posed convex shapes.

    Args:
        shape_a: shape A (body frame).
        X_a: (R (3, 3), p (3,)) pose of A's body frame in world (x_W = R x_B + p).
        shape_b: shape B (body frame).
        X_b: (R (3, 3), p (3,)) pose of B.
        tolerances: rounding pads.
        tight_overlap: for two overlapping polytope cores, always run the depth LP
            (~1.5 ms) to make ``upper`` as negative as a ball in both bodies allows.
            By default the LP runs only when the numba kernel could not already
            prove ``upper < 0`` (the sign is all a witness or start-pose test needs;
            ``distance`` and ``lower`` are exact either way for polytope pairs).

    Returns:
        :class:`DistanceResult` with ``lower <= true signed distance <= upper``
        (metres) and world witness points.

    Raises:
        InvalidInputError: bad shape or pose (shape, NaN, unknown kind).
    """
    ca_, cb_ = _core(shape_a, "shape_a"), _core(shape_b, "shape_b")
    Ra, pa = _check_pose(X_a, "X_a")
    Rb, pb = _check_pose(X_b, "X_b")
    tol = tolerances
    out = np.empty(_gjk.OUT_SIZE)
    ha, hb = ca_.code < 0, cb_.code < 0
    if ha and hb:
        return _halfspace_pair(shape_a, Ra, pa, shape_b, Rb, pb, tol)
    if ha:
        return _halfspace_core(ca_, Ra, pa, cb_, Rb, pb, tol, out, True)
    if hb:
        return _halfspace_core(cb_, Rb, pb, ca_, Ra, pa, tol, out, False)
    _gjk.core_distance(ca_.P, Ra, pa, ca_.E, ca_.N, cb_.P, Rb, pb, cb_.E, cb_.N, ca_.code, cb_.code,
                       ca_.dpad, cb_.dpad, tol.rel_pad, tol.abs_pad, _EPS_REL, _MAX_ITER,
                       _MAX_EDGE_PAIRS, out)
    status = int(out[0])
    est, lower, upper = float(out[1]), float(out[2]), float(out[3])
    ra, rb = ca_.radius, cb_.radius
    rs = ra + rb
    if status != _gjk.SEPARATED:
        p = out[4:7]
        if (ca_.code == _gjk.KIND_POLYTOPE and cb_.code == _gjk.KIND_POLYTOPE
                and (tight_overlap or upper >= 0.0)):
            got = _depth_lp(shape_a, Ra, pa, shape_b, Rb, pb, p, max(-lower, 1e3 * float(out[10])), tol)
            if got is not None and -got[0] < upper:
                upper = -got[0]
                p = got[1]
        est = min(max(est, lower), upper)
        q = p + pa
        return DistanceResult(est - rs, lower - rs, upper - rs, q, q.copy())
    c_a, c_b = out[4:7] + pa, out[7:10] + pa
    if rs > 0.0:
        n = out[7:10] - out[4:7]
        nn = math.sqrt(n @ n)
        if nn > 0.0:
            n /= nn
            c_a += ra * n
            c_b -= rb * n
    return DistanceResult(est - rs, lower - rs, upper - rs, c_a, c_b)


def _halfspace_core(H: _Core, RH, pH, C: _Core, RC, pC, tol: Tolerances, out, h_first: bool
                    ) -> DistanceResult:
    """A half-space H and a core shape C (closed form); ``h_first``: H is shape A."""
    _gjk.halfspace_distance(H.N[0], H.offset, RH, pH, C.P, RC, pC, tol.rel_pad, tol.abs_pad, out)
    r = C.radius
    lower, upper, est = float(out[2]) - r, float(out[3]) - r, float(out[1]) - r
    p_h, p_c = out[4:7] + pC, out[7:10] + pC
    if r > 0.0:
        nH = RH @ H.N[0]
        p_c -= (r / math.sqrt(nH @ nH)) * nH
    if upper < 0.0:
        # overlap: the deepest core point (moved by the radius towards the plane) is common
        p_h = p_c.copy()
    if h_first:
        return DistanceResult(est, lower, upper, p_h, p_c)
    return DistanceResult(est, lower, upper, p_c, p_h)


def _batch_poses(Xs, name):
    try:
        R, p = Xs
        R = np.asarray(R, dtype=np.float64)
        p = np.asarray(p, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name}: expected poses (R (T, 3, 3), p (T, 3))") from None
    if R.shape == (3, 3):
        R = R[None]
    if p.shape == (3,):
        p = p[None]
    if R.ndim != 3 or R.shape[1:] != (3, 3) or p.ndim != 2 or p.shape[1] != 3:
        raise InvalidInputError(f"{name}: expected (R (T, 3, 3), p (T, 3)), got {R.shape}, {p.shape}")
    if not (np.isfinite(R).all() and np.isfinite(p).all()):
        raise InvalidInputError(f"{name}: poses are not finite")
    if (p.size and np.abs(p).max() > _MAX_COORD) or (R.size and np.abs(R).max() > _MAX_ROT):
        raise InvalidInputError(f"{name}: a translation is beyond {_MAX_COORD:g} m or a rotation entry "
                                f"beyond {_MAX_ROT:g}")
    return R, p


def shape_distance_batch(shape_a: ConvexShape, Xs_a, shape_b: ConvexShape, Xs_b, *,
                         tolerances: Tolerances = DEFAULT, exact_overlap: bool = True
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Rigorous signed distance bounds for many poses of one pair (oracle sampling).

    Args:
        shape_a, shape_b: the shapes (body frames).
        Xs_a: (R (T, 3, 3), p (T, 3)) poses of A; a single pose (R (3, 3), p (3,))
            broadcasts against the other side.
        Xs_b: same for B.
        tolerances: rounding pads.
        exact_overlap: if True, poses where two polytope cores touch and the
            kernel could not prove a negative upper bound are re-done with the LP
            depth, as in :func:`shape_distance` (point / segment cores get their
            depth in the kernel).

    Returns:
        (lower (T,), upper (T,)) metres, each with lower <= true signed distance <= upper.
    """
    ca_, cb_ = _core(shape_a, "shape_a"), _core(shape_b, "shape_b")
    Ra, pa = _batch_poses(Xs_a, "Xs_a")
    Rb, pb = _batch_poses(Xs_b, "Xs_b")
    T = max(len(Ra), len(Rb), len(pa), len(pb))
    for arr, nm in ((Ra, "Xs_a R"), (pa, "Xs_a p"), (Rb, "Xs_b R"), (pb, "Xs_b p")):
        if len(arr) not in (1, T):
            raise InvalidInputError(f"{nm}: length {len(arr)} does not broadcast to {T}")
    # C-contiguous AND writable copies where needed: numba compiles one specialisation per
    # readonly flag, and np.broadcast_to returns a readonly view even when nothing broadcasts
    # (a second ~10 s compile of core_distance_batch in a fresh process otherwise)
    Ra = np.require(np.broadcast_to(Ra, (T, 3, 3)), np.float64, ("C", "W"))
    Rb = np.require(np.broadcast_to(Rb, (T, 3, 3)), np.float64, ("C", "W"))
    pa = np.require(np.broadcast_to(pa, (T, 3)), np.float64, ("C", "W"))
    pb = np.require(np.broadcast_to(pb, (T, 3)), np.float64, ("C", "W"))
    tol = tolerances
    if ca_.code < 0 or cb_.code < 0:
        lo = np.empty(T)
        up = np.empty(T)
        for t in range(T):
            res = shape_distance(shape_a, (Ra[t], pa[t]), shape_b, (Rb[t], pb[t]), tolerances=tol)
            lo[t], up[t] = res.lower, res.upper
        return lo, up
    out = np.empty((T, _gjk.OUT_SIZE))
    _gjk.core_distance_batch(ca_.P, Ra, pa, ca_.E, ca_.N, cb_.P, Rb, pb, cb_.E, cb_.N, ca_.code, cb_.code,
                             ca_.dpad, cb_.dpad, tol.rel_pad, tol.abs_pad, _EPS_REL, _MAX_ITER,
                       _MAX_EDGE_PAIRS, out)
    rsum = ca_.radius + cb_.radius
    lo = out[:, 2] - rsum
    up = out[:, 3] - rsum
    if exact_overlap and ca_.code == _gjk.KIND_POLYTOPE and cb_.code == _gjk.KIND_POLYTOPE:
        redo = np.flatnonzero((out[:, 0] != _gjk.SEPARATED) & (out[:, 3] >= 0.0))
        for t in redo:
            got = _depth_lp(shape_a, Ra[t], pa[t], shape_b, Rb[t], pb[t], out[t, 4:7],
                            max(-out[t, 2], 1e3 * out[t, 10]), tol)
            if got is not None:
                up[t] = min(up[t], -got[0] - rsum)
    return lo, up


def point_in_shape(shape: ConvexShape, X, point: np.ndarray, pad: float = 0.0, *,
                   tolerances: Tolerances = DEFAULT) -> bool:
    """True if the world point is certainly within ``pad`` of the posed solid.

    Args:
        shape: the shape (body frame).
        X: (R (3, 3), p (3,)) its pose.
        point: (3,) world point, metres.
        pad: metres >= 0 of allowed distance outside the solid.
        tolerances: rounding pads.

    Returns:
        True iff the rigorous upper bound of the point-to-solid distance is <= pad.
    """
    q = np.asarray(point, dtype=np.float64).reshape(3)
    pt = ConvexShape("sphere", np.zeros((1, 3)), 0.0)
    res = shape_distance(pt, (np.eye(3), q), shape, X, tolerances=tolerances)
    return bool(res.upper <= pad)


def sample_surface(shape: ConvexShape, n: int, rng: np.random.Generator) -> np.ndarray:
    """Random points on the boundary of a bounded shape, in its body frame (for oracles).

    Spheres and capsules are sampled uniformly by area (cylinder + two
    hemispheres); polytopes (radius 0) uniformly by area over fan-triangulated
    faces. Not for half-spaces (unbounded).

    Args:
        shape: sphere, capsule, or polytope with radius 0.
        n: number of points (>= 0).
        rng: numpy Generator.

    Returns:
        (n, 3) body-frame points, metres.

    Raises:
        InvalidInputError: half-space, polytope with a radius, or a polytope without faces.
    """
    core = _core(shape, "shape")
    n = int(n)
    if n < 0:
        raise InvalidInputError(f"n must be >= 0, got {n}")

    def unit(k):
        d = rng.normal(size=(k, 3))
        return d / np.linalg.norm(d, axis=1)[:, None]

    r = core.radius
    if core.code == _gjk.KIND_POINT:
        return core.P[0] + r * unit(n)
    if core.code == _gjk.KIND_SEGMENT:
        p0, p1 = core.P
        e = p1 - p0
        L = float(np.linalg.norm(e))
        if L == 0.0:
            return p0 + r * unit(n)
        a = e / L
        u = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        w = np.cross(a, u)
        cyl = rng.random(n) < (2 * np.pi * r * L) / (2 * np.pi * r * L + 4 * np.pi * r * r)
        out = np.empty((n, 3))
        k = int(cyl.sum())
        t = rng.random(k)
        phi = rng.uniform(0, 2 * np.pi, k)
        out[cyl] = p0 + t[:, None] * e + r * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * w)
        d = unit(n - k)
        ends = np.where((d @ a >= 0)[:, None], p1, p0)
        out[~cyl] = ends + r * d
        return out
    if core.code == _gjk.KIND_POLYTOPE:
        if r > 0.0:
            raise InvalidInputError("sample_surface: polytopes with a radius are not supported")
        if not shape.faces:
            raise InvalidInputError("sample_surface: the polytope has no faces")
        tris = np.array([(f[0], f[i], f[i + 1]) for f in shape.faces for i in range(1, len(f) - 1)],
                        dtype=np.int64)
        A, B, C = core.P[tris[:, 0]], core.P[tris[:, 1]], core.P[tris[:, 2]]
        area = 0.5 * np.linalg.norm(np.cross(B - A, C - A), axis=1)
        idx = rng.choice(len(tris), size=n, p=area / area.sum())
        s1 = np.sqrt(rng.random(n))[:, None]
        s2 = rng.random(n)[:, None]
        return (1 - s1) * A[idx] + s1 * (1 - s2) * B[idx] + s1 * s2 * C[idx]
    raise InvalidInputError("sample_surface: a half-space is unbounded")


__all__ = ["DistanceResult", "shape_distance", "shape_distance_batch", "point_in_shape", "sample_surface"]
