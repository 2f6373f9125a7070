"""monitor.certify.packed: the per-scene geom pack and the pair-order check (issue 12, scene packing).

Oracles: a pack of G geoms is the geoms' one-geom packs laid end to end (ragged arrays concatenated,
offsets shifted, per-geom values in geom order), whatever objects the geoms share; the pair-order
check is compared with the plain definition row by row.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor.certify import packed as PK
from monitor.errors import InvalidInputError
from monitor.geometry.polytope import (
    box_polytope,
    capsule_shape,
    cylinder_polytope,
    ellipsoid_polytope,
    halfspace_shape,
    sphere_shape,
)
from monitor.geometry.shapes import ConvexShape
from monitor.scene import Scene

RAGGED = {"verts": "vstart", "edges": "estart", "normals": "nstart", "mpts": "mstart", "mw": "mstart"}


def _assert_pack_is_concatenation(pack: PK.GeomPack, singles: list[PK.GeomPack]) -> None:
    """``pack`` == the one-geom packs ``singles`` laid end to end, bit for bit."""
    for f in PK.GeomPack._fields:
        got = getattr(pack, f)
        assert got.flags.c_contiguous, f
        if f in RAGGED:
            start = getattr(pack, RAGGED[f])
            for g, one in enumerate(singles):
                part, want = got[start[g]:start[g + 1]], getattr(one, f)
                assert part.dtype == want.dtype and part.tobytes() == want.tobytes(), (f, g)
        elif f in set(RAGGED.values()):
            counts = [int(getattr(one, f)[1]) for one in singles]
            assert got.dtype == np.int64 and got.tolist() == np.concatenate([[0], np.cumsum(counts)]).tolist()
        else:
            want = np.concatenate([getattr(one, f) for one in singles]) if singles else got
            assert got.dtype == want.dtype and got.shape == want.shape and got.tobytes() == want.tobytes(), f


def _shapes(rng: np.random.Generator) -> list:
    """A list with shared objects, None, a half-space, every core kind and moved copies."""
    box = box_polytope(np.array([0.1, 0.2, 0.3]))
    cyl = cylinder_polytope(0.05, 0.1, 12)
    ell = ellipsoid_polytope(np.array([0.05, 0.06, 0.07]), 12)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    moved = box.transformed(R, rng.normal(size=3))
    pool = [box, cyl, ell, moved, sphere_shape(0.1), capsule_shape(0.05, 0.2), halfspace_shape(), None,
            box_polytope(np.array([0.1, 0.2, 0.3]))]   # equal content, another object
    return [pool[i] for i in rng.integers(0, len(pool), 40)]


@pytest.mark.parametrize("seed", [0, 1])
def test_pack_shapes_is_the_one_geom_packs_end_to_end(seed):
    """Shared objects, equal contents, None and half-spaces: the gathered pack equals per-geom packing."""
    rng = np.random.default_rng(seed)
    shapes = _shapes(rng)
    bodies = rng.integers(0, 9, len(shapes))
    pack = PK.pack_shapes(shapes, bodies)
    _assert_pack_is_concatenation(pack, [PK.pack_shapes([s], [b]) for s, b in zip(shapes, bodies)])
    assert (pack.body == bodies).all()


def test_pack_shapes_curved_entries_per_geom():
    """A circumscribed cylinder shared by two geoms: the exact-curve entry is kept where it holds (its
    own frame) and ignored where it does not (a frame that does not contain it), per geom."""
    cyl = cylinder_polytope(0.05, 0.1, 12)
    ok = (PK.CURVE_CYLINDER, np.array([0.05, 0.1, 0.0]), np.eye(3), np.zeros(3))
    off = (PK.CURVE_CYLINDER, np.array([0.05, 0.1, 0.0]), np.eye(3), np.array([1.0, 0.0, 0.0]))
    shapes, curved = [cyl, cyl, cyl, None], [ok, off, ok, ok]
    pack = PK.pack_shapes(shapes, [1, 1, 2, 0], curved)
    assert pack.curve.tolist() == [PK.CURVE_CYLINDER, 0, PK.CURVE_CYLINDER, 0]
    singles = [PK.pack_shapes([s], [b], [c]) for s, b, c in zip(shapes, [1, 1, 2, 0], curved)]
    _assert_pack_is_concatenation(pack, singles)


def test_pack_shapes_empty_and_bad_shape_named_by_first_index():
    """No geoms packs to empty arrays with offsets [0]; a bad shape used twice is named by its first
    index (the per-geom order of errors)."""
    empty = PK.pack_shapes([], [])
    assert all(getattr(empty, f).tolist() == [0] for f in set(RAGGED.values()))
    assert empty.verts.shape == (0, 3) and empty.edges.shape == (0, 2) and empty.mw.shape == (0,)
    bad = ConvexShape("polytope", np.full((4, 3), np.nan))
    with pytest.raises(InvalidInputError, match=r"shapes\[2\]"):
        PK.pack_shapes([sphere_shape(0.1), None, bad, bad], [0, 0, 1, 2])


def test_pack_scene_of_a_model_equals_per_geom_packs():
    """pack_scene of a scene (cylinders and ellipsoids with exact curves, a mesh, a plane, shared shapes)
    equals its geoms packed one by one with their curve entries."""
    xml = """<mujoco><asset><mesh name="m" vertex="0 0 0 .1 0 0 0 .1 0 0 0 .1 .1 .1 .1"/></asset><worldbody>
      <geom type="plane" size="1 1 .1"/>
      <body pos="0 0 1"><freejoint/><geom type="cylinder" size=".05 .1"/><geom type="cylinder" size=".05 .1"
        pos=".2 0 0" euler="0 40 0"/><geom type="ellipsoid" size=".05 .06 .07"/></body>
      <body pos="1 0 1"><freejoint/><geom type="cylinder" size=".05 .1"/><geom type="mesh" mesh="m"/></body>
    </worldbody></mujoco>"""
    scene = Scene.from_model(mujoco.MjModel.from_xml_string(xml), pairs="all")
    curved = PK._curved_geoms(scene)
    pack = PK.pack_scene(scene)
    assert (pack.geoms.curve > 0).sum() == 4
    singles = [PK.pack_shapes([g.shape], [g.body_id], [c]) for g, c in zip(scene.geoms, curved)]
    _assert_pack_is_concatenation(pack.geoms, singles)
    assert pack.pair_ids.tobytes() == scene.pair_ids.tobytes()


def _lex_oracle(pid: np.ndarray, ngeom: int) -> bool:
    rows = [tuple(r) for r in np.asarray(pid).reshape(-1, 2).tolist()]
    return (all(0 <= a < b < ngeom for a, b in rows)
            and all(r < s for r, s in zip(rows, rows[1:])))


def test_lex_sorted_pairs_blocks_match_the_definition(monkeypatch):
    """The blocked check (blocks of 3 rows forced) equals the row-by-row definition on sorted lists and
    on every single defect placed at, before and after a block boundary."""
    monkeypatch.setattr(PK, "_LEX_ROWS", 3)
    rng = np.random.default_rng(3)
    G = 12
    good = np.array([(a, b) for a in range(G) for b in range(a + 1, G)], dtype=np.int64)
    good = good[np.sort(rng.choice(len(good), 20, replace=False))]
    cases = [good, good[:0], good[:1], good.astype(np.int32)]
    for k in range(1, 7):
        swapped = good.copy()
        swapped[[k - 1, k]] = swapped[[k, k - 1]]
        repeated = good.copy()
        repeated[k] = repeated[k - 1]
        flipped = good.copy()
        flipped[k] = flipped[k, ::-1]
        out = good.copy()
        out[k, 1] = G
        neg = good.copy()
        neg[k, 0] = -1
        cases += [swapped, repeated, flipped, out, neg]
    for pid in cases:
        assert PK.lex_sorted_pairs(pid, G) == _lex_oracle(pid, G)
    assert sum(not _lex_oracle(p, G) for p in cases) == 30
