"""``models/hand30``: the >= 30-body articulated mesh scene of issue 12's large-scene target.

Checks the counts the target needs (bodies, candidate pairs under the gate's default pair
policy, mesh hulls), that random joint targets move it without contacts (MuJoCo's own contacts
as the oracle), that the gate certifies a few windows, and that a motion driven down through an
object is a violation whose witness MuJoCo's distance confirms. No timings.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import mujoco
import numpy as np
import pytest

import monitor

SCENE = Path(__file__).resolve().parents[1] / "models" / "hand30" / "scene.xml"


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_path(str(SCENE))


def test_generator_reproduces_the_committed_xml():
    spec = importlib.util.spec_from_file_location("make_scene", SCENE.parent / "make_scene.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.scene_xml() == SCENE.read_text()


def test_counts_and_mesh_hulls(model):
    assert model.nbody - 1 >= 30  # bodies besides the world
    moving = [b for b in range(1, model.nbody) if model.body_weldid[b] != 0]
    assert len(moving) >= 25 and model.nu == model.njnt == 25
    geom_types = {int(t) for t in model.geom_type}
    # every geom a mesh hull, except the table top (a box)
    assert geom_types == {int(mujoco.mjtGeom.mjGEOM_MESH), int(mujoco.mjtGeom.mjGEOM_BOX)}
    scene = monitor.Scene.from_model(model)  # the gate's default pair policy (pairs="mujoco")
    assert len(scene.candidate_pairs) >= 250
    for g in scene.geoms:
        if g.type != "mesh":
            continue
        mesh_id = model.geom_dataid[g.id]
        start, count = model.mesh_vertadr[mesh_id], model.mesh_vertnum[mesh_id]
        verts = model.mesh_vert[start:start + count]
        assert g.shape.kind == "polytope" and g.shape.radius == 0.0, g.name
        core = g.shape.points  # the monitor's hull, body frame
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, model.geom_quat[g.id])
        pts = verts @ R.reshape(3, 3).T + model.geom_pos[g.id]  # compiled vertices, body frame
        # the hull holds every compiled vertex and adds none: exactly the mesh's convex hull
        assert np.all(pts @ g.shape.normals.T <= g.shape.offsets + 1e-9), g.name
        gap = np.linalg.norm(core[:, None, :] - pts[None, :, :], axis=2).min(axis=1)
        assert gap.max() < 1e-9 and 6 <= len(core) <= count, g.name


def test_random_targets_move_it_without_contacts(model):
    d = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    q_start = d.qpos.copy()
    contacts = 0
    for k in range(1500):
        if k % 50 == 0:
            d.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(model, d)
        contacts += d.ncon > 0
    assert contacts == 0
    assert np.abs(d.qpos - q_start).max() > 0.05  # it did move


def test_gate_certifies_random_windows(model):
    d = mujoco.MjData(model)
    gate = monitor.Gate(model)
    rng = np.random.default_rng(1)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    verdicts = []
    for _ in range(4):
        rep = gate.step(d, rng.uniform(lo, hi), nstep=5)
        verdicts.append(rep.verdict)
        assert not rep.replaced
    assert verdicts == ["certified"] * 4
    assert gate.npairs >= 250  # after the automatic ACM resolved at the first state
    gate.close()


def test_pressing_down_through_the_block_is_a_violation(model):
    scene = monitor.Scene.from_model(model)
    q0 = np.zeros(model.nq)
    q1 = q0.copy()
    q1[2] = -0.15  # gz: the fingertips (z 0.545 m) go down to 0.395 m, through the block (top 0.43 m)
    plan = monitor.Plan(np.array([0.0, 0.1]), np.stack([q0, q1]), model=model)
    cert = monitor.certify(scene, plan)
    assert cert.verdict == "violation"
    w = cert.witness
    # oracle: MuJoCo's own distance of the witness pair at the witness time
    d = mujoco.MjData(model)
    d.qpos[:] = plan.qpos_at(w.time)
    mujoco.mj_kinematics(model, d)
    ga, gb = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in w.geoms)
    assert mujoco.mj_geomDistance(model, d, ga, gb, 0.01, None) < 1e-6
    # the start pose is clear, so the violation is not at t0
    assert w.time > 0.0
