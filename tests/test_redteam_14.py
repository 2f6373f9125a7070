"""Red team 14: tonight's merges (scenepack's pair filter, armcert's whole-shape route, coldtrim).

Nothing broke (docs/notes/redteam-14.md); these are the cheapest of the fuzzers, kept as
regressions. Oracles, none of them the package's own code:

* candidate pairs: ``_pair_oracle.oracle_pairs`` (MuJoCo's documented filter rules, pair by pair
  in plain Python, from the generator's own record of ``<exclude>`` / ``<pair>``) and MuJoCo itself
  (``mj_collision`` on the same model with every geom as a sphere and every margin 100 m: a contact
  for exactly the pairs that pass MuJoCo's filter), with the filter's row blocks shrunk to 7 cells;
* in-place edits: a fresh ``Scene.from_model`` of the edited model, and a motion whose collision is
  obvious in closed form (a 0.8 m link swung half a turn through a wall at 0.5 m);
* rotating-only windows: ``redteam_oracle.motion_min`` (verified witnesses): with the margin above
  its minimum a violation exists, so "certified" would be a false certificate;
* shapes: MuJoCo's own geom poses (``geom_xpos`` / ``geom_xmat``) at a random configuration.
"""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest
import redteam_oracle as O
from _pair_oracle import (
    anchor_dropped,
    mujoco_contact_pairs,
    oracle_pairs,
    random_model,
    rotating_chain_xml,
    rotating_qpos,
)

import monitor
from monitor import scene as S
from monitor.certify import engine


def _scene(m, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # non-convex random meshes
        return monitor.Scene.from_model(m, **kw)


@pytest.mark.parametrize("seed", [16, 40, 51])
def test_candidate_pairs_are_mujocos_filter_in_small_row_blocks(monkeypatch, seed):
    """``"mujoco"`` == the documented rules == mj_collision's contacts at huge margins; ``"all"`` == its
    documented rules; with 7-cell row blocks (every block boundary inside the sparse rules)."""
    monkeypatch.setattr(S, "_CHUNK", 7)
    xml, info = random_model(seed)
    m = mujoco.MjModel.from_xml_string(xml)
    got = set(map(tuple, _scene(m, pairs="mujoco").pair_ids.tolist()))
    want = oracle_pairs(m, info, "mujoco")
    assert want and got == want
    assert got == {p for p in mujoco_contact_pairs(random_model(seed, margin=100.0)[0]) if p[0] != p[1]}
    got_all = set(map(tuple, _scene(m, pairs="all").pair_ids.tolist()))
    want_all = oracle_pairs(m, info, "all")
    assert got_all == want_all - anchor_dropped(m, want_all - got_all)
    must = anchor_dropped(m, want_all, depth=1e-6)
    assert must and not must & got_all


_WORLD = """<mujoco><worldbody>
  <geom name="postg" type="sphere" size="0.01" pos="0 0 -0.5" contype="0" conaffinity="0"/>
  <body name="wallb" pos="0.5 0 0"><geom name="wall" type="box" size="0.05 0.5 0.5" {wall}/></body>
  <body name="arm"><joint type="hinge" axis="0 0 1" range="-0.01 0.01"/>
    <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
    <body name="arm2"><joint name="yaw" type="hinge" axis="0 0 1"/>
      <geom name="link" type="capsule" fromto="0 0 0 -0.8 0 0" size="0.03" {link}/></body></body>
</worldbody>{contact}</mujoco>"""


_WALL = '<body name="wallb" pos="0.5 0 0"><geom name="wall" type="box" size="0.05 0.5 0.5" /></body>'
_PARENT = _WORLD.format(wall="", link="", contact="").replace(_WALL, "").replace(
    '<body name="arm2">', _WALL + '<body name="arm2">')
"""The wall welded to the link's moving parent body "arm": a parent-child pair while filterparent is on."""


def _set(arr, i, v):
    arr[i] = v


EDITS = {
    "contype 0 -> 1": (dict(wall="", link='contype="0" conaffinity="0"', contact=""),
                       lambda m: (_set(m.geom_contype, m.geom("link").id, 1),
                                  _set(m.geom_conaffinity, m.geom("link").id, 1))),
    "no bit common to all masks any more": (
        dict(wall='contype="2" conaffinity="2"', link='contype="1" conaffinity="1"', contact=""),
        lambda m: _set(m.geom_conaffinity, m.geom("wall").id, 3)),
    "exclude signature": (
        dict(wall="", link="", contact='<contact><exclude body1="arm2" body2="wallb"/></contact>'),
        lambda m: _set(m.exclude_signature, 0, (1 << 16) + 2)),   # (wallb, arm): arm has no geom
    "filterparent disabled": (None, lambda m: setattr(m.opt, "disableflags", int(m.opt.disableflags)
                                                      | int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT))),
    "<pair> re-pointed": (dict(wall='contype="0" conaffinity="0"', link="",
                               contact='<contact><pair geom1="postg" geom2="wall"/></contact>'),
                          lambda m: _set(m.pair_geom1, 0, m.geom("link").id)),
}


