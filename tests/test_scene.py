"""Scene.from_model: candidate pairs against mj_collision, shapes against the true geoms."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh
from conftest import ASSETS
from test_polytope import volume as _polytope_volume

from monitor.errors import InvalidInputError, UnsupportedGeometryError
from monitor.scene import GeomInfo, Scene

REPO = Path(__file__).resolve().parents[1]
PAIR_SCENES = sorted(p.name for p in ASSETS.glob("*.xml") if p.name != "hfield.xml")
MODEL_SCENES = sorted(str(p.relative_to(REPO)) for p in (REPO / "models").glob("*/scene*.xml"))
ALL_SCENES = [ASSETS / n for n in PAIR_SCENES] + [REPO / p for p in MODEL_SCENES]


def _gymnasium_assets() -> list[Path]:
    """gymnasium's bundled MuJoCo env XMLs (real-world MJCF), or [] if not found."""
    import importlib.util

    spec = importlib.util.find_spec("gymnasium")
    if spec is None or not spec.submodule_search_locations:
        return []
    root = Path(next(iter(spec.submodule_search_locations))) / "envs" / "mujoco" / "assets"
    return sorted(root.glob("*.xml"))


GYM_SCENES = _gymnasium_assets()
TYPES = mujoco.mjtGeom


def _reported(model: mujoco.MjModel, data: mujoco.MjData) -> set[tuple[int, int]]:
    mujoco.mj_forward(model, data)
    return {tuple(sorted(int(g) for g in c.geom)) for c in data.contact[: data.ncon]}


def contact_pairs(path: Path | str) -> set[tuple[int, int]]:
    """Geom pairs for which mj_collision reports a contact in either of two overlap setups.

    (a) Every geom and <pair> gets a margin (50 m) far above the scene size, at qpos0.
    (b) Every body and geom position is zeroed (all geoms centred at the world origin,
        free joints at the origin) with a 5 cm margin, so every pair overlaps deeply.
    (a) alone is not enough: MuJoCo 4.0's box-box collider reports nothing for separated
    boxes in many configurations whatever the margin (palm vs shelf in models/arm), and
    (b) alone could hit the capsule-box piercing defect (reference section 6). MuJoCo never
    reports a pair outside its candidate set, so the union is still a subset of it.
    """
    def fresh():
        if isinstance(path, Path):
            return mujoco.MjModel.from_xml_path(str(path))
        return mujoco.MjModel.from_xml_string(path)

    a = fresh()
    a.geom_margin[:] = 50.0
    a.pair_margin[:] = 100.0
    da = mujoco.MjData(a)
    mujoco.mj_setConst(a, da)
    b = fresh()
    b.geom_margin[:] = 0.05
    b.pair_margin[:] = 0.1
    b.body_pos[:] = 0.0
    b.geom_pos[:] = 0.0
    db = mujoco.MjData(b)
    mujoco.mj_setConst(b, db)
    for j in range(b.njnt):
        if b.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            db.qpos[b.jnt_qposadr[j]: b.jnt_qposadr[j] + 3] = 0.0
    return _reported(a, da) | _reported(b, db)


class PairSet(set):
    """Order-insensitive membership for (name_a, name_b) pairs."""

    def __init__(self, pairs):
        super().__init__(frozenset(p) for p in pairs)

    def __contains__(self, pair):
        return super().__contains__(frozenset(pair))


def load(path: Path) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(path))


# --------------------------------------------------------------------------- candidate pairs


def _scene_id(p: Path) -> str:
    if p.is_relative_to(REPO / "models"):
        return str(p.relative_to(REPO))
    return p.name if p.parent == ASSETS else f"gymnasium/{p.name}"


@pytest.mark.parametrize("path", ALL_SCENES, ids=_scene_id)
def test_mujoco_pairs_equal_mj_collision(path):
    scene = Scene.from_model(load(path), pairs="mujoco")
    got = {tuple(p) for p in scene.pair_ids.tolist()}
    want = contact_pairs(path)
    names = [g.name for g in scene.geoms]
    assert got == want, (
        f"extra {[(names[a], names[b]) for a, b in sorted(got - want)]}, "
        f"missing {[(names[a], names[b]) for a, b in sorted(want - got)]}")
    assert len(got) > 0


def test_pair_order_and_names(load_asset):
    scene = Scene.from_model(load_asset("arm_table.xml"))
    ids = scene.pair_ids
    assert ids.dtype == np.int64 and ids.shape == (len(scene.candidate_pairs), 2)
    assert (ids[:, 0] < ids[:, 1]).all()
    assert ids.tolist() == sorted(ids.tolist())
    for (a, b), (na, nb) in zip(ids.tolist(), scene.candidate_pairs):
        assert (scene.geoms[a].name, scene.geoms[b].name) == (na, nb)


def test_arm_table_rules(load_asset):
    scene = Scene.from_model(load_asset("arm_table.xml"))
    pairs = PairSet(scene.candidate_pairs)
    assert ("pedestal_geom", "upper_arm") in pairs  # world-welded parent collides with its child
    assert ("upper_arm", "fore_arm") not in pairs  # parent-child
    assert ("bench_top", "claw_geom") in pairs  # <pair>; claw contype 2 would not match bench
    assert ("ground", "claw_geom") not in pairs  # contype mask
    assert ("upper_arm", "claw_geom") not in pairs  # parent-child through the dof-less wrist
    assert ("bench_top", "block_geom") not in pairs  # <exclude>
    assert ("bench_leg", "block_geom") not in pairs  # <exclude> is per body
    assert ("ground", "goal_ball") not in pairs  # mocap vs static: MuJoCo skips (no dof)
    assert ("goal_ball", "block_geom") in pairs
    assert not any("wrist_marker" in p for p in pairs)


