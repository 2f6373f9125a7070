r"""Pack a scene's geom cores once into flat arrays for the compiled kernels (issue 12).

One :class:`GeomPack` holds every geom of a :class:`monitor.Scene` (or of a plain list
of shapes): core vertices, edges and face normals concatenated with offset tables, the
radius, the kind code of :mod:`monitor.geometry._gjk` (-1 for half-spaces, -2 for
geoms without a shape), the body of each geom, the over-approximation ``approx_error``
of circumscribed cylinders/ellipsoids and the depth pad of the face normals (both
from :mod:`monitor.geometry.distance`, whose validation is reused), plus, per geom,
the Schröcker & Weber metric of its core (§2: feature points ``m_i`` and weights
``w_i``) and ``rho_max``, the maximum of the distortion rate rho (eq. 4) over the
core's vertices (rho is convex, so this is its maximum over the core).

Everything is body frame, metres, float64 / int64 and C-contiguous, so a
:class:`GeomPack` is a numba-typable tuple. It is stored as five stacked arrays (float rows
of 3, per-geom float scalars, int64 offsets and codes, edges, metric weights) with named row
constants (``I_*``, ``S_*``, ``G_*``): the compile cost of every kernel typed on the pack grows
with the number of arrays in it (issue 12 item 7).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from monitor.errors import InvalidInputError
from monitor.geometry.shapes import ConvexShape

KIND_HALFSPACE = -1
"""Kind code of a half-space geom (``normals[0] . x <= offset`` in the body frame)."""
KIND_NONE = -2
"""Kind code of a geom without a convex shape (hfield / sdf outside every candidate pair)."""

_RHO_INFLATE = 1.0 + 1e-12
"""Upward relative inflation of rho_max (covers the float evaluation of eq. 4)."""


# Columns of the stacked arrays (issue 12 item 7, docs/notes/issue-12-coldstart-3.md): the compiled
# kernels index ``GeomPack.idx[I_*, g]``, ``GeomPack.scal[S_*, g]`` and the row ranges of ``GeomPack.rows``
# directly (no accessor function: a compiled helper typed on the pack is one more compile).
I_VROW = 0
"""``idx`` row: first row of geom g's core vertices in ``rows`` (row G: end of the vertex block)."""
I_EROW = 1
"""``idx`` row: first row of geom g's edges in ``edges``."""
I_NROW = 2
"""``idx`` row: first row of geom g's face normals (half-space: its normal) in ``rows``."""
I_MROW = 3
"""``idx`` row: first row of geom g's metric feature points in ``rows``."""
I_MW = 4
"""``idx`` row: first entry of geom g's metric weights in ``mw``."""
I_KIND = 5
"""``idx`` row: kind code (0 point, 1 segment, 2 polytope, -1 half-space, -2 none)."""
I_BODY = 6
"""``idx`` row: body id of geom g."""
I_CURVE = 7
"""``idx`` row: exact curved geom behind a circumscribed polytope (0 none, 1 cylinder, 2 ellipsoid)."""
I_GROW = 8
"""``idx`` row: first of geom g's ``G_ROWS`` per-geom rows in ``rows`` (see ``G_*``)."""
I_SIZE = 9

S_RADIUS = 0
"""``scal`` row: radius (m)."""
S_OFFSET = 1
"""``scal`` row: half-space offset (m; 0 otherwise)."""
S_DPAD = 2
"""``scal`` row: depth pad of the face normals (m; inf: no depth certificate)."""
S_APPROX = 3
"""``scal`` row: over-approximation ``approx_error`` (m)."""
S_RHO_MAX = 4
"""``scal`` row: max of rho over the core vertices (eq. 4), padded up."""
S_BRAD = 5
"""``scal`` row: radius (m) of the bounding sphere (inf for half-spaces and geoms without a shape)."""
S_SIZE = 6

G_CPARAM = 0
"""Per-geom row offset: cylinder (radius, half length, 0) / ellipsoid radii (m)."""
G_CCENTER = 1
"""Per-geom row offset: geom origin of the curved geom in the body frame (m)."""
G_BCENTER = 2
"""Per-geom row offset: centre of the bounding sphere, body frame (m)."""
G_CFRAME = 3
"""Per-geom row offset: 3 rows, rotation geom frame -> body frame of the curved geom."""
G_ROWS = 6