@pytest.mark.parametrize("name", sorted(EDITS))
def test_an_in_place_edit_that_makes_a_pair_a_candidate_reaches_certify(name):
    fmt, edit = EDITS[name]
    xml = _WORLD.format(**fmt) if fmt is not None else _PARENT
    m = mujoco.MjModel.from_xml_string(xml)
    scene = _scene(m)
    q = np.zeros((2, m.nq))
    q[1, 1] = np.pi   # the link's far end sweeps the circle of radius 0.8 through the wall at x = 0.5
    plan = monitor.Plan(np.array([0.0, 1.0]), q, m)
    assert str(monitor.certify(scene, plan).verdict) == "certified"   # the pair is not a candidate yet
    edit(m)
    assert str(monitor.certify(scene, plan).verdict) == "violation"
    assert scene.version == 1 and len(scene.pair_ids) == len(_scene(m).pair_ids) == 1


def _old_path(scene, plan, **kw):
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(engine, "_no_extrusion_route", lambda mpk, mov: False)
        mp.setattr(engine, "_kernel_decided", lambda *a, **k: None)
        return monitor.certify(scene, plan, **kw)


@pytest.mark.parametrize("seed", [5, 64])
def test_rotating_only_windows_never_certify_a_verified_violation(seed):
    """A hinge / ball chain (no translating body: "auto" takes the whole-shape route from stage 0):
    with the margin 2 mm above the oracle's verified minimum, never certified, and "auto" equals the
    previous path (route pass, no _kernel_decided) under a test budget too."""
    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(rotating_chain_xml(rng))
    scene = _scene(m, pairs="all")
    q = rotating_qpos(m, rng, 6)
    times = np.linspace(0.0, 1.0, len(q))
    plan = monitor.Plan(times, q, m)
    orc = O.PlanOracle(m, times, q)
    best = min(O.motion_min(orc, ga, gb, 0.0, 1.0, n=40, refine=1).upper
               for ga, gb in scene.pair_ids.tolist() if O.PLANE not in (m.geom_type[ga], m.geom_type[gb]))
    assert np.isfinite(best)
    margin = max(best, 0.0) + 0.002
    for kw in ({}, {"budget": {"tests": 3}}, {"ongoing": "deepen"}):
        cert = monitor.certify(scene, plan, margin=margin, **kw)
        if "ongoing" not in kw:
            assert str(cert.verdict) != "certified"
        old = _old_path(scene, plan, margin=margin, **kw)
        assert (str(cert.verdict), cert.earliest_time, cert.clearance) == \
            (str(old.verdict), old.earliest_time, old.clearance)


@pytest.mark.parametrize("seed", [1, 2])
def test_shared_shapes_sit_where_mujoco_puts_each_geom(seed):
    """Equal inputs on different bodies share one shape object; each still lands on MuJoCo's geom pose
    (sphere centres, capsule segments, box corners, mesh vertices) at a random configuration."""
    m = mujoco.MjModel.from_xml_string(random_model(seed, None, 4, shared=0.7)[0])
    d = mujoco.MjData(m)
    d.qpos[:] = m.qpos0 + np.random.default_rng(seed).normal(0, 0.5, m.nq)
    mujoco.mj_normalizeQuat(m, d.qpos)
    mujoco.mj_kinematics(m, d)
    sc = _scene(m)
    assert len({id(g.shape) for g in sc.geoms}) < len(sc.geoms)   # some shapes are shared
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    checked = 0
    for g in sc.geoms:
        if g.type not in ("sphere", "capsule", "box", "mesh"):
            continue
        Rb, pb = d.xmat[g.body_id].reshape(3, 3), d.xpos[g.body_id]
        Rg, pg, size = d.geom_xmat[g.id].reshape(3, 3), d.geom_xpos[g.id], m.geom_size[g.id]
        P = np.asarray(g.shape.points) @ Rb.T + pb
        if g.type == "sphere":
            local = np.zeros((1, 3))
        elif g.type == "capsule":
            local = np.array([[0.0, 0.0, -size[1]], [0.0, 0.0, size[1]]])
        elif g.type == "box":
            local = corners * size
        else:
            mid = m.geom_dataid[g.id]
            local = m.mesh_vert[m.mesh_vertadr[mid]:m.mesh_vertadr[mid] + m.mesh_vertnum[mid]].astype(float)
        want = local @ Rg.T + pg
        dist = np.linalg.norm(want[:, None] - P[None], axis=2)
        assert dist.min(axis=0).max() < 1e-9   # every scene point is one of MuJoCo's
        if g.type != "mesh":                   # (a mesh's hull keeps a subset of its vertices)
            assert dist.min(axis=1).max() < 1e-9
        checked += 1
    assert checked > 10
