"""Toleranced-ball collision checker (Schröcker & Weber), vectorised breadth-first.

Setting. A moving convex core A (a polytope, a flat polygon, a segment or a point)
and a fixed core B (same kinds, or a half-space), each inflated by its radius; the
pair is clear when ``dist(core_A, core_B) > r`` with ``r = radius_A + radius_B + margin``.
Everything is done in B's frame ("test frame"). A sub-interval of the motion is
covered by a ball B_R(g) of affine maps in R^12 (metric of :mod:`monitor.motion.metric`,
built on A's feature points): ``g`` maps A's body frame to the test frame (rigid for
trajectories: the relative pose at the sub-interval midpoint; affine for Bézier
motions: the curve point c(1/2)). For a point x of A, every pose of the sub-interval
maps x into the ball of radius ``R rho(x)`` about ``g(x)``.

Inflation by radius and margin (the paper's fat features stay quadrics). With
``rho_max = max rho`` over A (rho is convex, so the max is at a vertex) we use

    F(x)^2 = q(x) = R^2 rho(x)^2 + Delta,   Delta = r^2 + 2 r R rho_max   >=  (R rho(x) + r)^2 .

A feature pair (f_A, f_B) can touch during the sub-interval only if
``max_{x in f_A, z in f_B} q(x) - |g(x) - z|^2 >= 0``. This is the quantity every
elementary test bounds; with ``x = g^-1(y)`` it is the paper's fat-feature test in
world coordinates: ``q`` restricted to a line / plane is a convex quadratic whose
canonical form is eq. 5 / eq. 7, so the fat edge is bounded by the hyperboloid (6)
and the fat face by the two-sheet hyperboloid (8) over sigma(P) (Prop. 1). For an
affine, non-rigid g (Bézier centre) the same holds because rho is evaluated in A's
body frame (q(g(x)) = R^2 rho(x)^2 + Delta): only |g(x) - z| uses the mapped features,
i.e. the metric frames are those of the features mapped by g's linear part.

Elementary tests (rows). All are exact maxima of phi = q - |g(x) - z|^2 (up to the pad):

* VF  vertex v of A vs the interior part of a polygon face G of B: the projection of
  g(v) lies in G and h^2 <= q(v) (h = height over G's plane).
* EE  edge e of A vs edge (or degenerate edge = vertex) g of B: max of the 2-variable
  quadratic phi(s, tau) over [0, 1]^2 (sides: vertex balls vs segments; interior:
  the hyperboloid part of eq. 6, present iff the Hessian is negative definite, which
  is the paper's condition R < nu (beta < 1) tightened by the angle between the edges).
* FE  face P of A vs edge g of B: for fixed z the maximiser over P's plane is
  w*(z) (closed form when G - R^2 K is positive definite, i.e. all beta_i < 1); the
  row fires if ``max_tau V(tau)`` over the tau-interval with w*(z(tau)) in P is >= 0.
  This is the paper's "vertex in fat face" AND the case Listing 2 misses: g crossing
  the fat face with both end points outside it. If some beta_i >= 1 the face part is
  empty: for fixed z, phi is convex along a direction of P's plane, so its max over P
  is on P's boundary (covered by EE). (This improves Remark 1's third bullet, which
  subdivides instead.)
* EF  edge e of A crossing polygon G of B statically at the centre pose g.
* VH  vertex v of A vs half-space B: h(g(v)) <= F(v). (h - F is concave, so the min
  over A is at a vertex; VH rows alone are complete for half-spaces.)

Completeness for one (face P of A, face G of B) *unit*. The max of phi over P x G is
attained on a pair of faces (f, f') with independent direction spaces: a common
direction u gives the Hessian value 2 u^T (R^2 J^-1) u > 0 along (u, u). So (P-int,
G-int) never occurs; (vertex, *) is VF or EE's sides; (edge-int, vertex/edge of G) is
EE; (P-int, vertex/edge of G) is FE. The remaining case (edge-int e, G-int): along e,
psi(s) = q - h^2 has an interior local max, so it is concave and e is not parallel to
G; let s_z be where e's line meets G's plane. If s_z is in e and g(e(s_z)) lies in G,
EF fires. Otherwise the projections of the points between the maximiser and s_z (or
the end point of e between them, whose psi is >= min(psi(s_z) = q > 0, psi(s*)) by
concavity) leave G, so some ball of the fat edge meets G's boundary: an EE row fires
(or a VF row at that end point). Hence: the unit's rows fire iff the fat P meets G.

Solids. If the cores are disjoint at the start (the engine checks this exactly) and
they come within r later, at the first such time the closest points lie on the
boundaries, i.e. on a (face of A, face of B) unit whose rows must fire on every
sub-interval containing that time. Flat polygons / segments / points are tested as
whole (their unit IS the set), so they need no start test.

Remark 2 pruning. A unit excluded on a sub-interval I is clear for every pose of I,
so it stays excluded on sub-intervals of I: children only test the units that
fired on the parent (rows are recomputed with the child ball, and rows shared by
several units are evaluated once per item).

Rounding pad. Every row compares a quadratic value V with zero and fires when
``V >= -pad``, ``pad = 8 rel_pad S + 2 sqrt(S) e + e^2``, where ``S`` (m^2) is the sum of
the absolute values of the terms of V, and ``e = pad(L) + scale_pad L`` (m) is the
coordinate pad for the magnitude ``L`` of the coordinates involved (pair extent +
|translation of g|). Interior critical points scale the relative part by the 2x2
condition number, and near-singular Hessians (|det| within 1e3 ulp of its terms)
fire conservatively. Inclusion tests (point in polygon, tau in interval) are widened
by ``e`` (widening only adds candidates, each of which upper-bounds the true max).
R is padded upwards, J^-1 is inflated (see metric.py), and Delta uses the padded r.

Non-planar faces: face interiors are tested as the planar polygons (projections of the
face loops onto the plane through the loop centroid), while vertices and edges are the
true ones; a loop vertex may lie off that plane (hull facets merged within 1e-12 of the
extent, rounding) by ``flat_err``. Every true boundary point is within flat_err of the
projected face, and the unit argument holds for the projected polygons; the difference
between true and projected vertices/edges moves g(x) by <= |L| flat_A and F by <=
R sqrt(lambda_max(J^-1)) flat_A. Both go into the per-item length pad e (``_eps_items``),
which enters every row as a distance uncertainty.

Pre-filter (``_Prefilter``, design.md): F is convex and g affine, so the orbit of A lies
in conv{ball(g(v), F(v))}; if it lies strictly outside one face plane of B the item is
excluded without unit tests. Non-finite values (overflow, NaN poses) never exclude:
every comparison is written so that NaN fires.

Termination (eq. 11): an item that is not excluded ends as an interval of possible
violation once R * rho_max < epsilon, or at ``tolerances.max_depth``, or when the
budget runs out, or when its pair already splits ``tolerances.max_frontier`` earlier
items at the same level (memory cap; the item's whole interval stays unresolved, which
can only make the verdict less certain).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from monitor.certify.common import Budget, BudgetExhausted, Outcome, PairOutcome, check_active_budget
from monitor.geometry.shapes import ConvexShape
from monitor.motion.base import Trajectory, chord
from monitor.motion.metric import Metric, edge_coefficients, face_coefficients, shape_metric
from monitor.tolerances import DEFAULT, Tolerances

_U = 2.0**-53
_ETA = 1e-9
USE_COMPILED = True
SHORT_CIRCUIT = True
"""Compiled levels: a unit stops evaluating rows at its first firing row (same unit answers and
intervals; ``row_tests`` then counts the rows evaluated, fewer than the oracle's)."""
"""Default of :func:`subdivide`'s ``compiled``: the numba level kernel (``fat_kernels``), or the
numpy kernels of this module (False; the oracle the tests compare against)."""
"""Relative widening of parameter ranges [0, 1] and tau-intervals (conservative)."""


# ============================================================================ feature sets


def _plane_frame(pts: np.ndarray, normal: np.ndarray | None = None):
    """Origin, unit normal, (3, 2) orthonormal basis, 2D loop coordinates of a planar loop."""
    o = pts.mean(axis=0)
    if normal is None:
        # Newell's method: robust normal of a planar polygon
        nx = np.roll(pts, -1, axis=0)
        n = np.array([((pts[:, 1] - nx[:, 1]) * (pts[:, 2] + nx[:, 2])).sum(),
                      ((pts[:, 2] - nx[:, 2]) * (pts[:, 0] + nx[:, 0])).sum(),
                      ((pts[:, 0] - nx[:, 0]) * (pts[:, 1] + nx[:, 1])).sum()])
    else:
        n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    u1 = np.cross(n, a)
    u1 /= np.linalg.norm(u1)
    u2 = np.cross(n, u1)
    U = np.stack([u1, u2], axis=1)
    w = (pts - o) @ U
    return o, n, U, w


def _halfplanes(w: np.ndarray, kmax: int) -> tuple[np.ndarray, np.ndarray]:
    """Outward half-planes hn . w <= hc of a convex 2D loop (any orientation), padded to kmax."""
    area = 0.5 * np.sum(w[:, 0] * np.roll(w[:, 1], -1) - np.roll(w[:, 0], -1) * w[:, 1])
    if area < 0:
        w = w[::-1]
    dw = np.roll(w, -1, axis=0) - w
    hn = np.stack([dw[:, 1], -dw[:, 0]], axis=1)
    nrm = np.linalg.norm(hn, axis=1)
    keep = nrm > 0
    hn = hn[keep] / nrm[keep, None]
    hc = np.einsum("ij,ij->i", hn, w[keep])
    outn = np.zeros((kmax, 2))
    outc = np.ones(kmax)
    outn[: len(hn)] = hn
    outc[: len(hc)] = hc
    return outn, outc


@dataclass(eq=False)
class MovingFeatures:
    """Features of the moving core A in its body frame, with metric coefficients.

    Units are the pieces whose pair with a fixed unit is tested as a whole (faces of a
    polytope, the polygon itself, the segment, the point).
    """

    metric: Metric
    verts: np.ndarray            # (nv, 3)
    qv: np.ndarray               # (nv,) rho^2 at vertices
    e_v0: np.ndarray             # (ne, 3)
    e_d: np.ndarray              # (ne, 3)
    e_k: np.ndarray              # (ne, 3) rho^2 = k0 + k1 s + k2 s^2
    e_deg: np.ndarray            # (ne,) zero-length edge
    f_o: np.ndarray              # (nf, 3)
    f_U: np.ndarray              # (nf, 3, 2)
    f_k0: np.ndarray             # (nf,)
    f_kg: np.ndarray             # (nf, 2)
    f_K: np.ndarray              # (nf, 2, 2)
    f_hn: np.ndarray             # (nf, kmax, 2)
    f_hc: np.ndarray             # (nf, kmax)
    units: list[tuple[np.ndarray, np.ndarray, int]]  # (vertex ids, edge ids, face id or -1)
    rho_max: float
    extent: float                # max |coordinate| (m)
    solid: bool                  # polytope core (needs the start-pose test)
    flat_err: float = 0.0        # max distance of a face vertex from its face plane (m)


@dataclass(eq=False)
class FixedFeatures:
    """Features of the fixed core B in its own frame."""

    kind: str                    # "polytope" | "polygon" | "segment" | "point" | "halfspace"
    verts: np.ndarray
    e_w0: np.ndarray             # (ne, 3)
    e_e: np.ndarray              # (ne, 3)
    f_o: np.ndarray              # (nf, 3)
    f_n: np.ndarray              # (nf, 3)
    f_U: np.ndarray              # (nf, 3, 2)
    f_hn: np.ndarray             # (nf, kmax, 2)
    f_hc: np.ndarray             # (nf, kmax)
    units: list[tuple[np.ndarray, int]]  # (edge ids, face id or -1); half-space: one unit
    h_n: np.ndarray = field(default_factory=lambda: np.zeros(3))
    h_off: float = 0.0
    extent: float = 0.0
    solid: bool = False
    flat_err: float = 0.0


def _loops_and_edges(shape_points: np.ndarray, edges: np.ndarray, loops: list[np.ndarray]):
    """Edge list containing every loop edge; returns edges (m, 2) and per-loop edge ids."""
    E = [tuple(sorted(map(int, e))) for e in np.asarray(edges).reshape(-1, 2)]
    index = {e: i for i, e in enumerate(E)}
    per_loop = []
    for lp in loops:
        ids = []
        for i in range(len(lp)):
            key = tuple(sorted((int(lp[i]), int(lp[(i + 1) % len(lp)]))))
            if key not in index:
                index[key] = len(E)
                E.append(key)
            ids.append(index[key])
        per_loop.append(np.array(ids, dtype=np.int64))
    return np.array(E, dtype=np.int64).reshape(-1, 2), per_loop


_MOVING: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_FIXED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def moving_features(shape: ConvexShape | None = None, *, polygon: np.ndarray | None = None,
                    metric: Metric | None = None) -> MovingFeatures:
    """Moving feature set of a shape's core (body frame), or of a flat convex polygon.

    Args:
        shape: a sphere / capsule / polytope :class:`ConvexShape` (its radius is NOT part
            of the features; the checker adds it to r).
        polygon: alternatively (k, 3) vertices of a planar convex polygon (a surface, not a
            solid), as in the paper's examples.
        metric: mass distribution; default :func:`monitor.motion.metric.shape_metric`
            (or the polygon's vertices plus off-plane points).
    """
    if polygon is None and metric is None and shape is not None:
        hit = _MOVING.get(shape)
        if hit is None:
            hit = _MOVING[shape] = _moving_features(shape, None, None)
        return hit
    return _moving_features(shape, polygon, metric)


def _moving_features(shape, polygon, metric) -> MovingFeatures:
    if polygon is not None:
        V = np.asarray(polygon, float).reshape(-1, 3)
        loops = [np.arange(len(V))]
        edges, per_loop = _loops_and_edges(V, np.zeros((0, 2)), loops)
        if metric is None:
            from monitor.motion.metric import make_metric
            metric = make_metric(V)
        units = [(np.arange(len(V)), per_loop[0], 0)]
        solid = False
    else:
        assert shape is not None
        V = np.asarray(shape.points, float)
        metric = metric or shape_metric(shape)
        solid = shape.kind == "polytope"
        if shape.kind == "sphere":
            edges, loops, per_loop = np.array([[0, 0]]), [], []
            units = [(np.array([0]), np.array([0]), -1)]
        elif shape.kind == "capsule":
            edges, loops, per_loop = np.array([[0, 1]]), [], []
            units = [(np.array([0, 1]), np.array([0]), -1)]
        elif shape.kind == "polytope":
            loops = [np.asarray(f, np.int64) for f in shape.faces]
            edges, per_loop = _loops_and_edges(V, shape.edges, loops)
            units = [(loops[i], per_loop[i], i) for i in range(len(loops))]
        else:
            raise ValueError(f"a {shape.kind} core cannot be the moving side")
    nf = len(loops)
    kmax = max([len(lp) for lp in loops], default=1)
    f_o = np.zeros((nf, 3))
    f_U = np.zeros((nf, 3, 2))
    f_hn = np.zeros((nf, kmax, 2))
    f_hc = np.ones((nf, kmax))
    flat = 0.0
    for i, lp in enumerate(loops):
        o, n_, U, w = _plane_frame(V[lp])
        f_o[i], f_U[i] = o, U
        f_hn[i], f_hc[i] = _halfplanes(w, kmax)
        flat = max(flat, float(np.abs((V[lp] - o) @ n_).max()))
    f_k0, f_kg, f_K = face_coefficients(metric, f_o, f_U)
    v0 = V[edges[:, 0]]
    d = V[edges[:, 1]] - v0
    qv = metric.rho2(V)
    return MovingFeatures(metric, V, qv, v0, d, edge_coefficients(metric, v0, d),
                          ~(np.abs(d).max(axis=1) > 0), f_o, f_U, f_k0, f_kg, f_K, f_hn, f_hc,
                          units, float(np.sqrt(qv.max())), float(np.abs(V).max()), solid,
                          flat * (1.0 + 1e-6) + 4 * _U * float(np.abs(V).max()))


def fixed_features(shape: ConvexShape | None = None, *, polygon: np.ndarray | None = None
                   ) -> FixedFeatures:
    """Fixed feature set of a shape's core (its own frame), or of a flat convex polygon."""
    if polygon is None and shape is not None:
        hit = _FIXED.get(shape)
        if hit is None:
            hit = _FIXED[shape] = _fixed_features(shape, None)
        return hit
    return _fixed_features(shape, polygon)


def _fixed_features(shape, polygon) -> FixedFeatures:
    normals = None
    if polygon is not None:
        V = np.asarray(polygon, float).reshape(-1, 3)
        loops = [np.arange(len(V))]
        edges, per_loop = _loops_and_edges(V, np.zeros((0, 2)), loops)
        kind, solid = "polygon", False
    else:
        assert shape is not None
        V = np.asarray(shape.points, float)
        kind, solid = shape.kind, shape.kind == "polytope"
        if kind == "halfspace":
            n = np.asarray(shape.normals[0], float)
            return FixedFeatures("halfspace", V, np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                                 np.zeros((0, 3)), np.zeros((0, 3, 2)), np.zeros((0, 1, 2)),
                                 np.zeros((0, 1)), [(np.zeros(0, np.int64), -1)], n,
                                 float(shape.offsets[0]), float(np.abs(V).max()), True)
        if kind == "sphere":
            edges, loops, per_loop = np.array([[0, 0]]), [], []
            kind = "point"
        elif kind == "capsule":
            edges, loops, per_loop = np.array([[0, 1]]), [], []
            kind = "segment"
        else:
            loops = [np.asarray(f, np.int64) for f in shape.faces]
            edges, per_loop = _loops_and_edges(V, shape.edges, loops)
            normals = None  # Newell normals of the loops (independent of the H-rep row order)
    nf = len(loops)
    kmax = max([len(lp) for lp in loops], default=1)
    f_o, f_n = np.zeros((nf, 3)), np.zeros((nf, 3))
    f_U = np.zeros((nf, 3, 2))
    f_hn, f_hc = np.zeros((nf, kmax, 2)), np.ones((nf, kmax))
    flat = 0.0
    for i, lp in enumerate(loops):
        o, n, U, w = _plane_frame(V[lp], None if normals is None else normals[i])
        f_o[i], f_n[i], f_U[i] = o, n, U
        f_hn[i], f_hc[i] = _halfplanes(w, kmax)
        flat = max(flat, float(np.abs((V[lp] - o) @ n).max()))
    if nf:
        units = [(per_loop[i], i) for i in range(nf)]
    else:
        units = [(np.arange(len(edges)), -1)]
    w0 = V[edges[:, 0]]
    return FixedFeatures(kind, V, w0, V[edges[:, 1]] - w0, f_o, f_n, f_U, f_hn, f_hc, units,
                         extent=float(np.abs(V).max()), solid=solid,
                         flat_err=flat * (1.0 + 1e-6) + 4 * _U * float(np.abs(V).max()))


# ============================================================================ pair tables


_TYPES = ("VF", "EE", "FE", "EF", "VH")


@dataclass(eq=False)
class _Tables:
    """Concatenated row and unit tables of all pairs of one check."""

    rows: dict[str, dict[str, np.ndarray]]   # per type: column arrays (global feature ids)
    row_start: dict[str, int]                # global row id offset per type
    n_rows: int
    unit_ptr: np.ndarray                     # (n_units + 1,) CSR into unit_rows
    unit_rows: np.ndarray                    # global row ids
    unit_pair: np.ndarray                    # (n_units,) pair index
    pair_units: list[np.ndarray]             # per pair: its global unit ids


@dataclass(eq=False)
class _PairData:
    A: MovingFeatures
    B: FixedFeatures
    r: float
    name: Any = None


class _Concat:
    """Concatenation of per-pair feature arrays with offsets."""

    def __init__(self, pairs: list[_PairData]):
        def cat(getter, empty_shape):
            arrs = [getter(p) for p in pairs]
            offs = np.cumsum([0] + [len(a) for a in arrs])
            data = np.concatenate(arrs) if arrs else np.zeros(empty_shape)
            return data, offs

        A = lambda name: (lambda p: getattr(p.A, name))  # noqa: E731
        B = lambda name: (lambda p: getattr(p.B, name))  # noqa: E731
        self.av, self.av_off = cat(A("verts"), (0, 3))
        self.aqv, _ = cat(A("qv"), (0,))
        self.ae_v0, self.ae_off = cat(A("e_v0"), (0, 3))
        self.ae_d, _ = cat(A("e_d"), (0, 3))
        self.ae_k, _ = cat(A("e_k"), (0, 3))
        self.af_o, self.af_off = cat(A("f_o"), (0, 3))
        self.af_U, _ = cat(A("f_U"), (0, 3, 2))
        self.af_k0, _ = cat(A("f_k0"), (0,))
        self.af_kg, _ = cat(A("f_kg"), (0, 2))
        self.af_K, _ = cat(A("f_K"), (0, 2, 2))
        self.af_hn, self.af_hc = _pad_cat([p.A.f_hn for p in pairs], [p.A.f_hc for p in pairs])
        self.be_w0, self.be_off = cat(B("e_w0"), (0, 3))
        self.be_e, _ = cat(B("e_e"), (0, 3))
        self.bf_o, self.bf_off = cat(B("f_o"), (0, 3))
        self.bf_n, _ = cat(B("f_n"), (0, 3))
        self.bf_U, _ = cat(B("f_U"), (0, 3, 2))
        self.bf_hn, self.bf_hc = _pad_cat([p.B.f_hn for p in pairs], [p.B.f_hc for p in pairs])
        self.h_n = np.array([p.B.h_n for p in pairs]).reshape(-1, 3)
        self.h_off = np.array([p.B.h_off for p in pairs], float)


def _pad_cat(hns: list[np.ndarray], hcs: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    kmax = max([h.shape[1] for h in hns if h.ndim == 3 and len(h)], default=1)
    n = sum(len(h) for h in hns)
    out_n = np.zeros((n, kmax, 2))
    out_c = np.ones((n, kmax))
    i = 0
    for hn, hc in zip(hns, hcs):
        k = len(hn)
        if k:
            out_n[i:i + k, : hn.shape[1]] = hn
            out_c[i:i + k, : hc.shape[1]] = hc
        i += k
    return out_n, out_c


@dataclass(eq=False)
class _Template:
    """Rows and units of one (moving, fixed) feature-set pair in LOCAL feature indices."""

    cols: dict[str, np.ndarray]     # per type: (n_t, 1 or 2) local feature ids
    unit_ptr: np.ndarray            # (n_units + 1,)
    unit_type: np.ndarray           # (sum,) type index of each unit row
    unit_idx: np.ndarray            # (sum,) row index within its type


_TEMPLATES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _template(A: MovingFeatures, B: FixedFeatures) -> _Template:
    """Cached row/unit template of a feature-set pair (built once per pair of feature sets)."""
    per_a = _TEMPLATES.setdefault(A, weakref.WeakKeyDictionary())
    tpl = per_a.get(B)
    if tpl is not None:
        return tpl
    cols: dict[str, list[tuple[int, ...]]] = {t: [] for t in _TYPES}
    index: dict[tuple, int] = {}
    units: list[list[tuple[int, int]]] = []
    tnum = {t: k for k, t in enumerate(_TYPES)}

    def row(t: str, key: tuple[int, ...]) -> tuple[int, int]:
        k = (t, *key)
        if k not in index:
            index[k] = len(cols[t])
            cols[t].append(key)
        return (tnum[t], index[k])

    if B.kind == "halfspace":
        units = [[row("VH", (v,))] for v in range(len(A.verts))]
    else:
        for vs, es, fa in A.units:
            for ges, fb in B.units:
                rs = []
                if fb >= 0:
                    rs += [row("VF", (int(v), fb)) for v in vs]
                    rs += [row("EF", (int(e), fb)) for e in es if not A.e_deg[e]]
                rs += [row("EE", (int(e), int(g))) for e in es for g in ges]
                if fa >= 0:
                    rs += [row("FE", (fa, int(g))) for g in ges]
                units.append(rs)
    width = {"VF": 2, "EE": 2, "FE": 2, "EF": 2, "VH": 1}
    arr = {t: np.array(cols[t], dtype=np.int64).reshape(-1, width[t]) for t in _TYPES}
    flat = [x for u in units for x in u]
    tpl = _Template(arr, np.cumsum([0] + [len(u) for u in units]).astype(np.int64),
                    np.array([x[0] for x in flat], dtype=np.int64).reshape(-1),
                    np.array([x[1] for x in flat], dtype=np.int64).reshape(-1))
    per_a[B] = tpl
    return tpl


def _build_tables(pairs: list[_PairData], C: _Concat) -> _Tables:
    """Concatenate the cached templates of all pairs into global row and unit tables."""
    tpls = []
    for pd in pairs:
        check_active_budget()  # templates of big meshes take a while: the budget bounds them
        tpls.append(_template(pd.A, pd.B))
    counts = np.array([[len(tp.cols[t]) for t in _TYPES] for tp in tpls], np.int64).reshape(-1, len(_TYPES))
    type_off = np.cumsum(np.vstack([np.zeros((1, len(_TYPES)), np.int64), counts]), axis=0)[:-1]
    totals = counts.sum(axis=0)
    start_arr = np.concatenate([[0], np.cumsum(totals)[:-1]])
    start = {t: int(start_arr[k]) for k, t in enumerate(_TYPES)}
    rows: dict[str, dict[str, np.ndarray]] = {}
    # feature-id offsets per column: A vertices / edges / faces, B edges / faces
    offs = {"VF": (C.av_off, C.bf_off), "EE": (C.ae_off, C.be_off), "FE": (C.af_off, C.be_off),
            "EF": (C.ae_off, C.bf_off), "VH": (C.av_off, None)}
    for t in _TYPES:
        oa, ob = offs[t]
        a_l, b_l, p_l = [], [], []
        for pi, tp in enumerate(tpls):
            c = tp.cols[t]
            if not len(c):
                continue
            a_l.append(c[:, 0] + oa[pi])
            if ob is not None:
                b_l.append(c[:, 1] + ob[pi])
            p_l.append(np.full(len(c), pi, np.int64))
        e = np.zeros(0, np.int64)
        rows[t] = {"a": np.concatenate(a_l) if a_l else e, "pair": np.concatenate(p_l) if p_l else e}
        if ob is not None:
            rows[t]["b"] = np.concatenate(b_l) if b_l else e
    ptrs, flats, upair, pair_units = [np.zeros(1, np.int64)], [], [], []
    nunit = 0
    nflat = 0
    for pi, tp in enumerate(tpls):
        nu = len(tp.unit_ptr) - 1
        ptrs.append(tp.unit_ptr[1:] + nflat)
        flats.append(start_arr[tp.unit_type] + type_off[pi][tp.unit_type] + tp.unit_idx)
        nflat += len(tp.unit_type)
        upair.append(np.full(nu, pi, np.int64))
        pair_units.append(np.arange(nunit, nunit + nu, dtype=np.int64))
        nunit += nu
    return _Tables(rows, start, int(totals.sum()), np.concatenate(ptrs),
                   np.concatenate(flats) if flats else np.zeros(0, np.int64),
                   np.concatenate(upair) if upair else np.zeros(0, np.int64), pair_units)


# ============================================================================ kernels


def _pad2(S: np.ndarray, e: np.ndarray, rel: float) -> np.ndarray:
    """Pad (m^2) for a quadratic value whose terms sum to S in absolute value (module doc)."""
    S = np.abs(S)
    return 8.0 * rel * S + 2.0 * np.sqrt(S) * e + e * e


def _qmax01(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Max of a t^2 + b t + c over t in [0, 1] (the vertex is included if within [-eta, 1+eta])."""
    best = np.maximum(c, a + b + c)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -b / (2.0 * a)
        v = c - b * b / (4.0 * a)
    ok = (a < 0) & (t >= -_ETA) & (t <= 1 + _ETA)
    return np.where(ok, np.maximum(best, v), best)


def _inside2(hn: np.ndarray, hc: np.ndarray, w: np.ndarray, pad: np.ndarray) -> np.ndarray:
    """Point (n, 2) in padded convex polygon (n, k, 2) / (n, k)."""
    return ~(np.einsum("nkj,nj->nk", hn, w) > hc + pad[:, None]).any(axis=1)   # NaN -> inside


def _apply(L: np.ndarray, p: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("nij,nj->ni", L, x) + p


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ni,ni->n", a, b)


class _Ball:
    """Per-item ball data: g = (L, p) maps A's body frame to the test frame."""

    def __init__(self, L, p, R, rho_max, r, eps_pos, tol: Tolerances):
        self.L, self.p = L, p
        R = np.asarray(R, float)
        with np.errstate(over="ignore", invalid="ignore"):   # inf/NaN balls fire every row
            self.R2 = R * R
        ru = r + tol.pad(r) if np.ndim(r) == 0 else r + tol.rel_pad * np.abs(r) + tol.abs_pad
        with np.errstate(over="ignore", invalid="ignore"):
            self.Delta = ru * ru + 2.0 * ru * R * rho_max
        self.eps = eps_pos


def _kernel_VF(C: _Concat, it, a, b, ball: _Ball, tol) -> np.ndarray:
    y = _apply(ball.L[it], ball.p[it], C.av[a])
    rel = y - C.bf_o[b]
    h = _dot(rel, C.bf_n[b])
    w = np.einsum("ni,nik->nk", rel, C.bf_U[b])
    e = ball.eps[it]
    q = ball.R2[it] * C.aqv[a] + ball.Delta[it]
    inside = _inside2(C.bf_hn[b], C.bf_hc[b], w, 4 * e)
    return inside & ~(q - h * h < -_pad2(q + h * h, e, tol.rel_pad))   # NaN -> fire


def _kernel_VH(C: _Concat, it, a, pair, ball: _Ball, tol) -> np.ndarray:
    y = _apply(ball.L[it], ball.p[it], C.av[a])
    h = _dot(y, C.h_n[pair]) - C.h_off[pair]
    e = ball.eps[it] + tol.pad(0.0) + tol.rel_pad * np.abs(C.h_off[pair])
    q = ball.R2[it] * C.aqv[a] + ball.Delta[it]
    return ~((h > 4 * e) & (q - h * h < -_pad2(q + h * h, e, tol.rel_pad)))   # NaN -> fire


def _kernel_EE(C: _Concat, it, a, b, ball: _Ball, tol) -> np.ndarray:
    L, p = ball.L[it], ball.p[it]
    Y0 = _apply(L, p, C.ae_v0[a])
    D = np.einsum("nij,nj->ni", L, C.ae_d[a])
    E = C.be_e[b]
    P = Y0 - C.be_w0[b]
    k = C.ae_k[a]
    R2, Dl, e = ball.R2[it], ball.Delta[it], ball.eps[it]
    DD, EE, DE = _dot(D, D), _dot(E, E), _dot(D, E)
    PD, PE, PP = _dot(P, D), _dot(P, E), _dot(P, P)
    a_ss = R2 * k[:, 2] - DD
    a_tt = -EE
    a_st = 2.0 * DE
    b_s = R2 * k[:, 1] - 2.0 * PD
    b_t = 2.0 * PE
    c = R2 * k[:, 0] + Dl - PP
    S = (np.abs(R2 * k[:, 0]) + Dl + np.abs(R2 * k[:, 1]) + np.abs(R2 * k[:, 2])
         + (np.sqrt(PP) + np.sqrt(DD) + np.sqrt(EE)) ** 2)
    pad = _pad2(S, e, tol.rel_pad)
    best = np.maximum.reduce([
        _qmax01(a_tt, b_t, c),                       # s = 0
        _qmax01(a_tt, b_t + a_st, c + a_ss + b_s),   # s = 1
        _qmax01(a_ss, b_s, c),                       # tau = 0
        _qmax01(a_ss, b_s + a_st, c + a_tt + b_t),   # tau = 1
    ])
    fire = ~(best < -pad)   # NaN (overflow) -> fire
    det = 4.0 * a_ss * a_tt - a_st * a_st
    band = 1e3 * _U * (4.0 * np.abs(a_ss * a_tt) + a_st * a_st)
    deg = (DD == 0) | (EE == 0)
    amb = (~deg) & (np.abs(det) <= band)
    nd = (~deg) & (a_ss < 0) & (det > band)
    if nd.any():
        with np.errstate(divide="ignore", invalid="ignore"):
            s_ = (-2.0 * a_tt * b_s + a_st * b_t) / det
            t_ = (-2.0 * a_ss * b_t + a_st * b_s) / det
            val = c + 0.5 * (b_s * s_ + b_t * t_)
            cond = (2 * np.abs(a_ss) + np.abs(a_st) + 2 * np.abs(a_tt)) ** 2 / det
        inbox = (s_ >= -_ETA) & (s_ <= 1 + _ETA) & (t_ >= -_ETA) & (t_ <= 1 + _ETA)
        Sx = S + np.abs(b_s * s_) + np.abs(b_t * t_)
        padi = _pad2(Sx, e, tol.rel_pad) * (1.0 + cond)
        fire |= nd & inbox & (val >= -padi)
    return fire | amb


def _kernel_FE(C: _Concat, it, a, b, ball: _Ball, tol) -> np.ndarray:
    L, p = ball.L[it], ball.p[it]
    Oa = _apply(L, p, C.af_o[a])
    Up = np.einsum("nij,njk->nik", L, C.af_U[a])
    E = C.be_e[b]
    P0 = Oa - C.be_w0[b]
    R2, Dl, e = ball.R2[it], ball.Delta[it], ball.eps[it]
    G = np.einsum("nik,nil->nkl", Up, Up)
    Am = G - R2[:, None, None] * C.af_K[a]
    a11, a12, a22 = Am[:, 0, 0], Am[:, 0, 1], Am[:, 1, 1]
    det = a11 * a22 - a12 * a12
    band = 1e3 * _U * (np.abs(a11 * a22) + a12 * a12)
    amb = ~(np.abs(det) > band)   # NaN -> ambiguous -> fire
    pd = (a11 > 0) & (det > band)
    fire = amb.copy()
    if not pd.any():
        return fire
    idx = np.nonzero(pd)[0]
    a11, a12, a22, det = a11[idx], a12[idx], a22[idx], det[idx]
    Up, E, P0 = Up[idx], E[idx], P0[idx]
    R2, Dl, e = R2[idx], Dl[idx], e[idx]
    ca = R2[:, None] * C.af_kg[a[idx]] - np.einsum("nik,ni->nk", Up, P0)
    cb = np.einsum("nik,ni->nk", Up, E)

    def solve(v):
        return np.stack([(a22 * v[:, 0] - a12 * v[:, 1]) / det,
                         (-a12 * v[:, 0] + a11 * v[:, 1]) / det], axis=1)

    wa, wb = solve(ca), solve(cb)
    EE_, PE, PP = _dot(E, E), _dot(P0, E), _dot(P0, P0)
    cbwb, cawb, cawa = _dot(cb, wb), _dot(ca, wb), _dot(ca, wa)
    k0 = C.af_k0[a[idx]]
    v2 = -EE_ + cbwb
    v1 = 2.0 * PE + 2.0 * cawb
    v0 = R2 * k0 + Dl - PP + cawa
    S = np.abs(R2 * k0) + Dl + PP + np.abs(cawa) + 2 * np.abs(PE) + 2 * np.abs(cawb) + EE_ + np.abs(cbwb)
    cond = (np.abs(a11) + np.abs(a22) + 2 * np.abs(a12)) ** 2 / det
    pad = _pad2(S, e, tol.rel_pad) * (1.0 + cond)
    # tau-interval where w*(tau) = wa + tau wb lies in P (widened)
    hn, hc = C.af_hn[a[idx]], C.af_hc[a[idx]]
    gk = np.einsum("nkj,nj->nk", hn, wb)
    wscale = 1.0 + np.linalg.norm(wa, axis=1) + np.linalg.norm(wb, axis=1)
    hk = hc - np.einsum("nkj,nj->nk", hn, wa) + (_ETA * wscale * (1.0 + cond * 1e-6))[:, None] \
        + 4 * e[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = hk / gk
    upper = np.where(gk > 0, ratio, np.inf).min(axis=1)
    lower = np.where(gk < 0, ratio, -np.inf).max(axis=1)
    empty = ((gk == 0) & (hk < 0)).any(axis=1)
    lo = np.maximum(lower, -_ETA)
    hi = np.minimum(upper, 1.0 + _ETA)
    ok = (~empty) & (lo <= hi)
    lo_c, hi_c = np.where(ok, lo, 0.0), np.where(ok, hi, 0.0)

    def V(t):
        return v0 + v1 * t + v2 * t * t

    best = np.maximum(V(lo_c), V(hi_c))
    with np.errstate(divide="ignore", invalid="ignore"):
        tv = -v1 / (2.0 * v2)
    inv = (v2 < 0) & (tv >= lo_c) & (tv <= hi_c)
    best = np.where(inv, np.maximum(best, V(np.where(inv, tv, 0.0))), best)
    fire[idx] |= (ok & ~(best < -pad)) | ~np.isfinite(best)
    return fire


def _clip_interval(g: np.ndarray, h: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Intersect [lo, hi] with {s : g_k s <= h_k for all k} (rows (n, k)); returns lo, hi, empty."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = h / g
    upper = np.where(g > 0, ratio, np.inf).min(axis=1)
    lower = np.where(g < 0, ratio, -np.inf).max(axis=1)
    empty = ((g == 0) & (h < 0)).any(axis=1)
    lo = np.maximum(lo, lower)
    hi = np.minimum(hi, upper)
    return lo, hi, empty | (lo > hi)


def _kernel_EF(C: _Concat, it, a, b, ball: _Ball, tol) -> np.ndarray:
    """Edge of A (at the centre pose) meets polygon G: s-range in the slab |h| <= e, clipped by G."""
    L, p = ball.L[it], ball.p[it]
    Y0 = _apply(L, p, C.ae_v0[a])
    D = np.einsum("nij,nj->ni", L, C.ae_d[a])
    n, o = C.bf_n[b], C.bf_o[b]
    h0 = _dot(Y0 - o, n)
    dh = _dot(D, n)
    e = 4 * ball.eps[it]
    # slab: -e <= h0 + s dh <= e
    g = np.stack([dh, -dh], axis=1)
    h = np.stack([e - h0, e + h0], axis=1)
    lo, hi, empty = _clip_interval(g, h, np.full(len(h0), -_ETA), np.full(len(h0), 1 + _ETA))
    w0 = np.einsum("ni,nik->nk", Y0 - o, C.bf_U[b])
    dw = np.einsum("ni,nik->nk", D, C.bf_U[b])
    hn, hc = C.bf_hn[b], C.bf_hc[b]
    gk = np.einsum("nkj,nj->nk", hn, dw)
    hk = hc - np.einsum("nkj,nj->nk", hn, w0) + e[:, None]
    lo2, hi2, empty2 = _clip_interval(gk, hk, lo, hi)
    return ~empty & ~empty2


def _run_kernels(C: _Concat, T: _Tables, u_item: np.ndarray, u_row: np.ndarray, fired: np.ndarray,
                 ball: _Ball, tol: Tolerances) -> None:
    """Evaluate every unique (item, row) by its row type's kernel, writing into ``fired``."""
    for t in _TYPES:
        check_active_budget()  # one kernel call at a time: bounds a long level's overrun
        lo, hi = T.row_start[t], T.row_start[t] + len(T.rows[t]["pair"])
        sel = np.nonzero((u_row >= lo) & (u_row < hi))[0]
        if not len(sel):
            continue
        r = u_row[sel] - lo
        it = u_item[sel]
        cols = T.rows[t]
        if t == "VF":
            fired[sel] = _kernel_VF(C, it, cols["a"][r], cols["b"][r], ball, tol)
        elif t == "EE":
            fired[sel] = _kernel_EE(C, it, cols["a"][r], cols["b"][r], ball, tol)
        elif t == "FE":
            fired[sel] = _kernel_FE(C, it, cols["a"][r], cols["b"][r], ball, tol)
        elif t == "EF":
            fired[sel] = _kernel_EF(C, it, cols["a"][r], cols["b"][r], ball, tol)
        else:
            fired[sel] = _kernel_VH(C, it, cols["a"][r], cols["pair"][r], ball, tol)


def _evaluate(C: _Concat, T: _Tables, unit_item: np.ndarray, unit_id: np.ndarray, ball: _Ball,
              tol: Tolerances) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Evaluate the rows of the active units (deduplicated per item); returns per-unit fired."""
    ptr = T.unit_ptr
    cnt = ptr[unit_id + 1] - ptr[unit_id]
    rep_item = np.repeat(unit_item, cnt)
    seg_start = np.repeat(ptr[unit_id] - np.cumsum(np.concatenate([[0], cnt[:-1]])), cnt)
    row_g = T.unit_rows[np.arange(cnt.sum()) + seg_start]
    key = rep_item * np.int64(T.n_rows) + row_g
    ukey, inv = np.unique(key, return_inverse=True)
    u_item = ukey // T.n_rows
    u_row = ukey % T.n_rows
    fired = np.zeros(len(ukey), bool)
    with np.errstate(over="ignore", invalid="ignore"):   # non-finite values fire (NaN-safe tests)
        _run_kernels(C, T, u_item, u_row, fired, ball, tol)
    fired_rows = fired[inv]
    seg = np.concatenate([[0], np.cumsum(cnt)[:-1]]).astype(np.int64)
    unit_fired = np.zeros(len(cnt), bool)
    nz = cnt > 0
    if nz.any():
        unit_fired[nz] = np.logical_or.reduceat(fired_rows, seg[nz])
    return unit_fired, cnt, u_item, len(ukey)


def _eps_items(A_ext: np.ndarray, B_ext: np.ndarray, flat_A: np.ndarray, flat_B: np.ndarray,
               sqrt_jinv: np.ndarray, L: np.ndarray, p: np.ndarray, R: np.ndarray,
               tol: Tolerances) -> np.ndarray:
    """Per-item length pad (m): coordinate rounding plus the faces' non-planarity.

    Rounding: abs_pad + (scale_pad + 8 rel_pad) (extent + |p| + 1). Non-planarity (module
    doc): a true boundary point is within flat_A of the tested (projected) A feature and
    flat_B of the B feature; mapped by g this moves points by <= |L|_F flat_A and changes F
    by <= Lip(R rho) flat_A <= R sqrt(lambda_max(J^-1)) flat_A.
    """
    Lf = np.sqrt(np.einsum("nij,nij->n", L, L))
    mag = A_ext + B_ext + np.linalg.norm(p, axis=1) + 1.0
    return tol.abs_pad + (tol.scale_pad + 8 * tol.rel_pad) * mag + flat_A * (Lf + R * sqrt_jinv) + flat_B


def _sqrt_jinv(m: Metric) -> float:
    return float(np.sqrt(np.linalg.eigvalsh(m.Jinv).max()) * (1.0 + 1e-9))


def fat_units_fire(pd: _PairData, L: np.ndarray, p: np.ndarray, R: float,
                   tolerances: Tolerances = DEFAULT, *, compiled: bool = False) -> np.ndarray:
    """One ball test of one pair: which units' fat A-feature meets B (for tests and tools).

    Args:
        pd: pair data from :func:`prepare_pair` (or built from feature sets).
        L: (3, 3) linear part of the centre g (A body frame -> B frame); p: (3,).
        R: ball radius (metric of ``pd.A.metric``), used as given (no padding).
        compiled: evaluate with :func:`monitor.certify.fat_kernels.fat_level` (pre-filter
            off) instead of the numpy oracle kernels.

    Returns:
        (n_units,) bool, in the order of ``pd.A.units x pd.B.units`` (or A vertices for a half-space).
    """
    C = _Concat([pd])
    T = _build_tables([pd], C)
    tol = tolerances
    L1, p1, R1 = np.asarray(L, float)[None], np.asarray(p, float)[None], np.array([float(R)])
    if compiled:
        return _one_ball_compiled(pd, C, T, L1, p1, R1, tol, prefilter=False)[1]
    eps = _eps_items(np.array([pd.A.extent]), np.array([pd.B.extent]), np.array([pd.A.flat_err]),
                     np.array([pd.B.flat_err]), np.array([_sqrt_jinv(pd.A.metric)]), L1, p1, R1, tol)
    ball = _Ball(L1, p1, R1, np.array([pd.A.rho_max]), np.array([pd.r]), eps, tol)
    uid = T.pair_units[0]
    uf, *_ = _evaluate(C, T, np.zeros(len(uid), np.int64), uid, ball, tol)
    return uf


def prefilter_separated(pd: _PairData, L: np.ndarray, p: np.ndarray, R: float,
                        tolerances: Tolerances = DEFAULT, *, compiled: bool = False) -> bool:
    """The pre-filter's answer for one ball (True = whole orbit provably misses B); for tests.

    ``compiled``: the answer of :func:`monitor.certify.fat_kernels.fat_level` instead of
    the numpy oracle.
    """
    tol = tolerances
    L1, p1, R1 = np.asarray(L, float)[None], np.asarray(p, float)[None], np.array([float(R)])
    if compiled:
        C = _Concat([pd])
        return bool(_one_ball_compiled(pd, C, _build_tables([pd], C), L1, p1, R1, tol, prefilter=True)[0][0])
    eps = _eps_items(np.array([pd.A.extent]), np.array([pd.B.extent]), np.array([pd.A.flat_err]),
                     np.array([pd.B.flat_err]), np.array([_sqrt_jinv(pd.A.metric)]), L1, p1, R1, tol)
    ball = _Ball(L1, p1, R1, np.array([pd.A.rho_max]), np.array([pd.r]), eps, tol)
    return bool(_Prefilter([pd]).separated(np.zeros(1, np.int64), ball, tol)[0])


def _one_ball_compiled(pd: _PairData, C: _Concat, T: _Tables, L1: np.ndarray, p1: np.ndarray,
                       R1: np.ndarray, tol: Tolerances, prefilter: bool) -> tuple[np.ndarray, np.ndarray]:
    """(sep (1,), unit_fired (n_units,)) of one ball by the compiled level kernel."""
    fast = _FastLevel(C, T, _Prefilter([pd]) if prefilter else None, np.array([pd.A.rho_max]),
                      np.array([pd.r], float), np.array([pd.A.extent]), np.array([pd.B.extent]),
                      np.array([pd.A.flat_err]), np.array([pd.B.flat_err]),
                      np.array([_sqrt_jinv(pd.A.metric)]), tol, short_circuit=False)
    uid = T.pair_units[0]
    fr = _Frontier(np.zeros(1, np.int64), np.zeros(1), np.ones(1), np.zeros(1, np.int64),
                   np.zeros(len(uid), np.int64), uid)
    sep, fired, *_ = fast.level(fr, L1, p1, R1)
    return sep, fired


class _Prefilter:
    """Cheap sound pre-test: the orbit of A lies in conv{ball(g(v), F(v)) : v vertex of A}.

    F = sqrt(q) is convex and g affine, so ball(g(x), F(x)) for x = sum l_i v_i lies in
    sum l_i ball(g(v_i), F(v_i)). Its support in direction n is max_v n.g(v) + F(v); if
    min_v n_j.g(v) - F(v) > off_j for an outward face normal n_j of B (B in its half-space
    n_j.z <= off_j), the whole orbit misses B and the item is excluded without unit tests.
    Polygons B are tested on both sides of their plane; points, segments and half-spaces
    (VH is already this test) are skipped.
    """

    def __init__(self, pairs: list[_PairData]):
        P = len(pairs)
        nv = max(len(pd.A.verts) for pd in pairs)
        nf = max([len(pd.B.f_n) for pd in pairs] + [1])
        self.V = np.zeros((P, nv, 3))
        self.qv = np.zeros((P, nv))
        self.n = np.zeros((P, nf, 3))
        self.off = np.zeros((P, nf))
        self.on = np.zeros(P, bool)
        self.two = np.zeros(P, bool)
        for i, pd in enumerate(pairs):
            k = len(pd.A.verts)
            self.V[i, :k], self.V[i, k:] = pd.A.verts, pd.A.verts[0]
            self.qv[i, :k], self.qv[i, k:] = pd.A.qv, pd.A.qv[0]
            if pd.B.kind in ("polytope", "polygon") and len(pd.B.f_n):
                m = len(pd.B.f_n)
                off = np.einsum("ij,ij->i", pd.B.f_n, pd.B.f_o)
                self.n[i, :m], self.n[i, m:] = pd.B.f_n, pd.B.f_n[0]
                self.off[i, :m], self.off[i, m:] = off, off[0]
                self.on[i] = True
                self.two[i] = pd.B.kind == "polygon"

    def separated(self, pair: np.ndarray, ball: _Ball, tol: Tolerances) -> np.ndarray:
        """(N,) True where the item's whole orbit is outside one face plane of B."""
        out = np.zeros(len(pair), bool)
        idx = np.nonzero(self.on[pair])[0]
        if not len(idx):
            return out
        pr = pair[idx]
        Y = np.einsum("nij,nvj->nvi", ball.L[idx], self.V[pr]) + ball.p[idx][:, None, :]
        F = np.sqrt(ball.R2[idx][:, None] * self.qv[pr] + ball.Delta[idx][:, None])
        h = np.einsum("nfi,nvi->nfv", self.n[pr], Y) - self.off[pr][:, :, None]
        e = 4.0 * ball.eps[idx]
        mag = np.abs(h).max(axis=(1, 2)) + F.max(axis=1) + np.abs(self.off[pr]).max(axis=1)
        pad = 8.0 * tol.rel_pad * mag + e
        sep = ((h - F[:, None, :]).min(axis=2) > pad[:, None]).any(axis=1)
        two = self.two[pr]
        if two.any():
            sep |= two & ((h + F[:, None, :]).max(axis=2) < -pad[:, None]).any(axis=1)
        out[idx] = sep
        return out


# ============================================================================ driver


def _c(x: np.ndarray, dtype: Any = np.float64) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=dtype)


def _flat_rows(T: _Tables) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Global row table as three (n_rows,) int64 arrays: type code, A feature, B feature.

    Type codes follow ``_TYPES`` (``fat_kernels.T_VF`` ...); for VH rows the B column is
    the pair index (the half-space of that pair).
    """
    types, cols_a, cols_b = [], [], []
    for k, t in enumerate(_TYPES):
        rows = T.rows[t]
        n = len(rows["pair"])
        types.append(np.full(n, k, np.int64))
        cols_a.append(rows["a"])
        cols_b.append(rows["b"] if "b" in rows else rows["pair"])
    return (_c(np.concatenate(types), np.int64), _c(np.concatenate(cols_a), np.int64),
            _c(np.concatenate(cols_b), np.int64))


class _FastLevel:
    """Flat arrays of one :func:`subdivide` call for :func:`monitor.certify.fat_kernels.fat_level`."""

    def __init__(self, C: _Concat, T: _Tables, pre: _Prefilter | None, rho_max: np.ndarray,
                 r_pair: np.ndarray, a_ext: np.ndarray, b_ext: np.ndarray, flat_a: np.ndarray,
                 flat_b: np.ndarray, sqj: np.ndarray, tol: Tolerances, short_circuit: bool = True):
        from monitor.certify import fat_kernels
        self.kernel = fat_kernels.fat_level
        rt, ra, rb = _flat_rows(T)
        if pre is not None:
            pf = (_c(pre.V), _c(pre.qv), _c(pre.n), _c(pre.off), _c(pre.on, np.bool_),
                  _c(pre.two, np.bool_), 1)
        else:
            P = len(rho_max)
            pf = (np.zeros((P, 1, 3)), np.zeros((P, 1)), np.zeros((P, 1, 3)), np.zeros((P, 1)),
                  np.zeros(P, np.bool_), np.zeros(P, np.bool_), 0)
        self.per_pair = tuple(_c(x) for x in (rho_max, r_pair, a_ext, b_ext, flat_a, flat_b, sqj)) + pf
        self.feats = tuple(_c(x) for x in (C.av, C.aqv, C.ae_v0, C.ae_d, C.ae_k, C.af_o, C.af_U, C.af_k0,
                                            C.af_kg, C.af_K, C.af_hn, C.af_hc, C.be_w0, C.be_e, C.bf_o,
                                            C.bf_n, C.bf_U, C.bf_hn, C.bf_hc, C.h_n, C.h_off))
        self.rows = (rt, ra, rb, _c(T.unit_ptr, np.int64), _c(T.unit_rows, np.int64))
        self.tol = (float(tol.rel_pad), float(tol.abs_pad), float(tol.scale_pad), int(bool(short_circuit)))

    def level(self, fr: _Frontier, L: np.ndarray, p: np.ndarray, R: np.ndarray):
        """(sep (N,), unit_fired (K,), rows per item (N,), units per item (N,), distinct rows)."""
        N, K = len(fr.pair), len(fr.unit_item)
        sep = np.empty(N, np.bool_)
        fired = np.empty(K, np.bool_)
        rows_i = np.empty(N, np.int64)
        units_i = np.empty(N, np.int64)
        nrow = self.kernel(_c(fr.pair, np.int64), _c(L), _c(p), _c(R), *self.per_pair, *self.feats,
                           *self.rows, _c(fr.unit_item, np.int64), _c(fr.unit_id, np.int64), *self.tol,
                           sep, fired, rows_i, units_i)
        return sep, fired, rows_i, units_i, int(nrow)



@dataclass
class _Frontier:
    pair: np.ndarray      # (N,)
    t0: np.ndarray        # (N,)
    t1: np.ndarray
    depth: np.ndarray
    unit_item: np.ndarray  # (K,) index into items
    unit_id: np.ndarray    # (K,) global unit id
    extra: Any = None      # ball-provider state per item (e.g. Bézier control points)


# Public names of the subdivision state for ball providers outside this module
# (monitor.certify.bezier): a frontier of (pair, [t0, t1]) items and a prepared pair.
Frontier = _Frontier
PairData = _PairData


class BallProvider:
    """Interface: per-item g = (L (N,3,3), p (N,3)) and radius R (N,) for a frontier."""

    def balls(self, fr: _Frontier) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Centre (L, p) and radius R of every frontier item's ball."""
        raise NotImplementedError

    def split(self, fr: _Frontier, keep: np.ndarray) -> Any:
        """Per-child extra state for items ``keep`` (children ordered [left..., right...])."""
        return None


@dataclass
class SubdivisionResult:
    """Per-pair result of :func:`subdivide`."""

    intervals: list[list[tuple[float, float]]]
    unit_tests: np.ndarray   # per pair: (unit, item) evaluations ("polygon vs fat polygon")
    row_tests: np.ndarray    # per pair: elementary row evaluations
    max_depth: np.ndarray
    items: np.ndarray        # per pair: ball tests (items evaluated)
    exhausted: bool
    prefiltered: np.ndarray | None = None  # per pair: items excluded by the pre-filter
    capped: np.ndarray | None = None  # per pair: items left unresolved by the frontier cap


def frontier_over_cap(pair: np.ndarray, t0: np.ndarray, go: np.ndarray, cap: int) -> np.ndarray:
    """Items to stop because their pair already splits ``cap`` earlier items at this level.

    Args:
        pair: (N,) pair index of each frontier item.
        t0: (N,) item start times (s); earlier items are kept.
        go: (N,) bool, items that would be split.
        cap: maximum items split per pair (<= 0: no cap).

    Returns:
        (N,) bool mask (subset of ``go``) of the items over the cap.
    """
    over = np.zeros(len(pair), bool)
    if cap <= 0:
        return over
    idx = np.nonzero(go)[0]
    if len(idx) <= cap:
        return over
    order = idx[np.lexsort((t0[idx], pair[idx]))]
    sp = pair[order]
    starts = np.concatenate([[0], np.nonzero(np.diff(sp))[0] + 1])
    rank = np.arange(len(order)) - np.repeat(starts, np.diff(np.concatenate([starts, [len(order)]])))
    over[order[rank >= cap]] = True
    return over


def subdivide(pairs: list[_PairData], provider: BallProvider, t0: float, t1: float, epsilon: float,
              tolerances: Tolerances = DEFAULT, budget: Budget | None = None,
              active: np.ndarray | None = None, extra0: Any = None,
              prefilter: bool = True, compiled: bool | None = None) -> SubdivisionResult:
    """Breadth-first subdivision over all pairs (§6, Listings 1-2, Remark 2 pruning).

    ``prefilter`` runs :class:`_Prefilter` on every item first (items it excludes count no
    unit tests; their number is in ``SubdivisionResult.prefiltered``).
    ``compiled`` evaluates each level's pre-filter and rows in one numba call
    (:func:`monitor.certify.fat_kernels.fat_level`); False runs the numpy kernels of this
    module, kept as the test oracle (same tests, same pads, same counts); None: the module
    switch :data:`USE_COMPILED`.
    """
    tol = tolerances
    C = _Concat(pairs)
    T = _build_tables(pairs, C)
    pre = _Prefilter(pairs) if prefilter and pairs else None
    prefiltered = np.zeros(len(pairs), np.int64)
    npair = len(pairs)
    idx_pairs = np.arange(npair) if active is None else np.nonzero(active)[0]
    rho_max = np.array([pd.A.rho_max for pd in pairs]) * (1.0 + 1e-12)
    r_pair = np.array([pd.r for pd in pairs], float)
    a_ext = np.array([pd.A.extent for pd in pairs], float)
    b_ext = np.array([pd.B.extent for pd in pairs], float)
    flat_a = np.array([pd.A.flat_err for pd in pairs], float)
    flat_b = np.array([pd.B.flat_err for pd in pairs], float)
    sqj = np.array([_sqrt_jinv(pd.A.metric) for pd in pairs], float)
    fast = (_FastLevel(C, T, pre, rho_max, r_pair, a_ext, b_ext, flat_a, flat_b, sqj, tol, SHORT_CIRCUIT)
            if (USE_COMPILED if compiled is None else compiled) and pairs else None)
    units_i = [T.pair_units[i] for i in idx_pairs]
    fr = _Frontier(idx_pairs.astype(np.int64), np.full(len(idx_pairs), t0), np.full(len(idx_pairs), t1),
                   np.zeros(len(idx_pairs), np.int64),
                   np.repeat(np.arange(len(idx_pairs)), [len(u) for u in units_i]).astype(np.int64),
                   np.concatenate(units_i) if units_i else np.zeros(0, np.int64), extra0)
    stopped: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []   # (pair, t0, t1) chunks
    unit_tests = np.zeros(npair, np.int64)
    row_tests = np.zeros(npair, np.int64)
    items_n = np.zeros(npair, np.int64)
    max_depth = np.zeros(npair, np.int64)
    capped = np.zeros(npair, np.int64)
    exhausted = False
    while len(fr.pair):
        if budget is not None and budget.exhausted:
            exhausted = True
            stopped.append((fr.pair, fr.t0, fr.t1))
            break
        N = len(fr.pair)
        np.maximum.at(max_depth, fr.pair, fr.depth)
        try:  # the motion bounds and the kernels poll the certify budget (one level can be long)
            L, p, R = provider.balls(fr)
            R = R * (1.0 + 8 * tol.rel_pad) + tol.abs_pad
            pr = fr.pair
            if fast is None:
                eps_pos = _eps_items(a_ext[pr], b_ext[pr], flat_a[pr], flat_b[pr], sqj[pr], L, p, R, tol)
            if fast is not None:
                check_active_budget()
                sep, unit_fired, rows_i, units_i_n, nrow = fast.level(fr, L, p, R)
            else:
                ball = _Ball(L, p, R, rho_max[pr], r_pair[pr], eps_pos, tol)
                if pre is not None:
                    sep = pre.separated(fr.pair, ball, tol)
                    live = np.nonzero(~sep[fr.unit_item])[0]
                else:
                    live = np.arange(len(fr.unit_item))
                uf_live, cnt, u_item, nrow = _evaluate(C, T, fr.unit_item[live], fr.unit_id[live], ball, tol)
        except BudgetExhausted:  # this level's frontier stays unresolved, as at the check above
            exhausted = True
            stopped.append((fr.pair, fr.t0, fr.t1))
            break
        if pre is not None:
            prefiltered += np.bincount(fr.pair[sep], minlength=npair)
        if fast is not None:
            row_tests += _count(fr.pair, rows_i, npair)
            unit_tests += _count(fr.pair, units_i_n, npair)
        else:
            unit_fired = np.zeros(len(fr.unit_item), bool)
            unit_fired[live] = uf_live
            row_tests += np.bincount(fr.pair[u_item], minlength=npair)
            unit_tests += np.bincount(fr.pair[fr.unit_item[live]], minlength=npair)
        items_n += np.bincount(fr.pair, minlength=npair)
        if budget is not None:
            budget.charge(nrow)
        item_fired = np.zeros(N, bool)
        item_fired[fr.unit_item[unit_fired]] = True
        # termination (eq. 11) or depth cap
        small = R * rho_max[fr.pair] < epsilon
        stop = item_fired & (small | (fr.depth >= tol.max_depth))
        if stop.any():
            stopped.append((fr.pair[stop], fr.t0[stop], fr.t1[stop]))
        go = item_fired & ~stop
        over = frontier_over_cap(fr.pair, fr.t0, go, int(tol.max_frontier))
        if over.any():
            stopped.append((fr.pair[over], fr.t0[over], fr.t1[over]))
            capped += np.bincount(fr.pair[over], minlength=npair)
        go &= ~over
        if not go.any():
            break
        keep = np.nonzero(go)[0]
        newpos = -np.ones(N, np.int64)
        newpos[keep] = np.arange(len(keep))
        k = len(keep)
        uf = unit_fired & go[fr.unit_item]
        ui, uid = newpos[fr.unit_item[uf]], fr.unit_id[uf]
        mid = 0.5 * (fr.t0[keep] + fr.t1[keep])
        extra = provider.split(fr, keep)
        fr = _Frontier(np.concatenate([fr.pair[keep]] * 2), np.concatenate([fr.t0[keep], mid]),
                       np.concatenate([mid, fr.t1[keep]]), np.concatenate([fr.depth[keep] + 1] * 2),
                       np.concatenate([ui, ui + k]), np.concatenate([uid, uid]), extra)
    return SubdivisionResult(_merged_intervals(stopped, npair), unit_tests, row_tests, max_depth, items_n,
                             exhausted, prefiltered, capped)


def first_interval_dfs(pd: _PairData, provider: BallProvider, t0: float, t1: float, epsilon: float,
                       tolerances: Tolerances = DEFAULT, extra0: Any = None
                       ) -> tuple[tuple[float, float] | None, int, int]:
    """Depth-first variant of Listing 1 that returns at the FIRST interval of possible collision.

    Only for comparing counts with the paper (its Listing 1 returns after the first
    branch); the checkers use :func:`subdivide`. Same tests, pruning and termination.

    Returns:
        (interval or None if the motion is certified, unit tests performed, max depth).
    """
    tol = tolerances
    C = _Concat([pd])
    T = _build_tables([pd], C)
    uid0 = T.pair_units[0]
    sqj = np.array([_sqrt_jinv(pd.A.metric)])
    z = np.zeros(1, np.int64)
    stack = [_Frontier(z.copy(), np.array([t0]), np.array([t1]), z.copy(), np.zeros(len(uid0), np.int64),
                       uid0, extra0)]
    tests, depth = 0, 0
    while stack:
        fr = stack.pop()
        depth = max(depth, int(fr.depth[0]))
        L, p, R = provider.balls(fr)
        R = R * (1.0 + 8 * tol.rel_pad) + tol.abs_pad
        eps = _eps_items(np.array([pd.A.extent]), np.array([pd.B.extent]), np.array([pd.A.flat_err]),
                         np.array([pd.B.flat_err]), sqj, L, p, R, tol)
        ball = _Ball(L, p, R, np.array([pd.A.rho_max]), np.array([pd.r]), eps, tol)
        uf, *_ = _evaluate(C, T, fr.unit_item, fr.unit_id, ball, tol)
        tests += len(fr.unit_id)
        if not uf.any():
            continue
        if not (R[0] * pd.A.rho_max < epsilon) and fr.depth[0] < tol.max_depth:
            extra = provider.split(fr, np.array([0]))
            mid = 0.5 * (fr.t0[0] + fr.t1[0])
            ids = fr.unit_id[uf]
            zi = np.zeros(len(ids), np.int64)
            for k, (a, b) in ((1, (mid, fr.t1[0])), (0, (fr.t0[0], mid))):   # left child on top
                ex = None if extra is None else extra[k:k + 1]
                stack.append(_Frontier(z.copy(), np.array([a]), np.array([b]), fr.depth + 1, zi, ids, ex))
            continue
        return (float(fr.t0[0]), float(fr.t1[0])), tests, depth
    return None, tests, depth


def _count(idx: np.ndarray, weights: np.ndarray, n: int) -> np.ndarray:
    """Exact integer ``np.add.at(zeros(n), idx, weights)`` (weights >= 0, sums < 2^53)."""
    return np.bincount(idx, weights=weights, minlength=n).astype(np.int64)


def _merged_intervals(chunks: list[tuple[np.ndarray, np.ndarray, np.ndarray]], npair: int
                      ) -> list[list[tuple[float, float]]]:
    """Per pair, the sorted union of the stopped items' [t0, t1] (as :func:`_merge` of the sorted list).

    Sorted by (pair, t0, t1), an interval starts a new run iff its t0 exceeds the running max
    of the previous t1 (of the same pair); a run is [its first t0, its running max of t1].
    """
    out: list[list[tuple[float, float]]] = [[] for _ in range(npair)]
    if not chunks:
        return out
    pr = np.concatenate([c[0] for c in chunks])
    if not len(pr):
        return out
    a = np.concatenate([c[1] for c in chunks]).astype(float)
    b = np.concatenate([c[2] for c in chunks]).astype(float)
    order = np.lexsort((b, a, pr))
    pr, a, b = pr[order], a[order], b[order]
    cuts = np.flatnonzero(np.diff(pr)) + 1
    for lo, hi in zip(np.concatenate([[0], cuts]).tolist(), np.concatenate([cuts, [len(pr)]]).tolist()):
        aa, cm = a[lo:hi], np.maximum.accumulate(b[lo:hi])
        start = np.ones(hi - lo, bool)
        start[1:] = aa[1:] > cm[:-1]
        s_idx = np.flatnonzero(start)
        e_idx = np.concatenate([s_idx[1:] - 1, [hi - lo - 1]])
        out[int(pr[lo])] = list(zip(aa[s_idx].tolist(), cm[e_idx].tolist()))
    return out


def _merge(iv: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[tuple[float, float]] = []
    for a, b in sorted(iv):
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


# ============================================================================ trajectories


class _TrajectoryBalls(BallProvider):
    """Balls from the certified motion bounds of a Trajectory (relative motion of A in B's frame).

    Construction (both bodies may move). Sub-interval [ta, tb], midpoint m. The relative
    pose is X_BA(t) = X_WB(t)^-1 X_WA(t); the centre is g = X_BA(m) (rigid). For a point p
    of A (body frame), with w(t) = X_WA(t) p and u = g(p) = X_WB(m)^-1 w(m) (a point of B's
    rigid extension),

        |X_BA(t) p - g(p)| = |w(t) - X_WB(t) u|                     (X_WB(t)^-1 is an isometry)
                           <= |w(t) - w(m)| + |X_WB(m) u - X_WB(t) u|
                           <= T_A + ch_A |p - c_A| + T_B + ch_B |g(p) - c_B| =: delta(p),

    by the motion-bound contract applied to A at p and to B at u (c = reference points,
    ch = chord(angle)). Every relative pose of the sub-interval is then in B_R(g) with
    R^2 = sum_i w_i delta(m_i)^2 over A's feature points (the metric's definition), which
    we evaluate per feature point (tighter than the closed form in design.md) and pad.
    """

    def __init__(self, traj: Trajectory, body_a: np.ndarray, body_b: np.ndarray, metrics: list[Metric],
                 compiled: bool = False):
        self.traj = traj
        self.ba, self.bb = body_a, body_b
        self.ref = np.asarray(traj.ref_points, float)
        self.mp = [m.points for m in metrics]
        self.mw = [m.weights for m in metrics]
        self.mp_off = np.cumsum([0] + [len(x) for x in self.mp])
        self.mp_all = np.concatenate(self.mp)
        self.mw_all = np.concatenate(self.mw)
        self.pack = _motion_pack(traj) if compiled else None
        self.screw = None
        if compiled and self.pack is None and getattr(traj, "interpolation", None) == "screw" \
                and hasattr(traj, "screw_arrays"):
            self.screw = traj.screw_arrays()
        if compiled:
            self.flat = (_c(body_a, np.int64), _c(body_b, np.int64), _c(self.ref), _c(self.mp_all),
                         _c(self.mw_all), _c(self.mp_off, np.int64))

    def balls(self, fr: _Frontier):
        if hasattr(self, "flat"):
            return self._balls_compiled(fr)
        return self._balls_numpy(fr)

    def _balls_compiled(self, fr: _Frontier):
        """Compiled balls: the radii in :func:`fat_kernels.traj_balls`.

        Poses and bounds come from one compiled call when the motion packs (lerp+slerp
        BodyMotion, Plan), else from the Trajectory protocol (screw BodyMotion, others).
        """
        from monitor.certify import fat_kernels
        if self.pack is not None:
            from monitor.motion.pack import poses_and_bounds
            pos, rot, mb = poses_and_bounds(self.pack, fr.t0, fr.t1)
        elif self.screw is not None:
            pos, rot, mb = _screw_poses_bounds(self.traj, self.screw, fr.t0, fr.t1)
        else:
            pos, rot = self.traj.body_poses(0.5 * (fr.t0 + fr.t1))
            mb = self.traj.motion_bounds(fr.t0, fr.t1)
        N = len(fr.pair)
        L, p, R = np.empty((N, 3, 3)), np.empty((N, 3)), np.empty(N)
        ba, bb, ref, mp_all, mw_all, mp_off = self.flat
        fat_kernels.traj_balls(_c(fr.pair, np.int64), ba, bb, _c(pos), _c(rot), _c(mb.trans), _c(mb.angle),
                               ref, mp_all, mw_all, mp_off, 1.0 + 8 * DEFAULT.rel_pad, L, p, R)
        return L, p, R

    def _balls_numpy(self, fr: _Frontier):
        mids = 0.5 * (fr.t0 + fr.t1)
        pos, rot = self.traj.body_poses(mids)
        mb = self.traj.motion_bounds(fr.t0, fr.t1)
        n = np.arange(len(mids))
        a, b = self.ba[fr.pair], self.bb[fr.pair]
        Ra, pa = rot[n, a], pos[n, a]
        Rb, pb = rot[n, b], pos[n, b]
        L = np.einsum("nji,njk->nik", Rb, Ra)
        p = np.einsum("nji,nj->ni", Rb, pa - pb)
        # per feature point displacement bound of the relative motion (design doc)
        cnt = self.mp_off[fr.pair + 1] - self.mp_off[fr.pair]
        item = np.repeat(n, cnt)
        start = np.repeat(self.mp_off[fr.pair] - np.cumsum(np.concatenate([[0], cnt[:-1]])), cnt)
        j = np.arange(cnt.sum()) + start
        m = self.mp_all[j]
        w = self.mw_all[j]
        TA, AA = mb.trans[item, a[item]], mb.angle[item, a[item]]
        TB, AB = mb.trans[item, b[item]], mb.angle[item, b[item]]
        cA, cB = self.ref[a[item]], self.ref[b[item]]
        mB = np.einsum("nij,nj->ni", L[item], m) + p[item]
        d = (TA + chord(AA) * np.linalg.norm(m - cA, axis=1)
             + TB + chord(AB) * np.linalg.norm(mB - cB, axis=1))
        d = d * (1.0 + 8 * DEFAULT.rel_pad)
        R2 = np.bincount(item, weights=w * d * d, minlength=len(mids))
        return L, p, np.sqrt(R2)


def _screw_poses_bounds(traj: Any, arrays: tuple, t0: np.ndarray, t1: np.ndarray):
    """Midpoint poses and motion bounds of a screw BodyMotion in one compiled call.

    Same numbers as ``traj.body_poses((t0 + t1) / 2)`` and ``traj.motion_bounds(t0, t1)``
    (:func:`monitor.certify.fat_kernels.screw_poses_bounds`; rounding-level differences).
    """
    from monitor.certify import fat_kernels
    from monitor.motion import _kinematics as K
    from monitor.motion.base import MotionBounds
    a, b = K.check_interval_arrays(t0, t1, traj.window)
    N, nb = a.shape[0], arrays[1].shape[1]
    pos, rot = np.empty((N, nb, 3)), np.empty((N, nb, 3, 3))
    trans, angle = np.empty((N, nb)), np.empty((N, nb))
    fat_kernels.screw_poses_bounds(*arrays, _c(a), _c(b), pos, rot, trans, angle)
    return pos, rot, MotionBounds(t0=a, t1=b, trans=trans, angle=angle)


def _motion_pack(traj: Trajectory) -> Any:
    """The compiled kernels' pack of ``traj`` (lerp+slerp BodyMotion or Plan), or None.

    :func:`monitor.certify.kernels.trajectory_pack`: the engine's own pack, cached per
    trajectory object and checked once against the trajectory's poses. Its poses equal
    the trajectory's; its bounds are the compiled kernels' (``motion.kernel``, the contract
    of ``motion.plan``, the bound the compiled whole-shape stage already uses): on one
    segment with reference points at the body origins they equal BodyMotion's to < 1e-8
    relative (measured), across waypoints they can be tighter (minimum of the chain and
    Taylor bounds). tests/test_fat_kernels.py samples the resulting balls.
    """
    from monitor.certify.kernels import trajectory_pack
    return trajectory_pack(traj)


def _orient(shape_a: ConvexShape, body_a: int, shape_b: ConvexShape, body_b: int,
            static: np.ndarray | None) -> bool:
    """True if A and B must be swapped (B = half-space, or the static body, is the fixed side)."""
    if shape_a.kind == "halfspace":
        return True
    if shape_b.kind == "halfspace":
        return False
    if static is not None and static[body_a] and not static[body_b]:
        return True
    return False


def prepare_pair(shape_a: ConvexShape, shape_b: ConvexShape, margin: float,
                 tolerances: Tolerances = DEFAULT) -> _PairData:
    """Feature sets and inflation radius r of (moving A, fixed B)."""
    r = float(shape_a.radius) + float(shape_b.radius) + float(margin)
    return _PairData(moving_features(shape_a), fixed_features(shape_b), r + tolerances.pad(r))


def check_pairs(traj: Trajectory, items: list[tuple[ConvexShape, int, ConvexShape, int]],
                window: tuple[float, float], margin: float, epsilon: float,
                tolerances: Tolerances = DEFAULT, budget: Budget | None = None, *,
                static: np.ndarray | None = None, check_start: bool = True,
                compiled: bool | None = None) -> list[PairOutcome]:
    """Toleranced-ball check of shape pairs under a trajectory.

    Args:
        traj: the motion (Trajectory protocol; only body_poses / motion_bounds are used).
        items: (shape_a, body_a, shape_b, body_b) per pair, shapes in their body frames.
        window: (t0, t1) seconds.
        margin: clearance (m) that counts as safe.
        epsilon: termination tolerance (m): stop when R * rho_max < epsilon.
        tolerances: pads and max depth.
        budget: optional work limit; when exhausted the unfinished pairs are unresolved.
        static: optional (nbody,) bool; a static body is chosen as the fixed side.
        check_start: run the exact static test at t0 for solid pairs (containment is
            invisible to boundary tests). The engine does it itself and passes False.
        compiled: run the levels in :func:`monitor.certify.fat_kernels.fat_level`; False:
            the numpy kernels of this module (the test oracle); None: :data:`USE_COMPILED`.

    Returns:
        One :class:`PairOutcome` per item: ``"certified"`` or ``"unresolved"`` (the engine
        turns unresolved intervals into witnesses). ``info`` holds ``unit_tests``,
        ``row_tests``, ``items`` and ``swapped``.
    """
    t0, t1 = float(window[0]), float(window[1])
    pds, ba, bb, swapped = [], [], [], []
    for sa, a, sb, b in items:
        if budget is not None and budget.exhausted:  # feature sets of big meshes take a while
            return [PairOutcome(Outcome.UNRESOLVED, intervals=[(t0, t1)], info={"budget_exhausted": True})
                    for _ in items]
        sw = _orient(sa, a, sb, b, static)
        if sw:
            sa, a, sb, b = sb, b, sa, a
        pds.append(prepare_pair(sa, sb, margin, tolerances))
        ba.append(a)
        bb.append(b)
        swapped.append(sw)
    outs: list[PairOutcome | None] = [None] * len(items)
    active = np.ones(len(items), bool)
    if check_start:
        from monitor.geometry.distance import shape_distance
        pos, rot = traj.body_poses(np.array([t0]))
        for i, (sa, a, sb, b) in enumerate(items):
            if sa.kind != "polytope" and sb.kind != "polytope":
                continue
            if "halfspace" in (sa.kind, sb.kind):
                continue
            res = shape_distance(sa, (rot[0, a], pos[0, a]), sb, (rot[0, b], pos[0, b]),
                                 tolerances=tolerances)
            if res.lower + sa.radius + sb.radius <= 0.0 and res.lower <= margin:
                outs[i] = PairOutcome(Outcome.UNRESOLVED, intervals=[(t0, t0)],
                                      info={"start_overlap": True, "start_upper": res.upper})
                active[i] = False
    if active.any():
        comp = USE_COMPILED if compiled is None else compiled
        prov = _TrajectoryBalls(traj, np.array(ba), np.array(bb), [pd.A.metric for pd in pds], compiled=comp)
        res = subdivide(pds, prov, t0, t1, epsilon, tolerances, budget, active, compiled=comp)
        for i in np.nonzero(active)[0]:
            iv = res.intervals[i]
            outs[i] = PairOutcome(
                Outcome.CERTIFIED if not iv else Outcome.UNRESOLVED, tests=int(res.row_tests[i]),
                max_depth=int(res.max_depth[i]), intervals=iv,
                clearance=float(margin) if not iv else float("-inf"),
                info={"unit_tests": int(res.unit_tests[i]), "row_tests": int(res.row_tests[i]),
                      "items": int(res.items[i]), "swapped": bool(swapped[i]),
                      "prefiltered": int(res.prefiltered[i]),
                      "frontier_capped": int(res.capped[i]),
                      "budget_exhausted": bool(res.exhausted)})
    return outs  # type: ignore[return-value]


def warm_kernels() -> None:
    """Compile (or load from numba's disk cache) the fat-feature stage's kernels once.

    :func:`monitor.certify.fat_kernels.fat_level`, ``traj_balls`` and ``screw_poses_bounds``
    on a tiny box pair and a two-body screw motion. With an empty cache this takes several
    seconds (docs/notes/issue-12-slowcases.md); call it before any budgeted ``certify``
    that may reach the fat-feature stage (``monitor.warmup``).
    """
    from monitor.geometry.polytope import box_polytope
    from monitor.motion.bodymotion import BodyMotion

    box = box_polytope(np.array([0.1, 0.1, 0.1]))
    pos = np.zeros((2, 2, 3))
    pos[:, 1] = [[0.3, 0.0, 0.0], [0.3, 0.1, 0.0]]
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (2, 2, 1))
    quat[1, 1] = [np.cos(0.2), 0.0, 0.0, np.sin(0.2)]
    for interp in ("lerp_slerp", "screw"):
        bm = BodyMotion(np.array([0.0, 1.0]), pos, quat, interpolation=interp)
        check_pairs(bm, [(box, 1, box, 0)], (0.0, 1.0), 0.0, 0.05, compiled=True, check_start=False)


__all__ = ["MovingFeatures", "FixedFeatures", "moving_features", "fixed_features", "prepare_pair",
           "subdivide", "check_pairs", "BallProvider", "SubdivisionResult", "first_interval_dfs",
           "fat_units_fire", "prefilter_separated", "frontier_over_cap", "Frontier", "PairData",
           "warm_kernels", "USE_COMPILED", "SHORT_CIRCUIT"]