class GeomPack(NamedTuple):
    """G geoms stacked into five arrays (numba-typable; few arrays = cheap compiles, issue 12 item 7).

    Attributes:
        rows: (R, 3) float64 rows, body frames (m): the core vertices of all geoms, then their
            face normals (half-spaces: the plane normal), then their metric feature points,
            then ``G_ROWS`` rows per geom (``G_CPARAM``, ``G_CCENTER``, ``G_BCENTER``, the 3
            rows of ``G_CFRAME``).
        idx: (I_SIZE, G + 1) int64: row ranges (``I_VROW``, ``I_EROW``, ``I_NROW``, ``I_MROW``,
            ``I_MW``: geom g's rows are ``[idx[i, g], idx[i, g + 1])``) and the per-geom codes
            ``I_KIND``, ``I_BODY``, ``I_CURVE``, ``I_GROW`` (column G: 0).
        scal: (S_SIZE, G) float64 per-geom scalars (``S_*``).
        edges: (E, 2) int64 edges, vertex indices local to the geom.
        mw: (M,) float64 metric weights.

    The properties give the former per-field arrays (views; Python callers and tests):
    ``verts``, ``vstart``, ``edges``, ``estart``, ``normals``, ``nstart``, ``kind``, ``radius``,
    ``offset``, ``dpad``, ``approx``, ``body``, ``mpts``, ``mw``, ``mstart``, ``rho_max``,
    ``curve``, ``cparam``, ``cframe``, ``ccenter``, ``bcenter``, ``brad`` (meanings as in
    :func:`pack_shapes`).
    """

    rows: np.ndarray
    idx: np.ndarray
    scal: np.ndarray
    edges: np.ndarray
    mw: np.ndarray

    def _block(self, i: int) -> np.ndarray:
        return self.rows[self.idx[i, 0]:self.idx[i, -1]]

    def _start(self, i: int) -> np.ndarray:
        return self.idx[i] - self.idx[i, 0]

    def _per_geom(self, k: int, n: int = 1) -> np.ndarray:
        G = self.scal.shape[1]
        g0 = self.idx[I_GROW, 0] if G else 0
        per = self.rows[g0:g0 + G_ROWS * G].reshape(G, G_ROWS, 3)
        return per[:, k] if n == 1 else per[:, k:k + n]

    verts = property(lambda self: self._block(I_VROW), doc="(V, 3) core vertices (body frame, m).")
    vstart = property(lambda self: self._start(I_VROW), doc="(G + 1,) offsets into ``verts``.")
    estart = property(lambda self: self.idx[I_EROW], doc="(G + 1,) offsets into ``edges``.")
    normals = property(lambda self: self._block(I_NROW), doc="(N, 3) face normals / half-space normals.")
    nstart = property(lambda self: self._start(I_NROW), doc="(G + 1,) offsets into ``normals``.")
    mpts = property(lambda self: self._block(I_MROW), doc="(M, 3) metric feature points (body frame, m).")
    mstart = property(lambda self: self.idx[I_MW], doc="(G + 1,) offsets into ``mpts`` / ``mw``.")
    kind = property(lambda self: self.idx[I_KIND, :-1], doc="(G,) int64 kind code.")
    body = property(lambda self: self.idx[I_BODY, :-1], doc="(G,) int64 body id.")
    curve = property(lambda self: self.idx[I_CURVE, :-1], doc="(G,) int64 curved geom code.")
    radius = property(lambda self: self.scal[S_RADIUS], doc="(G,) radius (m).")
    offset = property(lambda self: self.scal[S_OFFSET], doc="(G,) half-space offset (m).")
    dpad = property(lambda self: self.scal[S_DPAD], doc="(G,) depth pad of the face normals (m).")
    approx = property(lambda self: self.scal[S_APPROX], doc="(G,) ``approx_error`` (m).")
    rho_max = property(lambda self: self.scal[S_RHO_MAX], doc="(G,) max of rho (eq. 4), padded up.")
    brad = property(lambda self: self.scal[S_BRAD], doc="(G,) bounding sphere radius (m).")
    cparam = property(lambda self: self._per_geom(G_CPARAM), doc="(G, 3) curved geom parameters (m).")
    ccenter = property(lambda self: self._per_geom(G_CCENTER), doc="(G, 3) curved geom origin (m).")
    bcenter = property(lambda self: self._per_geom(G_BCENTER), doc="(G, 3) bounding sphere centre (m).")
    cframe = property(lambda self: self._per_geom(G_CFRAME, 3), doc="(G, 3, 3) curved geom frame.")


