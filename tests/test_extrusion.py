"""Unit tests of the extrusion checker: S-bounds, semantics, half-spaces, n-ary search, errors, budget.

Oracles: dense sampling of closed-form box overlaps (S-bounds), exact static
distances (``monitor.geometry.distance``), closed forms for planes and spheres,
and the engine's toleranced checker for the cross-check.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from monitor.certify.common import Budget
from monitor.certify.extrusion import (
    TranslatingBody,
    TranslatingPair,
    check_many,
    check_pairs,
    compare_pairwise_nary,
    kappa,
    search_many,
)
from monitor.certify.extrusion_null import min_norm
from monitor.certify.extrusion_sbounds import pair_sbounds, root_operator
from monitor.errors import InvalidInputError, UnsupportedGeometryError
from monitor.geometry.distance import shape_distance
from monitor.geometry.polytope import box_polytope, capsule_shape, halfspace_shape, sphere_shape
from monitor.tolerances import DEFAULT

I3 = np.eye(3)


def _lin(p0, v, t0=0.0, t1=1.0):
    p0 = np.asarray(p0, float)
    return np.array([t0, t1]), np.stack([p0, p0 + np.asarray(v, float) * (t1 - t0)])


def _pair(sa, pa, va, sb, pb, vb, t1=1.0, Ra=I3, Rb=I3, name=("a", "b")):
    ta, oa = _lin(pa, va, 0.0, t1)
    tb, ob = _lin(pb, vb, 0.0, t1)
    return TranslatingPair(sa, Ra, ta, oa, sb, Rb, tb, ob, name)


BOX = box_polytope(np.array([0.5, 0.5, 0.5]))


# ----------------------------------------------------------------------------- S-bounds (App. B)

def test_kappa_is_the_papers_threshold():
    assert [kappa(d) for d in range(4)] == [6, 8, 10, 12]


def test_root_operator_against_dense_sampling():
    rng = np.random.default_rng(3)
    ts = np.linspace(0.0, 2.0, 4001)
    n_overlapping = 0
    for _ in range(300):
        a_lo = rng.uniform(-1, 1, 3)
        a_hi = a_lo + rng.uniform(0.1, 1.5, 3)
        b_lo = rng.uniform(-1, 1, 3)
        b_hi = b_lo + rng.uniform(0.1, 1.5, 3)
        u, v = rng.normal(size=3) * 2, rng.normal(size=3) * 2
        if rng.random() < 0.3:
            v[rng.integers(3)] = u[rng.integers(3)]  # some equal velocity components
        rb = root_operator(a_lo, a_hi, u, b_lo, b_hi, v, 0.0, 2.0)
        A_lo, A_hi = a_lo + ts[:, None] * u, a_hi + ts[:, None] * u
        B_lo, B_hi = b_lo + ts[:, None] * v, b_hi + ts[:, None] * v
        I_lo, I_hi = np.maximum(A_lo, B_lo), np.minimum(A_hi, B_hi)
        hit = np.all(I_lo <= I_hi, axis=1)
        if rb is None:
            assert not hit.any()
            continue
        if not hit.any():  # the closed form is exact for boxes: only a sub-step overlap is missed
            assert rb.t_hi - rb.t_lo <= 2 * (ts[1] - ts[0])
        else:
            n_overlapping += 1
            # every overlapping instant is inside [t_l, t_h], which is tight to the sampling step
            assert ts[hit].min() >= rb.t_lo - 1e-12 and ts[hit].max() <= rb.t_hi + 1e-12
            assert ts[hit].min() - rb.t_lo <= 2 * (ts[1] - ts[0]) + 1e-9
            assert rb.t_hi - ts[hit].max() <= 2 * (ts[1] - ts[0]) + 1e-9
            # tightened boxes (moving with u and v) still contain every overlap box
            k = np.flatnonzero(hit)
            assert np.all(I_lo[k] >= rb.a_lo + ts[k, None] * u - 1e-12)
            assert np.all(I_hi[k] <= rb.a_hi + ts[k, None] * u + 1e-12)
            assert np.all(I_lo[k] >= rb.b_lo + ts[k, None] * v - 1e-12)
            assert np.all(I_hi[k] <= rb.b_hi + ts[k, None] * v + 1e-12)
    assert n_overlapping > 50


def test_pair_sbounds_never_drop_a_colliding_leaf():
    rng = np.random.default_rng(11)
    for _ in range(40):
        nA, nB = 5, 4
        shapes_a = tuple(box_polytope(rng.uniform(0.1, 0.4, 3)).transformed(I3, rng.uniform(-1, 1, 3))
                         for _ in range(nA))
        shapes_b = tuple(box_polytope(rng.uniform(0.1, 0.4, 3)).transformed(I3, rng.uniform(-1, 1, 3))
                         for _ in range(nB))
        va, vb = rng.normal(size=3), rng.normal(size=3)
        pa, pb = rng.normal(size=3) * 2, rng.normal(size=3) * 2
        a_lo = np.array([s.points.min(0) + pa for s in shapes_a])
        a_hi = np.array([s.points.max(0) + pa for s in shapes_a])
        b_lo = np.array([s.points.min(0) + pb for s in shapes_b])
        b_hi = np.array([s.points.max(0) + pb for s in shapes_b])
        sb = pair_sbounds(a_lo, a_hi, np.ones(nA, bool), va, b_lo, b_hi, np.ones(nB, bool), vb, 0.0, 2.0)
        outs = check_pairs([_pair(sa, pa, va, sbb, pb, vb, t1=2.0) for sa in shapes_a for sbb in shapes_b],
                           (0.0, 2.0), clearance=False)
        for k, o in enumerate(outs):
            if o.verdict == "violation":
                i, j = divmod(k, nB)
                assert sb is not None and sb.a_alive[i] and sb.b_alive[j]
                assert sb.t_lo - 1e-12 <= o.info["earliest_time"] <= sb.t_hi + 1e-12


# ----------------------------------------------------------------------------- semantics

@pytest.mark.parametrize("offset", [0.0, 1e4])
def test_touching_is_not_a_collision_but_penetration_is(offset):
    o = np.full(3, offset)
    # face-face contact at t = 0.5: A moves +x and stops exactly at contact (end of window)
    touch = _pair(BOX, o + [-2.0, 0, 0], [2.0, 0, 0], BOX, o + [0.0, 0, 0], [0, 0, 0], t1=0.5)
    assert check_pairs([touch], (0.0, 0.5))[0].verdict == "certified"
    # edge-edge and vertex-vertex grazing in passing (exact touching mid-window)
    R = Rotation.from_euler("z", 45, degrees=True).as_matrix()
    e = 0.5 * np.sqrt(2)
    graze = _pair(BOX, o + [-3.0, e + 0.5, 0], [6.0, 0, 0], BOX, o, [0, 0, 0], Ra=R, name=("edge", "face"))
    assert check_pairs([graze], (0.0, 1.0))[0].verdict == "certified"
    corner = _pair(BOX, o + [-3.0, 1.0, 1.0], [6.0, 0, 0], BOX, o, [0, 0, 0])
    assert check_pairs([corner], (0.0, 1.0))[0].verdict == "certified"
    # a 1e-6 m deeper pass is a violation with the exact first-contact time
    hit = _pair(BOX, o + [-3.0, 1.0 - 1e-6, 0], [6.0, 0, 0], BOX, o, [0, 0, 0])
    out = check_pairs([hit], (0.0, 1.0))[0]
    assert out.verdict == "violation"
    assert out.info["earliest_time"] == pytest.approx(2.0 / 6.0, abs=1e-9)
    assert out.info["earliest_time"] <= out.witness_time


def test_margin_semantics_spheres():
    s = sphere_shape(0.5)
    at = _pair(s, [0, 0, 0], [0, 0, 0], s, [1.25, 0, 0], [0, 0, 0])  # distance 0.25 exactly
    assert check_pairs([at], (0.0, 1.0), margin=0.25)[0].verdict == "certified"
    assert check_pairs([at], (0.0, 1.0), margin=0.25 + 1e-6)[0].verdict == "violation"
    out = check_pairs([at], (0.0, 1.0), margin=0.0)[0]
    assert 0.25 - 1e-11 <= out.clearance <= 0.25


def test_margin_with_polytopes_is_exact_euclidean():
    # box corner passes a box corner diagonally: distance sqrt(2) * 0.1 at closest approach
    d = 0.1
    p = _pair(BOX, [-3.0, 1.0 + d, 0.0], [6.0, 0, 0], BOX, [0, 0, 0], [0, 0, 0])
    out = check_pairs([p], (0.0, 1.0))[0]
    assert d - 1e-11 <= out.clearance <= d
    assert check_pairs([p], (0.0, 1.0), margin=d)[0].verdict == "certified"
    assert check_pairs([p], (0.0, 1.0), margin=d + 1e-9)[0].verdict == "violation"


def test_capsule_and_sphere_first_contact_closed_form():
    cap = capsule_shape(0.2, 1.0)  # axis z, segment z in [-1, 1]
    s = sphere_shape(0.3)
    # sphere moves towards the capsule's side along -x from x = 3 at 2 m/s: contact at x = 0.5
    p = _pair(s, [3.0, 0, 0.4], [-2.0, 0, 0], cap, [0, 0, 0], [0, 0, 0], t1=2.0)
    out = check_pairs([p], (0.0, 2.0))[0]
    assert out.verdict == "violation"
    assert out.info["earliest_time"] == pytest.approx(1.25, abs=2e-9)


def test_piecewise_velocity_earliest_in_later_span():
    # A touches B at t = 1 (first span ends at contact), backs off, then hits at t = 2.5
    times = np.array([0.0, 1.0, 2.0, 3.0])
    oa = np.array([[-3.0, 0, 0], [-1.0, 0, 0], [-2.0, 0, 0], [0.0, 0, 0]])
    p = TranslatingPair(BOX, I3, times, oa, BOX, I3, np.array([0.0, 3.0]), np.zeros((2, 3)))
    out = check_pairs([p], (0.0, 3.0))[0]
    assert out.verdict == "violation"
    assert out.info["earliest_time"] == pytest.approx(2.5, abs=1e-9)
    assert out.info["span"] == [2.0, 3.0]


# ----------------------------------------------------------------------------- half-spaces

def test_box_falling_on_floor():
    floor = halfspace_shape()
    out = check_pairs([_pair(BOX, [0, 0, 2.0], [0, 0, -1.0], floor, [0, 0, 0], [0, 0, 0], t1=2.0)],
                      (0.0, 2.0))[0]
    assert out.verdict == "violation"
    assert out.info["earliest_time"] == pytest.approx(1.5, abs=1e-12)
    assert out.witness_time > 1.5
    # exactly resting on the floor (touching) is certified; 1 mm above with margin 1 mm too
    rest = _pair(BOX, [0, 0, 0.5], [1.0, 0, 0], floor, [0, 0, 0], [0, 0, 0])
    assert check_pairs([rest], (0.0, 1.0))[0].verdict == "certified"
    above = _pair(BOX, [0, 0, 0.501], [1.0, 0, 0], floor, [0, 0, 0], [0, 0, 0])
    assert check_pairs([above], (0.0, 1.0), margin=0.001)[0].verdict == "certified"
    assert check_pairs([above], (0.0, 1.0), margin=0.0011)[0].verdict == "violation"
    # tilted plane and a sphere: closed-form distance along the normal
    R = Rotation.from_euler("x", 30, degrees=True).as_matrix()
    sp = _pair(sphere_shape(0.5), [0, 0, 3.0], [0, 0, -1.0], floor, [0, 0, 0], [0, 0, 0], t1=3.0, Rb=R)
    out = check_pairs([sp], (0.0, 3.0))[0]
    n = R @ np.array([0, 0, 1.0])
    t_hit = (3.0 * n[2] - 0.5) / n[2]  # n.(c(t)) = 0.5
    assert out.info["earliest_time"] == pytest.approx(t_hit, abs=1e-9)


def test_two_planes_unsupported():
    p = _pair(halfspace_shape(), [0, 0, 0], [0, 0, 0], halfspace_shape(), [0, 0, 1], [0, 0, 0])
    with pytest.raises(UnsupportedGeometryError, match="half-spaces"):
        check_pairs([p], (0.0, 1.0))


# ----------------------------------------------------------------------------- errors and budget

def test_invalid_inputs_raise_typed_errors():
    good = _pair(BOX, [0, 0, 0], [1, 0, 0], BOX, [3, 0, 0], [0, 0, 0])
    with pytest.raises(InvalidInputError, match="window"):
        check_pairs([good], (1.0, 1.0))
    with pytest.raises(InvalidInputError, match="margin"):
        check_pairs([good], (0.0, 1.0), margin=-1.0)
    with pytest.raises(InvalidInputError, match="not the window"):
        check_pairs([good], (0.0, 2.0))
    bad_R = TranslatingPair(BOX, 2 * I3, good.times_a, good.origins_a, BOX, I3, good.times_b, good.origins_b)
    with pytest.raises(InvalidInputError, match="rotation"):
        check_pairs([bad_R], (0.0, 1.0))
    bad_t = TranslatingPair(BOX, I3, np.array([0.0, 0.5, 0.5, 1.0]), np.zeros((4, 3)), BOX, I3,
                            good.times_b, good.origins_b)
    with pytest.raises(InvalidInputError, match="increasing"):
        check_pairs([bad_t], (0.0, 1.0))
    nan = TranslatingPair(BOX, I3, good.times_a, np.full((2, 3), np.nan), BOX, I3, good.times_b,
                          good.origins_b)
    with pytest.raises(InvalidInputError, match="NaN"):
        check_pairs([nan], (0.0, 1.0))
    body = TranslatingBody("b", (BOX,), ("g",), I3, *_lin([0, 0, 0], [0, 0, 0]))
    other = TranslatingBody("c", (BOX,), ("h",), I3, *_lin([5, 0, 0], [0, 0, 0]))
    with pytest.raises(InvalidInputError, match="unknown geom"):
        check_many([body, other], [("g", "zz")], (0.0, 1.0))
    with pytest.raises(InvalidInputError, match="inside one body"):
        check_many([body, other], [("g", "g")], (0.0, 1.0))
    dup = TranslatingBody("d", (BOX,), ("g",), I3, *_lin([5, 0, 0], [0, 0, 0]))
    with pytest.raises(InvalidInputError, match="not unique"):
        check_many([body, dup], None, (0.0, 1.0))


def test_exhausted_budget_is_unresolved_never_certified():
    p = _pair(BOX, [-3.0, 0.2, 0], [6.0, 0, 0], BOX, [0, 0, 0], [0, 0, 0])
    out = check_pairs([p], (0.0, 1.0), budget=Budget(tests=0))[0]
    assert out.verdict == "unresolved"
    assert out.intervals


# ----------------------------------------------------------------------------- n-ary search (§6)

def _random_bodies(rng, n_bodies, n_geoms, spread=3.0):
    bodies = []
    for i in range(n_bodies):
        shapes = []
        for _ in range(n_geoms):
            kind = rng.random()
            c = rng.uniform(-0.6, 0.6, 3)
            if kind < 0.6:
                R = Rotation.random(random_state=rng).as_matrix()
                shapes.append(box_polytope(rng.uniform(0.05, 0.3, 3)).transformed(R, c))
            elif kind < 0.8:
                shapes.append(sphere_shape(float(rng.uniform(0.05, 0.3)), c))
            else:
                shapes.append(capsule_shape(float(rng.uniform(0.05, 0.2)), 0.2).transformed(
                    Rotation.random(random_state=rng).as_matrix(), c))
        times = np.array([0.0, 0.4, 1.0])
        p0 = rng.uniform(-spread, spread, 3)
        v = rng.normal(size=(2, 3)) * 2
        origins = np.stack([p0, p0 + 0.4 * v[0], p0 + 0.4 * v[0] + 0.6 * v[1]])
        R = Rotation.random(random_state=rng).as_matrix()
        bodies.append(TranslatingBody(f"body{i}", tuple(shapes), tuple(f"b{i}g{k}" for k in range(n_geoms)),
                                      R, times, origins))
    return bodies


def test_nary_equals_pairwise_and_respects_pair_policy():
    rng = np.random.default_rng(5)
    bodies = _random_bodies(rng, 5, 4, spread=1.2)
    res = search_many(bodies, None, (0.0, 1.0))
    assert len(res.outcomes) == 10 * 16
    pairs = []
    for (ga, gb) in res.pairs:
        ia, ka = int(ga[1]), int(ga[3])
        ib, kb = int(gb[1]), int(gb[3])
        A, B = bodies[ia], bodies[ib]
        pairs.append(TranslatingPair(A.shapes[ka], A.R, A.times, A.origins, B.shapes[kb], B.R, B.times,
                                     B.origins, (ga, gb)))
    single = check_pairs(pairs, (0.0, 1.0))
    n_viol = 0
    for a, b in zip(res.outcomes, single):
        assert a.verdict == b.verdict
        if a.verdict == "violation":
            n_viol += 1
            assert a.info["earliest_time"] == pytest.approx(b.info["earliest_time"], abs=1e-9)
        else:
            assert a.clearance == pytest.approx(b.clearance, abs=1e-9)
    assert 0 < n_viol < len(single)
    # pair policy: only the allowed pairs are reported, in request order
    allowed = [res.pairs[k] for k in range(0, len(res.pairs), 7)]
    sub = check_many(bodies, allowed, (0.0, 1.0))
    assert [o.info["geoms"] for o in sub] == [list(p) for p in allowed]
    for p, o in zip(allowed, sub):
        assert o.verdict == res.outcomes[res.pairs.index(p)].verdict


def test_divide_and_conquer_agrees_with_single_region():
    rng = np.random.default_rng(8)
    bodies = _random_bodies(rng, 3, 10, spread=0.8)  # crowded: many live leaf pairs
    a = search_many(bodies, None, (0.0, 1.0), divide=True)
    b = search_many(bodies, None, (0.0, 1.0), divide=False)
    assert a.stats["regions"] > len(a.stats["spans"])  # division happened
    for x, y in zip(a.outcomes, b.outcomes):
        assert x.verdict == y.verdict
        if x.verdict == "violation":
            assert x.info["earliest_time"] == pytest.approx(y.info["earliest_time"], abs=1e-9)


def test_full_region_proves_collision():
    # 8 x 8 deeply overlapping leaves: more live pairs than kappa(d) until regions are small
    # enough to lie strictly inside both extrusions (a full region proves the collision)
    rng = np.random.default_rng(4)
    big = box_polytope(np.array([1.0, 1.0, 1.0]))
    sa = tuple(big.transformed(I3, rng.uniform(-0.01, 0.01, 3)) for _ in range(8))
    sb = tuple(big.transformed(I3, rng.uniform(-0.01, 0.01, 3)) for _ in range(8))
    A = TranslatingBody("A", sa, tuple(f"a{k}" for k in range(8)), I3, *_lin([0, 0, 0], [0.1, 0, 0]))
    B = TranslatingBody("B", sb, tuple(f"b{k}" for k in range(8)), I3, *_lin([0.2, 0, 0], [0, 0, 0]))
    res = search_many([A, B], None, (0.0, 1.0))
    assert all(o.verdict == "violation" for o in res.outcomes)
    assert res.stats["full_region_proofs"] > 0
    assert sum(o.info["proof"] == "full region" for o in res.outcomes) > 0
    assert all(o.info["earliest_time"] == 0.0 for o in res.outcomes)


def test_compare_pairwise_nary_helper():
    rng = np.random.default_rng(9)
    bodies = _random_bodies(rng, 4, 3)
    r = compare_pairwise_nary(bodies, None, (0.0, 1.0))
    assert r["agree"] and r["pairs"] == 6 * 9
    assert set(r["verdicts"]) <= {"certified", "violation"}


# ----------------------------------------------------------------------------- witnesses

def test_violation_witness_is_a_real_overlap():
    rng = np.random.default_rng(12)
    bodies = _random_bodies(rng, 4, 3, spread=1.5)
    res = search_many(bodies, None, (0.0, 1.0))
    by_geom = {g: (b, k) for b in bodies for k, g in enumerate(b.geom_names)}
    n = 0
    for (ga, gb), o in zip(res.pairs, res.outcomes):
        if o.verdict != "violation":
            continue
        n += 1
        (A, ka), (B, kb) = by_geom[ga], by_geom[gb]

        def pose(b, t):
            return b.R, np.array([np.interp(t, b.times, b.origins[:, k]) for k in range(3)])

        d = shape_distance(A.shapes[ka], pose(A, o.witness_time), B.shapes[kb], pose(B, o.witness_time))
        assert d.upper < 0
        t_e = o.info["earliest_time"]
        if t_e > 1e-9:  # strictly before first contact the pair is apart
            d0 = shape_distance(A.shapes[ka], pose(A, t_e - 1e-7), B.shapes[kb], pose(B, t_e - 1e-7))
            assert d0.lower > -1e-12
    assert n > 0


def test_min_norm_bounds_are_rigorous_and_tight():
    rng = np.random.default_rng(2)
    for _ in range(200):
        P = rng.normal(size=(int(rng.integers(1, 60)), 3)) + rng.normal(size=3) * 3
        lo, up, lam = min_norm(P, DEFAULT)
        assert lo <= up
        assert up - lo < 1e-10
        assert np.all(lam >= 0) and lam.sum() == pytest.approx(1.0)
        # brute-force upper bound: no vertex is closer than the lower bound
        assert np.linalg.norm(P, axis=1).min() >= lo


# ----------------------------------------------------------------------------- cross-check (engine)

def _mjcf_pair(ga: str, gb: str) -> str:
    joints = "".join(f'<joint name="{{b}}{c}" type="slide" axis="{ax}"/>'
                     for c, ax in (("x", "1 0 0"), ("y", "0 1 0"), ("z", "0 0 1")))
    return ("<mujoco><option gravity='0 0 0'/><worldbody>"
            f"<body name='A'>{joints.format(b='a')}{ga}</body>"
            f"<body name='B'>{joints.format(b='b')}{gb}</body>"
            "</worldbody></mujoco>")


def _geom_xml(rng, name):
    kind = rng.choice(["box", "sphere", "capsule"])
    q = Rotation.random(random_state=rng).as_quat(scalar_first=True)
    quat = " ".join(repr(float(x)) for x in q)
    if kind == "box":
        size = " ".join(repr(float(x)) for x in rng.uniform(0.1, 0.5, 3))
    elif kind == "sphere":
        size = repr(float(rng.uniform(0.1, 0.4)))
    else:
        size = f"{float(rng.uniform(0.1, 0.3))!r} {float(rng.uniform(0.1, 0.4))!r}"
    return f"<geom name='{name}' type='{kind}' size='{size}' quat='{quat}' mass='1'/>"


def test_cross_check_against_toleranced_checker():
    """Neither checker certifies what the other proves colliding (engine, MJCF slide-joint pairs)."""
    mujoco = pytest.importorskip("mujoco")
    from monitor.certify.engine import certify
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    rng = np.random.default_rng(21)
    n_viol = n_cert = 0
    for i in range(24):
        m = mujoco.MjModel.from_xml_string(_mjcf_pair(_geom_xml(rng, "ga"), _geom_xml(rng, "gb")))
        scene = Scene.from_model(m, pairs="all")
        ga, gb = scene.geom("ga"), scene.geom("gb")
        times = np.array([0.0, 0.5, 1.0])
        qa = rng.normal(size=3) + np.cumsum(rng.normal(size=(3, 3)) * 0.8, axis=0)
        qb = np.zeros((3, 3))
        # shift B so that the swept min core distance is a chosen gap
        P = []
        for s0, s1 in ((0, 1), (1, 2)):
            for k in (s0, s1):
                A = ga.shape.points + qa[k]
                B = gb.shape.points + qb[k]
                P.append((A[:, None] - B[None]).reshape(-1, 3))
        best = min((min_norm(np.vstack(P[2 * s:2 * s + 2]), DEFAULT) + (s,) for s in range(2)),
                   key=lambda r: r[1])
        lo, up, lam, s = best
        Ps = np.vstack(P[2 * s:2 * s + 2])
        q = Ps.T @ lam
        n = q / np.linalg.norm(q)
        gap = float(rng.choice([0.05, 0.01, -0.01, -0.05]))
        rr = ga.shape.radius + gb.shape.radius
        if np.linalg.norm(q) - rr < 0.2:
            continue
        if gap < 0 and rr == 0.0:
            gap = -gap  # polytope pairs: pushing along n need not penetrate; keep a miss
        # misses: shape distance = gap; hits: cores stay apart, shapes overlap by rr / 2
        qb = qb + n * (np.linalg.norm(q) - rr - gap) if gap > 0 else qb + n * (np.linalg.norm(q) - rr * 0.5)
        plan = Plan(times, np.hstack([qa, qb]), model=m)
        ext = certify(scene, plan, method="extrusion")
        tol = certify(scene, plan, method="toleranced", epsilon=1e-3, budget=Budget(seconds=5.0))
        assert not (ext.verdict == "violation" and tol.verdict == "certified"), i
        assert not (tol.verdict == "violation" and ext.verdict == "certified"), i
        if gap > 0:
            assert ext.verdict == "certified", i
            n_cert += 1
        else:
            assert ext.verdict == "violation", i
            n_viol += 1
    assert n_viol >= 3 and n_cert >= 3


def test_check_pairs_nary_mode_equals_pairwise():
    rng = np.random.default_rng(32)
    bodies = _random_bodies(rng, 4, 3, spread=0.7)
    pairs = []
    for i, A in enumerate(bodies):
        for B in bodies[i + 1:]:
            for ka in range(3):
                for kb in range(3):
                    pairs.append(TranslatingPair(A.shapes[ka], A.R, A.times, A.origins, B.shapes[kb], B.R,
                                                 B.times, B.origins, (A.geom_names[ka], B.geom_names[kb])))
    # plus a pair whose two geoms share one motion (decided alone)
    A = bodies[0]
    pairs.append(TranslatingPair(A.shapes[0], A.R, A.times, A.origins, A.shapes[1], A.R, A.times, A.origins,
                                 (A.geom_names[0], A.geom_names[1])))
    a = check_pairs(pairs, (0.0, 1.0))
    b = check_pairs(pairs, (0.0, 1.0), nary=True)
    assert any(o.verdict == "violation" for o in a)
    for x, y in zip(a, b):
        assert x.verdict == y.verdict
        assert x.info["geoms"] == y.info["geoms"]
        if x.verdict == "violation":
            assert x.info["earliest_time"] == pytest.approx(y.info["earliest_time"], abs=1e-9)
        else:
            assert x.clearance == pytest.approx(y.clearance, abs=1e-9)


def test_sub_window_and_earliest_off():
    # motion defined on [0, 4] with breakpoints outside the window [1, 3]
    times = np.array([0.0, 0.5, 2.0, 3.5, 4.0])
    oa = np.array([[-6.0, 0, 0], [-5.0, 0, 0], [-2.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]])
    p = TranslatingPair(BOX, I3, times, oa, BOX, I3, np.array([0.0, 4.0]), np.zeros((2, 3)))
    # x_A(t) = -5 + 2 (t - 0.5) on [0.5, 3.5]: faces meet when x_A = -1, t = 2.5
    out = check_pairs([p], (1.0, 3.0))[0]
    assert out.verdict == "violation"
    assert out.info["earliest_time"] == pytest.approx(2.5, abs=1e-9)
    assert out.info["span"] == [2.0, 3.0]
    assert check_pairs([p], (1.0, 2.4))[0].verdict == "certified"
    fast = check_pairs([p], (1.0, 3.0), earliest=False)[0]
    assert fast.verdict == "violation" and fast.info["earliest_exact"] is False
    assert 2.5 <= fast.witness_time <= 3.0
    assert fast.tests < out.tests
