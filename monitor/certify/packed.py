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


def _starts(counts: list[int]) -> np.ndarray:
    return np.concatenate([[0], np.cumsum(counts, dtype=np.int64)]).astype(np.int64)


def _cat(arrs: list[np.ndarray], width: int, dtype) -> np.ndarray:
    if not arrs:
        return np.zeros((0, width), dtype)
    return np.ascontiguousarray(np.concatenate([a.reshape(-1, width) for a in arrs]), dtype=dtype)


def pack_shapes(shapes: list[ConvexShape | None], bodies: list[int] | np.ndarray) -> GeomPack:
    """Pack shapes (body frames) with their body ids.

    Args:
        shapes: G shapes; None for a geom without a convex shape.
        bodies: (G,) body id of each geom.

    Raises:
        InvalidInputError: a bad shape (message names ``shapes[i]``), or lengths differ.
    """
    from monitor.geometry.distance import _core
    from monitor.motion.metric import shape_metric

    bodies = np.asarray(bodies, dtype=np.int64).reshape(-1)
    if len(bodies) != len(shapes):
        raise InvalidInputError(f"bodies has {len(bodies)} entries, shapes has {len(shapes)}")
    V, E, N, MP, MW = [], [], [], [], []
    kind, radius, offset, dpad, approx, rho_max = [], [], [], [], [], []
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
        c = _core(s, f"shapes[{i}]")
        V.append(c.P)
        E.append(c.E)
        N.append(c.N)
        kind.append(KIND_HALFSPACE if c.code < 0 else int(c.code))
        radius.append(float(c.radius))
        offset.append(float(c.offset))
        dpad.append(float(c.dpad))
        approx.append(float(s.approx_error))
        if c.code < 0:
            MP.append(np.zeros((0, 3)))
            MW.append(np.zeros(0))
            rho_max.append(np.inf)
        else:
            m = shape_metric(s)
            MP.append(np.asarray(m.points, float))
            MW.append(np.asarray(m.weights, float))
            rho_max.append(float(np.sqrt(np.max(m.rho2(c.P)))) * _RHO_INFLATE)
    return GeomPack(
        verts=_cat(V, 3, np.float64), vstart=_starts([len(v) for v in V]),
        edges=_cat(E, 2, np.int64), estart=_starts([len(e) for e in E]),
        normals=_cat(N, 3, np.float64), nstart=_starts([len(n) for n in N]),
        kind=np.asarray(kind, np.int64), radius=np.asarray(radius, np.float64),
        offset=np.asarray(offset, np.float64), dpad=np.asarray(dpad, np.float64),
        approx=np.asarray(approx, np.float64), body=np.ascontiguousarray(bodies),
        mpts=_cat(MP, 3, np.float64), mw=np.ascontiguousarray(np.concatenate(MW) if MW else np.zeros(0)),
        mstart=_starts([len(m) for m in MP]), rho_max=np.asarray(rho_max, np.float64))


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
    return ScenePack(pack_shapes(shapes, bodies), pid)


__all__ = ["GeomPack", "ScenePack", "pack_shapes", "pack_scene", "KIND_HALFSPACE", "KIND_NONE"]