def _stack(verts: np.ndarray, vstart: np.ndarray, edges: np.ndarray, estart: np.ndarray, normals: np.ndarray,
           nstart: np.ndarray, mpts: np.ndarray, mw: np.ndarray, mstart: np.ndarray, codes: dict,
           scalars: dict, per_geom: dict) -> GeomPack:
    """The five stacked arrays of :class:`GeomPack` from the per-field arrays (values copied exactly)."""
    G = vstart.shape[0] - 1
    V, N, M = verts.shape[0], normals.shape[0], mpts.shape[0]
    rows = np.empty((V + N + M + G_ROWS * G, 3), np.float64)
    rows[:V] = verts
    rows[V:V + N] = normals
    rows[V + N:V + N + M] = mpts
    per = rows[V + N + M:].reshape(G, G_ROWS, 3)
    per[:, G_CPARAM] = per_geom["cparam"]
    per[:, G_CCENTER] = per_geom["ccenter"]
    per[:, G_BCENTER] = per_geom["bcenter"]
    per[:, G_CFRAME:G_CFRAME + 3] = per_geom["cframe"]
    idx = np.zeros((I_SIZE, G + 1), np.int64)
    idx[I_VROW] = vstart
    idx[I_EROW] = estart
    idx[I_NROW] = V + nstart
    idx[I_MROW] = V + N + mstart
    idx[I_MW] = mstart
    idx[I_KIND, :G] = codes["kind"]
    idx[I_BODY, :G] = codes["body"]
    idx[I_CURVE, :G] = codes["curve"]
    idx[I_GROW, :G] = V + N + M + G_ROWS * np.arange(G)
    scal = np.empty((S_SIZE, G), np.float64)
    for k, name in ((S_RADIUS, "radius"), (S_OFFSET, "offset"), (S_DPAD, "dpad"), (S_APPROX, "approx"),
                    (S_RHO_MAX, "rho_max"), (S_BRAD, "brad")):
        scal[k] = scalars[name]
    return GeomPack(rows, idx, scal, np.ascontiguousarray(edges, np.int64),
                    np.ascontiguousarray(mw, np.float64))


CURVE_NONE = 0
CURVE_CYLINDER = 1
CURVE_ELLIPSOID = 2


def exact_support(curve: int, param: np.ndarray, d_G: np.ndarray) -> float:
    """Support function h(d) of the exact cylinder / ellipsoid (geom frame, centred)."""
    if curve == CURVE_CYLINDER:
        return float(param[0] * np.hypot(d_G[0], d_G[1]) + param[1] * abs(d_G[2]))
    return float(np.linalg.norm(param * d_G))


def _curved_ok(shape: ConvexShape, curve: int, param: np.ndarray, R_BG: np.ndarray, c_B: np.ndarray) -> bool:
    """The exact geom lies in the packed polytope: h_exact(n_i) <= offset_i for every face normal.

    Guards the frame bookkeeping: the exact shape is used only where it provably is the
    geom the circumscribed polytope stands for (up to 1e-9 relative).
    """
    N, off = np.asarray(shape.normals, float), np.asarray(shape.offsets, float)
    if N.ndim != 2 or len(N) == 0:
        return False
    scale = float(np.abs(param).max())
    for n, o in zip(N, off):
        h = exact_support(curve, param, R_BG.T @ n) + float(n @ c_B)
        if not h <= o + 1e-9 * (scale + abs(o)):
            return False
    return True


def _starts(counts: list[int]) -> np.ndarray:
    return np.concatenate([[0], np.cumsum(counts, dtype=np.int64)]).astype(np.int64)


def _cat(arrs: list[np.ndarray], width: int, dtype) -> np.ndarray:
    if not arrs:
        return np.zeros((0, width), dtype)
    return np.ascontiguousarray(np.concatenate([a.reshape(-1, width) for a in arrs]), dtype=dtype)


