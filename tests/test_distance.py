"""Tests of monitor.geometry.distance against independent oracles.

Oracles: closed forms evaluated in extended precision (np.longdouble) from the
*actual* float64 poses (sphere-sphere, sphere-box, box-box axis aligned,
segment-segment, point-polytope depth, plane-vertex), LP feasibility with scipy
HiGHS on the H-representations (overlap sign), SLSQP (point / hull distance,
loose tolerance), and constructed near-touching configurations whose distance
is known exactly by construction. Every random case is seeded.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog, minimize
from scipy.spatial.transform import Rotation

from monitor.errors import InvalidInputError
from monitor.geometry.distance import (
    DistanceResult,
    point_in_shape,
    sample_surface,
    shape_distance,
    shape_distance_batch,
)
from monitor.geometry.polytope import (
    box_polytope,
    capsule_shape,
    cylinder_polytope,
    halfspace_shape,
    polytope_from_points,
    sphere_shape,
)
from monitor.geometry.shapes import ConvexShape
from monitor.tolerances import DEFAULT

LD = np.longdouble
I3 = np.eye(3)


def rand_rot(rng) -> np.ndarray:
    return Rotation.random(random_state=rng).as_matrix()


def rand_offset(rng) -> np.ndarray:
    """Pose translations spread from 0 to 1e4 m (log-uniform magnitude)."""
    mag = 10.0 ** rng.uniform(-1, 4)
    return rng.normal(size=3) / np.sqrt(3) * mag


def world_ld(shape_points, R, p):
    """Posed points in long double from the float64 pose (the exact image up to ~1e-19 rel)."""
    return np.asarray(shape_points, LD) @ np.asarray(R, LD).T + np.asarray(p, LD)


def check_bounds(res: DistanceResult, truth: float, *, width: float | None = None, est_tol: float = 1e-9):
    assert np.isfinite(res.lower) and np.isfinite(res.upper)
    assert res.lower <= truth <= res.upper, (res, truth)
    assert res.lower <= res.distance <= res.upper
    if width is not None:
        assert res.upper - res.lower <= width, (res, truth)
    assert abs(res.distance - truth) <= est_tol + 1e-9 * abs(truth), (res.distance, truth)


# ---------------------------------------------------------------------------- closed forms


def test_sphere_sphere_closed_form():
    rng = np.random.default_rng(1)
    for _ in range(300):
        scale = 10.0 ** rng.uniform(-3, 0)
        r1, r2 = rng.uniform(0.1, 1.0, 2) * scale
        sa = sphere_shape(r1, rng.normal(size=3) * scale)
        sb = sphere_shape(r2, rng.normal(size=3) * scale)
        Ra, Rb = rand_rot(rng), rand_rot(rng)
        pa = rand_offset(rng)
        pb = pa + rng.normal(size=3) * 3 * scale
        ca, cb = world_ld(sa.points, Ra, pa)[0], world_ld(sb.points, Rb, pb)[0]
        truth = float(np.sqrt(((ca - cb) ** 2).sum()) - LD(r1) - LD(r2))
        res = shape_distance(sa, (Ra, pa), sb, (Rb, pb))
        check_bounds(res, truth, width=1e-11)
        if truth > 0:
            # witnesses on the surfaces at the reported distance
            assert abs(np.linalg.norm(res.p_a - res.p_b) - truth) < 1e-9


def _box_sd_ld(q, h):
    """Signed distance (long double) from box-frame points q (n, 3) to the box |x_i| <= h_i."""
    d = np.abs(q) - np.asarray(h, LD)
    outside = np.sqrt((np.maximum(d, 0) ** 2).sum(axis=-1))
    inside = np.minimum(d.max(axis=-1), 0)
    return outside + inside


def test_sphere_box_closed_form():
    rng = np.random.default_rng(2)
    for _ in range(300):
        scale = 10.0 ** rng.uniform(-3, 0)
        h = rng.uniform(0.1, 1.0, 3) * scale
        r = rng.uniform(0.05, 0.5) * scale
        box, sph = box_polytope(h), sphere_shape(r)
        Rb, Rs = rand_rot(rng), rand_rot(rng)
        pb = rand_offset(rng)
        ps = pb + rng.normal(size=3) * scale
        c = world_ld(sph.points, Rs, ps)
        q = (c - np.asarray(pb, LD)) @ np.asarray(Rb, LD)  # R^T (c - p)
        truth = float(_box_sd_ld(q, h)[0] - LD(r))
        res = shape_distance(sph, (Rs, ps), box, (Rb, pb))
        check_bounds(res, truth, width=None if truth < -r else 1e-11)
        if truth < 0:
            assert res.upper < 0


def test_box_box_axis_aligned_closed_form():
    rng = np.random.default_rng(3)
    for i in range(300):
        scale = 10.0 ** rng.uniform(-3, 0)
        ha, hb = rng.uniform(0.1, 1.0, 3) * scale, rng.uniform(0.1, 1.0, 3) * scale
        R = rand_rot(rng)
        c = rng.uniform(-1.5, 1.5, 3) * (ha + hb)
        if i % 3 == 0:
            # near touching along one axis: gap in [-1e-9, 1e-9] * scale
            ax = rng.integers(3)
            c[ax] = np.sign(c[ax]) * (ha[ax] + hb[ax] + rng.uniform(-1, 1) * 1e-9 * scale)
        pa = rand_offset(rng)
        pb = pa + R @ c
        cl = (np.asarray(pb, LD) - np.asarray(pa, LD)) @ np.asarray(R, LD)
        g = np.abs(cl) - np.asarray(ha + hb, LD)
        truth = float(np.sqrt((np.maximum(g, 0) ** 2).sum()) if g.max() > 0 else g.max())
        res = shape_distance(box_polytope(ha), (R, pa), box_polytope(hb), (R, pb))
        check_bounds(res, truth, width=1e-11 if truth >= 0 else None)
        if truth < -1e-10 * scale:
            assert res.upper < 0
            assert res.upper - res.lower <= 1e-9 * abs(truth) + 1e-11  # EPA: exact depth
        if truth > 1e-11:  # above the absolute pad (1e-12 per side)
            assert res.lower > 0


def test_box_slab_overlap_depth_is_tight():
    """Two boxes overlapping in a slab of width 0.1 along x: depth exactly 0.1, and the LP
    certificate (a ball in both) reaches it."""
    rng = np.random.default_rng(16)
    A, B = box_polytope([0.5, 0.5, 0.5]), box_polytope([0.5, 0.3, 0.2])
    for _ in range(20):
        R, p = rand_rot(rng), rand_offset(rng)
        off = np.array([0.9, rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1)])
        res = shape_distance(A, (R, p), B, (R, p + R @ off), tight_overlap=True)
        check_bounds(res, -0.1)
        assert res.upper < -0.1 + 1e-9
        fast = shape_distance(A, (R, p), B, (R, p + R @ off))
        check_bounds(fast, -0.1)
        assert fast.upper < 0


def _seg_seg_ld(p0, p1, q0, q1):
    """Segment-segment distance (long double) by enumerating the critical candidates."""
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    best = None

    def pt_seg(x, a, b):
        e = b - a
        t = np.clip(((x - a) * e).sum() / (e * e).sum(), 0, 1)
        return np.sqrt(((a + t * e - x) ** 2).sum())

    for x, a, b in ((p0, q0, q1), (p1, q0, q1), (q0, p0, p1), (q1, p0, p1)):
        v = pt_seg(x, a, b)
        best = v if best is None else min(best, v)
    A = np.array([[(d1 * d1).sum(), -(d1 * d2).sum()], [-(d1 * d2).sum(), (d2 * d2).sum()]], LD)
    rhs = np.array([-(d1 * r).sum(), (d2 * r).sum()], LD)
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    if det > 1e-12 * A[0, 0] * A[1, 1]:
        s = (rhs[0] * A[1, 1] - A[0, 1] * rhs[1]) / det
        t = (A[0, 0] * rhs[1] - A[1, 0] * rhs[0]) / det
        if 0 <= s <= 1 and 0 <= t <= 1:
            best = min(best, np.sqrt(((p0 + s * d1 - q0 - t * d2) ** 2).sum()))
    return best


def test_capsule_capsule_segment_closed_form():
    rng = np.random.default_rng(4)
    for i in range(300):
        scale = 10.0 ** rng.uniform(-3, 0)
        ca = capsule_shape(rng.uniform(0.01, 0.2) * scale, rng.uniform(0.0, 1.0) * scale)
        cb = capsule_shape(rng.uniform(0.01, 0.2) * scale, rng.uniform(0.0, 1.0) * scale)
        Ra, Rb = rand_rot(rng), rand_rot(rng)
        pa = rand_offset(rng)
        pb = pa + rng.normal(size=3) * scale
        if i % 4 == 0:
            # parallel axes
            Rb = Ra.copy()
        A = world_ld(ca.points, Ra, pa)
        B = world_ld(cb.points, Rb, pb)
        truth = float(_seg_seg_ld(A[0], A[1], B[0], B[1]) - LD(ca.radius) - LD(cb.radius))
        res = shape_distance(ca, (Ra, pa), cb, (Rb, pb))
        core = truth + ca.radius + cb.radius
        check_bounds(res, truth, width=1e-11 if core > 1e-6 * scale else None)


def test_intersecting_segments_and_coincident_points():
    rng = np.random.default_rng(5)
    for _ in range(100):
        ca = capsule_shape(0.1, 0.5)
        cb = capsule_shape(0.05, 0.3)
        Ra, Rb = rand_rot(rng), rand_rot(rng)
        pa = rand_offset(rng)
        # B's axis passes through a point of A's axis (cores intersect): depth = ra + rb
        s = rng.uniform(-0.5, 0.5)
        pb = pa + Ra @ np.array([0, 0, s]) + Rb @ np.array([0, 0, rng.uniform(-0.3, 0.3)])
        res = shape_distance(ca, (Ra, pa), cb, (Rb, pb))
        assert res.upper < 0
        assert res.lower <= -0.15 + 1e-9 and res.upper >= -0.15 - 1e-9  # core distance ~0 up to rounding
    s1, s2 = sphere_shape(0.2), sphere_shape(0.3)
    p = np.array([1e4, -3.0, 2.5])
    res = shape_distance(s1, (I3, p), s2, (rand_rot(rng), p))
    check_bounds(res, -0.5, width=1e-9)
    # zero-length capsule equals a sphere
    res = shape_distance(capsule_shape(0.2, 0.0), (I3, np.zeros(3)), s2, (I3, np.array([1.0, 0, 0])))
    check_bounds(res, 0.5, width=1e-11)


# ---------------------------------------------------------------------------- polytopes


def rand_hull(rng, scale=1.0, n=None):
    n = rng.integers(4, 30) if n is None else n
    return polytope_from_points(rng.normal(size=(n, 3)) * scale)


def test_sphere_in_random_hull_depth_closed_form():
    """Point core inside a hull: depth = min face distance (normals are unit)."""
    rng = np.random.default_rng(6)
    for _ in range(150):
        hull = rand_hull(rng)
        R, p = rand_rot(rng), rand_offset(rng)
        lam = rng.dirichlet(np.ones(len(hull.points)))
        c_body = lam @ hull.points
        r = rng.uniform(0.0, 0.1)
        sph = sphere_shape(r) if r > 0 else ConvexShape("sphere", np.zeros((1, 3)), 0.0)
        c_w = R @ c_body + p
        cl = world_ld(c_body[None], R, p)[0]
        q = (cl - np.asarray(p, LD)) @ np.asarray(R, LD)
        depth = (np.asarray(hull.offsets, LD) - np.asarray(hull.normals, LD) @ q).min()
        truth = float(-depth - LD(r))
        res = shape_distance(sph, (I3, c_w), hull, (R, p))
        check_bounds(res, truth, est_tol=1e-9)
        if depth > 1e-9:
            assert res.upper < -r


def _qp_distance(NA, bA, NB, bB):
    """Euclidean distance between two H-polytopes by SLSQP (approximate oracle)."""
    x0 = np.zeros(6)
    cons = [{"type": "ineq", "fun": lambda z: bA - NA @ z[:3], "jac": lambda z: -np.c_[NA, 0 * NA]},
            {"type": "ineq", "fun": lambda z: bB - NB @ z[3:], "jac": lambda z: -np.c_[0 * NB, NB]}]
    res = minimize(lambda z: ((z[:3] - z[3:]) ** 2).sum(), x0,
                   jac=lambda z: np.r_[2 * (z[:3] - z[3:]), -2 * (z[:3] - z[3:])],
                   constraints=cons, method="SLSQP", options={"ftol": 1e-16, "maxiter": 500})
    return float(np.sqrt(max(res.fun, 0.0)))


def _lp_overlap_slack(NA, bA, NB, bB):
    """max s with a point x inside both polytopes at slack s (LP oracle; <0: disjoint)."""
    A = np.r_[np.c_[NA, np.ones(len(NA))], np.c_[NB, np.ones(len(NB))]]
    res = linprog(np.r_[0, 0, 0, -1.0], A_ub=A, b_ub=np.r_[bA, bB],
                  bounds=[(None, None)] * 3 + [(-10.0, None)], method="highs")
    assert res.status == 0
    return -res.fun


def _sat_penetration_depth(A: ConvexShape, Ra, B: ConvexShape, Rb, d) -> float:
    """Penetration depth of two overlapping polytopes by the separating-axis theorem
    (numpy, long double): min over face normals and edge x edge axes of the overlap."""
    VA = np.asarray(A.points, LD) @ np.asarray(Ra, LD).T
    VB = np.asarray(B.points, LD) @ np.asarray(Rb, LD).T + np.asarray(d, LD)
    eA = A.points[A.edges[:, 1]] - A.points[A.edges[:, 0]]
    eB = B.points[B.edges[:, 1]] - B.points[B.edges[:, 0]]
    axes = [A.normals @ Ra.T, B.normals @ Rb.T,
            np.cross((eA @ Ra.T)[:, None, :], (eB @ Rb.T)[None, :, :]).reshape(-1, 3)]
    n = np.concatenate(axes)
    n = n[np.linalg.norm(n, axis=1) > 1e-9]
    n = np.asarray(n / np.linalg.norm(n, axis=1)[:, None], LD)
    pa_, pb_ = VA @ n.T, VB @ n.T
    over = np.minimum(pa_.max(axis=0) - pb_.min(axis=0), pb_.max(axis=0) - pa_.min(axis=0))
    return float(over.min())


def test_random_hulls_overlap_sign_vs_lp_and_distance_vs_qp():
    rng = np.random.default_rng(7)
    n_over = n_sep = 0
    for i in range(300):
        A, B = rand_hull(rng), rand_hull(rng)
        Ra, Rb = rand_rot(rng), rand_rot(rng)
        pa = rand_offset(rng)
        pb = pa + rng.normal(size=3) * 1.5
        NA = A.normals @ Ra.T
        bA = (NA @ (A.points @ Ra.T + pa).T).max(axis=1)
        NB = B.normals @ Rb.T
        bB = (NB @ (B.points @ Rb.T + pb).T).max(axis=1)
        # shift the LP oracle to A's frame for accuracy
        bA0, bB0 = bA - NA @ pa, bB - NB @ pa
        slack = _lp_overlap_slack(NA, bA0, NB, bB0)
        res = shape_distance(A, (Ra, pa), B, (Rb, pb), tight_overlap=i % 2 == 0)
        assert res.lower <= res.distance <= res.upper
        if slack > 1e-7:
            n_over += 1
            assert res.upper < 0, (i, slack, res)
            if i % 2 == 0:
                assert res.upper <= -slack + 1e-9  # the LP ball of radius slack is in both
            # EPA certifies the penetration depth from both sides; the oracle is the
            # separating-axis theorem over face normals and edge x edge directions
            pd = _sat_penetration_depth(A, Ra, B, Rb, pb - pa)
            assert res.lower <= -pd + 1e-12 and -pd - 1e-12 <= res.upper, (i, pd, res)
            assert res.upper - res.lower <= 1e-9 * abs(res.lower) + 1e-11, (i, res)
        elif slack < -1e-7:
            n_sep += 1
            assert res.lower > 0, (i, slack, res)
            assert res.upper - res.lower < 1e-11
            if i % 3 == 0:
                qp = _qp_distance(NA, bA0, NB, bB0)
                assert abs(qp - res.distance) < 1e-6, (i, qp, res)
    assert n_over > 50 and n_sep > 50


def _touching_pair(rng, delta):
    """Hull A and a hull B whose lowest vertex sits ``delta`` beyond A's face centroid.

    B lies in {n . x >= b + delta} (n, b: the face plane), and its vertex
    q + delta n projects into the face, so the distance is exactly delta for
    delta > 0; for small delta < 0 the penetration depth is exactly -delta
    (the vertex is -delta deep, nearest to that face; moving B by -delta along n
    separates).
    """
    while True:
        A = rand_hull(rng, n=rng.integers(8, 30))
        k = rng.integers(len(A.faces))
        f = A.faces[k]
        if len(f) >= 3:
            break
    n = A.normals[k]
    q = A.points[f].mean(axis=0)
    u = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    v0 = q + delta * n
    m = rng.integers(4, 20)
    up = rng.uniform(0.1, 1.0, m)
    lat = rng.normal(size=(m, 2)) * 0.5
    P = v0 + up[:, None] * n + lat[:, :1] * u + lat[:, 1:] * w
    B = polytope_from_points(np.r_[v0[None], P])
    return A, B


@pytest.mark.parametrize("delta", [1e-9, 1e-6, -1e-9, -1e-6])
def test_constructed_near_touching_hulls_with_large_offsets(delta):
    rng = np.random.default_rng(8 + int(delta > 0))
    for _ in range(60):
        A, B = _touching_pair(rng, delta)
        R, p = rand_rot(rng), rand_offset(rng)
        # both bodies in the same pose: the relative geometry is the constructed one
        res = shape_distance(A, (R, p), B, (R, p))
        slop = 1e-14  # construction rounding (coordinates ~1)
        assert res.lower <= delta + slop and delta - slop <= res.upper, (res, delta)
        if delta > 0:
            assert res.lower > 0
            assert res.upper - res.lower < 3e-12
        else:
            assert res.upper < 0, res
        res2 = shape_distance(B, (R, p), A, (R, p))
        assert res2.lower <= delta + slop and delta - slop <= res2.upper
        assert (res2.upper < 0) == (delta < 0) and (res2.lower > 0) == (delta > 0)


def test_capsule_piercing_box_mujoco_regression():
    """Reference section 6: MuJoCo 4.0.0 reports a positive distance; we must not."""
    mujoco = pytest.importorskip("mujoco")
    xml = """
    <mujoco><worldbody>
      <body name="plate"><geom name="plate" type="box" size="0.27 0.21 0.01"/></body>
      <body name="cap" pos="0.05 0.03 0"><freejoint/>
        <geom name="cap" type="capsule" size="0.022 0.15"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    g_plate, g_cap = m.geom("plate").id, m.geom("cap").id
    mj = mujoco.mj_geomDistance(m, d, g_plate, g_cap, 1.0, None)
    X_plate = (d.geom_xmat[g_plate].reshape(3, 3).copy(), d.geom_xpos[g_plate].copy())
    X_cap = (d.geom_xmat[g_cap].reshape(3, 3).copy(), d.geom_xpos[g_cap].copy())
    res = shape_distance(box_polytope([0.27, 0.21, 0.01]), X_plate, capsule_shape(0.022, 0.15), X_cap)
    assert mj > 0  # the known MuJoCo defect (if fixed upstream, this documents the change)
    # exact penetration depth: lift the capsule by 0.15 + 0.01 + 0.022
    check_bounds(res, -0.182, est_tol=1e-9)
    assert res.upper <= -0.032 + 1e-9  # at least: the segment point at the mid plane is 0.01 deep
    assert res.upper <= -0.182 + 1e-9  # EPA certifies the full depth