def test_mocap_weld_groups(load_asset):
    scene = Scene.from_model(load_asset("mocap_group.xml"))
    pairs = PairSet(scene.candidate_pairs)
    assert ("hand_a_geom", "hand_b_geom") not in pairs  # two mocap bodies: neither has a dof
    assert ("hand_a_geom", "finger_a_geom") not in pairs  # same weld group
    assert ("hand_a_geom", "thumb_geom") not in pairs  # parent-child (mocap weld != 0)
    assert ("hand_b_geom", "thumb_geom") in pairs
    assert ("shelf_geom", "egg_geom") in pairs
    g = scene.geom
    assert g("finger_a_geom").mocap and not g("finger_a_geom").static
    assert g("hand_b_geom").mocap and not g("hand_b_geom").static
    assert not g("thumb_geom").mocap and not g("thumb_geom").static
    assert g("post_geom").static and not g("post_geom").mocap
    assert not g("egg_geom").static
    assert scene.body_static.tolist() == [True, True, True, False, False, False, False, False]
    assert scene.body_names[:3] == ("world", "shelf", "shelf_post")


def test_all_pairs(load_asset):
    model = load_asset("arm_table.xml")
    scene = Scene.from_model(model, pairs="all")
    pairs = PairSet(scene.candidate_pairs)
    assert ("ground", "goal_ball") in pairs  # mocap is moving in "all" mode
    assert ("wrist_marker", "bench_top") in pairs  # contype 0 ignored
    assert ("bench_top", "block_geom") in pairs  # exclude ignored
    assert ("upper_arm", "claw_geom") not in pairs  # parent-child through the dof-less wrist
    assert ("pedestal_geom", "upper_arm") in pairs  # world exception
    assert ("upper_arm", "fore_arm") not in pairs  # parent-child
    assert ("fore_arm", "claw_geom") not in pairs  # same weld group (wrist has no dof)
    assert ("ground", "bench_top") not in pairs  # both static
    assert ("bench_top", "bench_leg") not in pairs  # same body
    # independent brute force over the rule text
    weld, parent = model.body_weldid, model.body_parentid
    want = set()
    for a in range(model.ngeom):
        for b in range(a + 1, model.ngeom):
            wa, wb = weld[model.geom_bodyid[a]], weld[model.geom_bodyid[b]]
            if wa == wb or (wa == 0 and wb == 0):
                continue
            if wa and wb and (weld[parent[wa]] == wb or weld[parent[wb]] == wa):
                continue
            if model.geom_type[a] == model.geom_type[b] == TYPES.mjGEOM_PLANE:
                continue
            want.add((a, b))
    assert {tuple(p) for p in scene.pair_ids.tolist()} == want


def test_all_pairs_superset_of_mujoco_in_masks(load_asset):
    model = load_asset("masks.xml")
    mj = {tuple(p) for p in Scene.from_model(model).pair_ids.tolist()}
    allp = {tuple(p) for p in Scene.from_model(model, pairs="all").pair_ids.tolist()}
    # filterparent is disabled in masks.xml, so MuJoCo keeps parent-child pairs that "all" drops
    names = [model.geom(i).name for i in range(model.ngeom)]
    extra = {(names[a], names[b]) for a, b in mj - allp}
    assert extra == {("cart_geom", "pole_geom")}  # pole-tip fails the contype mask


def test_explicit_pairs(load_asset):
    model = load_asset("arm_table.xml")
    scene = Scene.from_model(model, pairs=[("block_geom", "ground"), ("ground", "block_geom"),
                                           (3, "goal_ball"), ("wrist_marker", "upper_arm")])
    assert scene.candidate_pairs == (("ground", "block_geom"), ("pedestal_geom", "goal_ball"),
                                     ("upper_arm", "wrist_marker"))
    with pytest.raises(InvalidInputError, match="nope"):
        Scene.from_model(model, pairs=[("ground", "nope")])
    with pytest.raises(InvalidInputError, match="paired with itself"):
        Scene.from_model(model, pairs=[("ground", "ground")])
    with pytest.raises(InvalidInputError, match="out of range"):
        Scene.from_model(model, pairs=[(0, 99)])
    with pytest.raises(InvalidInputError, match=r"pairs\[1\]"):
        Scene.from_model(model, pairs=[("ground", "block_geom"), ("ground",)])
    with pytest.raises(InvalidInputError, match="pairs must be"):
        Scene.from_model(model, pairs="some")
    with pytest.raises(InvalidInputError, match="pairs must be"):
        Scene.from_model(model, pairs=5)
    assert Scene.from_model(model, pairs=[]).pair_ids.shape == (0, 2)


def test_plane_plane_explicit_rejected():
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><geom name="p1" type="plane" size="1 1 1"/>'
        '<geom name="p2" type="plane" size="1 1 1" pos="0 0 1"/><body><freejoint/><geom size="0.1"/></body>'
        "</worldbody></mujoco>")
    with pytest.raises(InvalidInputError, match="planes"):
        Scene.from_model(model, pairs=[("p1", "p2")])
    assert ("p1", "p2") not in Scene.from_model(model, pairs="all").candidate_pairs


def test_hfield_raises_naming_geom(load_asset):
    model = load_asset("hfield.xml")
    for mode in ("mujoco", "all"):
        with pytest.raises(UnsupportedGeometryError, match="terrain_geom"):
            Scene.from_model(model, pairs=mode)
    with pytest.raises(UnsupportedGeometryError, match="terrain_geom"):
        Scene.from_model(model, pairs=[("ball_geom", "terrain_geom")])
    scene = Scene.from_model(model, pairs=[("ball_geom", "shadow_geom")])
    assert scene.geom("terrain_geom").shape is None
    assert scene.geom("terrain_geom").type == "hfield"


