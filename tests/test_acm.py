"""Allowed-contact matrix (issue 13): reasons, file format round trip, Scene/certificate plumbing, CLIs.

Reasons are checked against a model built so that each is known in closed form:
``link1`` is hinged on the top face of ``post`` (the anchor lies in both: in
contact in every configuration, so Default at the reference pose), ``box`` rests
on the floor, the sphere ``far`` slides inside ``wall`` over its whole joint
range but the keyframe puts it outside (Always, not Default), and ``far`` can
never reach ``link2`` (Never).
"""

from __future__ import annotations

import json
import warnings

import mujoco
import numpy as np
import pytest

from monitor import certify
from monitor._paths import models_dir
from monitor.acm import ACM, Reason, apply_policy, auto_acm, compute_acm
from monitor.certify.certificate import Certificate
from monitor.cli import main
from monitor.errors import InvalidInputError, ModelMismatchError
from monitor.motion.bodymotion import BodyMotion
from monitor.pairsel import ModelNames
from monitor.scene import Scene

XML = """
<mujoco>
  <compiler angle="radian"/>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <geom name="post" type="box" pos="0 0 .25" size=".05 .05 .25"/>
    <geom name="wall" type="box" pos="-1 0 1" size=".2 .2 .2"/>
    <body name="link1" pos="0 0 .5">
      <joint name="j1" type="hinge" axis="0 0 1" range="-3 3" limited="true"/>
      <geom name="link1" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
      <body name="link2" pos=".3 0 0">
        <joint name="j2" type="hinge" axis="0 1 0" range="-3 3" limited="true"/>
        <geom name="link2" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
      </body>
    </body>
    <body name="box" pos="1 0 .05">
      <freejoint/>
      <geom type="box" size=".05 .05 .05"/>
    </body>
    <body name="far" pos="-1 0 1">
      <joint name="s" type="slide" axis="1 0 0" range="-.1 .1" limited="true"/>
      <geom name="far" type="sphere" size=".05"/>
    </body>
  </worldbody>
  <keyframe>
    <key qpos="0 0  1 0 .05 1 0 0 0  .5"/>
  </keyframe>
</mujoco>
"""
PAIRS = [("link1", "link2"), ("post", "link1"), ("floor", "box/0"), ("far", "wall"), ("far", "link2"),
         ("post", "link2")]


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(XML)


@pytest.fixture(scope="module")
def acm(model):
    ids = {n: i for i, n in enumerate(ModelNames.from_model(model).geom_names)}
    ids["box/0"] = ids["geom5"]
    return compute_acm(model, pairs=[(ids[a], ids[b]) for a, b in PAIRS], samples=64, settle=0.0)


def test_reasons(acm):
    assert acm.reason("link1", "link2") is Reason.ADJACENT
    # link1's capsule sinks 3 cm into the post at every angle: a design overlap, deeper than a
    # resting contact (RESTING_MAX_DEPTH), so it is Always (sampled), not Default
    assert acm.reason("post", "link1") is Reason.ALWAYS
    assert acm.reason("floor", "geom5") is Reason.DEFAULT
    assert acm.reason("far", "wall") is Reason.ALWAYS
    assert acm.reason("link2", "far") is Reason.NEVER
    assert acm.reason("post", "link2") is None  # folded back (|j2| > ~2.7) it touches: not Never
    assert acm.skipped == {("link1", "link2"), ("link1", "post"), ("floor", "geom5"), ("far", "wall")}


def test_settling_adds_resting_contacts(model):
    """A box 1 cm above the floor at the reference pose lands on it within the settle time."""
    m = mujoco.MjModel.from_xml_string(XML.replace('<key qpos="0 0  1 0 .05', '<key qpos="0 0  1 0 .06'))
    g = ModelNames.from_model(m).geom_names.index("geom5")
    pairs = [(0, g)]
    assert compute_acm(m, pairs=pairs, samples=0, settle=0.0).reason("floor", "geom5") is None
    assert compute_acm(m, pairs=pairs, samples=0, settle=0.3).reason("floor", "geom5") is Reason.DEFAULT