def _qp_segment_hull(S, N, b):
    """Segment (2, 3) to H-polytope distance by SLSQP (approximate oracle)."""
    e = S[1] - S[0]
    cons = [{"type": "ineq", "fun": lambda z: b - N @ z[1:], "jac": lambda z: np.c_[0 * b, -N]}]
    qp = minimize(lambda z: ((S[0] + z[0] * e - z[1:]) ** 2).sum(), np.r_[0.5, S.mean(axis=0)],
                  method="SLSQP", bounds=[(0, 1)] + [(None, None)] * 3, constraints=cons,
                  options={"ftol": 1e-16, "maxiter": 500})
    return float(np.sqrt(max(qp.fun, 0.0)))


def test_capsule_vs_random_hull_lp_depth_and_qp_distance():
    """Segment core vs hull: LP oracle max_t depth (overlap), SLSQP distance (apart)."""
    rng = np.random.default_rng(13)
    n_over = n_sep = 0
    for i in range(200):
        H = rand_hull(rng)
        cap = capsule_shape(rng.uniform(0.01, 0.2), rng.uniform(0.0, 1.5))
        Rh, Rc = rand_rot(rng), rand_rot(rng)
        ph = rand_offset(rng)
        pc = ph + rng.normal(size=3) * 1.2
        N = H.normals @ Rh.T
        b = (N @ (H.points @ Rh.T).T).max(axis=1)  # frame shifted by ph
        S = cap.points @ Rc.T + (pc - ph)
        e = S[1] - S[0]
        # LP: max s  s.t.  N (s0 + t e) + s <= b,  t in [0, 1]
        A = np.c_[N @ e, np.ones(len(N))]
        lp = linprog([0, -1.0], A_ub=A, b_ub=b - N @ S[0], bounds=[(0, 1), (-10, None)], method="highs")
        depth = -lp.fun
        res = shape_distance(cap, (Rc, pc), H, (Rh, ph))
        res2 = shape_distance(H, (Rh, ph), cap, (Rc, pc))
        # argument order changes the relative frame (rounding pads) and the GJK path: the
        # lower bound (exact SAT) agrees; the uppers may come from different certificates
        assert abs(res.lower - res2.lower) < 1e-10
        r = cap.radius
        if depth > 1e-7:
            n_over += 1
            assert res.upper <= -depth - r + 1e-9, (i, depth, res)
            assert res2.upper <= -depth - r + 1e-9, (i, depth, res2)
            assert res.lower <= -depth - r + 1e-9
        elif depth < -1e-7:
            n_sep += 1
            assert res.lower > -r
            assert res.upper - res.lower < 1e-11
            if i % 2 == 0:
                qp = _qp_segment_hull(S, N, b)
                assert abs(qp - r - res.distance) < 1e-6, (i, qp, res)
    assert n_over > 30 and n_sep > 30