def test_hfield_outside_pairs_is_fine():
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><asset><hfield name="h" nrow="2" ncol="2" size="1 1 .1 .1"/></asset><worldbody>'
        '<geom name="terrain" type="hfield" hfield="h" contype="0" conaffinity="0"/>'
        '<body><freejoint/><geom name="a" size="0.1"/></body>'
        '<body pos="1 0 0"><freejoint/><geom name="b" size="0.1"/></body></worldbody></mujoco>')
    scene = Scene.from_model(model)
    assert scene.candidate_pairs == (("a", "b"),)


def test_unnamed_geoms_and_lookup(load_asset):
    scene = Scene.from_model(load_asset("meshes.xml"))
    assert scene.geoms[0].name == "geom0" and scene.geoms[1].name == "geom1"
    assert scene.geom("geom1") is scene.geoms[1]
    assert scene.geom(2).name == "base_cap_geom"
    assert scene.geom(np.int64(2)) is scene.geoms[2]
    for bad in ("missing", 99, -1, 1.5):
        with pytest.raises(InvalidInputError):
            scene.geom(bad)
    assert all(isinstance(g, GeomInfo) and g.id == i for i, g in enumerate(scene.geoms))
    assert scene.geoms[1].body == "base" and scene.geoms[1].body_id == 1


def test_geom_info_fields(load_asset):
    model = load_asset("arm_table.xml")
    model.geom_margin[model.geom("upper_arm").id] = 0.015
    scene = Scene.from_model(model)
    g = scene.geom("upper_arm")
    assert (g.type, g.body, g.margin, g.static, g.mocap) == ("capsule", "shoulder", 0.015, False, False)
    assert scene.geom("ground").type == "plane" and scene.geom("ground").shape.kind == "halfspace"
    assert scene.geom("claw_geom").shape.kind == "polytope"
    assert scene.model is model


def test_approximations_reported(load_asset):
    scene = Scene.from_model(load_asset("meshes.xml"), facets=12)
    assert set(scene.approximations) == {"base_cap_geom", "tool_cyl", "link_geom"}
    r = 0.02
    assert scene.approximations["tool_cyl"] == pytest.approx(r * (1 / np.cos(np.pi / 12) - 1), rel=1e-9)
    assert scene.facets == 12
    assert all(scene.geom(n).shape.approx_error == v for n, v in scene.approximations.items())
    with pytest.raises(InvalidInputError, match="facets"):
        Scene.from_model(load_asset("meshes.xml"), facets=2)


def test_model_hash(load_asset):
    a = Scene.from_model(load_asset("arm_table.xml")).model_hash
    b = Scene.from_model(load_asset("arm_table.xml")).model_hash
    m = load_asset("arm_table.xml")
    m.geom_size[0, 2] += 0.01
    c = Scene.from_model(m).model_hash
    assert a == b and a != c and len(a) == 64


def test_bad_model():
    with pytest.raises(InvalidInputError, match="MjModel"):
        Scene.from_model("scene.xml")


# --------------------------------------------------------------------------- shapes vs true geoms


def _unit(rng, n):
    u = rng.normal(size=(n, 3))
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def _mesh_hull(model, g):
    """Vertices (mesh frame) of the hull MuJoCo collides, and its triangles (from mesh_graph)."""
    mid = model.geom_dataid[g]
    a, n = model.mesh_vertadr[mid], model.mesh_vertnum[mid]
    V = model.mesh_vert[a:a + n].astype(float)
    G = model.mesh_graph[model.mesh_graphadr[mid]:]
    nv, nf = G[0], G[1]
    tri = G[2 + 3 * nv + 3 * nf: 2 + 3 * nv + 6 * nf].reshape(nf, 3)
    return V, tri


def true_surface_points(model, g, rng, n=400):
    """(k, 3) points on the true geom's surface in the GEOM frame (independent of monitor)."""
    t, s = model.geom_type[g], model.geom_size[g]
    if t == TYPES.mjGEOM_SPHERE:
        return s[0] * _unit(rng, n)
    if t == TYPES.mjGEOM_CAPSULE:
        z = rng.uniform(-s[1], s[1], n)
        return np.c_[np.zeros(n), np.zeros(n), z] + s[0] * _unit(rng, n)
    if t == TYPES.mjGEOM_ELLIPSOID:
        return s * _unit(rng, n)
    if t == TYPES.mjGEOM_BOX:
        p = rng.uniform(-1, 1, (n, 3))
        k = rng.integers(0, 3, n)
        p[np.arange(n), k] = rng.choice([-1.0, 1.0], n)
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
        return np.concatenate([p, corners]) * s
    if t == TYPES.mjGEOM_CYLINDER:
        th = rng.uniform(0, 2 * np.pi, n)
        side = np.c_[s[0] * np.cos(th), s[0] * np.sin(th), rng.uniform(-s[1], s[1], n)]
        rr = s[0] * np.sqrt(rng.uniform(0, 1, n))
        cap = np.c_[rr * np.cos(th), rr * np.sin(th), rng.choice([-s[1], s[1]], n)]
        rim = np.c_[s[0] * np.cos(th), s[0] * np.sin(th), rng.choice([-s[1], s[1]], n)]
        return np.concatenate([side, cap, rim])
    if t == TYPES.mjGEOM_MESH:
        V, tri = _mesh_hull(model, g)
        w = rng.dirichlet(np.ones(3), n)
        k = rng.integers(0, len(tri), n)
        return np.concatenate([V[np.unique(tri)], np.einsum("nj,njk->nk", w, V[tri[k]])])
    if t == TYPES.mjGEOM_PLANE:
        return np.c_[rng.uniform(-5, 5, (n, 2)), np.zeros(n)]
    raise AssertionError(f"type {t}")


