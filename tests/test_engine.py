"""monitor.certify end to end on small MuJoCo scenes (oracle: dense exact static distances)."""

import json

import mujoco
import numpy as np
import pytest

from monitor.certify.certificate import Certificate
from monitor.certify.common import Budget
from monitor.certify.engine import certify
from monitor.errors import InvalidInputError, ModelMismatchError
from monitor.geometry.distance import shape_distance
from monitor.motion.plan import Plan
from monitor.scene import Scene
from monitor.tolerances import Tolerances

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 .1"/>
    <geom name="table" type="box" size=".5 .5 .05" pos="0 0 .5"/>
    <body name="arm" pos="0 0 1.0">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom name="link" type="capsule" fromto="0 0 0 .6 0 0" size=".04"/>
      <body name="hand" pos=".6 0 0">
        <joint name="h2" type="hinge" axis="0 1 0"/>
        <geom name="handbox" type="box" size=".05 .05 .05" pos=".1 0 0"/>
      </body>
    </body>
    <body name="cube" pos="2 0 0.3">
      <freejoint/>
      <geom name="cube" type="box" size=".1 .1 .1"/>
    </body>
    <body name="ball" pos="-1.5 0 0.3">
      <freejoint/>
      <geom name="ball" type="sphere" size=".02"/>
    </body>
  </worldbody>