@pytest.mark.parametrize("make", [lambda: sphere_shape(0.3, np.array([0.1, -0.2, 0.05])),
                                  lambda: capsule_shape(0.1, 0.4), lambda: box_polytope([0.2, 0.3, 0.1]),
                                  lambda: cylinder_polytope(0.1, 0.2, 8)])
def test_sample_surface_points_are_on_the_boundary(make):
    rng = np.random.default_rng(14)
    shape = make()
    pts = sample_surface(shape, 200, rng)
    assert pts.shape == (200, 3)
    R, p = rand_rot(rng), rand_offset(rng)
    pt = ConvexShape("sphere", np.zeros((1, 3)), 0.0)
    for q in pts:
        res = shape_distance(pt, (I3, R @ q + p), shape, (R, p))
        assert res.lower <= 1e-9 and res.upper >= -1e-9
        assert abs(res.distance) < 1e-9
    with pytest.raises(InvalidInputError):
        sample_surface(halfspace_shape(), 3, rng)


# ---------------------------------------------------------------------------- half-spaces, degenerate


def test_halfspace_pairs_closed_form():
    rng = np.random.default_rng(9)
    plane = halfspace_shape()
    for _ in range(100):
        Rh, ph = rand_rot(rng), rand_offset(rng)
        n_w = np.asarray(Rh, LD) @ np.array([0, 0, 1], LD)
        for shape in (box_polytope(rng.uniform(0.1, 1, 3)), capsule_shape(0.1, 0.4), sphere_shape(0.3),
                      rand_hull(rng)):
            Rc = rand_rot(rng)
            pc = ph + rng.normal(size=3)
            V = world_ld(shape.points, Rc, pc)
            truth = float(((V - np.asarray(ph, LD)) @ n_w).min() - LD(shape.radius))
            res = shape_distance(plane, (Rh, ph), shape, (Rc, pc))
            check_bounds(res, truth, width=1e-10)
            res2 = shape_distance(shape, (Rc, pc), plane, (Rh, ph))
            check_bounds(res2, truth, width=1e-10)
    flip = (np.diag([1.0, -1.0, -1.0]), np.array([0, 0, 2.0]))
    res = shape_distance(plane, (I3, np.zeros(3)), plane, flip)
    check_bounds(res, 2.0, width=1e-10)
    res = shape_distance(plane, (I3, np.zeros(3)), plane, (rand_rot(rng), np.zeros(3)))
    assert res.upper == -np.inf