def true_support(model, g, d_G):
    """Support values (k,) of the true geom for unit directions d_G (k, 3) in the geom frame."""
    t, s = model.geom_type[g], model.geom_size[g]
    if t == TYPES.mjGEOM_SPHERE:
        return np.full(len(d_G), s[0])
    if t == TYPES.mjGEOM_CAPSULE:
        return s[1] * np.abs(d_G[:, 2]) + s[0]
    if t == TYPES.mjGEOM_BOX:
        return np.abs(d_G) @ s
    if t == TYPES.mjGEOM_MESH:  # the mesh's convex hull: all vertices count
        V, _ = _mesh_hull(model, g)
        return (d_G @ V.T).max(axis=1)
    raise AssertionError(f"type {t}")


def shape_support(shape, d):
    return (d @ shape.points.T).max(axis=1) + shape.radius


def inside_excess(shape, p):
    """(k,) how far points (k, 3) lie outside the shape (<= 0 inside), body frame."""
    if shape.kind in ("polytope", "halfspace"):
        return (p @ shape.normals.T - shape.offsets).max(axis=1)
    if shape.kind == "sphere":
        return np.linalg.norm(p - shape.points[0], axis=1) - shape.radius
    a, b = shape.points
    ab = b - a
    t = np.clip((p - a) @ ab / max(ab @ ab, 1e-300), 0, 1)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1) - shape.radius


@pytest.mark.parametrize("path", ALL_SCENES + GYM_SCENES, ids=_scene_id)
def test_shapes_contain_true_geoms_in_body_frame(path):
    """At random joint poses, MuJoCo's world geom pose composed with the body pose places the true
    geom inside the scene's body-frame shape; exact shapes have the true support function."""
    model = load(path)
    scene = Scene.from_model(model)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(7)
    for _ in range(3):
        data.qpos[:] = model.qpos0 + rng.uniform(-1, 1, model.nq)
        for j in range(model.njnt):  # keep quaternions unit
            a = model.jnt_qposadr[j]
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
                data.qpos[a + 3: a + 7] /= np.linalg.norm(data.qpos[a + 3: a + 7])
            elif model.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:
                data.qpos[a: a + 4] /= np.linalg.norm(data.qpos[a: a + 4])
        mujoco.mj_kinematics(model, data)
        for g, info in enumerate(scene.geoms):
            b = model.geom_bodyid[g]
            R_WB, p_WB = data.xmat[b].reshape(3, 3), data.xpos[b]
            R_WG, p_WG = data.geom_xmat[g].reshape(3, 3), data.geom_xpos[g]
            pts_W = true_surface_points(model, g, rng) @ R_WG.T + p_WG
            pts_B = (pts_W - p_WB) @ R_WB
            exc = inside_excess(info.shape, pts_B)
            assert exc.max() <= 1e-12, (info.name, exc.max())
            if info.type in ("sphere", "capsule", "box", "mesh"):
                assert info.shape.approx_error == 0.0
                d_B = _unit(rng, 200)
                d_G = d_B @ R_WB.T @ R_WG  # body-frame direction -> geom frame
                offset = d_B @ (R_WB.T @ (p_WG - p_WB))
                np.testing.assert_allclose(shape_support(info.shape, d_B),
                                           true_support(model, g, d_G) + offset, atol=1e-12)
            if info.type == "plane":
                n_B = R_WB.T @ R_WG[:, 2]
                np.testing.assert_allclose(info.shape.normals[0], n_B, atol=1e-12)
                below = pts_B - 0.3 * n_B
                above = pts_B + 0.3 * n_B
                assert (inside_excess(info.shape, below) < 0).all()
                assert (inside_excess(info.shape, above) > 0).all()


def test_mesh_hull_volume_matches_trimesh(load_asset):
    model = load_asset("meshes.xml")
    scene = Scene.from_model(model)
    g = model.geom("tool_geom").id
    mid = model.geom_dataid[g]
    a, n = model.mesh_vertadr[mid], model.mesh_vertnum[mid]
    fa, fn = model.mesh_faceadr[mid], model.mesh_facenum[mid]
    V = model.mesh_vert[a:a + n].astype(float)
    F = model.mesh_face[fa:fa + fn]
    shape = scene.geom(g).shape
    want = trimesh.Trimesh(V, F, process=False).convex_hull.volume
    assert _polytope_volume(shape) == pytest.approx(want, rel=1e-10)
    # the L-prism is not convex: its hull is strictly bigger than the mesh
    assert want > trimesh.Trimesh(V, F, process=False).volume * 1.2


def test_maxhullvert_mesh_uses_hull_of_all_vertices(load_asset):
    """maxhullvert makes MuJoCo store a reduced hull that lies inside the mesh; the scene keeps
    the hull of all vertices (a superset, so certificates hold for the real mesh too)."""
    model = load_asset("meshes.xml")
    scene = Scene.from_model(model)
    shape = scene.geom("stone_geom").shape
    V, tri = _mesh_hull(model, model.geom("stone_geom").id)
    reduced = trimesh.Trimesh(V, tri, process=False)
    full = trimesh.Trimesh(V, process=False).convex_hull
    assert len(np.unique(tri)) == 8 < len(full.vertices)  # maxhullvert="8" really reduced it
    assert _polytope_volume(shape) == pytest.approx(full.volume, rel=1e-10)
    assert _polytope_volume(shape) > abs(reduced.volume)


@pytest.mark.parametrize("path", GYM_SCENES, ids=lambda p: p.name)
def test_gymnasium_models_pairs_equal_mj_collision(path):
    """Real-world MJCF (gymnasium's bundled MuJoCo envs): the filter equals mj_collision."""
    model = load(path)
    scene = Scene.from_model(model)
    assert {tuple(p) for p in scene.pair_ids.tolist()} == contact_pairs(path)
    Scene.from_model(model, pairs="all")  # every geom type in these files is supported


