"""Build :class:`~monitor.geometry.shapes.ConvexShape` objects for MuJoCo primitives.

Pure numpy/scipy (no MuJoCo). Every constructor returns a shape in its own
*geom* frame; :mod:`monitor.scene` moves it into the body frame with
:meth:`ConvexShape.transformed`.

Soundness rule: a shape always **contains** the true geom. Exact shapes
(sphere, capsule, box, mesh hull, half-space) have ``approx_error == 0``.
Circumscribed shapes (cylinder, ellipsoid, thickened flat point sets) report
in ``approx_error`` an upper bound (m) on the distance from any point of the
shape to the true geom (the one-sided Hausdorff excess).

Containment of the primitives (cylinder, ellipsoid) is *verified* after
construction with the exact support function of the true geom in every face
normal direction, against the lowest loop vertex of each face: if rounding made
any face cut the geom, all vertices are scaled about the centre until no face
does (plus a relative rounding pad), so both the H-representation and the hull
of the vertices contain the geom.

Degenerate point sets (:func:`polytope_from_points`): a coplanar, collinear or
single-point set has no 3-D hull. By default this raises
:class:`~monitor.errors.InvalidInputError`. With ``thicken=t > 0`` the set is
thickened **outwards** by ``t`` (flat: a prism of half-height ``t`` about the
best-fit plane; collinear: a square box of half-width ``t`` about the line;
point: a cube of half-size ``t``). Outward thickening is an over-approximation,
so it is sound for certification; the excess is reported in ``approx_error``.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError, cKDTree

from monitor.errors import InvalidInputError
from monitor.geometry.shapes import ConvexShape
from monitor.tolerances import DEFAULT, Tolerances

_COPLANAR_REL = 1e-12
"""Two adjacent hull triangles are merged into one face when each one's vertices
lie within ``_COPLANAR_REL * scale`` of the other's plane (scale = the point
set's largest extent). This is ~4500 ulp: it merges the triangles qhull splits
a flat facet into (identical planes up to rounding), nothing coarser. A face of a
float32 mesh that was flat before float32 rounding (noise ~1e-7 relative) stays
split into its triangles: more faces, but every face exactly planar. Merging is
not a soundness decision: every offset is recomputed as the max over all
input points, so the H-rep always contains the point set."""

_FLAT_REL = 1e-9
"""A point set whose width along a principal direction is at most this times its
extent is degenerate (flat/collinear): qhull would return slivers whose normals
are dominated by rounding. 1e-9 is far above rounding (1e-16) and far below any
real part (a 1 m part thinner than 1 nm)."""

_DEDUP_REL = 1e-12
"""Vertices of a half-space intersection closer than ``_DEDUP_REL * scale`` are
one vertex (a vertex where more than three tangent planes meet is returned once
per plane triple, with rounding differences)."""


# --------------------------------------------------------------------------- helpers


def _as_points(points: np.ndarray, what: str = "points") -> np.ndarray:
    """Validate an (n, 3) finite float array."""
    try:
        P = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{what}: not a numeric array ({exc})") from None
    if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] < 1:
        raise InvalidInputError(f"{what}: expected shape (n>=1, 3), got {P.shape}")
    bad = np.flatnonzero(~np.isfinite(P).all(axis=1))
    if bad.size:
        raise InvalidInputError(f"{what}: row {int(bad[0])} is not finite: {P[bad[0]].tolist()}")
    return P


def _positive(value: float, what: str) -> float:
    v = float(value)
    if not np.isfinite(v) or v <= 0.0:
        raise InvalidInputError(f"{what} must be finite and > 0, got {value!r}")
    return v


def _facet_count(facets: int) -> int:
    if isinstance(facets, bool) or int(facets) != facets or int(facets) < 3:
        raise InvalidInputError(f"facets must be an integer >= 3, got {facets!r}")
    return int(facets)


def _plane_basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors u, w with (u, w, n) right-handed orthonormal."""
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, a)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    return u, w