_MEMO: dict = {}
_MEMO_MAX = 4096
"""Per-content memo of :func:`_pack_one` (bounded; cleared when full)."""


def _content_key(s: ConvexShape) -> tuple | None:
    """Everything :func:`_pack_one` reads from a shape, as bytes (None: not a plain ConvexShape)."""
    if not isinstance(s, ConvexShape):
        return None
    try:
        arrs = tuple(np.asarray(a) for a in (s.points, s.edges, s.normals, s.offsets))
        return (s.kind, float(s.radius), float(s.approx_error)) + tuple(
            (a.dtype.str, a.shape, a.tobytes()) for a in arrs)
    except (TypeError, ValueError):
        return None


def _pack_one(s: ConvexShape, name: str) -> tuple:
    """Validated core, metric points / weights, rho_max, bounding centre and radius of one shape.

    A function of the shape's content only (:func:`_content_key`): the scaling scenes'
    1000 equal boxes are validated once (the depth pad of a polytope's normals costs ms).
    """
    from monitor.geometry.distance import _core
    from monitor.motion.metric import shape_metric

    c = _core(s, name)
    if c.code < 0:
        return c, np.zeros((0, 3)), np.zeros(0), np.inf, np.zeros(3), np.inf
    m = shape_metric(s)
    rho = float(np.sqrt(np.max(m.rho2(c.P)))) * _RHO_INFLATE
    return (c, np.asarray(m.points, float), np.asarray(m.weights, float), rho,
            np.asarray(s.bounding_center, float), float(s.bounding_radius))


def pack_shapes(shapes: list[ConvexShape | None], bodies: list[int] | np.ndarray,
                curved: list[tuple | None] | None = None) -> GeomPack:
    """Pack shapes (body frames) with their body ids.

    Args:
        shapes: G shapes; None for a geom without a convex shape.
        bodies: (G,) body id of each geom.
        curved: optional per geom None or (curve code, params (3,), R_BG (3, 3), c_B (3,))
            of the exact cylinder / ellipsoid that a circumscribed polytope stands for.
            Entries whose exact shape is not inside the polytope are ignored.

    Raises:
        InvalidInputError: a bad shape (message names ``shapes[i]``), or lengths differ.
    """
    bodies = np.asarray(bodies, dtype=np.int64).reshape(-1)
    if len(bodies) != len(shapes):
        raise InvalidInputError(f"bodies has {len(bodies)} entries, shapes has {len(shapes)}")
    V, E, N, MP, MW = [], [], [], [], []
    kind, radius, offset, dpad, approx, rho_max = [], [], [], [], [], []
    G = len(shapes)
    curve = np.zeros(G, np.int64)
    cparam = np.zeros((G, 3))
    cframe = np.tile(np.eye(3), (G, 1, 1))
    ccenter = np.zeros((G, 3))
    bcenter = np.zeros((G, 3))
    brad = np.full(G, np.inf)
    for i, cv in enumerate(curved or []):
        if cv is None or shapes[i] is None or shapes[i].kind != "polytope":
            continue
        code, par = int(cv[0]), np.asarray(cv[1], float)
        R_BG, c_B = np.asarray(cv[2], float), np.asarray(cv[3], float)
        if code in (CURVE_CYLINDER, CURVE_ELLIPSOID) and np.isfinite(par).all() and (par[:2] > 0).all() \
                and _curved_ok(shapes[i], code, par, R_BG, c_B):
            curve[i], cparam[i], cframe[i], ccenter[i] = code, par, R_BG, c_B
    for i, s in enumerate(shapes):
        if s is None:
            V.append(np.zeros((0, 3)))
            E.append(np.zeros((0, 2), np.int64))
            N.append(np.zeros((0, 3)))
            MP.append(np.zeros((0, 3)))
            MW.append(np.zeros(0))
            kind.append(KIND_NONE)
            radius.append(0.0)
            offset.append(0.0)
            dpad.append(np.inf)
            approx.append(0.0)
            rho_max.append(np.inf)
            continue
        key = _content_key(s)
        hit = _MEMO.get(key) if key is not None else None
        if hit is None:
            hit = _pack_one(s, f"shapes[{i}]")
            if key is not None:
                if len(_MEMO) >= _MEMO_MAX:
                    _MEMO.clear()
                _MEMO[key] = hit
        c, mp_, mw_, rho_, bc_, br_ = hit
        bcenter[i] = bc_
        brad[i] = br_
        V.append(c.P)
        E.append(c.E)
        N.append(c.N)
        kind.append(KIND_HALFSPACE if c.code < 0 else int(c.code))
        radius.append(float(c.radius))
        offset.append(float(c.offset))
        dpad.append(float(c.dpad))
        approx.append(float(s.approx_error))
        MP.append(mp_)
        MW.append(mw_)
        rho_max.append(rho_)
    return _stack(
        _cat(V, 3, np.float64), _starts([len(v) for v in V]), _cat(E, 2, np.int64),
        _starts([len(e) for e in E]),
        _cat(N, 3, np.float64), _starts([len(n) for n in N]), _cat(MP, 3, np.float64),
        np.concatenate(MW) if MW else np.zeros(0), _starts([len(m) for m in MP]),
        codes=dict(kind=np.asarray(kind, np.int64), body=bodies, curve=curve),
        scalars=dict(radius=np.asarray(radius, np.float64), offset=np.asarray(offset, np.float64),
                     dpad=np.asarray(dpad, np.float64), approx=np.asarray(approx, np.float64),
                     rho_max=np.asarray(rho_max, np.float64), brad=brad),
        per_geom=dict(cparam=cparam, ccenter=ccenter, bcenter=bcenter, cframe=cframe))


