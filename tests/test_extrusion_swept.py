"""The compiled first pass over translating pairs (``monitor.certify.extrusion_swept``, issue 12 items 1, 4).

Oracles, independent of the kernel:
* closed form: a sphere moving head-on at a rotated box face with a piecewise-linear
  motion (first contact = a root of a linear equation on the segment where it happens);
* dense sampling of the core distance (the former pure-Python min-norm,
  ``min_norm_reference``, its own verified bounds) with the Lipschitz margin ``|w| h / 2``
  (``d`` is ``|w|``-Lipschitz on a span);
* the exact space-time LP for two polytopes (scipy HiGHS): the earliest instant at which the
  polytopes overlap; a certificate at margin 0 needs the LP infeasible, and the first contact
  at a small margin is never after it;
* the other checker: the Python extrusion checker alone (``engine._SWEPT_FIRST = False``),
  through ``monitor.certify``, on the cross-check cases, the AGV scenes (Cameron §5) and the
  tunnel gate: the same verdicts, earliest times and clearances.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial.transform import Rotation

from monitor.certify import engine
from monitor.certify.extrusion_null import min_norm_reference
from monitor.certify.extrusion_swept import decide_pair
from monitor.geometry.polytope import (
    box_polytope,
    capsule_shape,
    halfspace_shape,
    polytope_from_points,
    sphere_shape,
)
from monitor.tolerances import DEFAULT

EYE = np.eye(3)


def _ext(margin: float) -> float:
    """The engine's stronger certificate margin."""
    return margin + DEFAULT.extrusion_slack + DEFAULT.pad(margin)


def _decide(sa, Ra, ta, oa, sb, Rb, tb, ob, window, margin):
    return decide_pair(sa, Ra, np.asarray(ta, float), np.asarray(oa, float), sb, Rb, np.asarray(tb, float),
                       np.asarray(ob, float), window, margin, _ext(margin), DEFAULT, ("a", "b"))


def _origin(times: np.ndarray, origins: np.ndarray, t: float) -> np.ndarray:
    return np.array([np.interp(t, times, origins[:, c]) for c in range(3)])


def _cores(s, R, times, origins, t):
    return s.points @ R.T + _origin(times, origins, t)


def _dist_bounds(pa, pb, t):
    """Verified (lower, upper) core distance at t by the pure-Python reference min-norm."""
    A, B = _cores(*pa, t), _cores(*pb, t)
    D = (A[:, None, :] - B[None, :, :]).reshape(-1, 3)
    lo, up, _ = min_norm_reference(D, DEFAULT)
    return lo, up


# ----------------------------------------------------------------------------- closed form

@pytest.mark.parametrize("seed", range(12))
def test_sphere_head_on_at_box_face_closed_form(seed):
    """First contact of a sphere with a rotated box face over a 3-segment motion (closed form)."""
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=seed).as_matrix()
    half = rng.uniform(0.05, 0.3, 3)
    box = box_polytope(half)
    r = float(rng.uniform(0.005, 0.05))
    margin = float(rng.choice([0.0, 0.01]))
    n = R[:, 0]                                # the +x face normal in the world
    c = rng.normal(size=3)                     # box centre
    gap0 = float(rng.uniform(0.2, 0.5))        # centre-to-face distance minus radius and margin at t=0
    # the sphere centre approaches the face along -n at speeds s1, s2, s3 on [0, .3], [.3, .6], [.6, 1]
    speeds = rng.uniform(0.05, 0.8, 3)
    times = np.array([0.0, 0.3, 0.6, 1.0])
    dists = [gap0 + r + margin]
    for k in range(3):
        dists.append(dists[-1] - speeds[k] * (times[k + 1] - times[k]))
    p0 = c + n * half[0]
    origins = np.array([p0 + n * d for d in dists])
    static = np.array([c, c])
    # closed form: the first time the face distance reaches r + margin
    t_star, acc = None, 0.0
    for k in range(3):
        travel = speeds[k] * (times[k + 1] - times[k])
        if acc + travel >= gap0:
            t_star = times[k] + (gap0 - acc) / speeds[k]
            break
        acc += travel
    o = _decide(sphere_shape(r), EYE, times, origins, box, R, [0.0, 1.0], static, (0.0, 1.0), margin)
    assert o is not None
    if t_star is None:
        assert o.verdict == "certified"
        true_clear = dists[-1] - r        # the closest instant is the end (the face is head-on)
        assert o.clearance <= true_clear and o.clearance >= true_clear - 1e-9
    else:
        assert o.verdict == "violation"
        assert o.info["earliest_time"] == pytest.approx(t_star, abs=1e-9)
        assert o.intervals[0][0] == o.info["earliest_time"] <= o.witness_time
        assert o.info["stage"] == "exact_swept" and o.info["test"] == "swept_kernel"


