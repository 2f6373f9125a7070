"""Reproduction of Schröcker & Weber section 7.1: fixed octagon vs moving octagon, degree-8 motion.

How the motion was built (monitor.bench.paper_bezier.paper71_motion): a degree-4 quaternion
polynomial Q(t) (5 Bernstein control quaternions, tilting the octagon by up to ~50 degrees
about varying axes) gives the rotation R(t) = M(Q)/|Q|^2, exactly rigid, numerator and
denominator of degree 8; the translation is a degree-8 rational Bézier curve with the
same weights |Q|^2 (centre sweeping 5.2 m across the fixed octagon along an arc ~0.56 m
above its plane). The two variants differ by a constant translation (``shift``), as in
the paper. Both octagons are regular with circumradius 1 (diameter 2); epsilon = 0.02
(1 % of the diameter, as in the paper). The mass distribution is the moving octagon's
8 vertices plus two points 0.25*diameter above/below its barycentre (the paper uses one
point over the barycentre; two keep the barycentre in the plane).

The paper reports 173 polygon-vs-fat-polygon tests at max depth 8 (clear) and 9 tests
at depth 8 (colliding; its Listing 1 returns at the first interval, depth first, while
we subdivide breadth first and report all intervals, so our colliding count is larger;
``first_interval_bezier`` replays Listing 1's order for the comparison).
"""

import numpy as np
from scipy.optimize import linprog

from monitor.bench.paper_bezier import octagon, paper71_motion
from monitor.certify.bezier import check_bezier, first_interval_bezier
from monitor.certify.toleranced import fixed_features, moving_features

EPS = 0.02
CLEAR_SHIFT, COLLIDE_SHIFT = 0.06, 0.8


def _intersect(A, B):
    """Exact-ish LP oracle: do conv(A) and conv(B) share a point?"""
    na, nb = len(A), len(B)
    Aeq = np.zeros((5, na + nb))
    Aeq[:3, :na] = A.T
    Aeq[:3, na:] = -B.T
    Aeq[3, :na] = 1
    Aeq[4, na:] = 1
    res = linprog(np.zeros(na + nb), A_eq=Aeq, b_eq=[0, 0, 0, 1, 1], bounds=(0, None), method="highs")
    return res.status == 0


def _run(shift):
    P, F = octagon(1.0), octagon(1.0)
    curve = paper71_motion(shift)
    res = check_bezier(curve, [moving_features(polygon=P)], [fixed_features(polygon=F)], epsilon=EPS)
    return curve, P, F, res


def test_motion_is_rational_degree_8_on_se3():
    curve = paper71_motion(0.0)
    assert curve.degree == 8 and (curve.H[:, 0] > 0).all()
    L, _ = curve.evaluate(np.linspace(0, 1, 50))
    assert np.allclose(np.einsum("tji,tjk->tik", L, L), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(L), 1.0, atol=1e-12)


def test_clear_variant_is_certified_with_paper_like_counts():
    curve, P, F, res = _run(CLEAR_SHIFT)
    tests, depth = int(res.unit_tests[0]), int(res.max_depth[0])
    print(f"\n[7.1 clear] polygon-vs-fat-polygon tests: {tests} (paper 173), max depth {depth} "
          f"(paper 8), elementary rows {int(res.row_tests[0])}")
    assert res.intervals[0] == []
    assert 20 <= tests <= 600
    assert 5 <= depth <= 11
    # oracle: the certified motion really is clear at 2001 sampled times (min gap ~0.04 m)
    L, p = curve.evaluate(np.linspace(0, 1, 2001))
    assert not any(_intersect(P @ L[i].T + p[i], F) for i in range(0, 2001, 5))


def test_colliding_variant_is_not_certified_and_interval_contains_a_collision():
    curve, P, F, res = _run(COLLIDE_SHIFT)
    tests, depth = int(res.unit_tests[0]), int(res.max_depth[0])
    print(f"\n[7.1 colliding] polygon-vs-fat-polygon tests: {tests} (paper 9, depth first), "
          f"max depth {depth} (paper 8), intervals {res.intervals[0]}")
    assert res.intervals[0], "colliding motion must not be certified"
    assert 5 <= depth <= 12
    assert tests <= 2000
    hits = []
    for a, b in res.intervals[0]:
        ts = np.linspace(a, b, 41)
        L, p = curve.evaluate(ts)
        hits += [t for t, Li, pi in zip(ts, L, p) if _intersect(P @ Li.T + pi, F)]
    assert hits, "no sampled collision inside the reported intervals"
    # and outside the intervals (with epsilon slack) there is none at sampled times
    ts = np.linspace(0, 1, 801)
    L, p = curve.evaluate(ts)
    for t, Li, pi in zip(ts, L, p):
        if _intersect(P @ Li.T + pi, F):
            assert any(a <= t <= b for a, b in res.intervals[0]), t


def test_depth_first_order_like_listing_1():
    """Listing 1 order (depth first, return at the first interval): comparable to the paper's counts."""
    P, F = octagon(1.0), octagon(1.0)
    mf, ff = moving_features(polygon=P), fixed_features(polygon=F)
    iv, tests, depth = first_interval_bezier(paper71_motion(CLEAR_SHIFT), mf, ff, epsilon=EPS)
    _, _, _, res = _run(CLEAR_SHIFT)
    assert iv is None and tests == int(res.unit_tests[0])   # a certified run visits the same nodes
    iv, tests, depth = first_interval_bezier(paper71_motion(COLLIDE_SHIFT), mf, ff, epsilon=EPS)
    print(f"\n[7.1 colliding, depth first] tests until the first interval: {tests} (paper 9), depth {depth}, "
          f"interval {iv}")
    _, _, _, res = _run(COLLIDE_SHIFT)
    assert iv is not None and any(a <= iv[0] and iv[1] <= b for a, b in res.intervals[0])
    assert tests <= int(res.unit_tests[0])


def test_paper72_small_n_never_certifies_a_colliding_square_pair():
    """Section 7.2 setting at n = 2 (16 square pairs, global and per-square masses)."""
    from monitor.bench.paper_bezier import paper72_case

    for mass in ("global", "per-square"):
        case = paper72_case(2, "collision", mass)
        res = check_bezier(case["curve"], case["moving"], case["fixed"], case["pairs"],
                           epsilon=case["epsilon"])
        ts = np.linspace(0, 1, 101)
        L, p = case["curve"].evaluate(ts)
        hits = 0
        for k, (i, j) in enumerate(case["pairs"]):
            A, B = case["moving"][i].verts, case["fixed"][j].verts
            if any(_intersect(A @ L[t].T + p[t], B) for t in range(0, 101, 2)):
                hits += 1
                assert res.intervals[k], (mass, i, j)
        assert hits >= 1