def test_flat_polytope_bounds():
    sq = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    flat = ConvexShape("polytope", sq, 0.0, np.array([[0, 1], [1, 2], [2, 3], [0, 3]]),
                       (np.array([0, 1, 2, 3]), np.array([3, 2, 1, 0])),
                       np.array([[0, 0, 1.0], [0, 0, -1.0]]), np.zeros(2))
    box = box_polytope([0.5, 0.5, 0.5])
    res = shape_distance(flat, (I3, np.zeros(3)), box, (I3, np.array([0.2, 0.1, 0.8])))
    check_bounds(res, 0.3, width=1e-11)
    res = shape_distance(flat, (I3, np.zeros(3)), box, (I3, np.array([0.2, 0.1, 0.3])))
    check_bounds(res, -0.2)
    # two coplanar flat squares crossing: zero-measure overlap, distance 0
    res = shape_distance(flat, (I3, np.zeros(3)), flat, (I3, np.array([0.5, 0.5, 0.0])))
    check_bounds(res, 0.0)


def test_degenerate_polytope_cores_vs_sphere_closed_form():
    """Flat rectangles / segments / single points given as 'polytope' cores with duplicate
    vertices and no H-rep: the vertex-hull distance must still be bounded correctly."""
    rng = np.random.default_rng(15)
    for i in range(150):
        a, b = rng.uniform(0.01, 1.0, 2) * [1.0, [1.0, 0.0, 0.0][i % 3]]
        rect = np.array([[-a, -b, 0], [a, -b, 0], [a, b, 0], [-a, b, 0]], float)
        pts = np.r_[rect, rect[rng.integers(0, 4, 3)]]  # duplicates
        if i % 3 == 2:
            pts = np.zeros((3, 3))  # a point, three times
        flat = ConvexShape("polytope", pts)
        R, p = rand_rot(rng), rand_offset(rng)
        r = rng.uniform(0.0, 0.3)
        q_body = rng.normal(size=3) * 0.7
        if i % 5 == 0:
            q_body[2] = rng.uniform(-1, 1) * 1e-9  # (nearly) in the plane
        sph = ConvexShape("sphere", np.zeros((1, 3)), r)
        c = R @ q_body + p
        q = (np.asarray(c, LD) - np.asarray(p, LD)) @ np.asarray(R, LD)
        hx, hy = (LD(a), LD(b)) if i % 3 != 2 else (LD(0), LD(0))
        d = np.array([max(abs(q[0]) - hx, 0), max(abs(q[1]) - hy, 0), abs(q[2])], LD)
        truth = float(np.sqrt((d**2).sum()) - LD(r))
        res = shape_distance(sph, (I3, c), flat, (R, p))
        check_bounds(res, truth)
        res2 = shape_distance(flat, (R, p), sph, (I3, c))
        check_bounds(res2, truth)