def _brute_force_mujoco(model):
    """MuJoCo's static filter rules written out pair by pair (reference section 1.8)."""
    weld, parent, dof = model.body_weldid, model.body_parentid, model.body_dofnum
    filterparent = not model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_FILTERPARENT
    excluded = set(model.exclude_signature.tolist())
    explicit = {tuple(sorted(p)) for p in zip(model.pair_geom1.tolist(), model.pair_geom2.tolist())}
    out = set()
    for a, b in _pairs_not_both_planes(model):
        if (a, b) in explicit:
            out.add((a, b))
            continue
        ba, bb = model.geom_bodyid[a], model.geom_bodyid[b]
        wa, wb = weld[ba], weld[bb]
        if wa == wb or (dof[wa] == 0 and dof[wb] == 0):
            continue
        if filterparent and wa and wb and (weld[parent[wa]] == wb or weld[parent[wb]] == wa):
            continue
        if (min(ba, bb) << 16) + max(ba, bb) in excluded:
            continue
        ca, cb = model.geom_contype, model.geom_conaffinity
        if ca[a] & cb[b] or ca[b] & cb[a]:
            out.add((a, b))
    return out


def _pairs_not_both_planes(model):
    """Every geom pair a < b, one by one, except plane/hfield pairs (no collision test)."""
    planeish = (int(TYPES.mjGEOM_PLANE), int(TYPES.mjGEOM_HFIELD))
    for a in range(model.ngeom):
        for b in range(a + 1, model.ngeom):
            if not (model.geom_type[a] in planeish and model.geom_type[b] in planeish):
                yield a, b


@pytest.mark.parametrize("name", PAIR_SCENES)
def test_vectorised_filter_blocks_match_brute_force(name, monkeypatch):
    """Row-blocked vectorised filter (tiny blocks forced) equals the rule-by-rule loop."""
    import monitor.scene as scene_mod

    model = load(ASSETS / name)
    want = _brute_force_mujoco(model)
    for chunk in (1, 7, 1 << 20):
        monkeypatch.setattr(scene_mod, "_CHUNK", chunk)
        got = {tuple(p) for p in Scene.from_model(model).pair_ids.tolist()}
        assert got == want, chunk


def test_many_bodies_filter_matches_brute_force():
    """A 120-body scene (random masks, a chain, excludes) against the rule-by-rule loop."""
    rng = np.random.default_rng(11)
    parts, excl = [], []
    for i in range(60):
        ct, ca = rng.integers(0, 4, 2)
        parts.append(f'<body name="f{i}" pos="{i * 0.1} 0 0"><freejoint/>'
                     f'<geom size="0.05" contype="{ct}" conaffinity="{ca}"/></body>')
    chain = ""
    for i in range(59, -1, -1):
        ct, ca = rng.integers(0, 4, 2)
        chain = (f'<body name="c{i}" pos="0 0 0.1"><joint type="hinge"/>'
                 f'<geom type="capsule" size="0.02 0.05" contype="{ct}" conaffinity="{ca}"/>{chain}</body>')
    for _ in range(20):
        a, b = rng.integers(0, 60, 2)
        excl.append(f'<exclude body1="f{a}" body2="c{b}"/>')
    xml = (f'<mujoco><worldbody><geom type="plane" size="5 5 1"/>{"".join(parts)}{chain}</worldbody>'
           f'<contact>{"".join(excl)}</contact></mujoco>')
    model = mujoco.MjModel.from_xml_string(xml)
    got = {tuple(p) for p in Scene.from_model(model).pair_ids.tolist()}
    assert got == _brute_force_mujoco(model)
    assert got == contact_pairs(xml)
    assert len(got) > 500


@pytest.mark.parametrize("path", ALL_SCENES, ids=_scene_id)
def test_every_mesh_hull_volume(path):
    """Each mesh geom's polytope has the volume of trimesh's hull of all vertices, which equals
    MuJoCo's stored hull unless maxhullvert reduced it (then it contains it)."""
    model = load(path)
    scene = Scene.from_model(model)
    meshes = [g for g in scene.geoms if g.type == "mesh"]
    for info in meshes:
        V, tri = _mesh_hull(model, info.id)
        mj_hull = trimesh.Trimesh(V, tri, process=False)
        full = trimesh.Trimesh(V, process=False).convex_hull
        assert _polytope_volume(info.shape) == pytest.approx(full.volume, rel=1e-9)
        assert _polytope_volume(info.shape) >= abs(mj_hull.volume) * (1 - 1e-9)
        if len(full.vertices) == len(np.unique(tri)):
            assert _polytope_volume(info.shape) == pytest.approx(abs(mj_hull.volume), rel=1e-9)


def test_scene_pickles(load_asset):
    """Scenes cross process boundaries (ray extra, multiprocessing): pickle round trip."""
    import pickle

    scene = Scene.from_model(load_asset("meshes.xml"))
    back = pickle.loads(pickle.dumps(scene))
    assert back.candidate_pairs == scene.candidate_pairs
    assert back.model_hash == scene.model_hash
    for a, b in zip(scene.geoms, back.geoms):
        assert a.name == b.name and a.type == b.type
        if a.shape is not None:
            np.testing.assert_array_equal(a.shape.points, b.shape.points)


def test_explicit_pair_edge_cases_in_mujoco_mode():
    """<pair> keeps static-static and mocap-mocap pairs like MuJoCo; a self pair (which MuJoCo
    accepts and even reports as a contact) is dropped."""
    xml = ('<mujoco><worldbody><geom name="a" type="box" size=".1 .1 .1"/>'
           '<body name="s" pos="0.05 0 0"><geom name="b" size=".1"/></body>'
           '<body name="m" mocap="true"><geom name="c" size=".1"/></body>'
           '<body name="m2" mocap="true"><geom name="d" size=".1"/></body>'
           '<body name="f"><freejoint/><geom name="e" size=".1" contype="0" conaffinity="0"/></body>'
           '</worldbody><contact><pair geom1="a" geom2="b"/><pair geom1="a" geom2="c"/>'
           '<pair geom1="c" geom2="d"/><pair geom1="e" geom2="e"/></contact></mujoco>')
    scene = Scene.from_model(mujoco.MjModel.from_xml_string(xml))
    assert scene.candidate_pairs == (("a", "b"), ("a", "c"), ("c", "d"))
    assert {tuple(p) for p in scene.pair_ids.tolist()} == contact_pairs(xml) - {(4, 4)}