@pytest.mark.parametrize("seed", range(8))
def test_box_onto_tilted_moving_plane_closed_form(seed):
    """A rotated box moving onto a rotated, translating half-space over 2 segments (closed form).

    Signed distance of the box to the plane: ``min_i n.(x_i(t)) - h(t)``; its first crossing of
    the level is the smallest per-vertex root on the first segment where one exists.
    """
    rng = np.random.default_rng(50 + seed)
    Rp = Rotation.random(random_state=100 + seed).as_matrix()
    Rb = Rotation.random(random_state=200 + seed).as_matrix()
    half = rng.uniform(0.05, 0.2, 3)
    box = box_polytope(half)
    n = Rp[:, 2]                                    # the plane's world normal (body z)
    margin = float(rng.choice([0.0, 0.01]))
    times = np.array([0.0, 0.4, 1.0])
    p_plane = np.array([rng.normal(size=3) * 0.1, rng.normal(size=3) * 0.1, rng.normal(size=3) * 0.1])
    start = p_plane[0] + n * rng.uniform(0.5, 0.9)
    # the box moves towards the plane (along -n plus a sideways drift); the plane drifts too
    drift = rng.normal(size=3) * 0.1
    speeds = rng.uniform(0.3, 1.2, 2)
    ob = np.array([start, start - n * speeds[0] * 0.4 + drift * 0.4,
                   start - n * (speeds[0] * 0.4 + speeds[1] * 0.6) + drift])
    V = box.points @ Rb.T

    def signed(t):
        x = V + np.array([np.interp(t, times, ob[:, c]) for c in range(3)])
        p = np.array([np.interp(t, times, p_plane[:, c]) for c in range(3)])
        return float(np.min((x - p) @ n))

    # closed form per segment: each vertex's distance is linear on a segment
    t_star = None
    for k in range(2):
        a, b = times[k], times[k + 1]
        da = (V + ob[k] - p_plane[k]) @ n
        db = (V + ob[k + 1] - p_plane[k + 1]) @ n
        hit = [a + (b - a) * (da[i] - margin) / (da[i] - db[i]) for i in range(8)
               if da[i] >= margin > db[i]]
        if hit:
            t_star = min(hit)
            break
    o = _decide(halfspace_shape(), Rp, times, p_plane, box, Rb, times, ob, (0.0, 1.0), margin)
    assert o is not None and o.info.get("closed_form") == "halfspace"
    if t_star is None:
        assert o.verdict == "certified"
        true_min = min(signed(t) for t in times)       # concave piecewise linear: a breakpoint
        assert true_min - 1e-9 <= o.clearance <= true_min
    else:
        assert o.verdict == "violation"
        assert o.info["earliest_time"] == pytest.approx(t_star, abs=1e-9)
        assert signed(o.witness_time) < margin
        assert o.info["stage"] == "null_set"


# ----------------------------------------------------------------------------- random pairs, sampling

def _random_shape(rng, kind):
    if kind == "box":
        return box_polytope(rng.uniform(0.03, 0.2, 3))
    if kind == "hull":
        return polytope_from_points(rng.normal(size=(int(rng.integers(5, 14)), 3)) * rng.uniform(0.05, 0.2))
    if kind == "sphere":
        return sphere_shape(float(rng.uniform(0.02, 0.15)))
    return capsule_shape(float(rng.uniform(0.02, 0.08)), float(rng.uniform(0.03, 0.15)))


def _random_motion(rng, start, end, k):
    """k segments from ``start`` to ``end`` through random intermediate points (breakpoints random)."""
    times = np.r_[0.0, np.sort(rng.uniform(0.05, 0.95, k - 1)), 1.0]
    frac = np.sort(rng.uniform(0, 1, k - 1))
    mids = start + np.outer(frac, end - start) + rng.normal(size=(k - 1, 3)) * 0.05
    return times, np.vstack([start, mids, end])


