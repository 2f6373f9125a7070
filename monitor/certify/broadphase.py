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
"""

from __future__ import annotations

import numpy as np

from monitor.geometry.shapes import ConvexShape
from monitor.motion.base import Trajectory, chord
from monitor.tolerances import DEFAULT, Tolerances


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
    t0, t1 = float(window[0]), float(window[1])
    edges = np.linspace(t0, t1, nsub + 1)
    ta, tb = edges[:-1], edges[1:]
    mids = 0.5 * (ta + tb)
    pos, rot = traj.body_poses(mids)
    mb = traj.motion_bounds(ta, tb)
    ref = np.asarray(traj.ref_points, float)
    ch = chord(mb.angle)                                     # (T, nbody)
    grow_f = 1.0 + 8 * tolerances.rel_pad
    out = np.full(P, -np.inf)
    sa_l, sb_l, ba_l, bb_l, half = [], [], [], [], []
    for i in range(P):
        sa, sb = shapes_a[i], shapes_b[i]
        ba, bb = int(bodies_a[i]), int(bodies_b[i])
        if sa.kind == "halfspace":
            sa, sb, ba, bb = sb, sa, bb, ba
        sa_l.append(sa)
        sb_l.append(sb)
        ba_l.append(ba)
        bb_l.append(bb)
        half.append(sb.kind == "halfspace")
    ba_a, bb_a, half = np.array(ba_l), np.array(bb_l), np.array(half)
    both_half = np.array([x.kind == "halfspace" for x in sa_l])

    def spheres(shapes, bodies):
        c = np.array([s.bounding_center if s.kind != "halfspace" else np.zeros(3) for s in shapes])
        rad = np.array([s.bounding_radius if s.kind != "halfspace" else 0.0 for s in shapes])
        cw = np.einsum("tpij,pj->tpi", rot[:, bodies], c) + pos[:, bodies]      # (T, P, 3)
        lever = np.linalg.norm(c - ref[bodies], axis=1) + rad                    # (P,)
        grow = mb.trans[:, bodies] + ch[:, bodies] * lever[None, :]
        return cw, rad[None, :] + grow * grow_f

    ca, ra = spheres(sa_l, ba_a)
    mag = np.abs(pos).max() + 1.0
    pad = tolerances.pad(mag) + tolerances.scale_pad * mag
    gap = np.full((len(mids), P), -np.inf)
    ns = ~half
    if ns.any():
        cb, rb = spheres(sb_l, bb_a)
        gap[:, ns] = (np.linalg.norm(ca - cb, axis=2) - ra - rb)[:, ns]
    for i in np.nonzero(half & ~both_half)[0]:
        bb, sb = bb_a[i], sb_l[i]
        if (mb.trans[:, bb] > 0).any() or (mb.angle[:, bb] > 0).any():
            continue  # moving plane: no cull (planes are world-fixed in practice)
        n_W = rot[:, bb] @ sb.normals[0]
        pt_W = rot[:, bb] @ sb.points[0] + pos[:, bb]
        gap[:, i] = np.einsum("ti,ti->t", ca[:, i] - pt_W, n_W) - ra[:, i]
    out = gap.min(axis=0) - pad
    out[both_half] = -np.inf
    return out


__all__ = ["swept_sphere_gaps"]