def test_all_pairs_drop_only_always_touching_world_children():
    """pairs="all": a hinge child whose anchor lies in both geoms is always in contact with
    its world parent (dropped); a slider through a wall at qpos0 and a free body over the
    floor are real collision candidates (kept)."""
    import mujoco

    xml = """<mujoco><worldbody>
      <geom name="floor" type="plane" size="5 5 .1"/>
      <geom name="root" type="cylinder" size=".05 .02" pos="0 0 .5"/>
      <body name="arm" pos="0 0 .5"><joint type="hinge" axis="0 0 1"/>
        <geom name="link" type="capsule" fromto="0 0 0 .3 0 0" size=".02"/></body>
      <geom name="wall" type="box" size=".01 .5 .5" pos="2 0 .5"/>
      <body name="slider" pos="2 0 .5"><joint type="slide" axis="1 0 0"/>
        <geom name="ball" type="sphere" size=".05"/></body>
      <body name="crate" pos="-2 0 1"><freejoint/><geom name="crate" type="box" size=".1 .1 .1"/></body>
    </worldbody></mujoco>"""
    pairs = set(Scene.from_model(mujoco.MjModel.from_xml_string(xml), pairs="all").candidate_pairs)
    assert ("root", "link") not in pairs  # hinge anchor inside both: always touching
    assert ("wall", "ball") in pairs      # overlaps at qpos0, but a slider can leave
    assert ("floor", "crate") in pairs and ("floor", "link") in pairs


# --------------------------------------------------------------------------- issue 12: per-scene cost
RANDOM_SEEDS = range(10)


def _brute_force_all(model):
    """pairs="all" before the world-children drop, pair by pair (module docstring of monitor.scene)."""
    weld, parent = model.body_weldid, model.body_parentid
    out = set()
    for a, b in _pairs_not_both_planes(model):
        wa, wb = weld[model.geom_bodyid[a]], weld[model.geom_bodyid[b]]
        if wa == wb or (wa == 0 and wb == 0):
            continue
        if wa and wb and (weld[parent[wa]] == wb or weld[parent[wb]] == wa):
            continue
        out.add((a, b))
    return out


def _strictly_increasing(pid):
    rows = [tuple(r) for r in pid.tolist()]
    return all(a < b for a, b in rows) and all(r < s for r, s in zip(rows, rows[1:]))


@pytest.mark.parametrize("seed", RANDOM_SEEDS)
def test_random_mjcf_filter_matches_rule_loops(seed, monkeypatch):
    """Seeded random MJCF (welds, mocap, planes, meshes, masks, <exclude>, <pair>, filterparent on/off):
    the row-block filter equals the rule-by-rule loops for "mujoco" and "all" in every block size, with
    <exclude> decoded or compared as signatures, rows in strict (a, b) order, and every pair
    mj_collision reports is a "mujoco" candidate."""
    from _scene_cases import random_mjcf

    import monitor.scene as scene_mod

    xml = random_mjcf(seed)
    model = mujoco.MjModel.from_xml_string(xml)
    want = {"mujoco": _brute_force_mujoco(model), "all": _brute_force_all(model)}
    for chunk, signature_bodies in ((1, 1 << 16), (7, 0), (1 << 20, 1 << 16)):  # 0: signatures compared
        monkeypatch.setattr(scene_mod, "_CHUNK", chunk)
        monkeypatch.setattr(scene_mod, "_SIGNATURE_BODIES", signature_bodies)
        for mode in ("mujoco", "all"):
            pid = scene_mod._filter_pairs(model, mode)
            assert pid.dtype == np.int64 and pid.shape[1:] == (2,) and pid.flags.c_contiguous
            assert _strictly_increasing(pid), (mode, chunk)
            assert {tuple(p) for p in pid.tolist()} == want[mode], (mode, chunk)
    assert contact_pairs(xml) - {(a, a) for a in range(model.ngeom)} <= want["mujoco"]


