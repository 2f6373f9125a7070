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
:class:`GeomPack` is a numba-typable tuple.
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


class GeomPack(NamedTuple):
    """Flat arrays of G geoms (numba-typable).

    Attributes:
        verts: (V, 3) core vertices of all geoms, body frame (m).
        vstart: (G + 1,) int64 offsets into ``verts``.
        edges: (E, 2) int64 edges, vertex indices local to the geom.
        estart: (G + 1,) int64 offsets into ``edges``.
        normals: (N, 3) face normals (polytopes) / the plane normal (half-spaces).
        nstart: (G + 1,) int64 offsets into ``normals``.
        kind: (G,) int64 kind code (0 point, 1 segment, 2 polytope, -1 half-space, -2 none).
        radius: (G,) radius (m).
        offset: (G,) half-space offset (m; 0 otherwise).
        dpad: (G,) depth pad of the face normals (m; inf: no depth certificate).
        approx: (G,) over-approximation ``approx_error`` (m).
        body: (G,) int64 body id of each geom.
        mpts: (M, 3) metric feature points of all geoms (body frame, m).
        mw: (M,) their weights.
        mstart: (G + 1,) int64 offsets into ``mpts``.
        rho_max: (G,) max of rho over the core vertices (1/m units of eq. 4), padded up.
        curve: (G,) int64 exact curved geom behind a circumscribed polytope: 0 none,
            1 cylinder (axis z of its frame), 2 ellipsoid.
        cparam: (G, 3) cylinder (radius, half length, 0) / ellipsoid radii (m).
        cframe: (G, 3, 3) rotation geom frame -> body frame of the curved geom.
        ccenter: (G, 3) geom origin in the body frame (m).
        bcenter: (G, 3) centre of a sphere containing the geom (core + radius), body frame (m).
        brad: (G,) its radius (m); inf for half-spaces and geoms without a shape.
    """

    verts: np.ndarray
    vstart: np.ndarray
    edges: np.ndarray
    estart: np.ndarray
    normals: np.ndarray
    nstart: np.ndarray
    kind: np.ndarray
    radius: np.ndarray
    offset: np.ndarray
    dpad: np.ndarray
    approx: np.ndarray
    body: np.ndarray
    mpts: np.ndarray
    mw: np.ndarray
    mstart: np.ndarray
    rho_max: np.ndarray
    curve: np.ndarray
    cparam: np.ndarray
    cframe: np.ndarray
    ccenter: np.ndarray
    bcenter: np.ndarray
    brad: np.ndarray


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


_NONE_ENTRY = (np.zeros((0, 3)), np.zeros((0, 2), np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0),
               KIND_NONE, 0.0, 0.0, np.inf, 0.0, np.inf, np.zeros(3), np.inf)
""":func:`_shape_entry` of a geom without a shape."""


def _shape_entry(s: ConvexShape | None, name: str) -> tuple:
    """Everything one geom contributes to a :class:`GeomPack`, from its shape alone.

    (verts, edges, normals, mpts, mw, kind, radius, offset, dpad, approx, rho_max, bcenter, brad);
    :func:`_pack_one` through the per-content memo (:data:`_MEMO`).
    """
    if s is None:
        return _NONE_ENTRY
    key = _content_key(s)
    hit = _MEMO.get(key) if key is not None else None
    if hit is None:
        hit = _pack_one(s, name)
        if key is not None:
            if len(_MEMO) >= _MEMO_MAX:
                _MEMO.clear()
            _MEMO[key] = hit
    c, mp_, mw_, rho_, bc_, br_ = hit
    return (c.P, c.E, c.N, mp_, mw_, KIND_HALFSPACE if c.code < 0 else int(c.code), float(c.radius),
            float(c.offset), float(c.dpad), float(s.approx_error), rho_, bc_, br_)