def _assemble(V: np.ndarray, faces: list[np.ndarray], normals: np.ndarray, contain: np.ndarray,
              approx_error: float = 0.0) -> ConvexShape:
    """Polytope from vertices, CCW face loops and unit outward normals.

    Offsets are the max of ``normal . x`` over the vertices AND the points
    ``contain`` (the original input), so the H-rep contains both exactly as
    evaluated in float64. Checks the topology: every edge is used by exactly two
    faces in opposite directions and V - E + F == 2.
    """
    normals = np.asarray(normals, dtype=np.float64)
    offsets = (normals @ np.concatenate([V, contain]).T).max(axis=1)
    tails = np.concatenate(faces).astype(np.int64)
    heads = np.concatenate([np.concatenate([f[1:], f[:1]]) for f in faces]).astype(np.int64)
    nv = len(V)
    code = tails * nv + heads
    uniq = np.unique(code)
    ok = len(uniq) == len(code) and bool(np.isin(heads * nv + tails, uniq).all())
    E = np.unique(np.stack([np.minimum(tails, heads), np.maximum(tails, heads)], axis=1), axis=0)
    if not ok or nv - len(E) + len(faces) != 2:
        raise _BadHull(f"inconsistent hull topology (V={nv}, E={len(E)}, F={len(faces)})")
    return ConvexShape("polytope", V, 0.0, E.astype(np.int64).reshape(-1, 2),
                       tuple(np.asarray(f, dtype=np.int64) for f in faces), normals, offsets,
                       float(approx_error))


class _BadHull(Exception):
    """qhull's output could not be assembled into a valid polytope."""