class ScenePack(NamedTuple):
    """A scene packed once: its geoms and candidate pairs.

    Attributes:
        geoms: the :class:`GeomPack` (index == MuJoCo geom id).
        pair_ids: (P, 2) int64 geom ids of the candidate pairs (scene order).
    """

    geoms: GeomPack
    pair_ids: np.ndarray


def pack_scene(scene) -> ScenePack:
    """Pack a :class:`monitor.Scene` (all geoms, candidate pairs)."""
    shapes = [g.shape for g in scene.geoms]
    bodies = [g.body_id for g in scene.geoms]
    pid = np.ascontiguousarray(np.asarray(scene.pair_ids, np.int64).reshape(-1, 2))
    return ScenePack(pack_shapes(shapes, bodies, _curved_geoms(scene)), pid)


def _curved_geoms(scene) -> list:
    """Exact cylinder / ellipsoid data of the scene's circumscribed geoms (from the model arrays).

    Reads ``geom_size`` of the scene's MjModel and the scene's ``geom_frames`` (body frame, as
    MuJoCo places the geom) as plain arrays (no mujoco import); each entry is re-checked by
    :func:`_curved_ok`.
    Geoms that are not the model's own (ids past ``ngeom``, or a scene view flagged
    ``derived_geoms``, e.g. the ongoing-contact rule's shrunk / inflated copies, whose
    shapes differ from the model's geom) get None: their packed polytope is used.
    """
    model = getattr(scene, "model", None)
    if model is None:
        return []
    frames = getattr(scene, "geom_frames", None)   # (R_BG, p_BG) per geom, as MuJoCo places it
    out: list = []
    derived = bool(getattr(scene, "derived_geoms", False))
    ngeom = len(model.geom_size)
    for g in scene.geoms:
        code = {"cylinder": CURVE_CYLINDER, "ellipsoid": CURVE_ELLIPSOID}.get(g.type, CURVE_NONE)
        if (code == CURVE_NONE or g.shape is None or derived or not 0 <= g.id < ngeom or frames is None
                or len(frames) != ngeom):
            out.append(None)
            continue
        size = np.asarray(model.geom_size[g.id], float)
        par = np.array([size[0], size[1], 0.0]) if code == CURVE_CYLINDER else size.copy()
        R_BG, c_B = frames[g.id]
        out.append((code, par, np.array(R_BG, float), np.array(c_B, float)))
    return out


__all__ = ["GeomPack", "ScenePack", "pack_shapes", "pack_scene", "KIND_HALFSPACE", "KIND_NONE", "CURVE_NONE",
           "CURVE_CYLINDER", "CURVE_ELLIPSOID", "exact_support"]