def _gather_rows(parts: list[np.ndarray], width: int, dtype,
                 which: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ``parts[which[0]], parts[which[1]], ...`` concatenated, and their (G + 1,) offsets.

    Args:
        parts: U arrays of rows (``width`` columns).
        width: columns per row.
        dtype: output dtype.
        which: (G,) int64 index into ``parts`` per geom.
    """
    counts_u = np.array([len(a.reshape(-1, width)) for a in parts], dtype=np.int64)
    rows_u = _cat(parts, width, dtype)
    counts = counts_u[which]
    start = _starts(counts)
    ustart = _starts(counts_u)
    shift = np.repeat(ustart[:-1][which] - start[:-1], counts)
    rows = rows_u[np.arange(int(start[-1]), dtype=np.int64) + shift]
    rows = rows.reshape(-1, width) if width > 1 else rows.reshape(-1)
    return np.ascontiguousarray(rows, dtype=dtype), start


def pack_shapes(shapes: list[ConvexShape | None], bodies: list[int] | np.ndarray,
                curved: list[tuple | None] | None = None) -> GeomPack:
    """Pack shapes (body frames) with their body ids.

    Each distinct shape object is packed once (:func:`_shape_entry`, first occurrence first, so
    a bad shape is reported under its first index) and the per-geom arrays are gathered from
    those entries with numpy: no per-geom numpy work, the same arrays as packing geom by geom.

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
    G = len(shapes)
    curve = np.zeros(G, np.int64)
    cparam = np.zeros((G, 3))
    cframe = np.tile(np.eye(3), (G, 1, 1))
    ccenter = np.zeros((G, 3))
    checked: dict[tuple, bool] = {}   # _curved_ok of equal inputs (same shape object, same bytes)
    for i, cv in enumerate(curved or []):
        if cv is None or shapes[i] is None or shapes[i].kind != "polytope":
            continue
        code, par = int(cv[0]), np.asarray(cv[1], float)
        R_BG, c_B = np.asarray(cv[2], float), np.asarray(cv[3], float)
        if code in (CURVE_CYLINDER, CURVE_ELLIPSOID) and np.isfinite(par).all() and (par[:2] > 0).all():
            key = (id(shapes[i]), code, par.tobytes(), R_BG.tobytes(), c_B.tobytes())
            if key not in checked:
                checked[key] = _curved_ok(shapes[i], code, par, R_BG, c_B)
            if checked[key]:
                curve[i], cparam[i], cframe[i], ccenter[i] = code, par, R_BG, c_B
    first: dict[int, int] = {}   # id(shape) -> its distinct index (``shapes`` keeps the objects alive)
    which = np.array([first.setdefault(id(s), len(first)) for s in shapes], dtype=np.int64)
    at = np.unique(which, return_index=True)[1]   # first geom of each distinct shape, in geom order
    entries = [_shape_entry(shapes[i], f"shapes[{i}]") for i in at.tolist()]
    cols = list(zip(*entries)) if entries else [[]] * 13
    verts, vstart = _gather_rows(list(cols[0]), 3, np.float64, which)
    edges, estart = _gather_rows(list(cols[1]), 2, np.int64, which)
    normals, nstart = _gather_rows(list(cols[2]), 3, np.float64, which)
    mpts, mstart = _gather_rows(list(cols[3]), 3, np.float64, which)
    mw, _ = _gather_rows(list(cols[4]), 1, np.float64, which)

    def per_geom(k: int, dtype) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(cols[k], dtype=dtype).reshape(-1)[which])

    return GeomPack(
        verts=verts, vstart=vstart, edges=edges, estart=estart, normals=normals, nstart=nstart,
        kind=per_geom(5, np.int64), radius=per_geom(6, np.float64), offset=per_geom(7, np.float64),
        dpad=per_geom(8, np.float64), approx=per_geom(9, np.float64), body=np.ascontiguousarray(bodies),
        mpts=mpts, mw=mw, mstart=mstart, rho_max=per_geom(10, np.float64),
        curve=curve, cparam=np.ascontiguousarray(cparam), cframe=np.ascontiguousarray(cframe),
        ccenter=np.ascontiguousarray(ccenter),
        bcenter=np.ascontiguousarray(np.asarray(cols[11], dtype=np.float64).reshape(-1, 3)[which]),
        brad=per_geom(12, np.float64))


class ScenePack(NamedTuple):
    """A scene packed once: its geoms and candidate pairs.

    Attributes:
        geoms: the :class:`GeomPack` (index == MuJoCo geom id).
        pair_ids: (P, 2) int64 geom ids of the candidate pairs (scene order).
    """

    geoms: GeomPack
    pair_ids: np.ndarray


_LEX_ROWS = 1 << 16
"""Rows per block of :func:`lex_sorted_pairs` (its temporaries stay small: no fresh pages per call)."""


def lex_sorted_pairs(pair_ids: np.ndarray, ngeom: int) -> bool:
    """True if the (P, 2) int rows are strictly increasing in (a, b) with 0 <= a < b < ngeom (O(P)).

    Evaluated on blocks of :data:`_LEX_ROWS` rows, each overlapping the previous block by one row
    (so every consecutive pair of rows is compared once).
    """
    pid = np.asarray(pair_ids).reshape(-1, 2)
    n = max(int(ngeom), 1)
    for s in range(0, len(pid), _LEX_ROWS):
        block = pid[max(s - 1, 0):s + _LEX_ROWS]
        a, b = block[:, 0].astype(np.int64), block[:, 1].astype(np.int64)
        if not (a.min() >= 0 and b.max() < ngeom and (a < b).all()):
            return False
        lex = a * n + b
        if not (lex[1:] > lex[:-1]).all():
            return False
    return True


def pack_scene(scene) -> ScenePack:
    """Pack a :class:`monitor.Scene` (all geoms, candidate pairs)."""
    shapes = [g.shape for g in scene.geoms]
    bodies = [g.body_id for g in scene.geoms]
    pid = np.ascontiguousarray(np.asarray(scene.pair_ids, np.int64).reshape(-1, 2))
    return ScenePack(pack_shapes(shapes, bodies, _curved_geoms(scene)), pid)


_CURVE_OF_TYPE = {"cylinder": CURVE_CYLINDER, "ellipsoid": CURVE_ELLIPSOID}


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
        code = _CURVE_OF_TYPE.get(g.type, CURVE_NONE)
        if (code == CURVE_NONE or g.shape is None or derived or not 0 <= g.id < ngeom or frames is None
                or len(frames) != ngeom):
            out.append(None)
            continue
        size = np.asarray(model.geom_size[g.id], float)
        par = np.array([size[0], size[1], 0.0]) if code == CURVE_CYLINDER else size.copy()
        R_BG, c_B = frames[g.id]
        out.append((code, par, np.array(R_BG, float), np.array(c_B, float)))
    return out


__all__ = ["GeomPack", "ScenePack", "pack_shapes", "pack_scene", "lex_sorted_pairs", "KIND_HALFSPACE",
           "KIND_NONE", "CURVE_NONE", "CURVE_CYLINDER", "CURVE_ELLIPSOID", "exact_support"]