def _hull_polytope(P: np.ndarray, scale: float, merge: bool = True) -> ConvexShape:
    """Polytope from a full-rank point set (raises QhullError/_BadHull if degenerate).

    Adjacent qhull triangles whose vertices lie within ``_COPLANAR_REL * scale``
    of each other's planes form one face (connected components); the face normal
    is the area-weighted mean of its triangles' outward normals and its loop is
    its vertices sorted by angle about the face centroid (CCW seen from outside).
    If a merged face ends up non-planar by more than ``_COPLANAR_REL * scale`` or
    the merged faces do not form a closed manifold (possible only through long
    chains of near-coplanar triangles), the hull is rebuilt with one face per
    qhull triangle (``merge=False``), which is always planar.
    """
    hull = ConvexHull(P)
    simp = hull.simplices.astype(np.int64)
    eq = hull.equations  # (nt, 4): n . x + d <= 0 inside, n outward unit
    nrm, d = eq[:, :3], eq[:, 3]
    nt = len(simp)
    tol = _COPLANAR_REL * scale

    ti = np.repeat(np.arange(nt), 3)
    tj = hull.neighbors.reshape(-1).astype(np.int64)
    m = (tj > ti) & (np.einsum("ij,ij->i", nrm[ti], nrm[tj]) > 0.0)
    ti, tj = ti[m], tj[m]
    dij = np.abs(np.einsum("kvj,kj->kv", P[simp[tj]], nrm[ti]) + d[ti, None]).max(axis=1)
    dji = np.abs(np.einsum("kvj,kj->kv", P[simp[ti]], nrm[tj]) + d[tj, None]).max(axis=1)
    m = (dij <= tol) & (dji <= tol) & merge
    graph = coo_matrix((np.ones(int(m.sum())), (ti[m], tj[m])), shape=(nt, nt))
    nface, label = connected_components(graph, directed=False)

    used = np.unique(simp)
    remap = -np.ones(len(P), np.int64)
    remap[used] = np.arange(len(used))
    V = P[used]
    T = remap[simp]  # triangles in the new vertex numbering

    area = np.linalg.norm(np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]), axis=1)
    N = np.zeros((nface, 3))
    np.add.at(N, label, nrm * (area + np.finfo(float).tiny)[:, None])
    N /= np.linalg.norm(N, axis=1, keepdims=True)

    inc = np.unique(np.stack([np.repeat(label, 3), T.reshape(-1)], axis=1), axis=0)  # (face, vertex)
    fl, fv = inc[:, 0], inc[:, 1]
    cnt = np.bincount(fl, minlength=nface)
    cen = np.zeros((nface, 3))
    np.add.at(cen, fl, V[fv])
    cen /= cnt[:, None]
    a = np.where((np.abs(N[:, 0]) < 0.9)[:, None], np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    U = np.cross(N, a)
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    W = np.cross(N, U)
    q = V[fv] - cen[fl]
    ang = np.arctan2(np.einsum("ij,ij->i", q, W[fl]), np.einsum("ij,ij->i", q, U[fl]))
    order = np.lexsort((ang, fl))
    faces = np.split(fv[order], np.cumsum(cnt)[:-1])
    try:
        shape = _assemble(V, faces, N, P)
    except _BadHull:
        if merge:  # a merged group that is not one convex planar face
            return _hull_polytope(P, scale, merge=False)
        raise
    spread = shape.offsets[fl] - np.einsum("ij,ij->i", N[fl], V[fv])  # >= 0: depth of loop vertices
    if merge and spread.max() > tol:
        return _hull_polytope(P, scale, merge=False)
    return shape


def _prism(center: np.ndarray, u: np.ndarray, w: np.ndarray, n: np.ndarray, ring: np.ndarray,
           lo: float, hi: float, contain: np.ndarray, approx_error: float) -> ConvexShape:
    """Right prism over a convex polygon, built without qhull (robust when very thin).

    Args:
        center: (3,) origin of the (u, w, n) frame; (u, w, n) right-handed orthonormal.
        ring: (k, 2) polygon vertices in (u, w) coordinates, counter-clockwise, k >= 3.
        lo, hi: extent along n (lo < hi).
        contain: (m, 3) points the H-rep must contain.
        approx_error: reported excess (m).
    """
    base = center + ring[:, :1] * u + ring[:, 1:] * w
    k = len(ring)
    V = np.concatenate([base + lo * n, base + hi * n])
    faces = [np.arange(k, 2 * k), np.arange(k)[::-1]]
    normals = [n, -n]
    for i in range(k):
        j = (i + 1) % k
        faces.append(np.array([i, j, k + j, k + i]))
        e = ring[j] - ring[i]
        side = (e[0] * u + e[1] * w)
        out = np.cross(side, n)
        normals.append(out / np.linalg.norm(out))
    return _assemble(V, faces, np.array(normals), contain, approx_error)


def _ccw_square(a: float) -> np.ndarray:
    return np.array([[-a, -a], [a, -a], [a, a], [-a, a]])


# --------------------------------------------------------------------------- public builders


def polytope_from_points(points: np.ndarray, *, thicken: float = 0.0) -> ConvexShape:
    """Convex hull of a point set as a polytope :class:`ConvexShape`.

    Coplanar hull triangles are merged into convex face loops ordered
    counter-clockwise seen from outside; edges are unique vertex pairs; the
    H-representation has one row per merged face, with offsets equal to the
    max of ``normal . x`` over all input points (so it contains the whole set).
    Duplicate and interior points are dropped from the vertices.

    A set is *degenerate* when its width along its least principal direction
    (or the next one) is at most ``_FLAT_REL = 1e-9`` times its extent: then a
    3-D hull would be numerically meaningless (slivers, merged faces).

    Args:
        points: (n, 3) points, metres, any frame.
        thicken: metres. 0 (default): a degenerate set raises. > 0: the set is
            thickened outwards (module docstring); full-rank sets are never
            thickened.

    Returns:
        A polytope shape; ``approx_error`` is 0 for a full-rank set, else an
        upper bound on the distance from any point of the shape to the hull of
        the input.

    Raises:
        InvalidInputError: bad shape / non-finite values, a negative
            ``thicken``, or a degenerate set with ``thicken == 0``.
    """
    P = _as_points(points)
    t = float(thicken)
    if not np.isfinite(t) or t < 0.0:
        raise InvalidInputError(f"thicken must be finite and >= 0, got {thicken!r}")
    P = np.unique(P, axis=0)
    c = P.mean(axis=0)
    Q = P - c
    if len(P) > 1:
        _, _, Vt = np.linalg.svd(Q, full_matrices=len(P) < 3)  # Vt (3, 3) either way
    else:
        Vt = np.eye(3)
    widths = np.ptp(Q @ Vt.T, axis=0)  # extent along each principal direction
    extent = float(widths[0])
    flat = widths <= _FLAT_REL * max(extent, np.finfo(float).tiny)
    rank = 3 - int(flat.sum()) if extent > 0 else 0
    if rank == 3:
        try:
            return _hull_polytope(P, float(np.ptp(P, axis=0).max()))
        except (QhullError, _BadHull) as exc:
            if t == 0.0:
                raise InvalidInputError(f"points: no valid 3-D hull ({exc})") from None
            rank = 2
    names = {2: "coplanar", 1: "collinear", 0: "a single point"}
    if t == 0.0:
        raise InvalidInputError(
            f"points are {names[rank]} (widths {widths.tolist()} m along the principal axes): no 3-D "
            "hull; pass thicken > 0 to thicken the set outwards")
    if rank == 2:
        n = Vt[2]
        u, w = _plane_basis(n)
        r = Q @ n
        q2 = np.stack([Q @ u, Q @ w], axis=1)
        try:
            ring = q2[ConvexHull(q2).vertices]  # counter-clockwise for 2-D input
        except QhullError:
            rank = 1
        else:
            err = float(r.max() - r.min()) + t
            return _prism(c, u, w, n, ring, float(r.min()) - t, float(r.max()) + t, P, err)
    if rank == 1:
        d = Vt[0]
        u, w = _plane_basis(d)
        sd = Q @ d
        perp = float(np.sqrt((Q @ u) ** 2 + (Q @ w) ** 2).max())
        rho = perp + t
        err = float(np.sqrt(2.0)) * rho + perp
        return _prism(c, u, w, d, _ccw_square(rho), float(sd.min()), float(sd.max()), P, err)
    perp = float(np.linalg.norm(Q, axis=1).max())
    rho = perp + t
    err = float(np.sqrt(3.0)) * rho + perp
    return _prism(c, np.eye(3)[0], np.eye(3)[1], np.eye(3)[2], _ccw_square(rho), -rho, rho, P, err)


def _with_error(shape: ConvexShape, err: float) -> ConvexShape:
    return ConvexShape(shape.kind, shape.points, shape.radius, shape.edges, shape.faces,
                       shape.normals, shape.offsets, float(err))


def _contain(shape: ConvexShape, support, tol: Tolerances) -> ConvexShape:
    """Scale a centred polytope about the origin until every face clears the true geom.

    The test uses, per face, the LOWEST of ``normal . v`` over the face's own loop
    vertices (not just the offset), so a face whose vertices are not exactly
    coplanar after rounding still lies outside the geom by ``rel_pad`` relative:
    both the H-rep and the hull of the vertices contain the geom.

    Args:
        shape: polytope whose interior contains the origin (the geom centre).
        support: callable (f, 3) unit directions -> (f,) support values h(n) of the
            true geom (exact closed form).
        tol: tolerances (``rel_pad`` pads the scale factor).
    """
    h = support(shape.normals)
    loops = np.concatenate(shape.faces)
    starts = np.cumsum([0] + [len(f) for f in shape.faces[:-1]])
    face_of = np.repeat(np.arange(len(shape.faces)), [len(f) for f in shape.faces])
    k = 1.0
    for _ in range(8):
        V = shape.points * k
        offsets = (shape.normals @ V.T).max(axis=1)  # recomputed: the H-rep contains V exactly
        low = np.minimum.reduceat(np.einsum("ij,ij->i", shape.normals[face_of], V[loops]), starts)
        ratio = float((h / low).max())
        if ratio <= 1.0 / (1.0 + tol.rel_pad):
            return ConvexShape("polytope", V, 0.0, shape.edges, shape.faces, shape.normals, offsets,
                               shape.approx_error)
        k *= max(ratio, 1.0) * (1.0 + 2.0 * tol.rel_pad)
    raise AssertionError("containment scaling did not converge")  # pragma: no cover


def box_polytope(half_extents: np.ndarray) -> ConvexShape:
    """Axis-aligned box centred at the origin (exact; built without qhull).

    Args:
        half_extents: (3,) half sizes, metres, each > 0.
    """
    h = np.asarray(half_extents, dtype=np.float64).reshape(-1)
    if h.shape != (3,):
        raise InvalidInputError(f"half_extents: expected shape (3,), got {h.shape}")
    for i in range(3):
        _positive(h[i], f"half_extents[{i}]")
    ring = np.array([[-h[0], -h[1]], [h[0], -h[1]], [h[0], h[1]], [-h[0], h[1]]])
    ex, ey, ez = np.eye(3)
    return _prism(np.zeros(3), ex, ey, ez, ring, -h[2], h[2], np.zeros((0, 3)), 0.0)


def cylinder_polytope(radius: float, half_length: float, facets: int = DEFAULT.facets,
                      *, tolerances: Tolerances = DEFAULT) -> ConvexShape:
    """Regular prism circumscribing a cylinder with axis z, centred at the origin.

    The N-gon has circumradius ``radius / cos(pi / N)``, so its apothem is the
    cylinder radius and it contains the cylinder. ``approx_error`` is measured
    over the final vertices (the radial excess, analytically
    ``radius * (1 / cos(pi / N) - 1)``, plus the containment pad).

    Args:
        radius: metres, > 0.
        half_length: metres, > 0.
        facets: N >= 3 side faces.
        tolerances: rounding pads.
    """
    r = _positive(radius, "radius")
    hl = _positive(half_length, "half_length")
    N = _facet_count(facets)
    R = r / np.cos(np.pi / N)
    th = 2.0 * np.pi * np.arange(N) / N
    ring = np.stack([R * np.cos(th), R * np.sin(th)], axis=1)  # counter-clockwise
    ex, ey, ez = np.eye(3)
    shape = _prism(np.zeros(3), ex, ey, ez, ring, -hl, hl, np.zeros((0, 3)), 0.0)

    def support(n: np.ndarray) -> np.ndarray:
        return r * np.hypot(n[:, 0], n[:, 1]) + hl * np.abs(n[:, 2])

    shape = _contain(shape, support, tolerances)
    P = shape.points
    radial = np.maximum(np.hypot(P[:, 0], P[:, 1]) - r, 0.0)
    axial = np.maximum(np.abs(P[:, 2]) - hl, 0.0)
    err = float(np.hypot(radial, axial).max())
    return _with_error(shape, err * (1.0 + tolerances.rel_pad))


def _sphere_directions(facets: int) -> np.ndarray:
    """Well-spread unit directions: poles plus latitude rings, ~facets^2/pi of them."""
    n_rings = max(2, facets // 2)
    dirs = [np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 1.0])]
    for k in range(1, n_rings):
        lat = -0.5 * np.pi + k * np.pi / n_rings
        cnt = max(3, round(facets * np.cos(lat)))
        lon = 2.0 * np.pi * (np.arange(cnt) + 0.5 * (k % 2)) / cnt
        dirs.extend(np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon),
                              np.full(cnt, np.sin(lat))], axis=1))
    return np.array(dirs)