def test_random_mjcf_cover_the_filter_rules():
    """The random models exercise every rule the filter has (else the test above proves little)."""
    from _scene_cases import random_mjcf

    seen = dict.fromkeys(("exclude", "pair", "plane pair", "weld child", "mocap", "filterparent off",
                          "parent-child", "mesh", "masked"), False)
    for seed in RANDOM_SEEDS:
        m = mujoco.MjModel.from_xml_string(random_mjcf(seed))
        weld, parent = m.body_weldid, m.body_parentid
        seen["exclude"] |= m.nexclude > 0
        seen["pair"] |= m.npair > 0
        seen["plane pair"] |= int((m.geom_type == TYPES.mjGEOM_PLANE).sum()) >= 2
        seen["weld child"] |= any(weld[b] not in (0, b) for b in range(m.nbody))
        seen["mocap"] |= bool((m.body_mocapid >= 0).any())
        seen["filterparent off"] |= bool(m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
        seen["parent-child"] |= any(weld[parent[w]] not in (0,) for w in set(weld.tolist()) - {0})
        seen["mesh"] |= bool((m.geom_type == TYPES.mjGEOM_MESH).any())
        seen["masked"] |= bool((m.geom_contype != 1).any())
    assert all(seen.values()), seen


WORLD_CHILDREN_XML = """<mujoco><worldbody>
  <geom name="floor" type="plane" size="5 5 .1"/>
  <geom name="post" type="box" pos="0 0 .26" size=".05 .05 .26"/>
  <geom type="sphere" pos="0 0 .5" size=".04"/>
  <geom name="far" type="box" pos="3 0 .5" size=".1 .1 .1"/>
  <body name="hinged" pos="0 0 .5"><joint type="hinge" axis="0 0 1"/>
    <geom name="h1" type="capsule" fromto="0 0 0 .3 0 0" size=".02"/>
    <geom type="sphere" pos=".3 0 0" size=".02"/>
    <body name="welded" pos=".1 0 0"><geom name="h2" type="box" size=".02 .02 .02"/></body></body>
  <body name="two" pos="0 0 .5"><joint type="hinge" axis="1 0 0"/><joint type="ball"/>
    <geom name="t1" type="sphere" size=".03"/></body>
  <body name="apart" pos="0 0 .5"><joint type="hinge" axis="1 0 0"/><joint type="hinge" pos=".01 0 0"/>
    <geom name="a1" type="sphere" size=".03"/></body>
  <body name="slide" pos="0 0 .5"><joint type="hinge" axis="1 0 0"/><joint type="slide"/>
    <geom name="s1" type="sphere" size=".03"/></body>
  <body name="free" pos="0 0 .5"><freejoint/><geom name="f1" type="sphere" size=".03"/></body>
</worldbody></mujoco>"""


def _drop_oracle(scene, pair_ids):
    """The world-children rule pair by pair: world geom vs a geom of a world child whose joints are all
    hinge/ball with one shared anchor lying (point_in_shape) in both geoms."""
    from monitor.geometry.distance import point_in_shape

    model = scene.model
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    weld, parent = model.body_weldid, model.body_parentid
    rot = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_BALL))
    out = set()
    for a, b in pair_ids:
        ga, gb = scene.geoms[a], scene.geoms[b]
        wa, wb = weld[ga.body_id], weld[gb.body_id]
        if not ((wa == 0 and wb and weld[parent[wb]] == 0) or (wb == 0 and wa and weld[parent[wa]] == 0)):
            continue
        child = wb if wa == 0 else wa
        jnts = [j for j in range(model.njnt) if model.jnt_bodyid[j] == child]
        if not jnts or any(model.jnt_type[j] not in rot for j in jnts) or None in (ga.shape, gb.shape):
            continue
        p = data.xanchor[jnts[0]].copy()
        if any(not np.array_equal(data.xanchor[j], p) for j in jnts):
            continue
        poses = [(data.xmat[g.body_id].reshape(3, 3).copy(), data.xpos[g.body_id].copy()) for g in (ga, gb)]
        if all(point_in_shape(g.shape, X, p, 0.0) for g, X in zip((ga, gb), poses)):
            out.add((a, b))
    return out


@pytest.mark.parametrize("seed", [None, *RANDOM_SEEDS])
def test_all_pairs_world_children_drop_matches_pair_loop(seed):
    """pairs="all" == the rule loop minus the world-children pairs the pair-by-pair oracle drops; on a
    scene made for the rule (shared anchors, two anchors, a slider, a welded child, an unnamed geom)
    and on the random models."""
    from _scene_cases import random_mjcf

    xml = WORLD_CHILDREN_XML if seed is None else random_mjcf(seed)
    model = mujoco.MjModel.from_xml_string(xml)
    scene = Scene.from_model(model, pairs="all")
    loop = _brute_force_all(model)
    dropped = _drop_oracle(scene, sorted(loop))
    assert {tuple(p) for p in scene.pair_ids.tolist()} == loop - dropped
    if seed is None:
        names = {tuple(sorted(p)) for p in scene.candidate_pairs}
        gone = {tuple(sorted((scene.geoms[a].name, scene.geoms[b].name))) for a, b in dropped}
        assert gone == {("h1", "post"), ("geom2", "h1"), ("post", "t1"), ("geom2", "t1")}
        assert ("a1", "post") in names and ("post", "s1") in names and ("f1", "post") in names
        assert ("h2", "post") in names  # the welded child's own geom does not hold the anchor


@pytest.mark.parametrize("seed", RANDOM_SEEDS[:5])
def test_geoms_equal_the_per_geom_construction(seed):
    """Every GeomInfo (name, frame, body-frame shape) equals the one-geom-at-a-time construction
    (model.geom(g).name, geom_frame, _geom_shape + _to_body) bit for bit, shared objects or not."""
    from _scene_cases import random_mjcf

    import monitor.scene as scene_mod

    model = mujoco.MjModel.from_xml_string(random_mjcf(seed))
    scene = Scene.from_model(model, pairs="all")
    R_all, p_all, bad = scene_mod.geom_frames(model)
    assert bad == model.ngeom
    for g, info in enumerate(scene.geoms):
        assert info.name == (model.geom(g).name or f"geom{g}")
        assert info.body == (model.body(info.body_id).name or f"body{info.body_id}")
        R, p = scene_mod.geom_frame(model, g)
        for got in ((R_all[g], p_all[g]), scene.geom_frames[g]):
            assert got[0].tobytes() == R.tobytes() and got[1].tobytes() == p.tobytes()
        shape = scene_mod._geom_shape(model, g, scene.facets, scene.tolerances)
        if shape is None:
            assert info.shape is None
            continue
        ref = scene_mod._to_body(shape, R, p)
        assert (info.shape.kind, info.shape.radius, info.shape.approx_error) == (ref.kind, ref.radius,
                                                                                  ref.approx_error)
        for f in ("points", "edges", "normals", "offsets"):
            assert getattr(info.shape, f).tobytes() == getattr(ref, f).tobytes(), (g, f)
        assert len(info.shape.faces) == len(ref.faces)


