"""Issue 12 prototype (NOT part of the package): a sort-and-sweep broad phase on the swept AABBs.

The current cull (``monitor.certify.kernels.window_kernel`` stage 0) visits every one of the P
selected pairs. This prototype produces the candidate pairs whose per-geom swept AABBs (the SAME
boxes as stage 0: the union over the T sub-ranges of the swept spheres' boxes) are within the
threshold on all three axes, by sorting the geoms on their box's x minimum and sweeping, and then
applies the scene's pair policy per produced pair, so no n(n-1)/2 list is visited or stored.

Policy representation (``pairs="all"``, :func:`monitor.scene._filter_pairs` mode "all" and
``_drop_overlapping_world_children``): per geom its weld group ``gweld`` (G,), the weld group of
its body's parent ``gwparent`` (G,), a plane/hfield flag ``planeish`` (G,), plus a CSR list of the
dropped world-child pairs (``exc_ptr`` (G + 1,), ``exc_idx`` sorted partners > the row's geom).
A pair (a < b) is kept iff not both planeish, weld groups differ, not both weld 0, not a
parent-child pair of two non-world weld groups, and (a, b) is not in the exception list.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from monitor.certify.kernels import WP_ABS, WP_REL, WP_SCALE_PAD, WP_T0, WP_T1, _norm3, sphere_gap
from monitor.motion.kernel import _bounds_core, bounds_workspace


@njit(cache=True)
def swept_boxes(gp, mp, prm, T):
    """Per-geom swept spheres and their AABBs over T sub-ranges: stage 0's geom loop, same expressions.

    Returns:
        lo, hi (G, 3) m (-inf/inf: unbounded), sc (T, G, 3) m, sr (T, G) m, pad (m).
    """
    t0, t1 = prm[WP_T0], prm[WP_T1]
    rel_pad, abs_pad = prm[WP_REL], prm[WP_ABS]
    nbody = mp.body_parent.shape[0]
    G = gp.kind.shape[0]
    pos = np.empty((T, nbody, 3))
    rot = np.empty((T, nbody, 3, 3))
    trans = np.empty((T, nbody))
    ang = np.empty((T, nbody))
    step = (t1 - t0) / T
    need_all = np.ones(nbody, np.int64)
    ws = bounds_workspace(mp)
    for t in range(T):
        ta = t * step + t0
        tb = t1 if t == T - 1 else (t + 1) * step + t0
        _bounds_core(mp, ta, tb, need_all, pos[t], rot[t], trans[t], ang[t], ws)
    mag = 0.0
    for t in range(T):
        for b in range(nbody):
            for r in range(3):
                mag = max(mag, abs(pos[t, b, r]))
    mag += 1.0
    pad = rel_pad * mag + abs_pad + prm[WP_SCALE_PAD] * mag
    grow_f = 1.0 + 8.0 * rel_pad
    sc = np.empty((T, G, 3))
    sr = np.empty((T, G))
    lo = np.empty((G, 3))
    hi = np.empty((G, 3))
    for g in range(G):
        b = gp.body[g]
        rad = gp.brad[g]
        if gp.kind[g] < 0 or not rad < np.inf:
            for t in range(T):
                sr[t, g] = np.inf
                for r in range(3):
                    sc[t, g, r] = 0.0
            for r in range(3):
                lo[g, r] = -np.inf
                hi[g, r] = np.inf
            continue
        cg = gp.bcenter[g]
        ref = mp.ref_points[b]
        lever = _norm3(cg[0] - ref[0], cg[1] - ref[1], cg[2] - ref[2]) + rad
        for r in range(3):
            lo[g, r] = np.inf
            hi[g, r] = -np.inf
        for t in range(T):
            R = rot[t, b]
            rr = rad + (trans[t, b] + 2.0 * math.sin(0.5 * min(ang[t, b], math.pi)) * lever) * grow_f
            if not rr >= 0.0:
                rr = np.inf
            sr[t, g] = rr
            for r in range(3):
                x = R[r, 0] * cg[0] + R[r, 1] * cg[1] + R[r, 2] * cg[2] + pos[t, b, r]
                sc[t, g, r] = x
                if not x - rr >= lo[g, r]:
                    lo[g, r] = x - rr
                if not x + rr <= hi[g, r]:
                    hi[g, r] = x + rr
        for r in range(3):
            if not (lo[g, r] == lo[g, r] and hi[g, r] == hi[g, r]):
                lo[g, r] = -np.inf
                hi[g, r] = np.inf
    return lo, hi, sc, sr, pad


@njit(cache=True)
def _policy_all(a, b, planeish, gweld, gwparent, exc_ptr, exc_idx):
    """``pairs="all"`` rule for geoms a != b (see the module docstring)."""
    if a > b:
        a, b = b, a
    if planeish[a] != 0 and planeish[b] != 0:
        return False
    w1, w2 = gweld[a], gweld[b]
    if w1 == w2 or (w1 == 0 and w2 == 0):
        return False
    if w1 != 0 and w2 != 0 and (w1 == gwparent[b] or w2 == gwparent[a]):
        return False
    lo_i, hi_i = exc_ptr[a], exc_ptr[a + 1]
    if hi_i > lo_i:      # binary search in the sorted exception row
        k = np.searchsorted(exc_idx[lo_i:hi_i], b)
        if k < hi_i - lo_i and exc_idx[lo_i + k] == b:
            return False
    return True


@njit(cache=True)
def sweep_pairs(lo, hi, thr, planeish, gweld, gwparent, exc_ptr, exc_idx):
    """Pairs (a < b) allowed by the policy whose boxes are within ``thr`` on every axis.

    A pair is left out only when some axis separation ``max(lo_b - hi_a, lo_a - hi_b) > thr``.
    Unbounded geoms (any infinite bound) are paired with every other geom.

    Returns:
        (K, 2) int64, rows sorted lexicographically (the order of ``Scene.pair_ids``).
    """
    G = lo.shape[0]
    nb = 0
    bounded = np.empty(G, np.int64)
    unb = np.empty(G, np.int64)
    nu = 0
    for g in range(G):
        if lo[g, 0] > -np.inf and hi[g, 0] < np.inf and lo[g, 1] > -np.inf and hi[g, 1] < np.inf \
                and lo[g, 2] > -np.inf and hi[g, 2] < np.inf:
            bounded[nb] = g
            nb += 1
        else:
            unb[nu] = g
            nu += 1
    bounded = bounded[:nb]
    key = np.empty(nb)
    for i in range(nb):
        key[i] = lo[bounded[i], 0]
    order = bounded[np.argsort(key)]
    out = np.empty((4 * G + 16, 2), np.int64)
    K = 0
    for i in range(nb):
        a = order[i]
        xa = hi[a, 0] + thr
        for j in range(i + 1, nb):
            b = order[j]
            if lo[b, 0] > xa:
                break            # sorted on lo_x: every later geom is further along x
            if lo[b, 1] - hi[a, 1] > thr or lo[a, 1] - hi[b, 1] > thr:
                continue
            if lo[b, 2] - hi[a, 2] > thr or lo[a, 2] - hi[b, 2] > thr:
                continue
            if not _policy_all(a, b, planeish, gweld, gwparent, exc_ptr, exc_idx):
                continue
            out = _push(out, K, a, b)
            K += 1
    for u in range(nu):
        a = unb[u]
        for b in range(G):
            if b == a or (b < a and _is_unbounded(lo, hi, b)):
                continue         # each unbounded-unbounded pair once
            if not _policy_all(a, b, planeish, gweld, gwparent, exc_ptr, exc_idx):
                continue
            out = _push(out, K, a, b)
            K += 1
    out = out[:K]
    # lexicographic order (the kernel's pair order; certificates list pairs in that order)
    if K > 1:
        code = out[:, 0] * G + out[:, 1]
        out = out[np.argsort(code)]
    return out


@njit(cache=True)
def _push(out, K, a, b):
    """Row K of ``out`` := (min, max) of (a, b), doubling ``out`` when full; returns the array."""
    if K == out.shape[0]:
        o2 = np.empty((2 * out.shape[0], 2), np.int64)
        o2[:K] = out[:K]
        out = o2
    out[K, 0] = min(a, b)
    out[K, 1] = max(a, b)
    return out


@njit(cache=True)
def _is_unbounded(lo, hi, g):
    for r in range(3):
        if not (lo[g, r] > -np.inf and hi[g, r] < np.inf):
            return True
    return False


@njit(cache=True)
def proto_cull(gp, mp, prm, T, margin, planeish, gweld, gwparent, exc_ptr, exc_idx):
    """Boxes, sweep, policy, then the current per-pair decision on the produced pairs only.

    The threshold: stage 0 culls on the AABB alone when ``sep - pad - 1e-12 scale > margin``
    (scale >= 1: the pair's largest box coordinate); with the scene-wide largest finite
    coordinate ``smax`` and a further 1e-9 relative slack, a pair the sweep leaves out has an
    axis separation > margin + pad + 1e-12 smax, so stage 0 would cull it too.

    Returns:
        pairs (K, 2) produced, survive (K,) 1 where the sphere test keeps the pair
        (static-static, half-space and special kinds are not decided here: 1).
    """
    lo, hi, sc, sr, pad = swept_boxes(gp, mp, prm, T)
    smax = 1.0
    for g in range(lo.shape[0]):
        for r in range(3):
            if lo[g, r] > -np.inf:
                smax = max(smax, abs(lo[g, r]))
            if hi[g, r] < np.inf:
                smax = max(smax, abs(hi[g, r]))
    thr = (margin + pad + 1e-12 * smax) * (1.0 + 1e-9) + 1e-12
    pairs = sweep_pairs(lo, hi, thr, planeish, gweld, gwparent, exc_ptr, exc_idx)
    survive = np.ones(pairs.shape[0], np.int64)
    for k in range(pairs.shape[0]):
        ga, gb = pairs[k, 0], pairs[k, 1]
        if gp.kind[ga] >= 0 and gp.kind[gb] >= 0:
            if sphere_gap(sc, sr, ga, gb, pad) > margin:
                survive[k] = 0
    return pairs, survive


@njit(cache=True)
def all_sphere_gaps(sc, sr, pairs, pad):
    """Sphere gap of every listed pair (the oracle of the soundness check)."""
    out = np.empty(pairs.shape[0])
    for k in range(pairs.shape[0]):
        out[k] = sphere_gap(sc, sr, pairs[k, 0], pairs[k, 1], pad)
    return out


def policy_arrays(model, scene):
    """The per-geom policy arrays of ``pairs="all"`` and the CSR of its dropped world-child pairs.

    The exceptions are recovered here as (rule pairs) minus ``scene.pair_ids`` (an O(n^2)
    set difference: a Scene would store them directly from ``_drop_overlapping_world_children``).
    """
    G = int(model.ngeom)
    weld = np.asarray(model.body_weldid, np.int64)
    parent = np.asarray(model.body_parentid, np.int64)
    gbody = np.asarray(model.geom_bodyid, np.int64)
    types = np.asarray(model.geom_type, np.int64)
    planeish = np.isin(types, (0, 1)).astype(np.int64)   # mjGEOM_PLANE, mjGEOM_HFIELD
    gweld = weld[gbody]
    gwparent = weld[parent[gweld]]   # weld group of the parent of the geom's weld group
    exc_ptr = np.zeros(G + 1, np.int64)
    exc_idx = np.zeros(0, np.int64)
    return planeish, gweld, gwparent, exc_ptr, exc_idx


@njit(cache=True)
def _min_culled_gap(sc, sr, pairs, pad, margin, kind):
    """Smallest sphere gap > margin among the listed pairs of two bounded kinds (inf if none)."""
    best = np.inf
    for k in range(pairs.shape[0]):
        ga, gb = pairs[k, 0], pairs[k, 1]
        if kind[ga] >= 0 and kind[gb] >= 0:
            g = sphere_gap(sc, sr, ga, gb, pad)
            if g > margin and g < best:
                best = g
    return best


@njit(cache=True)
def proto_best(gp, mp, prm, T, margin, planeish, gweld, gwparent, exc_ptr, exc_idx):
    """``info[WI_BEST]`` without visiting every pair: the smallest culled sphere gap of the window.

    1. sweep at the cull threshold: best1 = the smallest culled gap among the produced pairs;
    2. while best1 is inf (nothing culled nearby: sparse scenes), sweep again with the
       threshold doubled, from the largest box extent, until a culled gap appears (or the
       threshold is infinite: every pair);
    3. a last sweep at best1 + pad + 1e-12 smax (1e-9 relative slack): a pair it leaves out has
       an axis separation beyond that, so its sphere gap (>= its AABB separation - pad -
       1e-12 scale) exceeds best1; the minimum over the produced pairs is the exact minimum.

    Returns:
        (best (m), number of sweeps).
    """
    lo, hi, sc, sr, pad = swept_boxes(gp, mp, prm, T)
    smax = 1.0
    ext = 0.0
    for g in range(lo.shape[0]):
        for r in range(3):
            if lo[g, r] > -np.inf and hi[g, r] < np.inf:
                smax = max(smax, abs(lo[g, r]), abs(hi[g, r]))
                ext = max(ext, hi[g, r] - lo[g, r])
    slack = 1e-12 * smax
    thr = (margin + pad + slack) * (1.0 + 1e-9) + 1e-12
    pairs = sweep_pairs(lo, hi, thr, planeish, gweld, gwparent, exc_ptr, exc_idx)
    best = _min_culled_gap(sc, sr, pairs, pad, margin, gp.kind)
    sweeps = 1
    thr = max(thr, ext)
    while best == np.inf and thr < np.inf:
        thr = 2.0 * thr if thr > 0.0 else 1.0
        if thr > 1e300:
            thr = np.inf
        pairs = sweep_pairs(lo, hi, thr, planeish, gweld, gwparent, exc_ptr, exc_idx)
        best = _min_culled_gap(sc, sr, pairs, pad, margin, gp.kind)
        sweeps += 1
    if best < np.inf:
        thr = (best + pad + slack) * (1.0 + 1e-9) + 1e-12
        pairs = sweep_pairs(lo, hi, thr, planeish, gweld, gwparent, exc_ptr, exc_idx)
        best = _min_culled_gap(sc, sr, pairs, pad, margin, gp.kind)
        sweeps += 1
    return best, sweeps
