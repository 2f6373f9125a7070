"""Vectorised broad phase (monitor.certify.broadphase) and the engine's cull on many bodies.

Oracles: dense exact static distances (shape_distance upper bounds at 201 times, which a
certified lower bound can never exceed), an explicit per-pair loop over the sphere arrays,
and certify() on the same scene with an explicit pair subset.
"""

import json

import mujoco
import numpy as np

from monitor.certify.broadphase import halfspace_gaps, sphere_pair_gaps, swept_geom_spheres, swept_sphere_gaps
from monitor.certify.certificate import Certificate, PairResult
from monitor.certify.engine import certify
from monitor.geometry.distance import shape_distance
from monitor.motion.bodymotion import BodyMotion
from monitor.scene import Scene


def _boxes(n: int, pitch: float, step: float, turn: float, seed: int, half: float = 0.08):
    """n free boxes on a grid (pitch m), each moving ``step`` m and turning ``turn`` rad."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(seed)
    k = int(np.ceil(n ** (1 / 3)))
    c = np.array([(i, j, m) for i in range(k) for j in range(k) for m in range(k)][:n], float) * pitch
    body = "".join(f'<body name="b{i}" pos="{x} {y} {z}"><freejoint/>'
                   f'<geom name="g{i}" type="box" size="{half} {half} {half}"/></body>'
                   for i, (x, y, z) in enumerate(c))
    model = mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{body}</worldbody></mujoco>")
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    pos = np.zeros((2, n + 1, 3))
    pos[0, 1:], pos[1, 1:] = c, c + step * d
    quat = np.zeros((2, n + 1, 4))
    quat[..., 0] = 1.0
    ax = rng.normal(size=(n, 3))
    ax /= np.linalg.norm(ax, axis=1, keepdims=True)
    quat[1, 1:] = Rotation.from_rotvec(turn * ax).as_quat(scalar_first=True)
    return model, BodyMotion(np.array([0.0, 0.1]), pos, quat)


def _sampled_min(scene, plan, pairs, n=201):
    ts = np.linspace(plan.t0, plan.t1, n)
    pos, rot = plan.body_poses(ts)
    out = []
    for a, b in pairs:
        ga, gb = scene.geoms[a], scene.geoms[b]
        out.append(min(shape_distance(ga.shape, (rot[k, ga.body_id], pos[k, ga.body_id]),
                                      gb.shape, (rot[k, gb.body_id], pos[k, gb.body_id])).upper
                       for k in range(n)))
    return np.array(out)


def test_vectorised_gaps_are_lower_bounds_of_the_sampled_distance():
    model, plan = _boxes(12, 0.3, 0.15, 1.0, seed=3)
    scene = Scene.from_model(model, pairs="all")
    pid = np.asarray(scene.pair_ids)
    shapes = [g.shape for g in scene.geoms]
    bodies = np.array([g.body_id for g in scene.geoms])
    sph = swept_geom_spheres(plan, shapes, bodies, (plan.t0, plan.t1))
    gaps = sphere_pair_gaps(sph, pid[:, 0], pid[:, 1])
    truth = _sampled_min(scene, plan, pid)
    assert np.all(gaps <= truth), (gaps - truth).max()
    # the spheres are not trivial: some pairs are proven apart, some are not
    assert (gaps > 0).any() and (gaps <= 0).any()


def test_block_size_and_explicit_loop_agree():
    model, plan = _boxes(20, 0.4, 0.1, 0.5, seed=5)
    scene = Scene.from_model(model, pairs="all")
    pid = np.asarray(scene.pair_ids)
    sph = swept_geom_spheres(plan, [g.shape for g in scene.geoms],
                             np.array([g.body_id for g in scene.geoms]), (0.0, 0.1))
    a = sphere_pair_gaps(sph, pid[:, 0], pid[:, 1])
    b = sphere_pair_gaps(sph, pid[:, 0], pid[:, 1], chunk=7)
    loop = np.array([min(np.linalg.norm(sph.centres[t, i] - sph.centres[t, j]) - sph.radii[t, i]
                         - sph.radii[t, j] for t in range(sph.centres.shape[0])) - sph.pad for i, j in pid])
    np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(a, loop, rtol=0, atol=1e-12)
    # the list-of-shapes wrapper gives the same numbers
    c = swept_sphere_gaps(plan, [scene.geoms[i].shape for i in pid[:, 0]],
                          np.array([scene.geoms[i].body_id for i in pid[:, 0]]),
                          [scene.geoms[i].shape for i in pid[:, 1]],
                          np.array([scene.geoms[i].body_id for i in pid[:, 1]]), (0.0, 0.1))
    np.testing.assert_allclose(a, c, rtol=0, atol=1e-12)


def test_non_finite_spheres_never_cull():
    model, plan = _boxes(4, 1.0, 0.05, 0.0, seed=1)
    scene = Scene.from_model(model, pairs="all")
    sph = swept_geom_spheres(plan, [g.shape for g in scene.geoms],
                             np.array([g.body_id for g in scene.geoms]), (0.0, 0.1))
    c = sph.centres.copy()
    c[3, 1] = np.nan
    r = sph.radii.copy()
    r[0, 2] = np.inf
    bad = sph._replace(centres=c, radii=r)
    g = sphere_pair_gaps(bad, np.array([0, 1, 2, 0]), np.array([1, 3, 3, 3]))
    assert g[0] == -np.inf and g[1] == -np.inf and g[2] == -np.inf
    assert g[3] > 0.5


def test_halfspace_gap_closed_form():
    xml = """<mujoco><worldbody><geom name="floor" type="plane" size="5 5 .1"/>
    <body name="s" pos="0 0 1"><freejoint/><geom name="s" type="sphere" size=".1"/></body>
    </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    scene = Scene.from_model(model, pairs="all")
    pos = np.zeros((2, 2, 3))
    pos[0, 1] = (0, 0, 1.0)
    pos[1, 1] = (0.3, 0, 0.6)            # falls 0.4 m: lowest point 0.5 m above the floor
    quat = np.zeros((2, 2, 4))
    quat[..., 0] = 1.0
    plan = BodyMotion(np.array([0.0, 1.0]), pos, quat)
    fl = [g.name for g in scene.geoms].index("floor")
    sp = 1 - fl
    sph = swept_geom_spheres(plan, [g.shape for g in scene.geoms],
                             np.array([g.body_id for g in scene.geoms]), (0.0, 1.0))
    g = halfspace_gaps(plan, sph, [scene.geoms[fl].shape], np.array([scene.geoms[fl].body_id]),
                       np.array([sp]), (0.0, 1.0))
    # true clearance 0.5 m; swept spheres over 8 sub-intervals lose at most one sub-interval of travel
    assert 0.5 - np.hypot(0.3, 0.4) / 8 - 1e-9 <= g[0] <= 0.5
    cert = certify(scene, plan)
    assert cert.verdict == "certified" and cert.pairs[0].method == "culled"
    assert cert.clearance == g[0]