</mujoco>"""


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(XML)


@pytest.fixture(scope="module")
def scene(model):
    return Scene.from_model(model, pairs="all")


def _plan(model, arm_end=(0.0, 0.0), cube_end=None, ball_end=None, T=0.5):
    Q = np.stack([model.qpos0.copy(), model.qpos0.copy()])
    Q[1, 0], Q[1, 1] = arm_end
    if cube_end is not None:
        Q[1, 2:5] = cube_end
    if ball_end is not None:
        Q[1, 9:12] = ball_end
    return Plan(np.array([0.0, T]), Q, model)


def _oracle_min(scene, plan, n=801):
    """Min over sampled times and all candidate pairs of the exact distance upper bound."""
    ts = np.linspace(plan.t0, plan.t1, n)
    pos, rot = plan.body_poses(ts)
    best = np.inf
    for a, b in scene.pair_ids:
        ga, gb = scene.geoms[int(a)], scene.geoms[int(b)]
        for k in range(0, n, 4):
            d = shape_distance(ga.shape, (rot[k, ga.body_id], pos[k, ga.body_id]),
                               gb.shape, (rot[k, gb.body_id], pos[k, gb.body_id]))
            best = min(best, d.upper)
    return best


def test_clear_hinge_motion_is_certified(scene, model):
    plan = _plan(model, (0.3, 0.2))
    cert = certify(scene, plan, margin=0.0, epsilon=1e-3)
    assert cert.verdict == "certified"
    assert cert.earliest_time is None and cert.witness is None
    assert cert.stats["pairs"] == len(scene.candidate_pairs)
    assert cert.stats["pairs_culled"] >= 1
    dmin = _oracle_min(scene, plan)
    assert dmin > 0
    assert 0.0 <= cert.clearance <= dmin + 1e-12   # certified lower bound, never above the truth


def test_colliding_hinge_motion_is_a_confirmed_violation(scene, model):
    plan = _plan(model, (1.0, 0.5))
    cert = certify(scene, plan, margin=0.0, epsilon=1e-3)
    assert cert.verdict == "violation"
    w = cert.witness
    assert w is not None and set(w.geoms) <= {"table", "link", "handbox"}
    ga, gb = scene.geom(w.geoms[0]), scene.geom(w.geoms[1])
    pos, rot = plan.body_poses(np.array([w.time]))
    d = shape_distance(ga.shape, (rot[0, ga.body_id], pos[0, ga.body_id]),
                       gb.shape, (rot[0, gb.body_id], pos[0, gb.body_id]))
    assert d.upper < 0
    assert cert.earliest_time <= w.time
    bad = [p for p in cert.pairs if p.verdict != "certified"]
    assert all(p.intervals for p in bad)
    # round trip through JSON
    back = Certificate.from_dict(json.loads(json.dumps(cert.to_dict())))
    assert back.verdict == cert.verdict and back.witness.geoms == w.geoms


def test_margin_turns_near_miss_into_violation(scene, model):
    plan = _plan(model, (0.3, 0.2))
    gap = _oracle_min(scene, plan)
    cert = certify(scene, plan, margin=gap + 0.05, epsilon=1e-3)
    assert cert.verdict == "violation"
    assert cert.witness.distance < gap + 0.05


def test_translating_cube_goes_to_extrusion_and_method_forcing(scene, model):
    plan = _plan(model, (0.0, 0.0), cube_end=(0.2, 0.0, 0.61))   # slides into the table
    cert = certify(scene, plan)
    assert cert.verdict == "violation"
    assert "extrusion" in cert.stats["checker_mix"]
    cert_t = certify(scene, plan, method="toleranced")
    assert cert_t.verdict == "violation"
    assert "extrusion" not in cert_t.stats["checker_mix"]
    with pytest.raises(InvalidInputError):
        certify(scene, _plan(model, (0.5, 0.0)), method="extrusion")


def test_start_pose_containment_is_a_violation(scene, model):
    # the small ball starts inside the table and moves inside it: no boundary ever touches
    Q = np.stack([model.qpos0.copy(), model.qpos0.copy()])
    Q[:, 9:12] = [[0.1, 0.0, 0.5], [0.2, 0.05, 0.5]]
    plan = Plan(np.array([0.0, 0.5]), Q, model)
    cert = certify(scene, plan, method="toleranced", pairs=[("table", "ball")])
    assert cert.verdict == "violation"
    assert cert.pairs[0].method == "static" and cert.witness.time == 0.0


def test_budget_never_certifies(scene, model):
    plan = _plan(model, (0.75, 0.0))
    cert = certify(scene, plan, budget=Budget(tests=1), method="toleranced")
    assert cert.verdict in ("uncertain", "violation")
    near = _plan(model, (0.65, 0.0))           # clear by ~6 mm, needs depth ~6
    full = certify(scene, near)
    assert full.verdict == "certified" and full.stats["max_depth"] >= 3
    cut = certify(scene, near, budget={"tests": 1})
    assert cut.verdict == "uncertain"
    assert cut.stats["budget_exhausted"]
    assert any(p.verdict == "uncertain" and p.method == "toleranced" for p in cut.pairs)


def test_pairs_subset_and_window(scene, model):
    plan = _plan(model, (1.0, 0.5))
    sub = certify(scene, plan, pairs=[("link", "table")], window=(0.0, 0.25))
    assert [p.geoms for p in sub.pairs] == [("table", "link")]
    assert sub.window == (0.0, 0.25)


@pytest.mark.parametrize("kw, err", [
    ({"window": (0.2, 0.2)}, InvalidInputError),
    ({"window": (0.3, 0.1)}, InvalidInputError),
    ({"window": (0.0, 2.0)}, InvalidInputError),
    ({"epsilon": 0.0}, InvalidInputError),
    ({"epsilon": -1e-3}, InvalidInputError),
    ({"epsilon": float("nan")}, InvalidInputError),
    ({"margin": -0.1}, InvalidInputError),
    ({"margin": float("nan")}, InvalidInputError),
    ({"method": "magic"}, InvalidInputError),
    ({"pairs": [("floor", "nosuchgeom")]}, InvalidInputError),
])
def test_bad_input_raises_typed_errors(scene, model, kw, err):
    with pytest.raises(err):
        certify(scene, _plan(model), **kw)


def test_plan_of_another_model_is_rejected(scene):
    other = mujoco.MjModel.from_xml_string(XML.replace('size=".04"', 'size=".05"'))
    with pytest.raises(ModelMismatchError):
        certify(scene, _plan(other))
    same = mujoco.MjModel.from_xml_string(XML)   # same XML, different object: accepted
    assert certify(scene, _plan(same)).verdict == "certified"


def test_public_entry_point_is_monitor_certify(scene, model):
    import monitor

    cert = monitor.certify(scene, _plan(model, (0.3, 0.2)), margin=0.0, epsilon=1e-3, method="toleranced")
    assert cert.verdict == "certified"
    assert cert.clearance >= 0.0


def test_swept_sphere_gap_is_a_lower_bound_of_the_sampled_distance():
    from monitor.certify.broadphase import swept_sphere_gaps
    from monitor.geometry.distance import shape_distance_batch
    from monitor.geometry.polytope import box_polytope, capsule_shape, halfspace_shape
    from monitor.motion.bodymotion import BodyMotion

    rng = np.random.default_rng(7)
    shapes = [box_polytope(np.array([0.1, 0.2, 0.05])), capsule_shape(0.05, 0.2), halfspace_shape()]
    checked = 0
    for _ in range(20):
        K = 3
        pos = np.zeros((K, 3, 3))
        quat = np.tile([1.0, 0, 0, 0], (K, 3, 1))
        pos[:, 1] = rng.normal(size=(K, 3)) * 0.5 + [0, 0, 0.6]
        pos[:, 2] = rng.normal(size=(K, 3)) * 0.5 + [0, 0, 0.6]
        q = rng.normal(size=(K, 2, 4))
        quat[:, 1:] = q / np.linalg.norm(q, axis=2, keepdims=True)
        bm = BodyMotion(np.array([0.0, 0.5, 1.0]), pos, quat)
        sa, sb = [shapes[0], shapes[1], shapes[0]], [shapes[1], shapes[0], shapes[2]]
        ba, bb = np.array([1, 2, 1]), np.array([2, 1, 0])
        gaps = swept_sphere_gaps(bm, sa, ba, sb, bb, (0.0, 1.0))
        ts = np.linspace(0, 1, 401)
        P, R = bm.body_poses(ts)
        for k in range(3):
            _, up = shape_distance_batch(sa[k], (R[:, ba[k]], P[:, ba[k]]), sb[k], (R[:, bb[k]], P[:, bb[k]]))
            assert gaps[k] <= up.min() + 1e-12
            checked += np.isfinite(gaps[k])
    assert checked > 20


def test_touching_translating_boxes_are_uncertain_not_violation():
    """Two boxes resting face to face (distance exactly 0, margin 0) while one slides along
    the shared face. Touching is not a collision (regularised semantics: never "violation"),
    and 0 is not > margin, so it cannot be certified either: "uncertain". The start-pose
    rule does not demote extruded pairs; the engine's stricter extrusion margin does.
    A clear gap is certified by the extrusion checker, and a margin above the gap is a
    confirmed violation at t0."""
    import mujoco

    import monitor

    def scene_plan(gap):
        xml = f"""<mujoco><worldbody>
          <body name="base"><geom name="lower" type="box" size="0.5 0.5 0.5" pos="0 0 -0.5"/></body>
          <body name="slider"><joint name="sx" type="slide" axis="1 0 0"/>
            <geom name="upper" type="box" size="0.1 0.1 0.1" pos="0 0 {0.1 + gap!r}"/></body>
        </worldbody></mujoco>"""
        model = mujoco.MjModel.from_xml_string(xml)
        plan = monitor.Plan([0.0, 1.0], [[0.0], [0.2]], model=model)
        return monitor.Scene.from_model(model, pairs="all"), plan

    scene, plan = scene_plan(0.0)
    cert = monitor.certify(scene, plan, margin=0.0, method="auto")
    assert cert.verdict == "uncertain" and cert.pairs[0].method == "extrusion", cert.pairs
    scene, plan = scene_plan(1e-6)
    cert = monitor.certify(scene, plan, margin=0.0, method="auto")
    assert cert.verdict == "certified" and cert.pairs[0].method == "extrusion", cert.pairs
    assert cert.clearance <= 1e-6 + 1e-12
    cert = monitor.certify(scene, plan, margin=1e-3, method="auto")
    assert cert.verdict == "violation" and cert.witness.time == 0.0



def _covered(inner, outer):
    """Every interval of ``inner`` lies inside one merged interval of ``outer``."""
    return all(any(a <= lo and hi <= b for a, b in outer) for lo, hi in inner)


def test_frontier_over_cap_matches_a_per_pair_reference():
    from monitor.certify.toleranced import frontier_over_cap

    rng = np.random.default_rng(11)
    pair = rng.integers(0, 4, 300)
    t0 = rng.random(300)
    go = rng.random(300) < 0.7
    for cap in (0, 1, 5, 40, 1000):
        got = frontier_over_cap(pair, t0, go, cap)
        ref = np.zeros(300, bool)
        if cap > 0:
            for p in range(4):
                idx = [i for i in np.argsort(t0, kind="stable") if pair[i] == p and go[i]]
                ref[idx[cap:]] = True
        np.testing.assert_array_equal(got, ref)


def test_frontier_cap_keeps_every_uncapped_interval_unresolved(scene, model):
    from monitor.certify import toleranced

    plan = _plan(model, (1.0, 0.5))                  # link and handbox sweep through the table
    items = []
    for a, b in (("table", "link"), ("table", "handbox")):
        ga, gb = scene.geom(a), scene.geom(b)
        items.append((ga.shape, ga.body_id, gb.shape, gb.body_id))
    static = ~np.asarray(plan.moving_bodies(), bool)
    free = toleranced.check_pairs(plan, items, (plan.t0, plan.t1), 0.0, 1e-4,
                                  Tolerances(max_frontier=0), static=static)
    capped = toleranced.check_pairs(plan, items, (plan.t0, plan.t1), 0.0, 1e-4,
                                    Tolerances(max_frontier=2), static=static)
    assert any(o.info["frontier_capped"] > 0 for o in capped)
    assert all(o.info["frontier_capped"] == 0 for o in free)
    for f, c in zip(free, capped):
        assert f.verdict == "unresolved" and c.verdict == "unresolved"
        assert _covered(f.intervals, c.intervals)           # the cap only widens what is unresolved
        assert c.info["items"] <= f.info["items"]


def test_frontier_cap_never_certifies(scene, model, monkeypatch):
    # the arm dips towards the table twice (clear by ~6 mm each time): two separate
    # sub-intervals of the same pairs fire at the deeper levels
    # (the compiled whole-shape stage would certify these pairs before the fat-feature
    # checker runs; switch it off so the frontier cap of that checker is what is tested)
    from monitor.certify import kernels
    monkeypatch.setattr(kernels, "whole_shape_stage", lambda scene, plan, pairs, *a, **k: [None] * len(pairs))
    Q = np.stack([model.qpos0.copy()] * 5)
    Q[:, 0] = [0.0, 0.65, 0.0, 0.65, 0.0]
    plan = Plan(np.linspace(0.0, 1.0, 5), Q, model)
    assert _oracle_min(scene, plan) > 0
    full = certify(scene, plan, method="toleranced")
    assert full.verdict == "certified"
    cut = certify(scene, plan, method="toleranced", tolerances=Tolerances(max_frontier=1))
    assert cut.verdict == "uncertain"                # no witness exists: the motion is clear
    bad = [p for p in cut.pairs if p.verdict != "certified"]
    assert bad and all(p.method == "toleranced" and p.intervals for p in bad)
    # the earliest items are kept: the first dip is resolved, the rest is left unresolved
    assert all(p.intervals[0][0] >= 0.25 for p in bad)
    hit = certify(scene, _plan(model, (1.0, 0.5)), method="toleranced", epsilon=1e-4,
                  tolerances=Tolerances(max_frontier=1))
    assert hit.verdict == "violation"


def test_cylinder_witness_needs_the_true_shape_to_violate():
    """A sphere 2 mm outside a true cylinder, but overlapping its circumscribed prism (corner
    8 mm outside at 8 facets): not a confirmed violation at margin 0; a confirmed one at a
    margin far above the true distance."""
    import mujoco

    import monitor

    r = 0.1
    probe = mujoco.MjModel.from_xml_string(
        f'<mujoco><worldbody><geom name="cyl" type="cylinder" size="{r} 0.2"/></worldbody></mujoco>')
    prism = monitor.Scene.from_model(probe, pairs="all", facets=8).geom("cyl").shape.points
    k = int(np.argmax(prism[:, 0] * 0.3 + prism[:, 1]))  # some prism corner
    u = prism[k] * [1.0, 1.0, 0.0]
    u /= np.linalg.norm(u)
    c = (r + 0.002 + 0.01) * u  # sphere (radius 1 cm) surface 2 mm outside the true cylinder
    xml = f"""<mujoco><worldbody>
      <geom name="cyl" type="cylinder" size="{r} 0.2"/>
      <body name="b" pos="{float(c[0])!r} {float(c[1])!r} 0"><joint name="x" type="slide"
        axis="{float(u[0])!r} {float(u[1])!r} 0"/>
        <geom name="s" type="sphere" size="0.01"/></body>
    </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    scene = monitor.Scene.from_model(model, pairs="all", facets=8)
    assert scene.approximations["cyl"] > 0.006  # the prism corner reaches past the sphere surface
    plan = monitor.Plan([0.0, 1.0], [[0.0], [1e-3]], model=model)  # moves 1 mm outward
    cert = monitor.certify(scene, plan, margin=0.0)
    assert cert.verdict != "violation", cert.witness  # true distance >= 2 mm > margin 0
    cert = monitor.certify(scene, plan, margin=0.05)  # true distance <= 3 mm << 5 cm - error
    assert cert.verdict == "violation"


def test_no_candidate_pairs_is_certified_with_complete_stats(scene, model):
    plan = _plan(model, (0.0, 0.0))
    full = certify(scene, plan)
    empty = certify(scene, plan, pairs=[])
    assert empty.verdict == "certified" and empty.pairs == () and empty.clearance == float("inf")
    assert set(empty.stats) == set(full.stats)