def test_file_round_trip(tmp_path, model, acm):
    names = ModelNames.from_model(model)
    path = tmp_path / "acm.json"
    acm.save(path, names)
    text = path.read_text()
    assert '"box/0"' in text and "geom5" not in text  # unnamed geoms by body/index
    assert text.count("\n") >= len(acm.entries) + 6  # one entry per line: diffable
    doc = json.loads(text)
    assert doc["format"] == "monitor-acm" and doc["version"] == 1
    back = ACM.load(path, names)
    assert back.entries == acm.entries and back.model_hash == acm.model_hash
    # the same pair set in a scene built from the file and from the object
    s1 = Scene.from_model(model, pairs="all", allowed=path)
    s2 = Scene.from_model(model, pairs="all", allowed=acm)
    assert s1.candidate_pairs == s2.candidate_pairs and s1.allowed_pairs == s2.allowed_pairs


@pytest.mark.parametrize("doc, err, match", [
    ({"format": "x", "version": 1, "entries": []}, InvalidInputError, "format"),
    ({"format": "monitor-acm", "version": 9, "entries": []}, InvalidInputError, "version"),
    ({"format": "monitor-acm", "version": 1, "entries": {}}, InvalidInputError, "entries"),
    ({"format": "monitor-acm", "version": 1, "entries": [{"geoms": ["post"]}]}, InvalidInputError,
     r"entries\[0\]"),
    ({"format": "monitor-acm", "version": 1, "entries": [{"geoms": ["post", "link1"], "reason": "Maybe"}]},
     InvalidInputError, "reason"),
    ({"format": "monitor-acm", "version": 1, "entries": [{"geoms": ["post", "ghost"], "reason": "User"}]},
     ModelMismatchError, "ghost"),
])
def test_malformed_files(tmp_path, model, doc, err, match):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(err, match=match):
        Scene.from_model(model, allowed=path)


def test_not_json(tmp_path, model):
    path = tmp_path / "bad.json"
    path.write_text("{not json")
    with pytest.raises(InvalidInputError, match="not valid JSON"):
        Scene.from_model(model, allowed=path)


def test_certificate_lists_allowed_pairs(model, acm):
    scene = Scene.from_model(model, pairs="all", allowed=acm)
    allowed = {(a, b) for a, b, _ in scene.allowed_pairs}
    # pairs="all" has no parent-child pairs, so no Adjacent entry applies
    assert {tuple(sorted(p)) for p in allowed} == {("link1", "post"), ("far", "wall"), ("floor", "geom5")}
    assert not allowed & set(scene.candidate_pairs)
    assert ("far", "link2") in {tuple(sorted(p)) for p in scene.candidate_pairs}  # Never: still checked
    d = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, d, 0)
    mujoco.mj_kinematics(model, d)
    pos = np.repeat(np.array(d.xpos)[None], 2, axis=0)
    quat = np.repeat(np.array(d.xquat)[None], 2, axis=0)
    cert = certify(scene, BodyMotion(np.array([0.0, 1.0]), pos, quat))
    assert cert.allowed == scene.allowed_pairs
    assert {r for *_x, r in cert.allowed} <= {"Adjacent", "Default", "Always"}
    assert Certificate.from_dict(json.loads(json.dumps(cert.to_dict()))).allowed == cert.allowed


def test_python_lists_and_user_reason(model):
    scene = Scene.from_model(model, pairs="all", allowed=[("post", "link1"), ("far", "box/0", "Always")])
    assert dict(((a, b), r) for a, b, r in scene.allowed_pairs) == {("post", "link1"): "User",
                                                                   ("geom5", "far"): "Always"}


def test_auto_is_cached(model):
    assert auto_acm(model) is auto_acm(model)
    pol = apply_policy(model, Scene.from_model(model).pair_ids, allowed="auto")
    assert len(pol.monitored) + len(pol.allowed) == len(Scene.from_model(model).pair_ids)


SCENES = sorted(p.parent.name for p in models_dir().glob("*/scene.xml"))
STOCK = ["Reacher-v5", "Pusher-v5", "Ant-v5", "HalfCheetah-v5", "Hopper-v5", "Walker2d-v5", "Swimmer-v5",
         "InvertedPendulum-v5", "InvertedDoublePendulum-v5", "Humanoid-v5", "HumanoidStandup-v5"]


