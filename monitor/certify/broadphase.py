"""Broad phase: swept bounding spheres from the certified motion bounds.

For a shape with bounding sphere (centre c, radius rad, body frame) and a sub-interval
[ta, tb] with midpoint m, every point p of the shape satisfies |p - c| <= rad, so by the
motion-bound contract (:mod:`monitor.motion.base`)

    |X(t) p - X(m) c| <= |X(t) p - X(m) p| + |X(m) p - X(m) c|
                      <= trans + chord(angle) |p - ref| + rad
                      <= trans + chord(angle) (|c - ref| + rad) + rad,

i.e. the shape stays in the ball of that radius about X(m) c over the sub-interval.
Two such balls (or a ball and a half-space) that are further apart than the margin on
every sub-interval prove the pair clear; the smallest gap is a certified clearance lower
bound. The gap is padded downwards by ``Tolerances.pad`` of the coordinate magnitude.

Cost: the spheres are computed once per geom (:func:`swept_geom_spheres`, one
``body_poses`` and one ``motion_bounds`` call, or one call of the compiled motion kernel
when the trajectory packs), then the gaps of all P pairs are pure
array arithmetic in blocks (:func:`sphere_pair_gaps`, O(P T) flops, no Python per pair).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from monitor.certify.common import check_active_budget
from monitor.geometry.shapes import ConvexShape
from monitor.motion.base import MotionBounds, Trajectory, chord
from monitor.tolerances import DEFAULT, Tolerances


class SweptSpheres(NamedTuple):
    """Per-geom swept bounding spheres over the sub-intervals of a window.

    Attributes:
        centres: (T, G, 3) world-frame centres (m) at the sub-interval midpoints.
        radii: (T, G) radii (m) covering the geom over each sub-interval (inf: half-space).
        pad: rounding pad (m) to subtract from any gap computed from them.
    """

    centres: np.ndarray
    radii: np.ndarray
    pad: float


def subinterval_bounds(traj: Trajectory, t0: float, t1: float,
                       n: int) -> tuple[np.ndarray, np.ndarray, MotionBounds, np.ndarray, np.ndarray]:
    """Poses at the midpoints of n equal sub-intervals of [t0, t1] and their motion bounds.

    One ``body_poses`` and one ``motion_bounds`` call (the contract of
    :mod:`monitor.motion.base`), shared by the broad phase and the engine's clearance bound.

    Returns:
        pos (n, nbody, 3) m and rot (n, nbody, 3, 3) at the midpoints, the
        :class:`~monitor.motion.base.MotionBounds`, ref_points (nbody, 3) body frame,
        and chord(angle) (n, nbody).
    """
    edges = np.linspace(t0, t1, n + 1)
    ta, tb = edges[:-1], edges[1:]
    from monitor.certify.kernels import trajectory_pack  # lazy: kernels imports numba

    mp = trajectory_pack(traj)
    if mp is not None:
        # the compiled motion kernel (same contract, checked against the trajectory's own poses),
        # so this numpy broad phase and the engine's compiled one use the same bounds
        from monitor.motion.pack import poses_and_bounds

        pos, rot, mb = poses_and_bounds(mp, ta, tb)
    else:
        pos, rot = traj.body_poses(0.5 * (ta + tb))
        mb = traj.motion_bounds(ta, tb)
    return pos, rot, mb, np.asarray(traj.ref_points, float), chord(mb.angle)


def swept_geom_spheres(traj: Trajectory, shapes: Sequence[ConvexShape], bodies: np.ndarray,
                       window: tuple[float, float], nsub: int = 8,
                       tolerances: Tolerances = DEFAULT) -> SweptSpheres:
    """Swept bounding spheres of G geoms over ``nsub`` equal sub-intervals of the window.

    One ``body_poses`` and one ``motion_bounds`` call for all geoms; the per-pair work is
    then :func:`sphere_pair_gaps` (pure array arithmetic).

    Args:
        traj: the motion.
        shapes: G shapes (body frames); half-spaces get centre 0 and radius inf.
        bodies: (G,) body index of each shape.
        window: (t0, t1) seconds.
        nsub: number of equal sub-intervals.
        tolerances: rounding pads.

    Returns:
        :class:`SweptSpheres` with centres (T, G, 3) m (world), radii (T, G) m and the
        scalar pad (m) to subtract from every gap.
    """
    bodies = np.asarray(bodies, np.int64).reshape(-1)
    G = len(bodies)
    t0, t1 = float(window[0]), float(window[1])
    pos, rot, mb, ref, ch = subinterval_bounds(traj, t0, t1, nsub)
    grow_f = 1.0 + 8 * tolerances.rel_pad
    c = np.zeros((G, 3))
    rad = np.full(G, np.inf)
    for g, s in enumerate(shapes):
        if s.kind != "halfspace":
            c[g] = s.bounding_center
            rad[g] = s.bounding_radius
    finite = np.isfinite(rad)
    cw = np.einsum("tgij,gj->tgi", rot[:, bodies], c) + pos[:, bodies]             # (T, G, 3)
    lever = np.where(finite, np.linalg.norm(c - ref[bodies], axis=1) + np.where(finite, rad, 0.0), 0.0)
    grow = mb.trans[:, bodies] + ch[:, bodies] * lever[None, :]
    radii = np.where(finite[None, :], rad[None, :] + grow * grow_f, np.inf)
    mag = np.abs(pos).max() + 1.0 if pos.size else 1.0
    pad = tolerances.pad(mag) + tolerances.scale_pad * mag
    return SweptSpheres(cw, radii, float(pad))


def sphere_pair_gaps(spheres: SweptSpheres, ia: np.ndarray, ib: np.ndarray,
                     chunk: int = 1 << 16) -> np.ndarray:
    """Certified lower bound (m) on each pair's distance: min over sub-intervals of the sphere gap.

    Args:
        spheres: from :func:`swept_geom_spheres`.
        ia, ib: (P,) indices into the spheres' geoms.
        chunk: pairs per vectorised block (bounds the temporary memory to ~chunk * T * 24 B).

    Returns:
        (P,) min_t (|c_a - c_b| - r_a - r_b) - pad; -inf for pairs with a half-space
        (infinite radius) or non-finite centres (NaN never culls).
    """
    ia = np.asarray(ia, np.int64).reshape(-1)
    ib = np.asarray(ib, np.int64).reshape(-1)
    out = np.empty(len(ia))
    C, R = spheres.centres, spheres.radii
    for s in range(0, len(ia), chunk):
        check_active_budget()  # hundreds of thousands of pairs: a certify budget bounds this
        a, b = ia[s:s + chunk], ib[s:s + chunk]
        d = np.linalg.norm(C[:, a] - C[:, b], axis=2) - R[:, a] - R[:, b]          # (T, n)
        g = d.min(axis=0) - spheres.pad
        g[~np.isfinite(d).all(axis=0)] = -np.inf
        out[s:s + chunk] = g
    return out


def swept_sphere_gaps(traj: Trajectory, shapes_a: list[ConvexShape], bodies_a: np.ndarray,
                      shapes_b: list[ConvexShape], bodies_b: np.ndarray, window: tuple[float, float],
                      nsub: int = 8, tolerances: Tolerances = DEFAULT) -> np.ndarray:
    """Certified lower bound (m) on each pair's distance over the window (may be negative).

    Args:
        traj: the motion.
        shapes_a, shapes_b: the pair's shapes (body frames); half-spaces allowed on either side
            (never both).
        bodies_a, bodies_b: (P,) body indices.
        window: (t0, t1) seconds.
        nsub: number of equal sub-intervals (one body_poses and one motion_bounds call).
        tolerances: rounding pads.

    Returns:
        (P,) lower bounds on the signed distance over the window (-inf if unknown).
    """
    P = len(shapes_a)
    if P == 0:
        return np.zeros(0)
    key: dict[tuple[int, int], int] = {}
    shapes: list[ConvexShape] = []
    bodies: list[int] = []

    def gid(s: ConvexShape, b: int) -> int:
        k = (id(s), int(b))
        if k not in key:
            key[k] = len(shapes)
            shapes.append(s)
            bodies.append(int(b))
        return key[k]

    ia = np.array([gid(s, b) for s, b in zip(shapes_a, np.asarray(bodies_a).reshape(-1))], np.int64)
    ib = np.array([gid(s, b) for s, b in zip(shapes_b, np.asarray(bodies_b).reshape(-1))], np.int64)
    sph = swept_geom_spheres(traj, shapes, np.array(bodies, np.int64), window, nsub, tolerances)
    out = sphere_pair_gaps(sph, ia, ib)
    half_a = np.array([s.kind == "halfspace" for s in shapes_a])
    half_b = np.array([s.kind == "halfspace" for s in shapes_b])
    one_half = np.nonzero(half_a ^ half_b)[0]
    if len(one_half):
        out[one_half] = halfspace_gaps(traj, sph, [shapes[j] for j in np.where(half_a, ia, ib)[one_half]],
                                       np.array(bodies)[np.where(half_a, ia, ib)[one_half]],
                                       np.where(half_a, ib, ia)[one_half], window, nsub)
    return out


def halfspace_gaps(traj: Trajectory, spheres: SweptSpheres, planes: Sequence[ConvexShape],
                   plane_bodies: np.ndarray, ball_geoms: np.ndarray, window: tuple[float, float],
                   nsub: int = 8) -> np.ndarray:
    """Certified lower bounds (m) for (half-space, geom) pairs: signed ball-to-plane gaps.

    Args:
        traj: the motion (the same one the spheres were built from).
        spheres: from :func:`swept_geom_spheres` with the same window and ``nsub``.
        planes: H half-space shapes (body frames).
        plane_bodies: (H,) their bodies.
        ball_geoms: (H,) index of the other geom of each pair into ``spheres``.
        window: (t0, t1) seconds.
        nsub: number of sub-intervals.

    Returns:
        (H,) min over sub-intervals of (signed centre-to-plane distance - radius) - pad;
        -inf for a plane on a moving body (no cull).
    """
    H = len(planes)
    out = np.full(H, -np.inf)
    if H == 0:
        return out
    pos, rot, mb, _ref, _ch = subinterval_bounds(traj, float(window[0]), float(window[1]), nsub)
    for h in range(H):
        bb, sb, g = int(plane_bodies[h]), planes[h], int(ball_geoms[h])
        if (mb.trans[:, bb] > 0).any() or (mb.angle[:, bb] > 0).any():
            continue  # moving plane: no cull (planes are world-fixed in practice)
        n_W = rot[:, bb] @ sb.normals[0]
        pt_W = rot[:, bb] @ sb.points[0] + pos[:, bb]
        gap = np.einsum("ti,ti->t", spheres.centres[:, g] - pt_W, n_W) - spheres.radii[:, g]
        v = float(gap.min()) - spheres.pad
        out[h] = v if np.isfinite(v) else -np.inf
    return out


__all__ = ["swept_sphere_gaps", "swept_geom_spheres", "sphere_pair_gaps", "halfspace_gaps", "SweptSpheres"]