def test_many_sparse_bodies_all_culled_complete_and_round_trip():
    model, plan = _boxes(60, 1.0, 0.05, 0.3, seed=2)
    scene = Scene.from_model(model, pairs="all")
    cert = certify(scene, plan)
    assert cert.verdict == "certified"
    assert len(cert.pairs) == len(scene.candidate_pairs) == 60 * 59 // 2
    assert [p.geoms for p in cert.pairs] == [tuple(p) for p in scene.candidate_pairs]
    assert cert.stats["pairs_culled"] == len(cert.pairs) and cert.stats["checker_mix"] == {"culled": 1770}
    p0 = cert.pairs[0]
    ref = PairResult(p0.geoms, p0.bodies, "certified", "culled", clearance=p0.clearance)
    assert p0 == ref and hash(p0) == hash(ref) and repr(p0) == repr(ref)
    assert cert.clearance == min(p.clearance for p in cert.pairs) > 0.5
    back = Certificate.from_dict(json.loads(json.dumps(cert.to_dict())))
    assert back.pairs == cert.pairs and back.verdict == cert.verdict


def test_dense_scene_verdicts_match_the_per_pair_subsets():
    model, plan = _boxes(8, 0.25, 0.1, 0.4, seed=4)
    scene = Scene.from_model(model, pairs="all")
    cert = certify(scene, plan, epsilon=1e-2)
    assert len(cert.pairs) == 28
    for k in (0, 5, 13, 27):
        one = certify(scene, plan, epsilon=1e-2, pairs=[tuple(scene.candidate_pairs[k])])
        assert one.pairs[0].verdict == cert.pairs[k].verdict
        assert one.pairs[0].method == cert.pairs[k].method
    truth = _sampled_min(scene, plan, np.asarray(scene.pair_ids))
    for p, d in zip(cert.pairs, truth):
        if p.verdict == "certified":
            assert p.clearance <= d
        if p.verdict == "violation":
            assert d < 1e-6
