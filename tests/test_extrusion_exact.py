"""Exactness of the extrusion checker against an independent LP oracle.

>= 1000 seeded random translating cases: boxes and random hulls, constant and
piecewise-constant velocity, near misses 1e-2..1e-9, exact touching,
penetrations, offsets up to 1e4 m. The oracle below is written separately: it
rebuilds each H-representation from the *world vertices* with scipy's
ConvexHull (the checker uses the shapes' own normals), and solves one LP per
merged time span in (x, t) with absolute time.

Ground truth by construction: the minimum over the window of the core
distance is computed by least distance (NNLS) on the swept Minkowski
difference, then B's whole trajectory is shifted along the closest direction
so that the minimum becomes exactly ``gap`` (distance along a fixed direction
changes linearly; other spans cannot get closer than ``d0 - delta``).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy.optimize import linprog, minimize_scalar, nnls
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from monitor.certify.extrusion import TranslatingPair, check_pairs
from monitor.certify.extrusion_null import min_norm
from monitor.geometry.distance import shape_distance
from monitor.geometry.polytope import box_polytope, capsule_shape, polytope_from_points, sphere_shape
from monitor.tolerances import DEFAULT

ORACLE_SLACK = 2.5e-10  # oracle: collision iff max inscribed slack > this (misses are <= -5e-10)


# ----------------------------------------------------------------------------- case generation

def _random_shape(rng):
    if rng.random() < 0.5:
        return box_polytope(rng.uniform(0.1, 1.0, 3)), "box"
    pts = rng.normal(size=(int(rng.integers(6, 20)), 3)) * rng.uniform(0.2, 0.8, 3)
    return polytope_from_points(pts), "hull"


def _random_motion(rng, t0, t1, base):
    k = 1 if rng.random() < 0.5 else int(rng.integers(2, 4))
    inner = np.sort(rng.uniform(t0, t1, k - 1)) if k > 1 else np.zeros(0)
    times = np.concatenate([[t0], inner, [t1]])
    if rng.random() < 0.2:  # static body
        vel = np.zeros((k, 3))
    else:
        vel = rng.normal(size=(k, 3)) * rng.uniform(0.1, 2.0)
    origins = [base]
    for i in range(k):
        origins.append(origins[-1] + vel[i] * (times[i + 1] - times[i]))
    return times, np.array(origins)


def _world_vertices(shape, R, times, origins, t):
    o = np.array([np.interp(t, times, origins[:, k]) for k in range(3)])
    return shape.points @ R.T + o


def _merged(ta, tb):
    return np.unique(np.concatenate([ta, tb]))


def _swept_min(P):
    """(distance, closest point) from the origin to conv(P).

    Lawson-Hanson least distance by NNLS, then polished: the min-norm point of
    the affine hull of the NNLS support (least squares), kept if its weights
    stay positive (NNLS alone loses digits when the origin is near the hull).
    """
    E = np.vstack([P.T, np.ones(len(P))])
    u, _ = nnls(E, np.array([0, 0, 0, 1.0]), maxiter=2000)
    lam = u / u.sum()
    S = np.flatnonzero(lam > 1e-12)
    if 1 <= len(S) <= 4:
        Q = P[S]
        if len(S) == 1:
            w = np.ones(1)
        else:
            beta = np.linalg.lstsq((Q[1:] - Q[0]).T, -Q[0], rcond=None)[0]
            w = np.concatenate([[1 - beta.sum()], beta])
        if np.all(w >= 0):
            lam = np.zeros(len(P))
            lam[S] = w
    q = P.T @ lam
    nq = float(np.linalg.norm(q))
    if nq > 0 and float(np.min(P @ q)) / nq < nq - 1e-12:
        # NNLS support was wrong (not a KKT point): use Wolfe's method of the package
        lo, up, lam = min_norm(P, DEFAULT)
        q = P.T @ lam
        nq = float(np.linalg.norm(q))
    return nq, q, lam


def _global_min(pair):
    """Min over the window of dist(core A(t), core B(t)), the closest CSO point, and its time."""
    ts = _merged(pair.times_a, pair.times_b)
    best = (np.inf, None, None)
    for s0, s1 in zip(ts[:-1], ts[1:]):
        pts = []
        for t in (s0, s1):
            A = _world_vertices(pair.shape_a, pair.R_a, pair.times_a, pair.origins_a, t)
            B = _world_vertices(pair.shape_b, pair.R_b, pair.times_b, pair.origins_b, t)
            pts.append((A[:, None] - B[None]).reshape(-1, 3))
        d, q, lam = _swept_min(np.vstack(pts))
        if d < best[0]:
            best = (d, q, s0 + (s1 - s0) * lam[len(lam) // 2:].sum())
    return best


def _shift_b(pair, delta):
    return TranslatingPair(pair.shape_a, pair.R_a, pair.times_a, pair.origins_a, pair.shape_b,
                           pair.R_b, pair.times_b, pair.origins_b + delta, pair.name)


def make_case(rng, label, gap):
    """A random pair whose min distance over the window is ``gap`` (< 0: pushed in by -gap)."""
    offset = rng.choice([0.0, 1e3, 1e4]) * rng.choice([-1, 1], 3)
    t0 = float(rng.choice([0.0, rng.uniform(0, 100)]))
    t1 = t0 + float(rng.uniform(0.3, 3.0))
    sa, _ = _random_shape(rng)
    sb, _ = _random_shape(rng)
    Ra = Rotation.random(random_state=rng).as_matrix()
    Rb = Rotation.random(random_state=rng).as_matrix() if rng.random() < 0.7 else Ra
    ta, oa = _random_motion(rng, t0, t1, offset)
    tb, ob = _random_motion(rng, t0, t1, offset + rng.normal(size=3))
    pair = TranslatingPair(sa, Ra, ta, oa, sb, Rb, tb, ob, ("a", "b"))
    d0, q, _ = _global_min(pair)
    if d0 < 1e-3:  # overlapping: move B far out of the way first
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        pair = _shift_b(pair, -u * 50.0)
        d0, q, _ = _global_min(pair)
    n = q / np.linalg.norm(q)  # direction from B towards A in the CSO A - B
    if gap >= 0:
        return _shift_b(pair, n * (d0 - gap)), (t0, t1), label, gap
    # hit: from the touching shift s_T towards the shift s_D that puts B's vertex centroid
    # on A's at the touching time t*: s_T is on the boundary of the CSO at t*, s_D inside,
    # so s_T + eps (s_D - s_T) overlaps with depth ~ eps
    touch = _shift_b(pair, n * d0)
    _, _, t_star = _global_min(touch)
    c_a = _world_vertices(pair.shape_a, pair.R_a, pair.times_a, pair.origins_a, t_star).mean(0)
    c_b = _world_vertices(touch.shape_b, touch.R_b, touch.times_b, touch.origins_b, t_star).mean(0)
    return _shift_b(touch, -gap * (c_a - c_b)), (t0, t1), label, gap


def cases(seed, n):
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        r = i % 10
        if r < 4:
            gap = float(10.0 ** rng.uniform(-9, -2))
            out.append(make_case(rng, "miss", gap))
        elif r < 6:
            out.append(make_case(rng, "touch", 0.0))
        else:
            out.append(make_case(rng, "hit", -float(10.0 ** rng.uniform(-4, -0.5))))
    return out


# ----------------------------------------------------------------------------- oracle

def _hrep(V):
    """(normals, offsets) of conv(V) from Qhull facets: n.x <= o."""
    h = ConvexHull(V)
    return h.equations[:, :3], -h.equations[:, 3]


def oracle(pair, window):
    """Independent LP oracle: (collides, earliest time or None)."""
    ts = _merged(pair.times_a, pair.times_b)
    ts = ts[(ts >= window[0]) & (ts <= window[1])]
    for s0, s1 in zip(ts[:-1], ts[1:]):
        Va0 = _world_vertices(pair.shape_a, pair.R_a, pair.times_a, pair.origins_a, s0)
        Va1 = _world_vertices(pair.shape_a, pair.R_a, pair.times_a, pair.origins_a, s1)
        Vb0 = _world_vertices(pair.shape_b, pair.R_b, pair.times_b, pair.origins_b, s0)
        Vb1 = _world_vertices(pair.shape_b, pair.R_b, pair.times_b, pair.origins_b, s1)
        c = 0.5 * (Va0.mean(0) + Vb0.mean(0))  # work near the pair: kills the 1e4 offsets
        va = (Va1[0] - Va0[0]) / (s1 - s0)
        vb = (Vb1[0] - Vb0[0]) / (s1 - s0)
        rows, rhs = [], []
        for V, v in ((Va0 - c, va), (Vb0 - c, vb)):
            N, o = _hrep(V)
            # x in P(t) <=> N x <= o + N v (t - s0); variables (x, u = t - s0, s)
            rows.append(np.hstack([N, -(N @ v)[:, None], np.ones((len(N), 1))]))
            rhs.append(o)
        A = np.vstack(rows)
        b = np.concatenate(rhs)
        bounds = [(None, None)] * 3 + [(0.0, s1 - s0), (None, 1e3)]
        r = linprog([0, 0, 0, 0, -1], A_ub=A, b_ub=b, bounds=bounds, method="highs",
                    options={"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10})
        assert r.status == 0, r.message
        if -r.fun > ORACLE_SLACK:
            A0 = A[:, :4]
            r2 = linprog([0, 0, 0, 1], A_ub=A0, b_ub=b, bounds=[(None, None)] * 3 + [(0.0, s1 - s0)],
                         method="highs", options={"primal_feasibility_tolerance": 1e-10,
                                                  "dual_feasibility_tolerance": 1e-10})
            assert r2.status == 0, r2.message
            return True, s0 + r2.x[3]
    return False, None


# ----------------------------------------------------------------------------- tests

N_CASES = 1000


@pytest.fixture(scope="module")
def random_cases():
    return cases(20261122, N_CASES)


def test_case_mix(random_cases):
    labels = [c[2] for c in random_cases]
    assert len(random_cases) >= 1000
    assert labels.count("miss") >= 350 and labels.count("touch") >= 150 and labels.count("hit") >= 350


def test_verdicts_and_earliest_match_oracle(random_cases):
    _check_against_oracle(random_cases)


@pytest.mark.slow
def test_large_sweep_against_oracle(request):
    """5000 more cases (about 4 minutes): ``pytest -m slow tests/test_extrusion_exact.py``."""
    if "slow" not in (request.config.getoption("markexpr") or "") and not os.environ.get("MONITOR_SLOW"):
        pytest.skip("slow: run with -m slow (or MONITOR_SLOW=1)")
    _check_against_oracle(cases(977, 5000))


def _check_against_oracle(random_cases):
    mismatches, time_errors = [], []
    for i, (pair, window, label, gap) in enumerate(random_cases):
        out = check_pairs([pair], window)[0]
        hit, t_e = oracle(pair, window)
        # the oracle must agree with the construction (sanity of the oracle itself)
        assert hit == (label == "hit"), (i, label)
        mine = out.verdict == "violation"
        assert out.verdict in ("certified", "violation"), (i, out.verdict, out.info)
        if mine != hit:
            mismatches.append((i, label, out.verdict))
            continue
        if hit:
            err = abs(out.info["earliest_time"] - t_e) / (window[1] - window[0])
            time_errors.append(err)
            assert window[0] <= out.witness_time <= window[1]
            # the witness is a real overlap: the exact static distance is negative there
            X_a = (pair.R_a, np.array([np.interp(out.witness_time, pair.times_a, pair.origins_a[:, k])
                                       for k in range(3)]))
            X_b = (pair.R_b, np.array([np.interp(out.witness_time, pair.times_b, pair.origins_b[:, k])
                                       for k in range(3)]))
            d = shape_distance(pair.shape_a, X_a, pair.shape_b, X_b)
            assert d.upper < 0.0, (i, d)
        else:
            # certified: clearance is a tight lower bound of the constructed min distance
            assert gap - 1e-8 <= out.clearance <= gap + 1e-9, (i, gap, out.clearance)
    assert not mismatches, mismatches[:10]
    assert max(time_errors) <= 1e-9, max(time_errors)


# ----------------------------------------------------------------------------- quadratic cores

def _round_case(rng, gap, margin):
    kind_a, kind_b = rng.choice(["sphere", "capsule", "box"], 2)

    def shape(kind):
        if kind == "sphere":
            return sphere_shape(float(rng.uniform(0.1, 0.6)))
        if kind == "capsule":
            return capsule_shape(float(rng.uniform(0.1, 0.4)), float(rng.uniform(0.1, 0.6)))
        return box_polytope(rng.uniform(0.1, 0.8, 3))

    sa, sb = shape(kind_a), shape(kind_b)
    offset = rng.choice([0.0, 1e4]) * rng.choice([-1, 1], 3)
    t0, t1 = 0.0, float(rng.uniform(0.5, 2.0))
    Ra = Rotation.random(random_state=rng).as_matrix()
    Rb = Rotation.random(random_state=rng).as_matrix()
    ta, oa = _random_motion(rng, t0, t1, offset)
    tb, ob = _random_motion(rng, t0, t1, offset + rng.normal(size=3))
    pair = TranslatingPair(sa, Ra, ta, oa, sb, Rb, tb, ob, (kind_a, kind_b))
    d0, q, _ = _global_min(pair)
    rr = sa.radius + sb.radius
    if d0 - rr < 1e-3:
        u = rng.normal(size=3)
        pair = _shift_b(pair, -u / np.linalg.norm(u) * 50.0)
        d0, q, _ = _global_min(pair)
    n = q / np.linalg.norm(q)
    # target: shape distance min = margin + gap
    return _shift_b(pair, n * (d0 - rr - margin - gap)), (t0, t1)


def _oracle_min_distance(pair, window):
    """Min over time of the exact static distance (geometry.distance), per span by convexity."""
    ts = _merged(pair.times_a, pair.times_b)
    best = np.inf

    def f(t):
        Xa = (pair.R_a, np.array([np.interp(t, pair.times_a, pair.origins_a[:, k]) for k in range(3)]))
        Xb = (pair.R_b, np.array([np.interp(t, pair.times_b, pair.origins_b[:, k]) for k in range(3)]))
        return shape_distance(pair.shape_a, Xa, pair.shape_b, Xb).distance

    for s0, s1 in zip(ts[:-1], ts[1:]):
        r = minimize_scalar(f, bounds=(s0, s1), method="bounded", options={"xatol": 1e-12})
        best = min(best, r.fun, f(s0), f(s1))
    return best


@pytest.mark.parametrize("margin", [0.0, 0.05])
def test_round_shapes_and_margins_exact(margin):
    rng = np.random.default_rng(7 + int(margin * 100))
    n_bad = []
    for i in range(60):
        gap = float(rng.choice([1e-6, 1e-4, 1e-2, -1e-4, -1e-2])) * rng.choice([1, 3])
        pair, window = _round_case(rng, gap, margin)
        if pair.shape_a.kind == "polytope" and pair.shape_b.kind == "polytope" and margin == 0.0:
            continue  # LP path, covered above
        out = check_pairs([pair], window, margin=margin)[0]
        dmin = _oracle_min_distance(pair, window)
        assert abs(dmin - (margin + gap)) < 1e-7, (i, dmin, gap)
        expect = "violation" if gap < 0 else "certified"
        if out.verdict != expect:
            n_bad.append((i, gap, out.verdict))
        if out.verdict == "certified":
            assert abs(out.clearance - dmin) < 1e-7
        else:
            assert out.info["earliest_time"] <= out.witness_time
    assert not n_bad, n_bad


# ----------------------------------------------------------------------------- cross-check (engine)

def _geom_xml(name, shape, R):
    """MJCF geom for a generated shape: a box primitive when it is one, else an inline-mesh hull."""
    quat = " ".join(repr(float(x)) for x in Rotation.from_matrix(R).as_quat(scalar_first=True))
    P = shape.points
    half = 0.5 * (P.max(0) - P.min(0))
    if len(P) == 8 and np.allclose(np.abs(P - P.mean(0)), half, atol=1e-12):
        size = " ".join(repr(float(x)) for x in half)
        return f"<geom name='{name}' type='box' size='{size}' quat='{quat}' mass='1'/>", ""
    verts = " ".join(repr(float(x)) for x in P.reshape(-1))
    return (f"<geom name='{name}' type='mesh' mesh='m{name}' quat='{quat}' mass='1'/>",
            f"<mesh name='m{name}' vertex='{verts}'/>")


def _mjcf(pair):
    ga, ma = _geom_xml("ga", pair.shape_a, pair.R_a)
    gb, mb = _geom_xml("gb", pair.shape_b, pair.R_b)
    joints = "".join(f"<joint name='{{b}}{c}' type='slide' axis='{ax}'/>"
                     for c, ax in (("x", "1 0 0"), ("y", "0 1 0"), ("z", "0 0 1")))
    return (f"<mujoco><option gravity='0 0 0'/><asset>{ma}{mb}</asset><worldbody>"
            f"<body name='A'>{joints.format(b='a')}{ga}</body>"
            f"<body name='B'>{joints.format(b='b')}{gb}</body></worldbody></mujoco>")


def test_cross_check_with_toleranced_on_the_same_cases(random_cases):
    """Through the engine: neither checker certifies what the other proves colliding.

    The first 60 generated cases (boxes as box geoms, hulls as inline meshes, the same
    rotations and piecewise-linear motions as slide-joint plans). MuJoCo stores mesh
    vertices in float32, so near misses may change side; both checkers see the same scene.
    """
    mujoco = pytest.importorskip("mujoco")
    from monitor.certify.common import Budget
    from monitor.certify.engine import certify
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    tally: dict[tuple[str, str], int] = {}
    for i, (pair, _window, _label, _gap) in enumerate(random_cases[:60]):
        m = mujoco.MjModel.from_xml_string(_mjcf(pair))
        scene = Scene.from_model(m, pairs="all")
        ts = _merged(pair.times_a, pair.times_b)
        qa = np.stack([np.interp(ts, pair.times_a, pair.origins_a[:, k]) for k in range(3)], axis=1)
        qb = np.stack([np.interp(ts, pair.times_b, pair.origins_b[:, k]) for k in range(3)], axis=1)
        plan = Plan(ts, np.hstack([qa, qb]), model=m)
        ext = certify(scene, plan, method="extrusion")
        tol = certify(scene, plan, method="toleranced", epsilon=1e-3, budget=Budget(seconds=2.0))
        assert not (ext.verdict == "violation" and tol.verdict == "certified"), i
        assert not (tol.verdict == "violation" and ext.verdict == "certified"), i
        if ext.verdict == "uncertain":
            # Only exact touching: regularised semantics say "no collision" (never a
            # violation), but the engine's contract (clearance > margin) cannot certify a
            # distance of 0 either, so it asks the checker at margin + extrusion_slack + pad.
            assert _label == "touch" and _gap == 0.0, (i, _label, _gap, ext.pairs[0])
        tally[(ext.verdict, tol.verdict)] = tally.get((ext.verdict, tol.verdict), 0) + 1
    assert tally.get(("violation", "violation"), 0) > 10
    assert tally.get(("certified", "certified"), 0) >= 2, tally  # toleranced: near misses stay uncertain