def test_identical_geoms_share_one_shape():
    """Equal geoms at equal frames share one body-frame shape object (the bench's 27 equal boxes); the
    shape is the one-geom construction's."""
    import monitor.scene as scene_mod
    from monitor.bench.suites import scaling_scene

    model, _ = scaling_scene(27, "sparse", "translating")
    scene = Scene.from_model(model, pairs="all")
    assert len({id(g.shape) for g in scene.geoms}) == 1
    ref = scene_mod._to_body(scene_mod._geom_shape(model, 5, scene.facets, scene.tolerances),
                             *scene_mod.geom_frame(model, 5))
    assert scene.geoms[5].shape.points.tobytes() == ref.points.tobytes()


def test_geom_frames_inertial_and_bad_sameframe():
    """Geoms placed in their body's inertial frame (INERTIA / INERTIAROT, body_sameframe BODY / BODYROT /
    NONE) get geom_frame's values; an edited-in body_sameframe is refused with geom_frame's error."""
    import monitor.scene as scene_mod

    xml = """<mujoco><worldbody>
      <body name="a" pos="0 0 1"><freejoint/><geom name="a0" type="box" size=".1 .2 .3" pos=".1 0 0"/></body>
      <body name="b" pos="1 0 1"><freejoint/><geom name="b0" type="box" size=".1 .2 .3" pos=".1 .2 0"
          euler="10 20 30"/></body>
      <body name="c" pos="2 0 1"><freejoint/><geom name="c0" type="capsule" size=".1 .2" euler="0 90 0"/>
        <geom name="c1" type="sphere" size=".1" pos=".3 0 0"/></body>
    </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    for sf in range(5):   # every geom_sameframe value on every geom, geom_frame as the oracle
        model.geom_sameframe[:] = sf
        R_all, p_all, bad = scene_mod.geom_frames(model)
        assert bad == model.ngeom
        for g in range(model.ngeom):
            R, p = scene_mod.geom_frame(model, g)
            assert R_all[g].tobytes() == R.tobytes() and p_all[g].tobytes() == p.tobytes(), (sf, g)
    model.geom_sameframe[:] = mujoco.mjtSameFrame.mjSAMEFRAME_INERTIA
    model.body_sameframe[2] = mujoco.mjtSameFrame.mjSAMEFRAME_INERTIAROT   # never set by the compiler
    with pytest.raises(UnsupportedGeometryError) as want:
        scene_mod.geom_frame(model, 1)
    assert scene_mod.geom_frames(model)[2] == 1
    with pytest.raises(UnsupportedGeometryError) as got:
        Scene.from_model(model)
    assert str(got.value) == str(want.value)


@pytest.mark.parametrize("seed", RANDOM_SEEDS[:4])
def test_from_model_pairs_are_in_strict_order(seed):
    """Scene.from_model trusts its own pair arrays to be in strict (a, b) order (the sweep's binary
    search needs it): every policy it builds is, checked row by row (explicit lists given shuffled and
    reversed, hazards=, allow=, an ACM)."""
    from _scene_cases import random_mjcf

    model = mujoco.MjModel.from_xml_string(random_mjcf(seed))
    rng = np.random.default_rng(seed)
    every = Scene.from_model(model, pairs="all").pair_ids.tolist()
    explicit = [tuple(every[k][::-1]) for k in rng.permutation(len(every))[:30]]
    scenes = [Scene.from_model(model, pairs=p) for p in ("all", "mujoco", explicit)]
    acm = [(scenes[0].geoms[a].name, scenes[0].geoms[b].name) for a, b in every[:5]]
    scenes += [Scene.from_model(model, pairs="all", hazards=["g1*", "w*"], allow=[["g2*", "*"]], allowed=acm)]
    for scene in scenes:
        assert _strictly_increasing(scene.pair_ids) and scene._sorted_pairs is scene.pair_ids
    assert len(scenes[2].pair_ids) == 30 and len(scenes[3].pair_ids) < len(every)


_SEALED_XML = """<mujoco><worldbody>
<geom name="wall" type="box" size="0.02 0.5 0.5" pos="0.3 0 0"/>
<geom name="far" type="box" size="0.02 0.5 0.5" pos="-3 0 0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="b" type="sphere" size="0.1"/></body>
</worldbody></mujoco>"""


def test_pair_ids_and_body_static_cannot_be_edited_under_the_engines_caches():
    """Red team 10's open item: the engine caches a scene's packs by the identity of ``pair_ids``; a
    read-only array that owns its memory could be made writable again and edited in place, and the
    next certify answered from the pack of the old pairs. The oracle: the same motion through the
    wall, certified on a fresh scene holding the edited pair, is a violation."""
    from monitor import Plan, certify

    model = mujoco.MjModel.from_xml_string(_SEALED_XML)
    scene = Scene.from_model(model, pairs=[("b", "far")])
    through = Plan([0.0, 1.0], [[0.0], [0.5]], model)          # the ball ends inside the wall
    assert str(certify(scene, through).verdict) == "certified"  # only ball-vs-far is asked
    fresh = Scene.from_model(model, pairs=[("b", "wall")])
    assert str(certify(fresh, through).verdict) == "violation"
    for arr in (scene.pair_ids, scene.body_static):
        for owner in (arr, arr.base):
            if isinstance(owner, np.ndarray):
                try:
                    owner.setflags(write=True)
                except ValueError:
                    continue
                if arr is scene.pair_ids and arr.flags.writeable:  # the edit went through: it must count
                    arr[0] = fresh.pair_ids[0]
                    assert str(certify(scene, through).verdict) != "certified"
    assert not scene.pair_ids.flags.writeable and not scene.body_static.flags.writeable
    again = __import__("pickle").loads(__import__("pickle").dumps(scene))
    assert not again.pair_ids.flags.writeable and not again.body_static.flags.writeable
    with pytest.raises(ValueError):
        again.pair_ids.setflags(write=True)
