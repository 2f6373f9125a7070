"""Cameron's pipeline issues the extrusion certificates (issue 14, items 1, 3, 4, 5).

Per pair (or n-ary group): S-bounds (§4.3, App. B) -> divide and conquer (§4.1) ->
null-set LP on the half-spaces offset by radius + margin/2 (§4.2) -> the exact swept
test only where the offset test leaves a region open. ``PairOutcome.info["stage"]``
names the deciding stage; ``cert.stats["extrusion_stages"]`` counts them.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from monitor.certify.extrusion import STAGES, TranslatingPair, check_pairs, core_hrep, search_summary
from monitor.geometry.distance import shape_distance_batch
from monitor.geometry.polytope import box_polytope, capsule_shape, polytope_from_points, sphere_shape
from monitor.tolerances import DEFAULT

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench_cases import QUICK_CASES_GROUP, quick_cases  # noqa: E402  (the quick set, built once per process)

PAPER_PATH = ("sbounds", "divide_and_conquer", "null_set")


@pytest.fixture(autouse=True, scope="module")
def _warm_simplex():
    """The compiled slack-LP simplex is used once warm (monitor.warmup's job); warm it here."""
    from monitor.certify.extrusion_null import warm_small_lp

    warm_small_lp()


def _lin_pair(sa, pa, va, sb, pb, vb, Ra=None, Rb=None, t1=1.0, name=("a", "b")):
    Ra = np.eye(3) if Ra is None else Ra
    Rb = np.eye(3) if Rb is None else Rb
    pa, va, pb, vb = (np.asarray(x, float) for x in (pa, va, pb, vb))
    t = np.array([0.0, t1])
    return TranslatingPair(sa, Ra, t, np.stack([pa, pa + va * t1]), sb, Rb, t, np.stack([pb, pb + vb * t1]),
                           name)


# ----------------------------------------------------------------------------- the offset polytope

@pytest.mark.parametrize("kind", ["sphere", "capsule", "capsule_tilted"])
def test_offset_hrep_contains_the_rounded_shape(kind):
    """Every point of the rounded shape satisfies every offset row (sampled on the surface)."""
    rng = np.random.default_rng(3)
    if kind == "sphere":
        s = sphere_shape(0.7, np.array([0.1, -0.2, 0.3]))
    else:
        s = capsule_shape(0.4, 0.9)
    R = Rotation.from_rotvec([0.3, -1.1, 0.7]).as_matrix() if kind == "capsule_tilted" else np.eye(3)
    N, h = core_hrep(s)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-15)
    # core points: the segment / point; surface: core point + radius * unit direction
    lam = rng.uniform(0, 1, 4000)
    P = s.points
    core = P[0] + lam[:, None] * (P[-1] - P[0])
    u = rng.normal(size=(4000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    x = (core + s.radius * u) @ R.T
    Nw = N @ R.T
    assert np.all(x @ Nw.T <= h + s.radius + 1e-12)
    # and the synthesised rows are tight: each touches the core (support values)
    np.testing.assert_allclose(h, (N @ P.T).max(axis=1), atol=0)


def test_box_corner_over_approximation_is_r_sqrt3_minus_1():
    """The offset box's corner lies r sqrt(3) from the box, r (sqrt 3 - 1) beyond the rounded box."""
    half = np.array([0.5, 0.3, 0.2])
    s = box_polytope(half)
    r = 0.05
    N, h = core_hrep(s)
    corner = half + r  # the offset polytope's corner (+, +, +)
    assert np.all(N @ corner <= h + r + 1e-15)
    assert np.isclose(np.max(N @ corner - h - r), 0.0, atol=1e-15)  # on the offset boundary
    excess = np.linalg.norm(corner - half) - r
    assert excess == pytest.approx(r * (math.sqrt(3) - 1), rel=1e-12)


def _passing_spheres(gap_centres: float):
    """Static unit sphere and a unit sphere passing along (1, -1, 0) at centre distance ``gap_centres``
    in direction (1, 1, 0)/sqrt 2 (between the 14 normals: the offset polytopes reach 1.2247 there)."""
    u = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)
    w = np.array([1.0, -1.0, 0.0]) / math.sqrt(2)
    return _lin_pair(sphere_shape(1.0), [0, 0, 0], [0, 0, 0],
                     sphere_shape(1.0), gap_centres * u - 1.5 * w, 3.0 * w)


def test_open_offset_region_goes_to_exact_swept_and_stays_exact():
    # centre distance 2.2: rounded gap 0.2 but the offset polytopes (1.2247 each along u) overlap
    out = check_pairs([_passing_spheres(2.2)], (0.0, 1.0))[0]
    assert out.verdict == "certified"
    assert out.info["stage"] == "exact_swept"
    assert out.info["stats"]["offset_open"] >= 1
    assert out.clearance == pytest.approx(0.2, abs=1e-9)
    # 2.6 > 2 * 1.2247: the offset test alone certifies
    out = check_pairs([_passing_spheres(2.6)], (0.0, 1.0))[0]
    assert out.verdict == "certified"
    assert out.info["stage"] in PAPER_PATH and out.info["stage"] != "sbounds"
    assert out.info["stats"]["exact_swept"] == 0
    # inside the margin: a violation whatever path (exact first contact)
    out = check_pairs([_passing_spheres(2.2)], (0.0, 1.0), margin=0.25)[0]
    assert out.verdict == "violation"
    assert out.info["stage"] == "exact_swept"


# ----------------------------------------------------------------------------- seeded equivalence

def _random_shape(rng, kind):
    if kind == "box":
        return box_polytope(rng.uniform(0.05, 0.4, 3))
    if kind == "hull":
        return polytope_from_points(rng.normal(size=(10, 3)) * rng.uniform(0.1, 0.35))
    if kind == "sphere":
        return sphere_shape(rng.uniform(0.05, 0.3))
    return capsule_shape(rng.uniform(0.05, 0.2), rng.uniform(0.0, 0.3))


def seeded_translating_pairs(seed: int = 11, n: int = 80):
    """Seeded translating pairs (my own set): random convex shapes and orientations, B passes A
    at a random offset (collisions, near misses and clear passes), window [0, 1] s."""
    rng = np.random.default_rng(seed)
    kinds = ["box", "hull", "sphere", "capsule"]
    pairs = []
    for i in range(n):
        ka, kb = (kinds[rng.choice(4, p=[0.4, 0.3, 0.15, 0.15])] for _ in range(2))
        sa, sb = _random_shape(rng, ka), _random_shape(rng, kb)
        Ra, Rb = Rotation.random(2, random_state=rng.integers(1 << 31)).as_matrix()
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        side = np.cross(d, rng.normal(size=3))
        side /= np.linalg.norm(side)
        off = rng.uniform(0.0, 1.2) * side
        vb = d * rng.uniform(0.5, 3.0)
        va = rng.normal(size=3) * 0.2 * rng.integers(0, 2)
        pairs.append(_lin_pair(sa, [0, 0, 0], va, sb, off - 0.5 * vb, vb, Ra, Rb, name=(f"a{i}", f"b{i}")))
    return pairs


@pytest.mark.parametrize("margin", [0.0, 0.01])
def test_offset_pipeline_agrees_with_exact_swept_and_sampling(margin):
    """Same verdicts, first-contact times and clearances as the exact swept test alone; certified pairs
    never come within the margin at 2001 sampled instants (exact static distances)."""
    pairs = seeded_translating_pairs()
    # the engine's question: margin + slack + pad (so every pair has r > 0)
    ext = margin + DEFAULT.extrusion_slack + DEFAULT.pad(margin)
    a = check_pairs(pairs, (0.0, 1.0), ext)
    b = check_pairs(pairs, (0.0, 1.0), ext, offset=False)
    ts = np.linspace(0.0, 1.0, 2001)
    for p, oa, ob in zip(pairs, a, b):
        assert oa.verdict == ob.verdict, p.name
        if oa.verdict == "violation":
            assert oa.info["earliest_time"] == pytest.approx(ob.info["earliest_time"], abs=1e-9)
        else:
            assert oa.clearance == pytest.approx(ob.clearance, abs=1e-12)
        if oa.verdict == "certified":
            pa = p.origins_a[0] + ts[:, None] * (p.origins_a[1] - p.origins_a[0])
            pb = p.origins_b[0] + ts[:, None] * (p.origins_b[1] - p.origins_b[0])
            _lo, up = shape_distance_batch(p.shape_a, (np.broadcast_to(p.R_a, (len(ts), 3, 3)), pa),
                                           p.shape_b, (np.broadcast_to(p.R_b, (len(ts), 3, 3)), pb))
            assert up.min() >= margin, p.name  # a certified pair is never seen within the margin
    assert {o.info["stage"] for o in a} <= set(STAGES)
    assert all(o.info["stage"] == "exact_swept" or o.verdict != "violation" or o.info["test"] != "quadratic"
               for o in a)
    cert = [o for o in a if o.verdict == "certified"]
    assert len(cert) >= 30 and sum(o.verdict == "violation" for o in a) >= 10  # both kinds occur


def _count_stages(outs):
    paper = sum(o.verdict == "certified" and o.info["stage"] in PAPER_PATH for o in outs)
    null = sum(o.verdict == "certified" and o.info["stage"] == "null_set" for o in outs)
    exact = sum(o.verdict == "certified" and o.info["stage"] == "exact_swept" for o in outs)
    return paper, null, exact


def test_null_set_path_issues_most_certificates_on_seeded_set():
    pairs = seeded_translating_pairs(seed=12, n=100)
    ext = DEFAULT.extrusion_slack + DEFAULT.pad(0.0)
    outs = check_pairs(pairs, (0.0, 1.0), ext, nary=True)
    paper, null, exact = _count_stages(outs)
    summ = search_summary(outs)
    print(f"\nseeded set: {paper} certificates from S-bounds/D&C/null-set ({null} null-set LP), "
          f"{exact} from the exact swept fallback; offset LPs {summ['offset_lps']}, "
          f"dual shortcuts {summ['dual_shortcut']}, left open {summ['offset_open']}")
    assert paper > exact and null > exact


@pytest.mark.xdist_group(QUICK_CASES_GROUP)
def test_null_set_path_issues_most_certificates_on_bench_cases(monkeypatch):
    """The translating group of monitor.bench.cases (quick set) through monitor.certify.

    About the Python checker's own pipeline: the engine's compiled first pass
    (:mod:`monitor.certify.extrusion_swept`, the exact swept test per span) is switched off.
    """
    pytest.importorskip("mujoco")
    import monitor
    from monitor.certify import engine

    monkeypatch.setattr(engine, "_SWEPT_FIRST", False)

    stages: dict[tuple[str, str], int] = {}
    for c in quick_cases():
        if c.group != "translating":
            continue
        cert = monitor.certify(c.scene(), c.body_motion(), method="auto")
        n_ext = cert.stats["checker_mix"].get("extrusion", 0)
        assert sum(cert.stats.get("extrusion_stages", {}).values()) == n_ext
        for k, v in cert.stats.get("extrusion_stages", {}).items():
            stages[(cert.verdict, k)] = stages.get((cert.verdict, k), 0) + v
    print("\nbench translating (quick):", stages)
    paper = sum(v for (verdict, k), v in stages.items() if verdict == "certified" and k in PAPER_PATH)
    exact = stages.get(("certified", "exact_swept"), 0)
    assert paper > exact and stages.get(("certified", "null_set"), 0) > exact


@pytest.mark.slow
def test_null_set_path_issues_most_certificates_on_full_bench_cases(monkeypatch):
    pytest.importorskip("mujoco")
    import monitor
    from monitor.bench.cases import make_cases
    from monitor.certify import engine

    monkeypatch.setattr(engine, "_SWEPT_FIRST", False)  # the Python checker's pipeline (see above)

    paper = exact = null = 0
    for c in make_cases(seed=7):
        if c.group != "translating":
            continue
        cert = monitor.certify(c.scene(), c.body_motion(), method="auto")
        if cert.verdict == "certified":
            st = cert.stats.get("extrusion_stages", {})
            paper += sum(st.get(k, 0) for k in PAPER_PATH)
            null += st.get("null_set", 0)
            exact += st.get("exact_swept", 0)
    print(f"\nbench translating (full): paper path {paper} (null-set {null}), exact swept {exact}")
    assert paper > exact and null > exact


# ----------------------------------------------------------------------------- AGV and trays (§5)

def _agv(skewed: bool, name: str, swept_first: bool = False):
    """The AGV scene certified through the public API.

    ``swept_first=False`` (these tests are about the paper's pipeline and its stage counts):
    the engine's compiled first pass (:mod:`monitor.certify.extrusion_swept`) is off, so
    every translating pair goes through the Python checker. tests/test_extrusion_swept.py
    runs the same scenes with it on (same verdicts, earliest time and clearance).
    """
    mujoco = pytest.importorskip("mujoco")
    import monitor
    from monitor._paths import models_dir
    from monitor.bench.extrusion_scenes import schedule
    from monitor.certify import engine

    m = mujoco.MjModel.from_xml_path(str(models_dir() / "agv_trays" / ("scene_skewed.xml" if skewed
                                                                         else "scene.xml")))
    scene = monitor.Scene.from_model(m, pairs="all")
    s = schedule(name)
    old = engine._SWEPT_FIRST
    engine._SWEPT_FIRST = swept_first
    try:
        return scene, monitor.certify(scene, monitor.Plan(s["times"], s["qpos"], model=m), method="auto")
    finally:
        engine._SWEPT_FIRST = old


def _agv_trays_sbounds(cert):
    return [b for b in cert.stats["extrusion"]["sbounds"] if sorted(b["bodies"]) == ["agv", "trays"]]


@pytest.mark.parametrize("skewed", [False, True])
def test_agv_straight_through_public_api(skewed):
    from monitor.bench.extrusion_scenes import STRAIGHT_FIRST_CONTACT

    scene, cert = _agv(skewed, "straight")
    assert cert.verdict == "violation"
    assert cert.witness.geoms == ("crate_top", "plate1")
    assert cert.earliest_time == pytest.approx(STRAIGHT_FIRST_CONTACT, abs=1e-9 * 20)
    n_ext = cert.stats["checker_mix"]["extrusion"]
    st = cert.stats["extrusion_stages"]
    assert sum(st.values()) == n_ext and set(st) <= set(STAGES)
    # the pairs' geoms: 19 vehicle + 10 tray primitives (the paper's 29)
    assert sum(g.body in ("agv", "trays") for g in scene.geoms) == 29
    first = _agv_trays_sbounds(cert)[0]  # first search, the only span
    print(f"\nskewed={skewed}: S-bound survivors {first['leaves_out']} of 29 "
          f"({first['leaves_in']} after the broad phase), {first['survivors']}, "
          f"time bounds {first['time_bounds']}, stages {st}")
    assert {"crate_top", "plate1"} <= set(first["survivors"])
    if not skewed:  # paper: 5 of 29 primitives survive, a 1.33 s sub-span of 20 s
        assert first["leaves_out"] <= 5
        t_lo, t_hi = first["time_bounds"]
        assert t_lo == pytest.approx(STRAIGHT_FIRST_CONTACT, abs=1e-6)
        assert t_hi == pytest.approx(11.2, abs=1e-6)
        assert st.get("sbounds", 0) >= n_ext - 3  # S-bounds alone decide all but the 3 survivor pairs


@pytest.mark.parametrize("skewed", [False, True])
def test_agv_weaving_certified_through_public_api(skewed):
    _scene, cert = _agv(skewed, "weaving")
    assert cert.verdict == "certified"
    assert cert.clearance == pytest.approx(0.005, abs=1e-9)
    st = cert.stats["extrusion_stages"]
    assert sum(st.values()) == cert.stats["checker_mix"]["extrusion"]
    print(f"\nweaving skewed={skewed}: stages {st}, LPs {cert.stats['extrusion']['lps']}, "
          f"dual shortcuts {cert.stats['extrusion']['dual_shortcut']}")
    assert st.get("exact_swept", 0) == 0  # the paper's stages decide every pair
    if not skewed:  # paper: aligned paths and objects -> the S-bound stage alone is sufficient
        assert set(st) == {"sbounds"}
        assert cert.stats["extrusion"]["lps"] == 0
    else:  # skewed copies: the offset null-set test certifies what S-bounds leave
        assert st.get("null_set", 0) > 0


def test_second_pass_only_for_pairs_that_need_it():
    """The witness re-run at the true margin searches only the pairs not certified by the first."""
    _scene, cert = _agv(False, "straight")
    assert cert.stats["extrusion"]["searches"] == 2
    second = _agv_trays_sbounds(cert)[1:]
    assert second and all(b["leaves_in"] <= 4 for b in second)


# ----------------------------------------------------------------------------- the LP and its shortcuts

def _random_lp(rng):
    m = int(rng.integers(8, 40))
    G = rng.normal(size=(m, 4))
    G[:, :3] /= np.linalg.norm(G[:, :3], axis=1, keepdims=True)
    h = rng.uniform(-0.5, 1.0, m)
    lo, hi = -rng.uniform(0.1, 2.0, 4), rng.uniform(0.1, 2.0, 4)
    return G, h, lo, hi


def test_small_simplex_matches_highs_and_dual_shortcut_is_an_upper_bound():
    from scipy.optimize import linprog

    from monitor.certify.extrusion_null import Leaf, dual_certificate, small_slack_lp

    rng = np.random.default_rng(5)
    for _ in range(150):
        G, h, lo, hi = _random_lp(rng)
        ref = linprog(np.array([0, 0, 0, 0, -1.0]), A_ub=np.hstack([G, np.ones((len(h), 1))]), b_ub=h,
                      bounds=[(lo[k], hi[k]) for k in range(4)] + [(None, None)], method="highs-ds")
        smax = -ref.fun
        fast = small_slack_lp(G, h, lo, hi)
        assert fast is not None
        z, s, y = fast
        assert s == pytest.approx(smax, abs=1e-9 * (1 + abs(smax)))
        assert np.all(lo - 1e-12 <= z) and np.all(z <= hi + 1e-12)
        # split the rows into two "leaves" (velocity 0: G's time column is carried by N @ v = 0 only
        # when it is zero, so build leaves with N = G[:, :3] and v chosen to reproduce G[:, 3])
        k = len(h) // 2
        leaves = []
        for rows in (slice(0, k), slice(k, len(h))):
            N, g4 = G[rows, :3], G[rows, 3]
            v = np.linalg.lstsq(N, -g4, rcond=None)[0]
            leaves.append(Leaf("polytope", N, h[rows], np.zeros((1, 3)), v, 0.0))
        Gl = np.vstack([leaves[0].G, leaves[1].G])
        ref2 = linprog(np.array([0, 0, 0, 0, -1.0]), A_ub=np.hstack([Gl, np.ones((len(h), 1))]), b_ub=h,
                       bounds=[(lo[k], hi[k]) for k in range(4)] + [(None, None)], method="highs-ds")
        assert dual_certificate(leaves[0], leaves[1], lo, hi, DEFAULT) >= -ref2.fun - 1e-12


def test_a_wrong_simplex_answer_is_never_trusted():
    """_verify_slack proves verdicts from the numbers it is given: garbage gives 'unresolved'."""
    from monitor.certify.extrusion_null import _verify_slack

    rng = np.random.default_rng(6)
    n_checked = 0
    for _ in range(100):
        G, h, lo, hi = _random_lp(rng)
        z = rng.uniform(lo, hi)
        y = rng.uniform(0, 1, len(h))
        res = _verify_slack(G, h, lo, hi, z, y, DEFAULT, 0.0)
        smax = float(np.min(h - G @ np.clip(z, lo, hi)))
        if res.verdict == "violation":
            assert smax > 0  # the point really has positive slack
        if res.verdict == "certified":  # the random dual really bounds the LP below the band
            from scipy.optimize import linprog

            ref = linprog(np.array([0, 0, 0, 0, -1.0]), A_ub=np.hstack([G, np.ones((len(h), 1))]), b_ub=h,
                          bounds=[(lo[k], hi[k]) for k in range(4)] + [(None, None)], method="highs-ds")
            assert -ref.fun <= DEFAULT.extrusion_slack
        n_checked += 1
    assert n_checked == 100


def test_division_16way_gives_the_same_verdicts_and_bad_value_raises():
    from monitor.bench.extrusion_scenes import WINDOW, agv_translating_bodies
    from monitor.certify.extrusion import search_many
    from monitor.errors import InvalidInputError

    bodies = agv_translating_bodies("straight", True)
    a = search_many(bodies, None, WINDOW, 0.01)
    b = search_many(bodies, None, WINDOW, 0.01, division="16way")
    assert [o.verdict for o in a.outcomes] == [o.verdict for o in b.outcomes]
    assert any(o.verdict == "violation" for o in a.outcomes)
    assert b.stats["regions"] >= a.stats["regions"]
    with pytest.raises(InvalidInputError, match="division"):
        search_many(bodies, None, WINDOW, division="octree")
