"""The ongoing-contact rule (issue 13): contacts present when a window starts.

Oracles: closed-form signed distances (sphere/plane, sphere/sphere, box/plane) and
the plain start-inside rule of ``certify`` for the same motions.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor import certify
from monitor.certify.ongoing import POLYTOPE_NOTE, shrink_pair
from monitor.errors import InvalidInputError
from monitor.geometry.distance import shape_distance
from monitor.geometry.polytope import box_polytope, capsule_shape, halfspace_shape, sphere_shape
from monitor.motion.bodymotion import BodyMotion
from monitor.scene import Scene

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <geom name="wall" type="box" pos=".3 0 .2" size=".05 .5 .2"/>
    <geom name="table" type="box" pos="-1 0 .05" size=".3 .3 .05"/>
    <body name="ball" pos="0 0 .049"><freejoint/><geom name="ball" type="sphere" size=".05"/></body>
    <body name="crate" pos="-1 0 .149"><freejoint/><geom name="crate" type="box" size=".05 .05 .05"/></body>
    <body name="brick" pos="1 0 .0495"><freejoint/><geom name="brick" type="box" size=".05 .05 .05"/></body>
  </worldbody>
</mujoco>
"""
R = 0.05  # ball radius
TOL = 0.005


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(XML)


def _motion(model, moves):
    """BodyMotion: each named body goes linearly from its model pose to pose + offset (m) over [0, 1]."""
    d = mujoco.MjData(model)
    mujoco.mj_kinematics(model, d)
    pos0 = np.array(d.xpos)
    quat = np.repeat(np.array(d.xquat)[None], 2, axis=0)
    pos = np.repeat(pos0[None], 2, axis=0)
    for name, off in moves.items():
        pos[1, model.body(name).id] += off
    return BodyMotion(np.array([0.0, 1.0]), pos, quat)


def _pair(cert, a, b):
    return next(p for p in cert.pairs if set(p.geoms) == {a, b})


@pytest.mark.parametrize("kind", ["sphere", "capsule", "box"])
def test_shrink_is_exact_against_a_plane(kind):
    """sd(shrunk) = sd(orig) + s: radius first, then the half-space moves (closed form sd = min z)."""
    rng = np.random.default_rng(3)
    shape = {"sphere": sphere_shape(0.002), "capsule": capsule_shape(0.003, 0.1),
             "box": box_polytope(np.array([0.05, 0.04, 0.03]))}[kind]
    plane = halfspace_shape()
    sa, sb, s = shrink_pair(shape, plane, TOL)
    assert s == pytest.approx(TOL, rel=1e-8) and s <= TOL
    assert sa.radius == 0.0 and sb.kind == "halfspace"
    eye = np.eye(3)
    for _ in range(20):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        Rm = np.zeros(9)
        mujoco.mju_quat2Mat(Rm, q)
        X = (Rm.reshape(3, 3), np.array([0.0, 0.0, rng.uniform(-0.04, 0.04)]))
        d0 = shape_distance(shape, X, plane, (eye, np.zeros(3))).distance
        d1 = shape_distance(sa, X, sb, (eye, np.zeros(3))).distance
        assert d1 - d0 == pytest.approx(s, abs=1e-9)
        # independent closed form: lowest core point minus radius
        z = (shape.points @ X[0].T + X[1])[:, 2].min() - shape.radius
        assert d0 == pytest.approx(z, abs=1e-9)


def test_shrink_polytopes_only_partial():
    """Box on box: no radius, no half-space: nothing can be shrunk exactly."""
    b = box_polytope(np.array([0.05, 0.05, 0.05]))
    _, _, s = shrink_pair(b, b, TOL)
    assert s == 0.0
    _, _, s = shrink_pair(sphere_shape(0.001), b, TOL)
    assert s == pytest.approx(0.001, rel=1e-9)


def test_resting_ball_sliding_is_certified_only_with_the_rule(model):
    """Ball penetrating the floor by 1 mm slides 5 cm: plain rule = violation at t0, deepen = certified."""
    scene = Scene.from_model(model, pairs=[("floor", "ball")])
    plan = _motion(model, {"ball": [-0.05, 0.0, 0.0]})
    plain = certify(scene, plan)
    assert plain.verdict == "violation" and plain.witness.time == 0.0
    cert = certify(scene, plan, ongoing="deepen", penetration_tol=TOL)
    assert cert.verdict == "certified", cert.pairs
    assert cert.ongoing == (("floor", "ball"),)
    p = _pair(cert, "floor", "ball")
    assert p.note.startswith("ongoing") and -TOL <= p.clearance <= -0.001 + 1e-9
    assert cert.stats["ongoing"] == 1 and cert.stats["penetration_tol"] == TOL


@pytest.mark.parametrize("sink, verdict", [(0.003, "certified"), (0.006, "violation")])
def test_deepening_beyond_the_tolerance_is_a_violation(model, sink, verdict):
    """Ball sinks from 1 mm to 1 + sink mm: allowed iff 1 mm + sink < 5 mm (closed form sd = z - r)."""
    scene = Scene.from_model(model, pairs=[("floor", "ball")])
    plan = _motion(model, {"ball": [0.0, 0.0, -sink]})
    cert = certify(scene, plan, ongoing="deepen", penetration_tol=TOL)
    assert cert.verdict == verdict
    if verdict == "violation":
        w = cert.witness
        z = plan.body_poses(np.array([w.time]))[0][0, model.body("ball").id, 2]
        assert z - R < -TOL  # the oracle: this instant really is deeper than the tolerance
        assert w.distance == pytest.approx(z - R, abs=2e-3) and w.distance < -TOL + 1e-12