def test_incomplete_face_normals_never_overstate_depth():
    """A box whose H-rep lacks its +z face: measured with the remaining normals a point
    just under the top would look 0.5 m deep. The per-shape completeness check must
    stop such a depth certificate (upper stays >= the true signed distance)."""
    full = box_polytope([0.5, 0.5, 0.5])
    keep = np.flatnonzero(full.normals[:, 2] < 0.5)
    broken = ConvexShape("polytope", full.points, 0.0, full.edges, full.faces,
                         full.normals[keep], full.offsets[keep])
    for r, shape in ((0.0, ConvexShape("sphere", np.zeros((1, 3)), 0.0)), (0.05, sphere_shape(0.05)),
                     (0.02, capsule_shape(0.02, 0.1))):
        R = I3 if shape.kind != "capsule" else Rotation.from_euler("y", 90, degrees=True).as_matrix()
        c = np.array([0.1, -0.2, 0.49])
        truth = -0.01 - r
        res = shape_distance(shape, (R, c), broken, (I3, np.zeros(3)))
        check_bounds(res, truth, est_tol=1.0)  # the estimate may be off: the H-rep is wrong
        good = shape_distance(shape, (R, c), full, (I3, np.zeros(3)))
        check_bounds(good, truth)
        assert good.upper < -r