def _random_pair(seed):
    """Two random convex geoms; B passes near A's path (about half the seeds collide)."""
    rng = np.random.default_rng(1000 + seed)
    kinds = ("box", "hull", "sphere", "capsule")
    sa, sb = _random_shape(rng, kinds[seed % 4]), _random_shape(rng, kinds[(seed // 4) % 4])
    Ra = Rotation.random(random_state=2 * seed).as_matrix()
    Rb = Rotation.random(random_state=2 * seed + 1).as_matrix()
    a0 = rng.normal(size=3) * 0.2
    ta, oa = _random_motion(rng, a0, a0 + rng.normal(size=3) * 0.1, int(rng.integers(1, 4)))
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    miss = rng.normal(size=3) * rng.uniform(0.0, 0.4)   # B's path passes a0 + miss
    tb, ob = _random_motion(rng, a0 + miss - 0.8 * u, a0 + miss + 0.8 * u, int(rng.integers(1, 4)))
    margin = float(rng.choice([0.0, 0.005, 0.02]))
    return (sa, Ra, ta, oa), (sb, Rb, tb, ob), margin


def test_random_pairs_against_dense_sampling():
    """Certified: no sampled instant closer than the level. Violation: none before the earliest time."""
    decided = {"certified": 0, "violation": 0, "undecided": 0}
    for seed in range(160):
        pa, pb, margin = _random_pair(seed)
        o = _decide(*pa, *pb, (0.0, 1.0), margin)
        level = pa[0].radius + pb[0].radius + margin
        if o is None:
            decided["undecided"] += 1
            continue
        decided[o.verdict] += 1
        grid = np.linspace(0.0, 1.0, 301)
        if o.verdict == "certified":
            for t in grid:
                lo, up = _dist_bounds(pa, pb, t)
                assert up >= level, (seed, t, up, level)          # no sampled collision
                assert o.clearance <= up - pa[0].radius - pb[0].radius + 1e-12
        else:
            tf = o.info["earliest_time"]
            for t in grid[grid < tf - 1e-9]:
                lo, up = _dist_bounds(pa, pb, t)
                assert lo >= level - 1e-9, (seed, t, lo, level)   # nothing in contact before it (not late)
            _lo, up = _dist_bounds(pa, pb, tf)
            assert up < level + 1e-9                              # in contact at it
            lo_w, up_w = _dist_bounds(pa, pb, o.witness_time)
            assert up_w < level                                   # the witness time is inside
    print("\ncompiled pass on 160 random pairs:", decided)
    assert decided["certified"] > 20 and decided["violation"] > 20


# ----------------------------------------------------------------------------- exact LP

def _lp_first_overlap(pa, pb, window):
    """Earliest t in the window at which the two polytope cores overlap (exact LP per span), or None."""
    (sa, Ra, ta, oa), (sb, Rb, tb, ob) = pa, pb
    bps = sorted({*window, *[t for t in np.r_[ta, tb] if window[0] < t < window[1]]})
    Na, Nb = sa.normals @ Ra.T, sb.normals @ Rb.T
    for s0, s1 in zip(bps[:-1], bps[1:]):
        a0, a1 = _origin(ta, oa, s0), _origin(ta, oa, s1)
        b0, b1 = _origin(tb, ob, s0), _origin(tb, ob, s1)
        va, vb = (a1 - a0) / (s1 - s0), (b1 - b0) / (s1 - s0)
        # variables (x, tau): Na (x - a0 - va tau) <= ha, Nb (x - b0 - vb tau) <= hb, 0 <= tau <= s1 - s0
        G = np.vstack([np.c_[Na, -(Na @ va)], np.c_[Nb, -(Nb @ vb)]])
        h = np.r_[sa.offsets + Na @ a0, sb.offsets + Nb @ b0]
        res = linprog([0, 0, 0, 1.0], A_ub=G, b_ub=h, bounds=[(None, None)] * 3 + [(0.0, s1 - s0)],
                      method="highs")
        if res.status == 0:
            return s0 + float(res.x[3])
    return None


def test_polytope_pairs_against_the_exact_lp():
    """Margin 0: a certificate needs no overlap (LP infeasible). Margin 1e-6: first contact <= LP overlap."""
    n_cert = n_first = 0
    for seed in range(120):
        pa, pb, _ = _random_pair(seed)
        if pa[0].kind != "polytope" or pb[0].kind != "polytope":
            continue
        t_lp = _lp_first_overlap(pa, pb, (0.0, 1.0))
        o0 = _decide(*pa, *pb, (0.0, 1.0), 0.0)
        if o0 is not None:
            assert o0.verdict == "certified"          # at level 0 the pass never claims a penetration
            assert t_lp is None, (seed, t_lp)
            n_cert += 1
        o1 = _decide(*pa, *pb, (0.0, 1.0), 1e-6)
        if o1 is not None and o1.verdict == "violation" and t_lp is not None:
            assert o1.info["earliest_time"] <= t_lp + 1e-9
            n_first += 1
        elif t_lp is not None:
            assert o1 is None or o1.verdict != "certified"
    print(f"\nLP oracle: {n_cert} certificates at margin 0, {n_first} first contacts checked")
    assert n_cert > 5 and n_first > 5


# ----------------------------------------------------------------------------- what the pass leaves

def test_undecided_cases_are_left_to_the_python_checker():
    box = box_polytope(np.array([0.1, 0.1, 0.1]))
    t = np.array([0.0, 1.0])
    still = np.zeros((2, 3))
    # two half-spaces: the checker raises UnsupportedGeometryError
    up = still + [0, 0, 1.0]
    assert _decide(halfspace_shape(), EYE, t, still, halfspace_shape(), EYE, t, up, (0.0, 1.0), 0.0) is None
    # touching exactly at the margin at t = 1 (the exactness band): neither proved
    far = np.array([[0.5, 0, 0], [0.2 + 0.01, 0, 0]])
    assert _decide(box, EYE, t, still, box, EYE, t, far, (0.0, 1.0), 0.01) is None
    # sharp polytopes penetrating at margin 0: the LP path (witness depth) decides
    deep = np.array([[0.5, 0, 0], [0.1, 0, 0]])
    assert _decide(box, EYE, t, still, box, EYE, t, deep, (0.0, 1.0), 0.0) is None
    # a motion that does not cover the window, or non-increasing times: the checker raises the typed error
    assert _decide(box, EYE, np.array([0.0, 0.5]), still, box, EYE, t, far, (0.0, 1.0), 0.0) is None
    assert _decide(box, EYE, np.array([0.0, 0.0]), still, box, EYE, t, far, (0.0, 1.0), 0.0) is None


def test_bad_motion_still_raises_the_typed_error():
    """The pass never swallows bad input: the engine's Python checker raises as before."""
    from monitor.certify.common import Budget
    from monitor.errors import InvalidInputError

    class _G:
        def __init__(self, name, shape, body_id):
            self.name, self.shape, self.body_id, self.body = name, shape, body_id, name

    class _Plan:
        def body_poses(self, t):
            return np.zeros((1, 2, 3)), np.broadcast_to(EYE, (1, 2, 3, 3)).copy()

    box = box_polytope(np.array([0.1, 0.1, 0.1]))
    bad = ((np.array([0.0, 0.0]), np.zeros((2, 3))), (np.array([0.0, 1.0]), np.ones((2, 3))))
    with pytest.raises(InvalidInputError):
        engine._run_extrusion(_Plan(), [(0, _G("a", box, 0), _G("b", box, 1), bad)], 0.0, DEFAULT, Budget(),
                              0.0, 1.0)


# ----------------------------------------------------------------------------- the other checker

def _both(run):
    old = engine._SWEPT_FIRST
    try:
        engine._SWEPT_FIRST = True
        a = run()
        engine._SWEPT_FIRST = False
        b = run()
    finally:
        engine._SWEPT_FIRST = old
    return a, b


def test_same_certificates_as_the_python_checker_on_crosscheck_cases():
    """60 seeded cross-check cases, method auto and extrusion: same verdict, earliest time, clearance."""
    from monitor.bench.cases import make_translating_cases
    from monitor.certify.engine import certify

    n_fast = 0
    for case in make_translating_cases(60, seed0=0):
        scene, motion = case.scene(), case.body_motion()
        for method in ("auto", "extrusion"):
            def run(scene=scene, motion=motion, margin=case.margin, method=method):
                return certify(scene, motion, margin=margin, epsilon=1e-3, method=method)

            a, b = _both(run)
            assert a.verdict == b.verdict, (case.name, method)
            if a.earliest_time is not None or b.earliest_time is not None:
                assert a.earliest_time == pytest.approx(b.earliest_time, abs=1e-12)
            if a.verdict == "certified":
                assert a.clearance == pytest.approx(b.clearance, abs=1e-12)
            if a.witness is not None:
                assert b.witness is not None and a.witness.geoms == b.witness.geoms
            n_fast += a.stats.get("extrusion", {}).get("swept_kernel", 0)
    assert n_fast > 40


@pytest.mark.parametrize(("name", "skewed"), [("straight", False), ("weaving", False), ("weaving", True)])
def test_agv_scenes_same_certificate_with_the_compiled_pass(name, skewed):
    """Cameron's §5 AGV scenes (29 primitives): same verdict, witness pair, earliest time, clearance."""
    pytest.importorskip("mujoco")
    import monitor

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _switch_cases import agv_scene_plan

    scene, plan = agv_scene_plan(name, skewed)
    a, b = _both(lambda: monitor.certify(scene, plan, method="auto"))
    assert a.verdict == b.verdict
    assert a.stats["extrusion"].get("swept_kernel", 0) > 0
    if a.verdict == "violation":
        assert a.witness.geoms == b.witness.geoms
        assert a.earliest_time == pytest.approx(b.earliest_time, abs=1e-9)
    else:
        assert a.clearance == pytest.approx(b.clearance, abs=1e-9)


def test_tunnel_gate_same_steps_with_the_compiled_pass():
    """models/tunnel, plain Gate.step: the same verdict, earliest time and state at every step."""
    mujoco = pytest.importorskip("mujoco")
    from monitor._paths import scene_path
    from monitor.gate import Gate

    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))

    def run():
        gate = Gate(m, margin=0.001)
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, 0)
        out = []
        for k in range(60):
            target = 0.3 if (k // 15) % 2 == 0 else -0.3
            r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
            out.append((str(r.verdict), r.certificate.earliest_time if r.certificate is not None else None,
                        float(d.qpos[0]), float(d.qvel[0])))
        return out

    a, b = _both(run)
    assert [x[0] for x in a] == [x[0] for x in b]
    assert {x[0] for x in a} >= {"certified", "violation"}
    for x, y in zip(a, b):
        assert x[2:] == pytest.approx(y[2:], abs=1e-12)
        if x[1] is not None or y[1] is not None:
            assert x[1] == pytest.approx(y[1], abs=1e-12)


def test_exhausted_budget_skips_the_pass():
    """A spent budget leaves the pair undecided (uncertain), never certified by the pass."""
    from monitor.bench.cases import make_translating_cases
    from monitor.certify.common import Budget
    from monitor.certify.engine import certify

    case = next(c for c in make_translating_cases(20, seed0=0) if c.intent == "clear")
    scene, motion = case.scene(), case.body_motion()
    cert = certify(scene, motion, margin=case.margin, method="extrusion", budget=Budget(tests=0))
    assert cert.verdict != "certified"


def test_engine_entry_box_calls_same_public_answers():
    """The recorded box-scene calls of tests/test_engine_entry.py (first pass on vs off): same verdict,
    earliest time, witness pair and per-pair verdicts; clearances within 1e-12 m."""
    import sys
    from pathlib import Path

    pytest.importorskip("mujoco")
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _engine_entry_cases import box_calls

    n_fast = 0
    for name, run in box_calls():
        a, b = _both(run)
        assert a.verdict == b.verdict, name
        assert (a.earliest_time is None) == (b.earliest_time is None), name
        if a.earliest_time is not None:
            assert a.earliest_time == pytest.approx(b.earliest_time, abs=1e-12), name
        assert (a.witness is None) == (b.witness is None), name
        assert a.witness is None or a.witness.geoms == b.witness.geoms, name
        assert [p.verdict for p in a.pairs] == [p.verdict for p in b.pairs], name
        assert [p.method for p in a.pairs] == [p.method for p in b.pairs], name
        for p, q in zip(a.pairs, b.pairs):
            if p.verdict == "certified":
                assert p.clearance == pytest.approx(q.clearance, abs=1e-12), name
        n_fast += a.stats.get("extrusion", {}).get("swept_kernel", 0)
    assert n_fast > 10