def test_new_hazard_contact_during_an_ongoing_one_is_still_blocked(model):
    """Ball resting on the floor rolls into the wall: the floor pair is ongoing, the wall is a violation."""
    scene = Scene.from_model(model, pairs=[("floor", "ball"), ("wall", "ball")])
    plan = _motion(model, {"ball": [0.3, 0.0, 0.0]})
    cert = certify(scene, plan, ongoing="deepen", penetration_tol=TOL)
    assert cert.verdict == "violation"
    assert set(cert.witness.geoms) == {"wall", "ball"}
    assert _pair(cert, "floor", "ball").verdict == "certified"
    assert _pair(cert, "wall", "ball").note == ""  # judged at full margin
    x = plan.body_poses(np.array([cert.witness.time]))[0][0, model.body("ball").id, 0]
    assert x + R > 0.25  # oracle: the wall's face is at x = 0.25


def test_new_contact_with_margin_while_ongoing(model):
    """With margin 2 cm, coming within 1 cm of the wall is blocked although the floor contact is ongoing."""
    scene = Scene.from_model(model, pairs=[("floor", "ball"), ("wall", "ball")])
    plan = _motion(model, {"ball": [0.25 - R - 0.01, 0.0, 0.0]})
    cert = certify(scene, plan, margin=0.02, ongoing="deepen", penetration_tol=TOL)
    assert cert.verdict == "violation" and set(cert.witness.geoms) == {"wall", "ball"}
    ok = certify(scene, _motion(model, {"ball": [-0.1, 0.0, 0.0]}), margin=0.02, ongoing="deepen")
    assert ok.verdict == "certified"


def test_box_on_plane_uses_the_halfspace(model):
    """Brick 0.5 mm into the floor slides: the plane moves down by the tolerance (exact)."""
    scene = Scene.from_model(model, pairs=[("floor", "brick")])
    cert = certify(scene, _motion(model, {"brick": [0.1, 0.0, 0.0]}), ongoing="deepen", penetration_tol=TOL)
    assert cert.verdict == "certified" and cert.ongoing == (("floor", "brick"),)


def test_box_on_box_is_uncertain_with_the_stated_reason(model):
    """Crate 1 mm into the table box: polytope cores cannot be eroded exactly."""
    scene = Scene.from_model(model, pairs=[("table", "crate")])
    cert = certify(scene, _motion(model, {"crate": [0.05, 0.0, 0.0]}), ongoing="deepen", penetration_tol=TOL)
    assert cert.verdict == "uncertain"
    assert _pair(cert, "table", "crate").note.startswith(POLYTOPE_NOTE)


def test_bad_rule_arguments(model):
    scene = Scene.from_model(model, pairs=[("floor", "ball")])
    plan = _motion(model, {"ball": [0.0, 0.0, 0.0]})
    with pytest.raises(InvalidInputError, match="ongoing"):
        certify(scene, plan, ongoing="ignore")
    with pytest.raises(InvalidInputError, match="penetration_tol"):
        certify(scene, plan, ongoing="deepen", penetration_tol=-1.0)


def test_certificate_json_keeps_notes(model):
    from monitor.certify.certificate import Certificate

    scene = Scene.from_model(model, pairs=[("floor", "ball")])
    cert = certify(scene, _motion(model, {"ball": [-0.05, 0.0, 0.0]}), ongoing="deepen")
    back = Certificate.from_dict(cert.to_dict())
    assert back.ongoing == cert.ongoing and back.pairs[0].note == cert.pairs[0].note


CYL_XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <body name="can" pos="0 0 .058"><freejoint/><geom name="can" type="cylinder" size=".04 .06"/></body>
    <body name="egg" pos=".3 0 .078"><freejoint/><geom name="egg" type="ellipsoid" size=".03 .04 .08"/></body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("body, geom", [("can", "can"), ("egg", "egg")])
def test_ongoing_contact_of_a_curved_geom_goes_through_the_compiled_window(body, geom):
    """A cylinder / ellipsoid resting 2 mm into the floor slides 5 cm (the rule's pair view is packed too).

    Regression: the compiled window kernel read the exact cylinder / ellipsoid of the rule's
    geom copies from the model by their (past-the-end) ids: IndexError from packed.py.
    Closed form: the geom stays 2 mm deep < 5 mm while sliding over the floor; pressed
    1 cm further it reaches 12 mm > 5 mm.
    """
    m = mujoco.MjModel.from_xml_string(CYL_XML)
    scene = Scene.from_model(m, pairs=[("floor", geom)])
    plan = _motion(m, {body: [0.05, 0.0, 0.0]})
    assert certify(scene, plan).verdict != "certified"  # plain rule: in contact at t0
    cert = certify(scene, plan, ongoing="deepen", penetration_tol=TOL)
    assert cert.verdict == "certified", cert.pairs
    sunk = _motion(m, {body: [0.05, 0.0, -0.01]})  # pressed 1 cm further in: 12 mm > 5 mm
    assert certify(scene, sunk, ongoing="deepen", penetration_tol=TOL).verdict == "violation"