def test_epa_certificate_rejects_a_tetrahedron_that_misses_the_origin():
    """The EPA kernel verifies its own surface: a start that does not enclose the origin
    (or is degenerate) yields no certificate; a valid one never exceeds the exact depth."""
    from monitor.geometry import _gjk

    box = box_polytope([0.5, 0.5, 0.5])
    VA = np.ascontiguousarray(box.points + [0.9, 0.0, 0.0])  # overlap 0.1 along x
    VB = np.ascontiguousarray(box.points)
    lb = np.full(1, -np.inf)
    dirs = np.array([[1, 1, 1], [-1, -1, 1], [-1, 1, -1], [1, -1, -1]], float)
    W = np.array([VA[np.argmax(VA @ d)] - VB[np.argmin(VB @ d)] for d in dirs])
    r = _gjk._epa_inradius(VA, VB, W, 1e-15, DEFAULT.rel_pad, 32, lb)
    assert 0.1 - 1e-9 < r <= 0.1  # exact penetration depth from inside
    assert -0.1 - 1e-12 <= lb[0] <= -0.1 + 1e-9
    off = W + np.array([5.0, 0.0, 0.0])  # origin outside the tetrahedron
    assert _gjk._epa_inradius(VA, VB, off, 1e-15, DEFAULT.rel_pad, 32, lb) == 0.0
    flat = W.copy()
    flat[:, 2] = 0.0  # degenerate start
    assert _gjk._epa_inradius(VA, VB, flat, 1e-15, DEFAULT.rel_pad, 32, lb) == 0.0