def ellipsoid_distance_upper(points: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Upper bounds (n,) on the distance from points (n, 3) to an axis-aligned ellipsoid.

    For a point y outside, the closest point is x_i = e_i^2 y_i / (t + e_i^2)
    with t >= 0 the root of sum (e_i y_i / (t + e_i^2))^2 = 1 (decreasing in t,
    bracketed by [0, max(e) |y|]); bisection to machine precision, then x is
    rescaled onto the surface, so ``|y - x|`` is >= the true distance up to
    rounding. Points inside give 0.

    Args:
        points: (n, 3) metres, ellipsoid frame.
        radii: (3,) semi-axes, metres.
    """
    Y = np.asarray(points, dtype=np.float64)
    e = np.asarray(radii, dtype=np.float64)
    inside = ((Y / e) ** 2).sum(axis=1) <= 1.0
    lo = np.zeros(len(Y))
    hi = e.max() * np.linalg.norm(Y, axis=1) + e.max() ** 2
    e2 = e**2
    for _ in range(200):  # stop at relative width ~1e-15: x is projected onto the surface below,
        if (hi - lo <= 8.0 * np.finfo(float).eps * hi).all():  # so t only needs to be near the root
            break
        mid = 0.5 * (lo + hi)
        f = (((e * Y) / (mid[:, None] + e2)) ** 2).sum(axis=1) - 1.0
        big = f > 0
        lo = np.where(big, mid, lo)
        hi = np.where(big, hi, mid)
    X = e2 * Y / (hi[:, None] + e2)
    X /= np.sqrt(((X / e) ** 2).sum(axis=1))[:, None]
    d = np.linalg.norm(Y - X, axis=1)
    return np.where(inside, 0.0, d)


@functools.lru_cache(maxsize=32)
def _unit_sphere_polytope(facets: int) -> ConvexShape:
    """Tangent-plane polytope of the unit sphere (directions from :func:`_sphere_directions`)."""
    U = _sphere_directions(facets)
    hs = HalfspaceIntersection(np.c_[U, -np.ones(len(U))], np.zeros(3))
    V = hs.intersections
    # merge near-duplicate vertices (more than three planes through one vertex)
    keep = np.ones(len(V), bool)
    for i, j in sorted(cKDTree(V).query_pairs(_DEDUP_REL * 2.0)):
        if keep[i]:
            keep[j] = False
    shape = _hull_polytope(V[keep], 2.0)
    if len(shape.faces) != len(U):
        raise AssertionError(f"{len(shape.faces)} faces for {len(U)} tangent planes")  # pragma: no cover
    for a in (shape.points, shape.normals, shape.offsets, *shape.faces):
        a.setflags(write=False)
    return shape


def ellipsoid_polytope(radii: np.ndarray, facets: int = DEFAULT.facets,
                       *, tolerances: Tolerances = DEFAULT) -> ConvexShape:
    """Polytope circumscribing an axis-aligned ellipsoid centred at the origin.

    Tangent planes of the unit sphere at well-spread directions (poles plus
    ``facets // 2 - 1`` latitude rings with up to ``facets`` planes each; about
    ``facets^2 / pi`` faces, 82 for 16) are mapped by ``diag(radii)``; an affine
    map keeps tangency, so every plane touches the ellipsoid. Vertices come from
    scipy's ``HalfspaceIntersection``. ``approx_error`` is the max over vertices
    of an upper bound on the vertex-to-ellipsoid distance
    (:func:`ellipsoid_distance_upper`); the distance to a convex set is convex,
    so the max over the polytope is attained at a vertex.

    Args:
        radii: (3,) semi-axes, metres, each > 0.
        facets: angular resolution (>= 3); 4 gives the bounding box.
        tolerances: rounding pads.
    """
    e = np.asarray(radii, dtype=np.float64).reshape(-1)
    if e.shape != (3,):
        raise InvalidInputError(f"radii: expected shape (3,), got {e.shape}")
    for i in range(3):
        _positive(e[i], f"radii[{i}]")
    unit = _unit_sphere_polytope(_facet_count(facets))
    # x = diag(e) z maps the unit-sphere polytope onto the ellipsoid's: same faces and
    # orientation (positive diagonal), plane n . z <= o becomes (n / e) . x <= o
    V = unit.points * e
    Nrm = unit.normals / e
    Nrm /= np.linalg.norm(Nrm, axis=1, keepdims=True)
    shape = _assemble(V, list(unit.faces), Nrm, np.zeros((0, 3)))

    def support(n: np.ndarray) -> np.ndarray:
        return np.linalg.norm(n * e, axis=1)

    shape = _contain(shape, support, tolerances)
    err = float(ellipsoid_distance_upper(shape.points, e).max())
    return _with_error(shape, err * (1.0 + tolerances.rel_pad))


def sphere_shape(radius: float, center: np.ndarray | None = None) -> ConvexShape:
    """Sphere: a point core plus the radius (exact).

    Args:
        radius: metres, > 0.
        center: (3,) centre, default the origin.
    """
    r = _positive(radius, "radius")
    c = np.zeros(3) if center is None else _as_points(np.reshape(center, (1, 3)), "center")[0]
    return ConvexShape("sphere", c.reshape(1, 3).copy(), r)


def capsule_shape(radius: float, half_length: float) -> ConvexShape:
    """Capsule with axis z: segment (0, 0, -h)-(0, 0, h) plus the radius (exact).

    Args:
        radius: metres, > 0.
        half_length: half the segment length, metres, >= 0.
    """
    r = _positive(radius, "radius")
    hl = float(half_length)
    if not np.isfinite(hl) or hl < 0.0:
        raise InvalidInputError(f"half_length must be finite and >= 0, got {half_length!r}")
    pts = np.array([[0.0, 0.0, -hl], [0.0, 0.0, hl]])
    return ConvexShape("capsule", pts, r, np.array([[0, 1]], dtype=np.int64))


def halfspace_shape() -> ConvexShape:
    """Half-space ``{z <= 0}`` (a MuJoCo plane in its geom frame; exact)."""
    return ConvexShape("halfspace", np.zeros((1, 3)), 0.0,
                       normals=np.array([[0.0, 0.0, 1.0]]), offsets=np.zeros(1))


__all__ = [
    "polytope_from_points",
    "box_polytope",
    "cylinder_polytope",
    "ellipsoid_polytope",
    "ellipsoid_distance_upper",
    "sphere_shape",
    "capsule_shape",
    "halfspace_shape",
]
