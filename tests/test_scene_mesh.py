"""Mesh geoms read through trimesh: validation and the one-time non-convexity warning (issue 16)."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

import monitor.scene as scene_mod
from monitor.errors import InvalidInputError, ModelMismatchError
from monitor.scene import Scene


def _prism(polygon_xy: np.ndarray, height: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed, outward-wound prism over a simple CCW polygon (n, 2): vertices (2n, 3), faces (F, 3).

    The caps are fanned from vertex 0, which is valid for the L below (vertex 0 sees every
    other vertex: it is the inner corner's opposite, the origin).
    """
    n = len(polygon_xy)
    bottom = np.column_stack([polygon_xy, np.zeros(n)])
    top = np.column_stack([polygon_xy, np.full(n, height)])
    V = np.vstack([bottom, top])
    faces = []
    for i in range(1, n - 1):
        faces.append([0, i + 1, i])  # bottom cap, normal -z
        faces.append([n, n + i, n + i + 1])  # top cap, normal +z
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i]]  # sides, outward for a CCW polygon
    return V, np.asarray(faces)


# L-shape: a 0.2 x 0.2 square minus its 0.1 x 0.1 upper-right quarter, 0.05 thick.
L_XY = np.array([[0, 0], [0.2, 0], [0.2, 0.1], [0.1, 0.1], [0.1, 0.2], [0, 0.2]], dtype=float)
SQUARE_XY = np.array([[0, 0], [0.2, 0], [0.2, 0.2], [0, 0.2]], dtype=float)
H = 0.05


def _model(V: np.ndarray, F: np.ndarray) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    mesh = spec.add_mesh()
    mesh.name = "part"
    mesh.uservert = V.ravel().tolist()
    mesh.userface = F.ravel().tolist()
    body = spec.worldbody.add_body(name="b", pos=[0, 0, 1])
    body.add_freejoint()
    body.add_geom(name="part_geom", type=mujoco.mjtGeom.mjGEOM_MESH, meshname="part")
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[1, 1, 0.1])
    return spec.compile()


@pytest.fixture(autouse=True)
def _fresh_mesh_cache(monkeypatch):
    monkeypatch.setattr(scene_mod, "_MESH_CHECKS", {})


def _build(model) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        Scene.from_model(model)
    return [str(w.message) for w in caught if "convex" in str(w.message)]


def test_l_shape_warns_once_with_extra_hull_volume():
    model = _model(*_prism(L_XY, H))
    msgs = _build(model)
    assert len(msgs) == 1, msgs
    # Oracle by hand: hull of the L (a pentagon, the square minus the triangle cut by the
    # diagonal from (0.2, 0.1) to (0.1, 0.2)) minus the L: the triangle with legs 0.1, 0.1.
    extra_m3 = 0.5 * 0.1 * 0.1 * H
    hull_m3 = (0.2 * 0.2 - 0.5 * 0.1 * 0.1) * H
    msg = msgs[0]
    assert "'part'" in msg and "'part_geom'" in msg and "convex hull" in msg
    assert f"{extra_m3:.3g} m^3" in msg and f"({100 * extra_m3 / hull_m3:.3g}% of the hull)" in msg
    assert _build(model) == []  # cached: a rebuild of the same mesh does not warn again


def test_convex_mesh_does_not_warn():
    assert _build(_model(*_prism(SQUARE_XY, H))) == []


def test_shipped_arm_finger_mesh_does_not_warn():
    from monitor._paths import scene_path

    assert _build(mujoco.MjModel.from_xml_path(str(scene_path("arm")))) == []


def test_non_finite_vertex_after_edit_is_typed_error():
    model = _model(*_prism(SQUARE_XY, H))
    scene = Scene.from_model(model)
    model.mesh_vert[0, 0] = np.nan
    with pytest.raises(ModelMismatchError, match="mesh 'part' .*non-finite"):
        scene.sync()
    with pytest.raises(InvalidInputError, match="geom 'part_geom'"):
        Scene.from_model(model)