def test_tiny_scales():
    rng = np.random.default_rng(10)
    for _ in range(50):
        h = rng.uniform(0.1, 1, 3) * 1e-3
        R, p = rand_rot(rng), rand_offset(rng)
        gap = rng.uniform(1e-9, 1e-6)
        pb = p + R @ np.array([2 * h[0] + gap, 0, 0])
        res = shape_distance(box_polytope(h), (R, p), box_polytope(h), (R, pb))
        cl = (np.asarray(pb, LD) - np.asarray(p, LD)) @ np.asarray(R, LD)
        g = np.abs(cl) - 2 * np.asarray(h, LD)
        truth = float(np.sqrt((np.maximum(g, 0) ** 2).sum()))
        check_bounds(res, truth, width=1e-11)


# ---------------------------------------------------------------------------- batch, helpers, errors


def test_batch_matches_single_calls():
    rng = np.random.default_rng(11)
    A, B = rand_hull(rng), capsule_shape(0.1, 0.3)
    T = 40
    Ra = np.stack([rand_rot(rng) for _ in range(T)])
    pa = rng.normal(size=(T, 3)) * 0.5
    Rb, pb = I3, np.zeros(3)
    lo, up = shape_distance_batch(A, (Ra, pa), B, (Rb, pb))
    assert lo.shape == up.shape == (T,)
    for t in range(T):
        r = shape_distance(A, (Ra[t], pa[t]), B, (Rb, pb))
        assert lo[t] == r.lower
        assert (up[t] < 0) == (r.upper < 0)
        assert up[t] >= r.upper if r.upper < 0 else up[t] == r.upper