@pytest.mark.parametrize("spec", SCENES + STOCK)
def test_cli_acm_and_pairs_on_every_model(tmp_path, capsys, spec):
    """`monitor acm` writes a file that `monitor pairs --acm FILE` and Scene load back to the same set."""
    out = tmp_path / "acm.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["acm", spec, "--samples", "8", "-o", str(out), "--no-progress"]) == 0
        from monitor.commands.acm import load_model

        model, _ = load_model(spec)
    acm = ACM.load(out, ModelNames.from_model(model))
    capsys.readouterr()
    assert main(["pairs", spec, "--acm", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    skipped = {tuple(sorted(k)) for k in acm.skipped}
    assert {tuple(sorted(a[:2])) for a in res["allowed"]} == skipped & {
        tuple(sorted(p)) for p in Scene.from_model(model).candidate_pairs}
    assert len(res["monitored"]) + len(res["allowed"]) == res["candidates"]
    assert main(["pairs", spec]) == 0


def test_cli_pairs_bad_pattern(capsys):
    assert main(["pairs", "tunnel", "--hazards", "nope*"]) == 2
    assert "available" in capsys.readouterr().err


def _policy_loop(names, pair_ids, acm, keep, user):
    """apply_policy's split written row by row (the reference for the vectorised one)."""
    allowed, never, out = [], [], keep.copy()
    for k, (a, b) in enumerate(pair_ids.tolist()):
        if not out[k]:
            continue
        na, nb = names[a], names[b]
        r = acm.reason(na, nb) if acm is not None else None
        if user[k] and (r is None or not r.skips):
            r = Reason.USER
        if r is not None and r.skips:
            out[k] = False
            allowed.append((na, nb, r.value))
        elif r is Reason.NEVER:
            never.append((na, nb))
    return pair_ids[out], tuple(allowed), tuple(never)


@pytest.mark.parametrize("seed", range(4))
def test_policy_split_equals_the_row_loop(seed):
    """Random ACMs (every reason, both name orders) with hazards= and allow=
    on a random model: monitored / allowed / never equal the row-by-row split, in row order."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from _scene_cases import random_mjcf

    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(random_mjcf(seed))
    names = ModelNames.from_model(m)
    pid = Scene.from_model(m, pairs="all").pair_ids
    picks = pid[rng.choice(len(pid), min(len(pid), 40), replace=False)].tolist()
    flips = rng.choice([-1, 1], len(picks))
    rows = [(names.geom_names[a], names.geom_names[b])[::int(f)] + (str(rng.choice(list(Reason))),)
            for (a, b), f in zip(picks, flips)]
    acm = ACM.from_pairs(rows)
    for hazards, allow in ((None, None), (["g1*", "w*"], None), (None, [["g2*", "*"]]), (["g*"], ["w0"])):
        got = apply_policy(m, pid, "all", allowed=acm, hazards=hazards, allow=allow)
        from monitor.pairsel import pair_mask

        keep = pair_mask(names, pid, hazards, arg="h") if hazards is not None else np.ones(len(pid), bool)
        user = pair_mask(names, pid, allow, arg="a") if allow is not None else np.zeros(len(pid), bool)
        mon, allowed, never = _policy_loop(names.geom_names, pid, acm, keep, user)
        assert got.monitored.tobytes() == mon.tobytes()
        assert got.allowed == allowed and got.never == never
        assert got.not_hazard == int((~keep).sum())
    assert {r for _, _, r in got.allowed} and got.allowed   # the split did remove pairs


@pytest.mark.parametrize("names", [("a", "b", "d", "c"), ("a", "b", "a", "c")])
def test_reason_codes_equal_name_lookups(names):
    """Per row, the reason of its two names (acm.reason), with entries naming no geom, reversed rows and
    two geoms sharing a name (a name pair then stands for several id pairs: looked up by names)."""
    from monitor.acm import _reason_codes

    pid = np.array([[0, 1], [0, 3], [1, 2], [2, 3], [1, 3], [3, 1]], dtype=np.int64)
    acm = ACM.from_pairs([("b", "a", "Never"), ("c", "a", "Default"), ("nope", "a"), ("b", "c", "Always")])
    got = _reason_codes(names, pid, acm)
    want = [list(Reason).index(r) if (r := acm.reason(names[a], names[b])) is not None else -1
            for a, b in pid.tolist()]
    assert got.tolist() == want and len(set(want)) >= 3
