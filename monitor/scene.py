"""MjModel -> :class:`Scene`: convex geom shapes in body frames and the candidate pairs.

This is the only module that reads geoms from MuJoCo. Shapes are built with
:mod:`monitor.geometry.polytope` (pure numpy/scipy) in the geom frame and moved
into the frame of the body that carries the geom (``geom_pos``/``geom_quat``, or the body's
(inertial) frame where MuJoCo's ``geom_sameframe`` says so: :func:`geom_frame`).

Geom type -> shape (body frame):

=========  =====================================================================
sphere     point + radius (exact)
capsule    segment + radius (exact)
box        polytope (exact)
mesh       convex hull of all compiled ``mesh_vert`` (float32, mesh frame == geom
           frame): exact for MuJoCo's hull; with ``maxhullvert`` a superset of
           MuJoCo's reduced hull (which MuJoCo itself does not always respect);
           validated with trimesh, one warning per non-convex mesh (extra hull volume)
cylinder   circumscribed regular prism (``facets`` sides), reported
ellipsoid  circumscribed tangent-plane polytope, reported
plane      half-space ``{z <= 0}`` in the geom frame (exact; MuJoCo planes are
           infinite for collision)
hfield/sdf :class:`~monitor.errors.UnsupportedGeometryError` naming the geom
           when it takes part in a candidate pair; ``shape is None`` otherwise
=========  =====================================================================

Pair modes:

* ``"mujoco"``: MuJoCo's static candidate filter (mj_collision without the
  bounding-volume test): no plane/hfield-plane/hfield pairs; ``<pair>`` geoms
  always (bypassing every other rule, so static-static and same-body pairs are
  kept), except a ``<pair>`` of a geom with itself, which MuJoCo accepts and
  collides but which has no meaning for a monitor (dropped: the one deviation
  from mj_collision); otherwise skip the same weld group,
  pairs whose weld groups both have no dof (static or mocap: MuJoCo >= 3.12
  never collides them), parent-child weld groups when ``filterparent`` is on and
  neither weld group is the world, ``<exclude>`` body pairs, and pairs failing
  ``(contype1 & conaffinity2) || (contype2 & conaffinity1)``. The global
  ``contact``/``constraint`` disable flags are ignored (the geometry still
  counts for safety).
* ``"all"``: every non plane-plane pair of geoms on distinct weld groups that
  are not parent-child and not both static (``body_weldid == 0``). Mocap bodies
  are moving here, so mocap-vs-static pairs are included (MuJoCo skips them).
  ``contype``/``conaffinity`` and ``<exclude>`` are ignored. A body whose parent
  is the world is a parent-child pair with every world geom; of those, only the
  pairs in contact in every configuration are dropped (rotational joints whose
  shared anchor lies in both geoms, e.g. a base and its first link), so that the
  floor vs a free body or a wall vs a slider stay checked
  (:func:`_drop_overlapping_world_children`).
* explicit list of ``(geom_a, geom_b)`` (names or ids), validated.

Model edits. A ``Scene`` keeps the ``MjModel`` and a snapshot of every model array it,
its pair policy or the motion bounds of a :class:`monitor.Plan` read (:data:`SYNC_FIELDS`,
plus the counts and ``opt.disableflags``). :meth:`Scene.sync` compares the live arrays
with the snapshot (raw bytes through views kept at construction: a few microseconds plus
a memory compare of the mesh vertices) and rebuilds the shapes and pairs after an
in-place edit (domain randomisation of ``geom_size``/``geom_pos``, tuning), bumping
:attr:`Scene.version`. :func:`monitor.certify` calls it first, so a certificate is
always about the model as it is when ``certify`` runs.

Flex bodies (``model.nflex > 0``) are not represented by any shape: construction raises
:class:`~monitor.errors.UnsupportedGeometryError` naming the flex rather than certifying
a scene that silently ignores it.

MuJoCo's per-geom ``margin`` (``geom_margin``) is recorded in :attr:`GeomInfo.margin` but
NOT added to the certified clearance: ``geom_margin`` tells MuJoCo's solver when to
start generating contacts (a physics setting, often tuned together with ``gap``), not how
close a geom may safely come. The certified clearance is the ``margin`` argument of
:func:`monitor.certify` / ``Gate``; pass ``margin=max(geom_margin)`` there to be at
least as strict as MuJoCo's contact activation.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import mujoco
import numpy as np

from monitor.certify.packed import lex_sorted_pairs
from monitor.errors import InvalidInputError, ModelMismatchError, UnsupportedGeometryError
from monitor.geometry.polytope import (
    box_polytope,
    capsule_shape,
    cylinder_polytope,
    ellipsoid_polytope,
    halfspace_shape,
    polytope_from_points,
    sphere_shape,
)
from monitor.geometry.shapes import ConvexShape
from monitor.motion.base import sealed
from monitor.pairsel import object_names
from monitor.tolerances import DEFAULT, Tolerances

FLAT_MESH_THICKNESS = 1e-6
"""Metres by which a flat (coplanar) mesh would be thickened outwards. MuJoCo
4.0's compiler rejects coplanar meshes ("cannot compute convex hull"), so this
only guards against future compilers; the excess is reported in
``Scene.approximations`` and is an over-approximation (sound)."""

_GEOM_TYPES = {int(v): k.removeprefix("mjGEOM_").lower() for k, v in mujoco.mjtGeom.__members__.items()}
_PLANE = int(mujoco.mjtGeom.mjGEOM_PLANE)
_HFIELD = int(mujoco.mjtGeom.mjGEOM_HFIELD)
_SDF = int(mujoco.mjtGeom.mjGEOM_SDF)
_UNSUPPORTED = (_HFIELD, _SDF)
_CHUNK = 1 << 20  # geom pairs per vectorised filter block
_SIGNATURE_BODIES = 1 << 16
"""Bodies up to which MuJoCo's exclusion signature ``(b1 << 16) + b2`` names one body pair (decoded
once by :func:`_filter_pairs`); above, the signatures are compared per block as MuJoCo computes them."""

SYNC_FIELDS: tuple[str, ...] = (
    # geometry of the shapes (body frame)
    "geom_type", "geom_size", "geom_pos", "geom_quat", "geom_dataid", "geom_bodyid", "geom_margin",
    "mesh_vertadr", "mesh_vertnum", "mesh_vert",
    # pair policy ("mujoco": masks, exclusions, <pair>; "all": weld groups and the anchor test;
    # geom_group: hazards= / allow= "group:N" patterns)
    "geom_contype", "geom_conaffinity", "geom_group", "body_weldid", "body_parentid", "body_dofnum",
    "body_mocapid", "exclude_signature", "pair_geom1", "pair_geom2",
    # kinematics: the world-children anchor test of pairs="all" and the motion bounds of a Plan
    "jnt_type", "jnt_qposadr", "jnt_bodyid", "jnt_pos", "jnt_axis", "qpos0", "body_pos", "body_quat",
    "body_jntadr", "body_jntnum", "body_ipos", "geom_rbound",
    # where MuJoCo puts a geom whose frame is its body's inertial frame (geom_frame)
    "body_iquat", "geom_sameframe", "body_sameframe",
)
"""``MjModel`` arrays that :meth:`Scene.sync` watches for in-place edits."""
_RUN_GAP = 1024
"""Bytes: watched arrays closer than this share one comparison run (:meth:`_Snapshot.unchanged`)."""


def _run_views(views: list[np.ndarray]) -> list[np.ndarray]:
    """Read-only uint8 views, each spanning a run of ``views`` (C-contiguous, non-empty) and their gaps.

    Runs are formed in address order; an array starts a new run when it begins more than
    :data:`_RUN_GAP` bytes after the current run's end (or is not C-contiguous). Each run
    view is strided over its first array's buffer (which keeps the model alive).
    """
    spans = sorted((v.__array_interface__["data"][0], v.nbytes, i) for i, v in enumerate(views))
    runs: list[list[int]] = []
    for a, n, i in spans:
        v = views[i]
        if runs and v.flags.c_contiguous and views[runs[-1][2]].flags.c_contiguous \
                and 0 <= a - runs[-1][1] <= _RUN_GAP:
            runs[-1][1] = max(runs[-1][1], a + n)
        else:
            runs.append([a, a + n, i])
    out = []
    for a, e, i in runs:
        v = views[i]
        if not v.flags.c_contiguous:   # compared on its own, as in changed()
            out.append(v)
            continue
        base = v.reshape(-1).view(np.uint8)
        out.append(np.lib.stride_tricks.as_strided(base, shape=(e - a,), strides=(1,), writeable=False))
    return out


class _Snapshot:
    """Raw bytes of the watched model arrays, read through views kept from construction.

    ``MjModel`` array attributes are views into the model's own buffers (assignment copies
    into them), so the views stay valid and a comparison costs one ``tobytes`` per field.
    Array sizes (``nbody``, ``ngeom``, ...) cannot change in place: an ``MjModel``'s
    buffers are allocated once, so only contents and ``opt.disableflags`` are compared.
    """

    def __init__(self, model: Any):
        self._bind(model)
        self.saved = [v.tobytes() for _, v in self.views]
        self.disableflags = int(self.opt.disableflags)

    def _bind(self, model: Any) -> None:
        self.model = model
        self.views = [(f, getattr(model, f)) for f in SYNC_FIELDS]
        self.opt = model.opt  # a live view of mjOption
        self._live: list[tuple[Any, bytes]] | None = None  # (view, saved bytes) of non-empty fields
        self._runs: list[tuple[Any, bytes]] | None = None  # (run view, reference bytes), see unchanged()

    def unchanged(self) -> bool:
        """True if no watched field differs from the snapshot (the per-call test of :meth:`Scene.sync`).

        Same answer as ``not changed()``: every byte of every watched field and
        ``opt.disableflags`` are compared, stopping at the first difference.

        Fast path: the watched arrays lie in few memory *runs* (MuJoCo allocates the model's
        arrays in one buffer, in a fixed order; fields closer than :data:`_RUN_GAP` bytes
        share a run, gap included), compared with one ``tobytes`` each. A run's reference
        bytes are taken only right after the field-by-field comparison against the
        snapshot found every watched byte equal, so equal runs imply equal watched fields.
        When a run differs (a watched field, or an unwatched array inside a gap, was
        edited) the field-by-field comparison decides, and the references are retaken if it
        finds nothing watched changed. Reading a gap is memory-safe: it is shorter than a
        page and lies between two live arrays, so every page it touches is mapped.
        Empty arrays (e.g. ``mesh_vert`` without meshes) have nothing to compare.
        """
        if int(self.opt.disableflags) != self.disableflags:
            return False
        runs = self._runs
        if runs is not None:
            for v, b in runs:
                if v.tobytes() != b:
                    break
            else:
                return True
        live = self._live
        if live is None:
            live = self._live = [(v, b) for (_f, v), b in zip(self.views, self.saved) if v.size]
        for v, b in live:
            if v.tobytes() != b:
                return False
        views = _run_views([v for v, _b in live])
        self._runs = [(v, v.tobytes()) for v in views]
        return True

    def __getstate__(self) -> dict[str, Any]:  # views are not picklable; rebound on load
        return {"model": self.model, "saved": self.saved, "disableflags": self.disableflags}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self._bind(state["model"])
        self.saved, self.disableflags = state["saved"], state["disableflags"]

    def changed(self) -> list[str]:
        """Names of the watched fields whose contents differ from the snapshot."""
        out = [f for (f, v), b in zip(self.views, self.saved) if v.tobytes() != b]
        if int(self.opt.disableflags) != self.disableflags:
            out.append("opt.disableflags")
        return out


@dataclass(frozen=True, eq=False)
class GeomInfo:
    """One MuJoCo geom as the monitor sees it.

    Attributes:
        name: geom name (``"geom<id>"`` when unnamed).
        id: MuJoCo geom id (== index in ``Scene.geoms``).
        body: name of the body carrying the geom.
        body_id: MuJoCo body id.
        type: MuJoCo geom type name (``"sphere"``, ``"capsule"``, ``"box"``,
            ``"mesh"``, ``"cylinder"``, ``"ellipsoid"``, ``"plane"``, ``"hfield"``, ``"sdf"``).
        shape: convex shape in the BODY frame, or None for unsupported types
            (hfield, sdf) that take part in no candidate pair.
        margin: ``geom_margin`` (m), informational; the certification margin is
            an argument of ``certify``.
        static: the body is welded to the world (``body_weldid == 0``).
        mocap: the body is a mocap body or a dof-less descendant of one.
    """

    name: str
    id: int
    body: str
    body_id: int
    type: str
    shape: ConvexShape | None
    margin: float
    static: bool
    mocap: bool


def _quat_to_mat(q: np.ndarray) -> np.ndarray:
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(q, dtype=np.float64))
    return R.reshape(3, 3)


_SAME = mujoco.mjtSameFrame
_SF_BODY, _SF_INERTIA, _SF_BODYROT, _SF_INERTIAROT, _SF_NONE = (
    int(_SAME.mjSAMEFRAME_BODY), int(_SAME.mjSAMEFRAME_INERTIA), int(_SAME.mjSAMEFRAME_BODYROT),
    int(_SAME.mjSAMEFRAME_INERTIAROT), int(_SAME.mjSAMEFRAME_NONE))
"""``geom_sameframe`` / ``body_sameframe`` codes as ints (numpy compares them without Python objects)."""


def geom_frame(model: Any, g: int) -> tuple[np.ndarray, np.ndarray]:
    """(R_BG (3, 3), p_BG (3,)): the frame of geom ``g`` in its body's frame, as MuJoCo places it.

    MuJoCo's compiler marks a geom whose frame is (within its tolerance) its body's frame or its
    body's inertial frame (``geom_sameframe``); ``mj_kinematics`` then takes that frame and ignores
    ``geom_pos`` / ``geom_quat``: BODY (frame = body), INERTIA (= ``body_ipos``/``body_iquat``),
    BODYROT (rotation = body's, position ``geom_pos``), INERTIAROT (rotation ``body_iquat``).
    So an in-place edit of ``geom_pos`` of such a geom moves nothing in the simulation, and an edit
    of ``body_ipos`` / ``body_iquat`` (centre-of-mass randomisation) moves the geom.
    """
    sf = int(model.geom_sameframe[g])
    b = int(model.geom_bodyid[g])
    if sf == _SAME.mjSAMEFRAME_BODY:
        return np.eye(3), np.zeros(3)
    if sf == _SAME.mjSAMEFRAME_INERTIA:
        return _inertial_frame(model, b)
    if sf == _SAME.mjSAMEFRAME_BODYROT:
        R = np.eye(3)
    elif sf == _SAME.mjSAMEFRAME_INERTIAROT:
        R = _inertial_frame(model, b)[0]
    else:
        R = _quat_to_mat(model.geom_quat[g])
    return R, np.array(model.geom_pos[g], dtype=np.float64)


def _inertial_frame(model: Any, b: int) -> tuple[np.ndarray, np.ndarray]:
    """(R_BI (3, 3), p_BI (3,)): body ``b``'s inertial frame in its body frame, as ``mj_kinematics`` puts it.

    MuJoCo places it by ``body_sameframe`` (red team 6): BODY -> the body frame itself
    (``body_ipos`` / ``body_iquat`` ignored), BODYROT -> the body's rotation at ``body_ipos``, NONE ->
    ``body_iquat`` at ``body_ipos``. The compiler sets no other value for a body; one edited in is
    refused rather than guessed. The world's (b = 0) is the world frame whatever its flags:
    ``mj_kinematics`` sets ``xipos[0]`` / ``ximat[0]`` to the origin / identity (red team 7).
    """
    sf = int(model.body_sameframe[b])
    if sf == _SAME.mjSAMEFRAME_BODY or b == 0:
        return np.eye(3), np.zeros(3)
    if sf == _SAME.mjSAMEFRAME_BODYROT:
        return np.eye(3), np.array(model.body_ipos[b], dtype=np.float64)
    if sf != _SAME.mjSAMEFRAME_NONE:
        raise UnsupportedGeometryError(
            f"body {b}: body_sameframe {sf} ({_SAME(sf).name}): MuJoCo's compiler never sets it for a body, "
            "so where mj_kinematics puts the body's inertial frame is not defined here")
    return _quat_to_mat(model.body_iquat[b]), np.array(model.body_ipos[b], dtype=np.float64)


def _quat_mats(quats: np.ndarray) -> np.ndarray:
    """(n, 3, 3) ``mju_quat2Mat`` of (n, 4) quaternions: one call per distinct quaternion (bytes)."""
    q = np.ascontiguousarray(quats, dtype=np.float64).reshape(-1, 4)
    if not len(q):
        return np.zeros((0, 3, 3))
    _, first, inverse = np.unique(q.view(np.dtype((np.void, 32))).ravel(), return_index=True,
                                  return_inverse=True)
    mats = np.stack([_quat_to_mat(q[i]) for i in first.tolist()])
    return mats[inverse.reshape(-1)]


def geom_frames(model: Any) -> tuple[np.ndarray, np.ndarray, int]:
    """:func:`geom_frame` of every geom at once: (R_BG (G, 3, 3), p_BG (G, 3), first bad geom).

    Values are :func:`geom_frame`'s bit for bit (the same ``mju_quat2Mat`` per distinct
    quaternion, the same copied positions). Where :func:`geom_frame` would raise (a geom placed
    in a body's inertial frame whose ``body_sameframe`` is not one the compiler sets), that
    geom's rows are left as the body frame and its id is returned (``G``: none), so that the
    caller raises :func:`geom_frame`'s error in its own order.
    """
    G = int(model.ngeom)
    sf = np.asarray(model.geom_sameframe, dtype=np.int64)
    body = np.asarray(model.geom_bodyid, dtype=np.int64)
    R = np.broadcast_to(np.eye(3), (G, 3, 3)).copy()
    p = np.array(model.geom_pos, dtype=np.float64).reshape(G, 3)
    own = ~np.isin(sf, (_SF_BODY, _SF_INERTIA, _SF_BODYROT,
                        _SF_INERTIAROT))
    R[own] = _quat_mats(np.asarray(model.geom_quat)[own])
    p[sf == _SF_BODY] = 0.0
    inertial = (sf == _SF_INERTIA) | (sf == _SF_INERTIAROT)
    bad = G
    if inertial.any():
        b = body[inertial]
        bsf = np.asarray(model.body_sameframe, dtype=np.int64)[b]
        frame_of_body = (bsf == _SF_BODY) | (b == 0)
        rot_of_body = ~frame_of_body & (bsf == _SF_BODYROT)
        own_rot = ~frame_of_body & (bsf == _SF_NONE)
        ok = frame_of_body | rot_of_body | own_rot
        if not ok.all():
            bad = int(np.flatnonzero(inertial)[np.flatnonzero(~ok)[0]])
        RI = np.broadcast_to(np.eye(3), (len(b), 3, 3)).copy()
        RI[own_rot] = _quat_mats(np.asarray(model.body_iquat)[b[own_rot]])
        pI = np.array(np.asarray(model.body_ipos)[b], dtype=np.float64).reshape(-1, 3)
        pI[frame_of_body] = 0.0
        keep = ok   # a bad geom keeps the body frame; the caller raises before using it
        rows = np.flatnonzero(inertial)[keep]
        R[rows] = RI[keep]
        whole = sf[rows] == _SF_INERTIA
        p[rows[whole]] = pI[keep][whole]
    return R, p, bad


def _to_body(shape_G: ConvexShape, R_BG: np.ndarray, p_BG: np.ndarray) -> ConvexShape:
    """Move a geom-frame shape into the body frame (x_B = R_BG x_G + p_BG).

    For polytopes the offsets are then raised to the max of ``normal . v`` over the
    moved vertices, so the H-rep contains the V-rep exactly in float64 (only enlarges).
    """
    s = shape_G.transformed(R_BG, p_BG)
    if s.kind != "polytope":
        return s
    off = np.maximum(s.offsets, (s.normals @ s.points.T).max(axis=1))
    return ConvexShape(s.kind, s.points, s.radius, s.edges, s.faces, s.normals, off, s.approx_error)


NONCONVEX_REL_TOL = 1e-6
"""Relative extra hull volume, ``(V_hull - V_mesh) / V_hull``, above which a closed mesh
counts as non-convex for the warning of :func:`_check_mesh` (float32 vertices; a convex
mesh's two volumes agree to ~1e-12 relative)."""

_MESH_CHECKS: dict[bytes, str | None] = {}
"""Mesh content digest -> warning text (None: convex). Filled by :func:`_check_mesh`, so a
mesh is examined, and warned about, once per process however often scenes are rebuilt."""


def _check_mesh(model: Any, mid: int, g: int) -> None:
    """Validate mesh ``mid`` (used by geom ``g``) with trimesh; warn once if it is not convex.

    Builds a ``trimesh.Trimesh`` from the compiled ``mesh_vert`` (V, 3) and ``mesh_face``
    (F, 3) of the mesh. Certification treats every mesh as the convex hull of its vertices
    (sound, conservative), so a non-convex mesh only costs clearance: one
    ``warnings.warn`` per mesh names the geom and the hull's extra volume (m^3 and %) for a
    closed mesh, or says the mesh is open and not convex. Results are cached by mesh
    content (:data:`_MESH_CHECKS`).

    Raises:
        InvalidInputError: non-finite vertices, or face indices outside the mesh's vertices
            (e.g. after an in-place edit of ``mesh_vert``/``mesh_face``).
    """
    import warnings

    va, vn = int(model.mesh_vertadr[mid]), int(model.mesh_vertnum[mid])
    fa, fn = int(model.mesh_faceadr[mid]), int(model.mesh_facenum[mid])
    V = np.asarray(model.mesh_vert[va:va + vn], dtype=np.float64)
    F = np.asarray(model.mesh_face[fa:fa + fn], dtype=np.int64)
    key = hashlib.blake2b(V.tobytes() + b"|" + F.tobytes(), digest_size=16).digest()
    if key in _MESH_CHECKS:
        return
    mesh_name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_MESH, mid) or f"#{mid}"
    geom_name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or f"#{g}"
    what = f"mesh {mesh_name!r} (geom {geom_name!r})"
    if vn == 0 or not np.isfinite(V).all():
        raise InvalidInputError(f"{what}: mesh_vert has {'no' if vn == 0 else 'non-finite'} vertices")
    if fn and (F.min() < 0 or F.max() >= vn):
        raise InvalidInputError(f"{what}: mesh_face indexes outside its {vn} vertices")
    message = None
    if fn:
        import trimesh

        mesh = trimesh.Trimesh(vertices=V, faces=F, process=False, validate=False)
        try:
            hull_volume = float(mesh.convex_hull.volume)
        except Exception:  # noqa: BLE001 - flat/degenerate hull (thickened in _geom_shape)
            hull_volume = 0.0
        if mesh.is_volume:
            extra = hull_volume - float(mesh.volume)
            if hull_volume > 0 and extra > NONCONVEX_REL_TOL * hull_volume:
                message = (f"{what} is not convex; it is certified as its convex hull, which adds "
                           f"{extra:.3g} m^3 ({100 * extra / hull_volume:.3g}% of the hull) "
                           f"(sound but conservative: clearances near it are underestimated)")
        elif not trimesh.convex.is_convex(mesh):
            message = (f"{what} is not a closed volume and not convex; it is certified as the convex "
                       f"hull of its vertices ({hull_volume:.3g} m^3), sound but conservative")
    if len(_MESH_CHECKS) > 4096:
        _MESH_CHECKS.clear()
    _MESH_CHECKS[key] = message
    if message is not None:
        warnings.warn(message, UserWarning, stacklevel=2)


def _geom_shape(model: Any, g: int, facets: int, tol: Tolerances) -> ConvexShape | None:
    """Shape of geom ``g`` in its geom frame (None for unsupported types)."""
    t = int(model.geom_type[g])
    size = np.asarray(model.geom_size[g], dtype=np.float64)
    name = _GEOM_TYPES.get(t, str(t))
    if t == int(mujoco.mjtGeom.mjGEOM_SPHERE):
        return sphere_shape(size[0])
    if t == int(mujoco.mjtGeom.mjGEOM_CAPSULE):
        return capsule_shape(size[0], size[1])
    if t == int(mujoco.mjtGeom.mjGEOM_BOX):
        return box_polytope(size)
    if t == int(mujoco.mjtGeom.mjGEOM_CYLINDER):
        return cylinder_polytope(size[0], size[1], facets, tolerances=tol)
    if t == int(mujoco.mjtGeom.mjGEOM_ELLIPSOID):
        return ellipsoid_polytope(size, facets, tolerances=tol)
    if t == _PLANE:
        return halfspace_shape()
    if t == int(mujoco.mjtGeom.mjGEOM_MESH):
        mid = int(model.geom_dataid[g])
        a, n = int(model.mesh_vertadr[mid]), int(model.mesh_vertnum[mid])
        # All compiled vertices, never the mesh_graph hull: with maxhullvert that hull is
        # reduced (it lies inside the mesh) and MuJoCo 4.0 still reports contacts with the
        # full mesh, so certifying against it would be unsound (red-team test
        # test_fn_mesh_maxhullvert_reduced_hull). The hull of all vertices contains both.
        V = np.asarray(model.mesh_vert[a:a + n], dtype=np.float64)
        _check_mesh(model, mid, g)
        try:
            return polytope_from_points(V)
        except InvalidInputError:
            return polytope_from_points(V, thicken=FLAT_MESH_THICKNESS)
    if t in _UNSUPPORTED:
        return None
    raise UnsupportedGeometryError(f"geom {g} has unknown type {name!r}")


class Scene:
    """Convex shapes of every geom of an ``MjModel`` plus the pairs to certify.

    Build with :meth:`from_model`. Attributes (read-only by convention):

    Attributes:
        model: the ``mujoco.MjModel`` (kept; plans are checked against it).
        geoms: tuple of :class:`GeomInfo`, index == geom id.
        candidate_pairs: tuple of (name_a, name_b), sorted by (id_a, id_b), id_a < id_b.
        pair_ids: (P, 2) int64 geom ids, same order.
        body_names: tuple of body names (nbody), ``"body<id>"`` when unnamed.
        body_static: (nbody,) bool, welded to the world with no dof (mocap is not static).
        approximations: {geom name: approx_error (m)} for circumscribed shapes.
        facets: facet count used for cylinders and ellipsoids.
        tolerances: the :class:`Tolerances` used.
        version: 0 at construction, +1 each time :meth:`sync` rebuilt the scene after an
            in-place edit of the model.
        allowed_pairs: ((geom_a, geom_b, reason), ...) candidate pairs removed by the
            ACM / ``allow=`` (never certified; listed in every certificate).
    """

    allowed_pairs: tuple[tuple[str, str, str], ...] = ()
    geom_frames: tuple[tuple[np.ndarray, np.ndarray], ...] | None = None
    """Per geom (R_BG, p_BG), its frame in the body frame (:func:`geom_frame`); set by :meth:`from_model`."""

    def __init__(self, model: Any, geoms: tuple[GeomInfo, ...], pair_ids: np.ndarray,
                 body_names: tuple[str, ...], body_static: np.ndarray, facets: int,
                 tolerances: Tolerances, *, pairs_sorted: bool = False):
        # sealed over immutable bytes (a copy, once per build): the engine caches the scene's packs by
        # the identity of these arrays, and a read-only array that owns its memory can be made
        # writable again and edited under the cache (red team 10's open item)
        pair_ids = sealed(pair_ids)
        body_static = sealed(body_static)
        self.model = model
        self.geoms = geoms
        self.pair_ids = pair_ids
        sorted_ = pairs_sorted or lex_sorted_pairs(pair_ids, len(geoms))
        self._sorted_pairs = pair_ids if sorted_ else None
        """``pair_ids`` itself when its rows are strictly increasing (a, b) with 0 <= a < b < ngeom (the
        engine's sweep finds rows by binary search), else None. Checked here, once per pair array, unless
        the caller passes ``pairs_sorted=True``: only :meth:`from_model`, for the arrays it builds, which
        are in that order by construction (:func:`_filter_pairs`' row-major cells, a sorted set of
        explicit pairs, and row subsets of those taken by boolean masks; tested on every model)."""
        self.body_names = body_names
        self.body_static = body_static
        self.facets = facets
        self.tolerances = tolerances
        self.approximations = {g.name: float(g.shape.approx_error) for g in geoms
                               if g.shape is not None and g.shape.approx_error > 0.0}
        self._by_name = {g.name: g for g in geoms}
        self.version = 0
        self._pairs_spec: Any = "mujoco"  # set by from_model: the pairs argument, for rebuilds
        self._acm_spec: dict[str, Any] = {}  # set by from_model: allowed/hazards/allow/reference
        # a scene built by hand without an MjModel (tests, pure-geometry use) has nothing to watch
        self._snapshot = _Snapshot(model) if model is not None else None
        self._hot: dict[str, Any] = {}
        """Per-scene values the engine derives from the scene (``monitor.certify.engine``:
        selections, packed flags, model checks already made); emptied by :meth:`sync` and
        not pickled. Entries also hold the objects they were derived from (``pair_ids``,
        the snapshot) and are used only while those are still the scene's."""

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_hot"] = {}
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Unpickle, sealing ``pair_ids`` and ``body_static`` again (unpickled arrays are writable)."""
        state = dict(state)
        for name in ("pair_ids", "body_static"):
            if isinstance(state.get(name), np.ndarray):
                state[name] = sealed(state[name])
        if state.get("_sorted_pairs") is not None:
            state["_sorted_pairs"] = state["pair_ids"]
        self.__dict__.update(state)

    # ------------------------------------------------------------------ model edits

    def sync(self) -> bool:
        """Rebuild the scene if the model was edited in place since the last build.

        Compares every watched array (:data:`SYNC_FIELDS`), the counts and
        ``opt.disableflags`` against the snapshot taken at the last build. On a change
        the shapes and candidate pairs are rebuilt from the live model with the same
        ``pairs`` argument, facets and tolerances, and :attr:`version` is incremented.

        Returns:
            True if the scene was rebuilt, False if nothing watched had changed.

        Raises:
            ModelMismatchError: the edit makes a rebuild impossible (e.g. an explicit pair
                or a pair of ``pairs="mujoco"`` now names an hfield geom, or two explicitly
                paired geoms became planes); the message names the changed fields. The
                snapshot is kept, so every later call raises again instead of certifying a
                stale scene.
        """
        if self._snapshot is None:
            return False
        if self._snapshot.unchanged():
            return False
        changed = self._snapshot.changed()
        if not changed:  # cannot differ from unchanged() (same bytes); kept as a guard
            return False
        what = ", ".join(changed)
        try:
            fresh = Scene.from_model(self.model, pairs=self._pairs_spec, facets=self.facets,
                                     tolerances=self.tolerances, **self._acm_spec)
        except (InvalidInputError, UnsupportedGeometryError) as exc:
            raise ModelMismatchError(f"the scene's MjModel was edited in place ({what}) and the scene "
                                     f"cannot be rebuilt: {exc}") from exc
        self.geoms = fresh.geoms
        self.geom_frames = fresh.geom_frames
        self.pair_ids = fresh.pair_ids
        self._sorted_pairs = fresh._sorted_pairs
        self.body_names = fresh.body_names
        self.body_static = fresh.body_static
        self.approximations = fresh.approximations
        self.allowed_pairs = fresh.allowed_pairs
        self._by_name = fresh._by_name
        self._snapshot = fresh._snapshot
        for cached in ("candidate_pairs", "model_hash"):
            self.__dict__.pop(cached, None)
        self._hot = {}
        self.version += 1
        return True

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_model(cls, model: Any, pairs: str | Iterable[tuple[str | int, str | int]] = "mujoco",
                   *, facets: int | None = None, tolerances: Tolerances = DEFAULT, allowed: Any = None,
                   hazards: Any = None, allow: Any = None, reference: Any = None) -> Scene:
        """Read every geom of ``model`` and select the candidate pairs.

        Args:
            model: a ``mujoco.MjModel``.
            pairs: ``"mujoco"`` (MuJoCo's own candidate filter), ``"all"`` (every
                pair that can move relative to each other, see module docstring),
                or an iterable of (geom_a, geom_b) names or ids.
            facets: facet count of circumscribed cylinders/ellipsoids (>= 3);
                default ``tolerances.facets`` (16).
            tolerances: numerical tolerances.
            allowed: allowed-contact matrix (:func:`monitor.acm.as_acm`: None, ``"auto"``,
                an :class:`monitor.acm.ACM`, a ``.json`` path or a list of pairs); its
                pairs (except reason Never) are removed from the candidates and listed
                in :attr:`allowed_pairs` with their reasons.
            hazards: None, or pattern items (:mod:`monitor.pairsel`) selecting the
                candidate pairs that are checked.
            allow: pattern items whose candidate pairs are allowed (reason User).
            reference: (nq,) reference pose for ``allowed="auto"`` (default keyframe 0 / qpos0).

        Returns:
            The scene.

        Raises:
            InvalidInputError: unknown pairs mode, unknown geom in a pair, a geom
                paired with itself, a plane-plane pair, bad ``facets``.
            UnsupportedGeometryError: an hfield/sdf geom in a candidate pair, or any flex
                (``model.nflex > 0``: deformable bodies have no convex shape here).
        """
        if not isinstance(model, mujoco.MjModel):
            raise InvalidInputError(f"model must be a mujoco.MjModel, got {type(model).__name__}")
        if int(model.nflex) > 0:
            fname = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_FLEX, 0) or "flex0"
            raise UnsupportedGeometryError(
                f"the model has {int(model.nflex)} flex object(s) (first: {fname!r}); deformable "
                "flex bodies cannot be certified by this monitor, and ignoring them would certify "
                "motions that collide with them")
        if not isinstance(pairs, str):
            try:  # keep the explicit list (a one-shot iterator too) for rebuilds after model edits
                pairs = list(pairs)
            except TypeError:
                raise InvalidInputError(f"pairs must be 'mujoco', 'all' or a list of geom pairs, "
                                        f"got {type(pairs).__name__}") from None
        nf = tolerances.facets if facets is None else facets
        if isinstance(nf, bool) or not isinstance(nf, int | np.integer) or nf < 3:
            raise InvalidInputError(f"facets must be an integer >= 3, got {facets!r}")
        nf = int(nf)

        ngeom = int(model.ngeom)
        body_names = tuple(object_names(model, model.name_bodyadr, "body"))
        weld = np.asarray(model.body_weldid, dtype=np.int64)
        body_static = weld == 0
        body_mocap = np.asarray(model.body_mocapid, dtype=np.int64)[weld] >= 0
        names = object_names(model, model.name_geomadr, "geom")
        if len(set(names)) != ngeom:  # an explicit name like "geom3" clashing with a generated one
            seen: dict[str, int] = {}
            for g, nm in enumerate(names):
                if nm in seen:
                    raise InvalidInputError(f"geom name {nm!r} is used by geoms {seen[nm]} and {g}")
                seen[nm] = g

        pair_ids = cls._select_pairs(model, pairs, names)
        allowed_rows: tuple[tuple[str, str, str], ...] = ()
        policy = None
        if allowed is not None or hazards is not None or allow is not None:  # issue 13: pair policy
            from monitor.acm import apply_policy

            policy = apply_policy(model, pair_ids, pairs, allowed=allowed, hazards=hazards, allow=allow,
                                  reference=reference)
            pair_ids, allowed_rows = policy.monitored, policy.allowed
        types = np.asarray(model.geom_type, dtype=np.int64)
        unsupported = np.isin(types, _UNSUPPORTED)
        if len(pair_ids) and unsupported.any():   # the pairs are read only when such a geom exists
            in_pair = np.zeros(ngeom, dtype=bool)
            in_pair[pair_ids.ravel()] = True
            bad = np.flatnonzero(in_pair & unsupported)
            if bad.size:
                g = int(bad[0])
                other = pair_ids[(pair_ids == g).any(axis=1)][0]
                partner = int(other[0] if other[1] == g else other[1])
                raise UnsupportedGeometryError(
                    f"geom {names[g]!r} (id {g}) has type {_GEOM_TYPES[int(types[g])]!r}, which the "
                    f"checkers cannot represent; it is in candidate pair ({names[g]!r}, "
                    f"{names[partner]!r}). Exclude it (contype/conaffinity, <exclude>) or pass "
                    "an explicit pair list without it")

        # Per geom: one geom-frame shape per distinct (type, size, mesh) and one body-frame shape per
        # distinct (geom-frame shape, frame bytes); every geom with the same inputs shares the objects.
        R_all, p_all, bad_frame = geom_frames(model)   # where MuJoCo's kinematics put each geom
        sizes = np.asarray(model.geom_size, dtype=np.float64).reshape(ngeom, 3)
        keys = list(zip(types.tolist(), map(tuple, sizes.tolist()), np.asarray(model.geom_dataid).tolist()))
        first_of: dict[tuple, int] = {}
        for g, key in enumerate(keys):
            first_of.setdefault(key, g)
        shapes_G: dict[tuple, ConvexShape | None] = {}
        for key, g in first_of.items():   # first occurrences, in geom order (errors as a geom loop)
            if g > bad_frame:
                break
            shapes_G[key] = _geom_shape(model, g, nf, tolerances)
        if bad_frame < ngeom:
            _inertial_frame(model, int(model.geom_bodyid[bad_frame]))   # raises its error
        shape_of = np.array([first_of[k] for k in keys], dtype=np.int64)  # first geom with the same key
        rows = np.ascontiguousarray(np.concatenate([shape_of.view(np.uint8).reshape(ngeom, 8),
                                                    R_all.reshape(ngeom, 9).view(np.uint8),
                                                    p_all.view(np.uint8)], axis=1))   # bytes per geom
        _, first, inverse = np.unique(rows.view(np.dtype((np.void, rows.shape[1]))).ravel(),
                                      return_index=True, return_inverse=True)
        shapes_B = []
        for g in first.tolist():
            s = shapes_G[keys[g]]
            shapes_B.append(None if s is None else _to_body(s, R_all[g].copy(), p_all[g].copy()))
        R_all.setflags(write=False)
        p_all.setflags(write=False)
        frames = tuple(zip(R_all, p_all))
        gbody = np.asarray(model.geom_bodyid, dtype=np.int64)
        geoms = [GeomInfo(name=names[g], id=g, body=body_names[b], body_id=b,
                          type=_GEOM_TYPES.get(t, str(t)), shape=shapes_B[u], margin=m,
                          static=s, mocap=mc)
                 for g, (b, t, u, m, s, mc) in enumerate(zip(
                     gbody.tolist(), types.tolist(), inverse.reshape(-1).tolist(),
                     np.asarray(model.geom_margin, dtype=np.float64).tolist(),
                     body_static[gbody].tolist(), body_mocap[gbody].tolist()))]
        if isinstance(pairs, str) and pairs == "all":
            pair_ids = _drop_overlapping_world_children(model, pair_ids, geoms, tolerances)
        scene = cls(model, tuple(geoms), pair_ids, body_names, body_static, nf, tolerances, pairs_sorted=True)
        scene.geom_frames = tuple(frames)
        scene._pairs_spec = pairs
        # rebuilds after model edits reuse the matrix resolved now ("auto" is not recomputed on an
        # edited model: an edit must never turn a hazard into an allowed pair)
        frozen = policy.acm if allowed is not None and policy is not None else allowed
        scene._acm_spec = {"allowed": frozen, "hazards": hazards, "allow": allow, "reference": reference}
        scene.allowed_pairs = allowed_rows
        return scene

    @staticmethod
    def _select_pairs(model: Any, pairs: Any, names: Sequence[str]) -> np.ndarray:
        ngeom = int(model.ngeom)
        if isinstance(pairs, str):
            if pairs not in ("mujoco", "all"):
                raise InvalidInputError(
                    f"pairs must be 'mujoco', 'all' or a list of geom pairs, got {pairs!r}")
            return _filter_pairs(model, mode=pairs)
        try:
            items = list(pairs)
        except TypeError:
            raise InvalidInputError(f"pairs must be 'mujoco', 'all' or a list of geom pairs, "
                                    f"got {type(pairs).__name__}") from None
        index = {n: i for i, n in enumerate(names)}

        def resolve(x: Any, k: int) -> int:
            if isinstance(x, str):
                if x not in index:
                    raise InvalidInputError(f"pairs[{k}]: unknown geom {x!r}")
                return index[x]
            if isinstance(x, int | np.integer) and not isinstance(x, bool):
                if not 0 <= int(x) < ngeom:
                    raise InvalidInputError(f"pairs[{k}]: geom id {x} out of range [0, {ngeom})")
                return int(x)
            raise InvalidInputError(f"pairs[{k}]: geom must be a name or id, got {x!r}")

        out = set()
        types = np.asarray(model.geom_type)
        for k, item in enumerate(items):
            if isinstance(item, str) or not hasattr(item, "__len__") or len(item) != 2:
                raise InvalidInputError(f"pairs[{k}]: expected a (geom_a, geom_b) pair, got {item!r}")
            a, b = resolve(item[0], k), resolve(item[1], k)
            if a == b:
                raise InvalidInputError(f"pairs[{k}]: geom {names[a]!r} is paired with itself")
            if types[a] == _PLANE and types[b] == _PLANE:
                raise InvalidInputError(f"pairs[{k}]: ({names[a]!r}, {names[b]!r}) are both planes; "
                                        "plane-plane pairs have no collision test")
            out.add((min(a, b), max(a, b)))
        return np.array(sorted(out), dtype=np.int64).reshape(-1, 2)

    # ------------------------------------------------------------------ queries

    @cached_property
    def candidate_pairs(self) -> tuple[tuple[str, str], ...]:
        """(name_a, name_b) per row of :attr:`pair_ids` (built on first access)."""
        names = np.array([g.name for g in self.geoms], dtype=object)
        return tuple(zip(names[self.pair_ids[:, 0]].tolist(), names[self.pair_ids[:, 1]].tolist()))

    def geom(self, name_or_id: str | int) -> GeomInfo:
        """The :class:`GeomInfo` of a geom given by name or id.

        Raises:
            InvalidInputError: unknown name or id out of range.
        """
        if isinstance(name_or_id, str):
            try:
                return self._by_name[name_or_id]
            except KeyError:
                raise InvalidInputError(f"unknown geom {name_or_id!r}") from None
        if isinstance(name_or_id, int | np.integer) and not isinstance(name_or_id, bool):
            if 0 <= int(name_or_id) < len(self.geoms):
                return self.geoms[int(name_or_id)]
            raise InvalidInputError(f"geom id {name_or_id} out of range [0, {len(self.geoms)})")
        raise InvalidInputError(f"geom must be a name or id, got {name_or_id!r}")

    @cached_property
    def model_hash(self) -> str:
        """sha256 hex digest of the model's binary (MJB) serialisation.

        Equal for two loads of the same XML; changes with any edit of model fields.
        """
        return model_hash(self.model)

    def __repr__(self) -> str:
        return (f"Scene(ngeom={len(self.geoms)}, nbody={len(self.body_names)}, "
                f"pairs={len(self.pair_ids)})")


def model_hash(model: Any) -> str:
    """sha256 hex digest of ``mj_saveModel`` bytes (MJB) of an ``MjModel``."""
    buf = np.zeros(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    return hashlib.sha256(buf.tobytes()).hexdigest()


def _body_pair_geoms(gbody: np.ndarray, nbody: int, b1: np.ndarray, b2: np.ndarray) -> np.ndarray:
    """(K, 2) int64 geom pairs (min, max): every geom of body ``b1[e]`` with every geom of ``b2[e]``.

    Args:
        gbody: (G,) body id of each geom.
        nbody: number of bodies.
        b1, b2: (E,) body ids (``b1[e] != b2[e]``).
    """
    order = np.argsort(gbody, kind="stable")
    count = np.bincount(gbody, minlength=nbody)
    first = np.concatenate([[0], np.cumsum(count)])[:-1]
    n1, n2 = count[b1], count[b2]
    size = n1 * n2
    e = np.repeat(np.arange(len(b1)), size)
    t = np.arange(int(size.sum())) - np.repeat(np.cumsum(size) - size, size)
    ga = order[first[b1[e]] + t // n2[e]]
    gb = order[first[b2[e]] + t % n2[e]]
    return np.stack([np.minimum(ga, gb), np.maximum(ga, gb)], axis=1).astype(np.int64)


def _filter_pairs(model: Any, mode: str) -> np.ndarray:
    """Vectorised candidate filter; returns (P, 2) int64 geom id pairs in (a, b) order, a < b.

    The rules are the module docstring's, evaluated on row blocks of the upper triangle
    (rows ``[r0, r1)``, columns ``(r0, G)``, at most :data:`_CHUNK` cells): a boolean matrix
    per block, from per-geom vectors (weld group, its parent's weld group, plane flag, dof,
    contype / conaffinity), with the rules that select nothing in this model skipped. The
    sparse rules are scattered into it: ``<exclude>`` body pairs (expanded to their geom
    pairs) cleared, then ``<pair>`` geom pairs set (``"mujoco"``). The rows come out in
    (a, b) order: the kept cells of each block, row by row.
    """
    ngeom, nbody = int(model.ngeom), int(model.nbody)
    if ngeom < 2:
        return np.zeros((0, 2), np.int64)
    types = np.asarray(model.geom_type, dtype=np.int64)
    gbody = np.asarray(model.geom_bodyid, dtype=np.int64)
    weld = np.asarray(model.body_weldid, dtype=np.int64)
    parent = np.asarray(model.body_parentid, dtype=np.int64)
    gweld = weld[gbody]
    gpweld = weld[parent][gweld]  # weld group of the parent of each geom's weld group
    planeish = np.isin(types, (_PLANE, _HFIELD))
    filterparent = not (int(model.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT))
    mujoco_mode = mode == "mujoco"
    # parent-child weld groups, neither the world: w_a == pw_b or pw_a == w_b with both groups
    # moving, folded into one comparison of keys that never match for a world geom
    moving = gweld != 0
    key_w = np.where(moving, gweld, -2)
    key_pw = np.where(moving, gpweld, -3)
    use_parent = (filterparent or not mujoco_mode) and bool(np.isin(key_pw, key_w).any())
    use_plane = int(planeish.sum()) >= 2
    dof_ok = use_dof = use_mask = None
    cleared = np.zeros((0, 2), np.int64)
    forced = np.zeros((0, 2), np.int64)
    sig_fallback = None
    if mujoco_mode:
        dofnum = np.asarray(model.body_dofnum, dtype=np.int64)
        contype = np.asarray(model.geom_contype, dtype=np.int64)
        conaff = np.asarray(model.geom_conaffinity, dtype=np.int64)
        dof_ok = dofnum[gweld] > 0
        use_dof = not bool(dof_ok.all())
        # every pair passes the contype/conaffinity test when one bit is in every contype and conaffinity
        use_mask = int(np.bitwise_and.reduce(contype) & np.bitwise_and.reduce(conaff)) == 0
        excl = np.asarray(model.exclude_signature, dtype=np.int64)
        if len(excl) and nbody > _SIGNATURE_BODIES:  # signatures ambiguous: compare them per block
            sig_fallback = np.sort(excl)
        elif len(excl):
            lo, hi = excl >> 16, excl & 0xFFFF  # the signature of body pair (lo, hi), lo <= hi
            ok = (lo >= 0) & (lo < hi) & (hi < nbody)
            cleared = _body_pair_geoms(gbody, nbody, lo[ok], hi[ok])
        ex = np.stack([np.asarray(model.pair_geom1, dtype=np.int64),
                       np.asarray(model.pair_geom2, dtype=np.int64)], axis=1).reshape(-1, 2)
        ex = np.stack([ex.min(axis=1), ex.max(axis=1)], axis=1)
        forced = ex[~(planeish[ex[:, 0]] & planeish[ex[:, 1]]) & (ex[:, 0] != ex[:, 1])]
    cleared = cleared[np.argsort(cleared[:, 0], kind="stable")]
    forced = forced[np.argsort(forced[:, 0], kind="stable")]

    index = np.arange(ngeom, dtype=np.int64)
    rows = max(1, _CHUNK // ngeom)
    blocks: list[tuple[int, int, np.ndarray, np.ndarray]] = []
    total = 0
    for r0 in range(0, ngeom - 1, rows):
        r1, c0 = min(r0 + rows, ngeom - 1), r0 + 1
        R, C = slice(r0, r1), slice(c0, ngeom)
        keep = gweld[R, None] != gweld[None, C]
        nr = r1 - r0
        keep[:, :nr] &= np.tri(nr, nr, 0, dtype=bool).T  # column c0 + j > row r0 + i  <=>  j >= i
        if use_plane and planeish[R].any():
            keep &= ~(planeish[R, None] & planeish[None, C])
        if use_parent:
            keep &= ~((key_w[R, None] == key_pw[None, C]) | (key_pw[R, None] == key_w[None, C]))
        if mujoco_mode:
            if use_dof:
                keep &= dof_ok[R, None] | dof_ok[None, C]
            if sig_fallback is not None:
                b1, b2 = gbody[R, None], gbody[None, C]
                keep &= ~np.isin((np.minimum(b1, b2) << 16) + np.maximum(b1, b2), sig_fallback)
            if use_mask:
                keep &= (((contype[R, None] & conaff[None, C]) != 0)
                         | ((contype[None, C] & conaff[R, None]) != 0))
            for sparse, value in ((cleared, False), (forced, True)):
                lo, hi = np.searchsorted(sparse[:, 0], [r0, r1])
                if hi > lo:
                    keep[sparse[lo:hi, 0] - r0, sparse[lo:hi, 1] - c0] = value
        count = np.count_nonzero(keep, axis=1)
        blocks.append((r0, c0, keep, count))
        total += int(count.sum())
    out = np.empty((total, 2), np.int64)
    at = 0
    for r0, c0, keep, count in blocks:
        n = int(count.sum())
        out[at:at + n, 0] = np.repeat(index[r0:r0 + len(count)], count)
        out[at:at + n, 1] = np.broadcast_to(index[c0:], keep.shape)[keep]
        at += n
    return out


def _drop_overlapping_world_children(model: Any, pair_ids: np.ndarray, geoms: Sequence[GeomInfo],
                                     tolerances: Tolerances) -> np.ndarray:
    """``pairs="all"``: drop world-vs-child pairs that are in contact in *every* configuration.

    A body whose parent is the world is literally a parent-child pair with every
    world geom, but dropping all of those would also drop the floor vs a free
    body or a wall vs a slider. A pair is dropped only when it is adjacent by
    design: the child attaches by rotational joints only (hinge/ball) that share
    one anchor, and that anchor lies in BOTH geoms (rigorous point-in-solid test
    at ``qpos0``). The anchor is fixed in both frames under such joints, so the
    pair overlaps for every joint value (Reacher's ``root`` vs ``link0``, a robot
    base vs its first link): planners' "always in collision" entries.

    Work per scene: O(G) to find the world children with such joints (none: nothing
    more, no pass over the pairs), then per such child the point tests of its geoms
    and of the world geoms; the pairs are read only when some pair is to be dropped.
    """
    if not len(pair_ids):
        return pair_ids
    nbody = int(model.nbody)
    weld = np.asarray(model.body_weldid, dtype=np.int64)
    gweld = weld[np.asarray(model.geom_bodyid, dtype=np.int64)]
    world_child = (gweld != 0) & (weld[np.asarray(model.body_parentid, dtype=np.int64)][gweld] == 0)
    jnt_body = np.asarray(model.jnt_bodyid, dtype=np.int64)
    rotational = np.isin(np.asarray(model.jnt_type), (int(mujoco.mjtJoint.mjJNT_HINGE),
                                                       int(mujoco.mjtJoint.mjJNT_BALL)))
    njnt = np.bincount(jnt_body, minlength=nbody)
    nrot = np.bincount(jnt_body[rotational], minlength=nbody)
    groups = np.unique(gweld[world_child])
    groups = groups[(njnt[groups] > 0) & (nrot[groups] == njnt[groups])]  # rotational joints only
    if not groups.size or not (gweld == 0).any():
        return pair_ids
    from monitor.geometry.distance import point_in_shape  # pure geometry; no import cycle

    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    shaped = np.array([g.shape is not None for g in geoms], dtype=bool)
    world_geoms = np.flatnonzero((gweld == 0) & shaped)

    def inside(g: int, p: np.ndarray) -> bool:
        b = geoms[g].body_id
        X = (data.xmat[b].reshape(3, 3).copy(), data.xpos[b].copy())
        return point_in_shape(geoms[g].shape, X, p, 0.0, tolerances=tolerances)

    drop: list[tuple[int, int]] = []
    for w in groups.tolist():
        pts = [np.array(data.xanchor[j]) for j in np.flatnonzero(jnt_body == w)]
        if not all(np.array_equal(q, pts[0]) for q in pts):
            continue
        kids = [g for g in np.flatnonzero((gweld == w) & shaped).tolist() if inside(g, pts[0])]
        if kids:
            walls = [g for g in world_geoms.tolist() if inside(g, pts[0])]
            drop += [(min(s, c), max(s, c)) for s in walls for c in kids]
    if not drop:
        return pair_ids
    G = max(len(geoms), 1)
    gone = np.array([a * G + b for a, b in drop], dtype=np.int64)
    return pair_ids[~np.isin(pair_ids[:, 0] * G + pair_ids[:, 1], gone)]


__all__ = ["Scene", "GeomInfo", "model_hash", "FLAT_MESH_THICKNESS", "SYNC_FIELDS"]
