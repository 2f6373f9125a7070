"""Pair patterns (issue 13): hazards= / allow= resolve to exactly the documented sets.

The model has unnamed geoms (``geom1``, ``geom3``, ``geom5``) addressed as
``body/index``; the expected sets are written out by hand from the module
docstring of :mod:`monitor.pairsel` and MuJoCo's candidate filter.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor.errors import InvalidInputError
from monitor.pairsel import ModelNames, resolve_pattern
from monitor.scene import Scene

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 .1"/>
    <body name="base" pos="0 0 .1">
      <geom type="box" size=".05 .05 .05" group="1"/>
      <body name="arm" pos="0 0 .2">
        <joint name="j1" type="hinge" axis="0 1 0"/>
        <geom name="arm_link" type="capsule" fromto="0 0 0 0 0 .2" size=".02" group="2"/>
        <geom type="sphere" size=".03" pos="0 0 .2" group="2"/>
        <body name="hand" pos="0 0 .25">
          <joint name="j2" type="hinge" axis="1 0 0"/>
          <geom name="hand_geom" type="box" size=".02 .02 .02" group="3"/>
        </body>
      </body>
    </body>
    <body name="object" pos=".5 0 .05">
      <freejoint/>
      <geom type="box" size=".05 .05 .05"/>
    </body>
  </worldbody>
</mujoco>
"""
# geom ids: 0 floor, 1 base/0 (unnamed), 2 arm_link, 3 arm/1 (unnamed), 4 hand_geom, 5 object/0 (unnamed)
CANDIDATES = {("floor", "arm_link"), ("floor", "geom3"), ("floor", "hand_geom"), ("floor", "geom5"),
              ("geom1", "arm_link"), ("geom1", "geom3"), ("geom1", "hand_geom"), ("geom1", "geom5"),
              ("arm_link", "geom5"), ("geom3", "geom5"), ("hand_geom", "geom5")}


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(XML)


@pytest.fixture(scope="module")
def names(model):
    return ModelNames.from_model(model)


@pytest.mark.parametrize("pattern, ids", [
    ("object/0", {5}),
    ("base/0", {1}),
    ("arm/1", {3}),
    ("arm/0", {2}),
    ("arm/**", {2, 3, 4}),
    ("base/**", {1, 2, 3, 4}),
    ("world/**", {0, 1, 2, 3, 4, 5}),
    ("group:2", {2, 3}),
    ("group:0", {0, 5}),
    ("hand*", {4}),           # body "hand" and geom "hand_geom": the same geom
    ("arm*", {2, 3}),         # geom "arm_link" + every geom of body "arm"
    ("geom5", {5}),           # generated names work too
    ("*_link", {2}),
    ("floor", {0}),
])
def test_patterns_resolve_to_documented_geoms(names, pattern, ids):
    assert set(resolve_pattern(names, pattern)) == ids


@pytest.mark.parametrize("pattern", ["nothing", "object/1", "group:7", "nobody/**"])
def test_no_match_lists_the_available_names(names, pattern):
    with pytest.raises(InvalidInputError) as err:
        resolve_pattern(names, pattern, arg="hazards[0]")
    msg = str(err.value)
    assert "hazards[0]" in msg and pattern in msg
    assert "geom5 (object/0)" in msg and "bodies: world, base, arm, hand, object" in msg and "group:3" in msg


def test_candidates_are_mujocos(model):
    assert set(Scene.from_model(model).candidate_pairs) == CANDIDATES


@pytest.mark.parametrize("hazards, expected", [
    (["object/0"], {("floor", "geom5"), ("geom1", "geom5"), ("arm_link", "geom5"), ("geom3", "geom5"),
                    ("hand_geom", "geom5")}),
    ("object/0", {("floor", "geom5"), ("geom1", "geom5"), ("arm_link", "geom5"), ("geom3", "geom5"),
                  ("hand_geom", "geom5")}),
    ([("arm/**", "object/0")], {("arm_link", "geom5"), ("geom3", "geom5"), ("hand_geom", "geom5")}),
    ([("object/0", "arm/**")], {("arm_link", "geom5"), ("geom3", "geom5"), ("hand_geom", "geom5")}),
    ([("arm/**", "floor"), "base/0"], {("floor", "arm_link"), ("floor", "geom3"), ("floor", "hand_geom"),
                                       ("geom1", "arm_link"), ("geom1", "geom3"), ("geom1", "hand_geom"),
                                       ("geom1", "geom5")}),
    (["group:3"], {("floor", "hand_geom"), ("geom1", "hand_geom"), ("hand_geom", "geom5")}),
])
def test_hazards_select_exactly(model, hazards, expected):
    scene = Scene.from_model(model, hazards=hazards)
    assert set(scene.candidate_pairs) == expected
    assert scene.allowed_pairs == ()


def test_allow_removes_with_reason_user(model):
    scene = Scene.from_model(model, allow=["base/0", ("floor", "object/0")])
    allowed = {(a, b): r for a, b, r in scene.allowed_pairs}
    assert allowed == {("geom1", "arm_link"): "User", ("geom1", "geom3"): "User",
                       ("geom1", "hand_geom"): "User", ("geom1", "geom5"): "User", ("floor", "geom5"): "User"}
    assert set(scene.candidate_pairs) == CANDIDATES - set(allowed)


def test_hazards_and_allow_combine(model):
    scene = Scene.from_model(model, hazards=["object/0"], allow=["arm/**"])
    assert set(scene.candidate_pairs) == {("floor", "geom5"), ("geom1", "geom5")}
    assert {(a, b) for a, b, _ in scene.allowed_pairs} == {("arm_link", "geom5"), ("geom3", "geom5"),
                                                           ("hand_geom", "geom5")}


@pytest.mark.parametrize("bad", [3, [("a",)], [("floor", 2)], [""]])
def test_bad_items_are_typed_errors(model, bad):
    with pytest.raises(InvalidInputError, match="hazards"):
        Scene.from_model(model, hazards=bad)


def test_alias_and_labels(names):
    assert names.alias(5) == "object/0" and names.alias(3) == "arm/1"
    assert names.label(5) == "geom5 (object/0)" and names.label(2) == "arm_link"
    assert np.array_equal(names.geom_body, [0, 1, 2, 2, 3, 4])


def test_object_names_equal_mujocos_accessors():
    """Names read from the names buffer equal model.geom(i).name / model.body(i).name, unnamed objects
    get the generated name, non-ASCII names decode."""
    from monitor.pairsel import object_names

    xml = ('<mujoco><worldbody><geom type="plane" size="1 1 .1"/><body name="bø"><freejoint/>'
           '<geom name="ħand" size=".1"/><geom size=".1"/></body><body><freejoint/><geom name="x" size=".1"/>'
           '</body></worldbody></mujoco>')
    m = mujoco.MjModel.from_xml_string(xml)
    assert object_names(m, m.name_geomadr, "geom") == [m.geom(g).name or f"geom{g}" for g in range(m.ngeom)]
    assert object_names(m, m.name_bodyadr, "body") == ["world", "bø", "body2"]
    assert object_names(m, m.name_geomadr, "geom") == ["geom0", "ħand", "geom2", "x"]
