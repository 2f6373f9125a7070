"""The paper's examples (Cameron 1990) as tests: sphere and cube (§4.1, App. B), AGV and trays (§5)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from monitor.bench.extrusion_scenes import (
    AGV_BOXES,
    STRAIGHT_FIRST_CONTACT,
    TRAY_BOXES,
    WINDOW,
    agv_scene_xml,
    agv_translating_bodies,
    schedule,
    sphere_cube_pair,
)
from monitor.certify.extrusion import check_pairs, earliest_violation, search_many
from monitor.geometry.distance import shape_distance, shape_distance_batch

NEAR_MISS = 3 * math.sqrt(2) - 4


# ----------------------------------------------------------------------------- sphere and cube

def _sphere_cube_distance(t):
    """Analytic distance: sphere centre minus cube centre is (t - 39, t - 49, 0) (z velocities equal).

    The distance from that offset to the cube [-2, 2]^3 is the norm of the per-axis
    excess max(|q| - 2, 0); on [41, 47] it is sqrt((t - 41)^2 + (47 - t)^2), minimal
    at t = 44 with value 3 sqrt(2); minus the radius 4 gives the near miss.
    """
    t = np.asarray(t, float)
    ex = np.maximum(np.abs(t - 39) - 2, 0)
    ey = np.maximum(np.abs(t - 49) - 2, 0)
    return np.sqrt(ex**2 + ey**2) - 4


def test_sphere_cube_analytic_near_miss():
    t = np.linspace(0, 64, 64001)
    d = _sphere_cube_distance(t)
    assert d.min() == pytest.approx(NEAR_MISS, abs=1e-12)
    assert t[np.argmin(d)] == pytest.approx(44.0)
    out = check_pairs([sphere_cube_pair()], (0.0, 64.0))[0]
    assert out.verdict == "certified"
    assert out.clearance == pytest.approx(NEAR_MISS, abs=1e-9)
    assert out.clearance <= NEAR_MISS + 1e-12  # a lower bound


def test_sphere_cube_sbound_region_matches_paper():
    """App. B closed form: the paper reports a 2 x 2 x 4 x 2 space-time region."""
    out = check_pairs([sphere_cube_pair()], (0.0, 64.0))[0]
    span = out.info["stats"]["spans"][0]
    (t_lo, t_hi), = span["time_bounds"]
    assert t_lo == pytest.approx(43.0, abs=1e-9) and t_hi == pytest.approx(45.0, abs=1e-9)
    dims = span["sbound_regions"][0]
    np.testing.assert_allclose(dims, [2, 2, 4, 2], atol=1e-9)
    assert span["frame_velocity"] == [0.0, 0.0, 1.0]  # z measured in the co-moving frame


def test_sphere_cube_with_margin_gives_exact_first_contact():
    margin = 0.25  # > 3 sqrt(2) - 4: now a violation
    out = check_pairs([sphere_cube_pair()], (0.0, 64.0), margin=margin)[0]
    assert out.verdict == "violation"
    # first t in [41, 47] with (t - 41)^2 + (47 - t)^2 = (4 + margin)^2
    r2 = (4 + margin) ** 2
    a, b, c = 2.0, -2 * (41 + 47), 41**2 + 47**2 - r2
    t_first = (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    assert out.info["earliest_time"] == pytest.approx(t_first, abs=64 * 1e-9)
    assert _sphere_cube_distance(out.witness_time) < margin
    assert t_first <= out.witness_time <= 44.0


@pytest.mark.parametrize("facets", [6, 16])
def test_sphere_cube_circumscribed_polytope(facets):
    """A circumscribed polytope may over-approximate; the verdict must be consistent with it."""
    pair = sphere_cube_pair(sphere_as_polytope=facets)
    err = pair.shape_a.approx_error
    assert err > 0
    out = check_pairs([pair], (0.0, 64.0))[0]
    if out.verdict == "certified":
        # the polytope contains the sphere: its clearance is at most the sphere's
        assert NEAR_MISS - err - 1e-9 <= out.clearance <= NEAR_MISS + 1e-9
    else:
        assert out.verdict == "violation"
        assert err >= NEAR_MISS  # only possible when the over-approximation exceeds the gap


# ----------------------------------------------------------------------------- AGV and trays

def test_agv_scene_files_match_generator():
    from monitor._paths import models_dir

    d = models_dir() / "agv_trays"
    assert (d / "scene.xml").read_text() == agv_scene_xml(False)
    assert (d / "scene_skewed.xml").read_text() == agv_scene_xml(True)
    assert len(AGV_BOXES) == 19 and len(TRAY_BOXES) == 10  # the paper's primitive counts


@pytest.mark.parametrize("skewed", [False, True])
def test_agv_mjcf_geometry_matches_bodies(skewed):
    mujoco = pytest.importorskip("mujoco")
    from monitor._paths import models_dir

    f = "scene_skewed.xml" if skewed else "scene.xml"
    m = mujoco.MjModel.from_xml_path(str(models_dir() / "agv_trays" / f))
    d = mujoco.MjData(m)
    for name in ("straight", "weaving"):
        s = schedule(name)
        bodies = agv_translating_bodies(name, skewed)
        for k in range(len(s["times"])):
            d.qpos[:] = s["qpos"][k]
            mujoco.mj_kinematics(m, d)
            for b in bodies[:2]:
                for g, sh in zip(b.geom_names, b.shapes):
                    P = sh.points @ b.R.T + b.origins[k]
                    gid = m.geom(g).id
                    R = d.geom_xmat[gid].reshape(3, 3)
                    local = (P - d.geom_xpos[gid]) @ R
                    np.testing.assert_allclose(np.abs(local), np.broadcast_to(m.geom_size[gid], local.shape),
                                               atol=1e-12)


@pytest.mark.parametrize("skewed", [False, True])
def test_agv_straight_collision_earliest_witness(skewed):
    res = search_many(agv_translating_bodies("straight", skewed), None, WINDOW)
    e = earliest_violation(res.outcomes)
    assert e is not None
    assert tuple(e.info["geoms"]) == ("crate_top", "plate1")
    assert abs(e.info["earliest_time"] - STRAIGHT_FIRST_CONTACT) <= 1e-9 * (WINDOW[1] - WINDOW[0])
    # the reported witness time is a real overlap (exact static distance), just after first contact
    assert STRAIGHT_FIRST_CONTACT < e.witness_time < STRAIGHT_FIRST_CONTACT + 0.1
    bodies = {b.name: b for b in agv_translating_bodies("straight", skewed)}
    A, B = bodies["agv"], bodies["trays"]
    sa = A.shapes[A.geom_names.index("crate_top")]
    sb = B.shapes[B.geom_names.index("plate1")]

    def pose(b, t):
        return b.R, np.array([np.interp(t, b.times, b.origins[:, k]) for k in range(3)])

    dist = shape_distance(sa, pose(A, e.witness_time), sb, pose(B, e.witness_time))
    assert dist.upper < 0
    # before the first contact every pair is clear (sampled, exact static distances)
    assert shape_distance(sa, pose(A, STRAIGHT_FIRST_CONTACT - 1e-6), sb,
                          pose(B, STRAIGHT_FIRST_CONTACT - 1e-6)).lower > 0
    others = [o for o in res.outcomes if o.verdict == "violation"]
    assert all(o.info["earliest_time"] >= e.info["earliest_time"] for o in others)


def test_agv_straight_sbound_stage_statistics():
    """Paper: S-bounds keep a 1.33 s sub-span of 20 s and 5 of 29 primitives after 2 passes."""
    res = search_many(agv_translating_bodies("straight", floor=False), None, WINDOW)
    span = res.stats["spans"][0]
    (t_lo, t_hi), = span["time_bounds"]
    assert t_lo == pytest.approx(STRAIGHT_FIRST_CONTACT, abs=1e-6)  # x faces meet
    assert t_hi == pytest.approx(11.2, abs=1e-6)  # y ranges part
    assert span["leaves_in"] == 29
    assert span["leaves_out"] <= 5
    assert span["passes"] <= 4


@pytest.mark.parametrize("skewed", [False, True])
def test_agv_weaving_certified_narrow_miss(skewed):
    bodies = agv_translating_bodies("weaving", skewed)
    res = search_many(bodies, None, WINDOW)
    assert all(o.verdict == "certified" for o in res.outcomes)
    clr = {p: o.clearance for p, o in zip(res.pairs, res.outcomes)}
    assert clr[("rail_l", "plate1")] == pytest.approx(0.01, abs=1e-9)
    assert clr[("rail_r", "plate1")] == pytest.approx(0.01, abs=1e-9)
    assert clr[("cab", "plate1")] == pytest.approx(0.05, abs=1e-9)
    assert min(clr.values()) == pytest.approx(0.005, abs=1e-9)  # the floor
    if not skewed:
        # paper: aligned paths and objects -> the S-bound stage alone decides agv/trays
        for span in res.stats["spans"]:
            assert span["body_pairs_pruned"] >= 1
        assert res.stats["lps"] == 0
    # independent check of the narrow pairs: dense exact static distances, Lipschitz margin
    by = {b.name: b for b in bodies}
    A, B = by["agv"], by["trays"]
    ts = np.linspace(*WINDOW, 8001)
    h = ts[1] - ts[0]
    vmax = 1.25 + 0.5  # fastest relative speed (m/s)

    def poses(b):
        p = np.stack([np.interp(ts, b.times, b.origins[:, k]) for k in range(3)], axis=1)
        return np.broadcast_to(b.R, (len(ts), 3, 3)), p

    for ga, gb in [("rail_l", "plate1"), ("rail_r", "plate1"), ("cab", "plate1"), ("crate", "plate1")]:
        lo, up = shape_distance_batch(A.shapes[A.geom_names.index(ga)], poses(A),
                                      B.shapes[B.geom_names.index(gb)], poses(B))
        assert lo.min() - vmax * h / 2 > 0  # clear between samples too
        assert clr[(ga, gb)] <= up.min() + 1e-12  # the checker's clearance is a lower bound


# ----------------------------------------------------------------------------- via the engine (MJCF)

@pytest.mark.parametrize("skewed", [False, True])
def test_agv_mjcf_through_engine(skewed):
    mujoco = pytest.importorskip("mujoco")
    from monitor._paths import models_dir
    from monitor.certify.engine import certify
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    f = "scene_skewed.xml" if skewed else "scene.xml"
    m = mujoco.MjModel.from_xml_path(str(models_dir() / "agv_trays" / f))
    scene = Scene.from_model(m, pairs="all")
    s = schedule("straight")
    cert = certify(scene, Plan(s["times"], s["qpos"], model=m), method="auto")
    assert cert.verdict == "violation"
    assert cert.witness.geoms == ("crate_top", "plate1")
    assert cert.earliest_time == pytest.approx(STRAIGHT_FIRST_CONTACT, abs=1e-9 * 20)
    assert cert.stats["checker_mix"].get("extrusion", 0) > 0
    assert cert.stats["checker_mix"].get("toleranced", 0) == 0
    s = schedule("weaving")
    cert = certify(scene, Plan(s["times"], s["qpos"], model=m), method="auto")
    assert cert.verdict == "certified"
    assert cert.clearance == pytest.approx(0.005, abs=1e-9)