def test_batch_box_box_closed_form():
    rng = np.random.default_rng(12)
    T = 200
    ha, hb = np.array([0.3, 0.2, 0.1]), np.array([0.1, 0.4, 0.2])
    R = rand_rot(rng)
    c = rng.uniform(-1, 1, (T, 3)) * (ha + hb) * 1.3
    pa = np.full(3, 5e3)
    pb = pa + c @ R.T
    lo, up = shape_distance_batch(box_polytope(ha), (R, pa), box_polytope(hb),
                                  (np.broadcast_to(R, (T, 3, 3)), pb))
    cl = (np.asarray(pb, LD) - np.asarray(pa, LD)) @ np.asarray(R, LD)
    g = np.abs(cl) - np.asarray(ha + hb, LD)
    truth = np.where(g.max(axis=1) > 0, np.sqrt((np.maximum(g, 0) ** 2).sum(axis=1)), g.max(axis=1))
    truth = truth.astype(float)
    assert np.all(lo <= truth) and np.all(truth <= up)
    assert np.all(up[truth < -1e-9] < 0) and np.all(lo[truth > 1e-9] > 0)


def test_point_in_shape():
    box = box_polytope([0.5, 0.5, 0.5])
    R = Rotation.from_euler("z", 30, degrees=True).as_matrix()
    p = np.array([1.0, 2.0, 3.0])
    assert point_in_shape(box, (R, p), p + R @ np.array([0.4, 0.4, 0.4]))
    assert not point_in_shape(box, (R, p), p + R @ np.array([0.6, 0.0, 0.0]))
    assert point_in_shape(box, (R, p), p + R @ np.array([0.6, 0.0, 0.0]), pad=0.11)


def test_invalid_inputs_raise():
    box = box_polytope([0.5, 0.5, 0.5])
    with pytest.raises(InvalidInputError, match="X_b"):
        shape_distance(box, (I3, np.zeros(3)), box, (I3, np.array([np.nan, 0, 0])))
    with pytest.raises(InvalidInputError, match="X_a"):
        shape_distance(box, (np.eye(2), np.zeros(3)), box, (I3, np.zeros(3)))
    with pytest.raises(InvalidInputError, match="shape_b"):
        shape_distance(box, (I3, np.zeros(3)), "box", (I3, np.zeros(3)))
    with pytest.raises(InvalidInputError, match="X_b"):
        shape_distance(box, (I3, np.zeros(3)), box, (I3, np.array([1e155, 1e155, 0.0])))
    with pytest.raises(InvalidInputError, match="X_a"):
        shape_distance(box, (I3 * 1e3, np.zeros(3)), box, (I3, np.zeros(3)))
    with pytest.raises(InvalidInputError, match="shape_a.points"):
        shape_distance(ConvexShape("sphere", np.full((1, 3), 1e300), 1.0), (I3, np.zeros(3)),
                       box, (I3, np.zeros(3)))
    with pytest.raises(InvalidInputError, match="Xs_a"):
        shape_distance_batch(box, (I3, np.array([[1e300, 0, 0]])), box, (I3, np.zeros(3)))
    bad = ConvexShape("cone", np.zeros((1, 3)))  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="kind"):
        shape_distance(bad, (I3, np.zeros(3)), box, (I3, np.zeros(3)))
