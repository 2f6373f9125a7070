"""Red team 15: can a Scene's pair_ids / body_static still be edited under the engine's caches?

Oracle (as tests/test_scene.py's): a ball moving into a wall; certified on a scene asked only ball-vs-far,
a violation on a fresh scene asked ball-vs-wall. Each probe edits the first scene's pairs to ball-vs-wall
by some route, certifies again and must not answer "certified".

Run: PYTHONPATH=$PWD /work/main/.venv/bin/python docs/notes/redteam-15/scene_seal_probe.py
"""

from __future__ import annotations

import copy
import pickle
import sys

import mujoco
import numpy as np

from monitor import Plan, certify
from monitor.scene import Scene

XML = """<mujoco><worldbody>
<geom name="wall" type="box" size="0.02 0.5 0.5" pos="0.3 0 0"/>
<geom name="far" type="box" size="0.02 0.5 0.5" pos="-3 0 0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="b" type="sphere" size="0.1"/></body>
</worldbody></mujoco>"""


def main() -> int:
    model = mujoco.MjModel.from_xml_string(XML)
    through = Plan([0.0, 1.0], [[0.0], [0.5]], model)
    wall = Scene.from_model(model, pairs=[("b", "wall")]).pair_ids[0].copy()
    assert str(certify(Scene.from_model(model, pairs=[("b", "wall")]), through).verdict) == "violation"
    out = []

    def fresh() -> Scene:
        s = Scene.from_model(model, pairs=[("b", "far")])
        assert str(certify(s, through).verdict) == "certified"  # caches warm
        return s

    def try_write(arr: np.ndarray) -> bool:
        for owner in (arr, arr.base, getattr(arr.base, "base", None)):
            if isinstance(owner, np.ndarray):
                try:
                    owner.setflags(write=True)
                except ValueError:
                    continue
        return bool(arr.flags.writeable)

    def probe(name: str, scene: Scene, edit) -> None:
        try:
            done = edit(scene)
        except (ValueError, TypeError, AttributeError) as exc:
            out.append((name, "refused", f"{type(exc).__name__}: {str(exc)[:70]}"))
            return
        if not done:
            out.append((name, "refused", "arrays stay read-only"))
            return
        v = str(certify(scene, through).verdict)
        out.append((name, "BROKEN" if v == "certified" else "held", f"after the edit: {v}"))

    def inplace(s: Scene) -> bool:
        if not try_write(s.pair_ids):
            return False
        s.pair_ids[0] = wall
        return True

    probe("from_model: setflags on pair_ids and its bases", fresh(), inplace)
    probe("pickle round trip", pickle.loads(pickle.dumps(fresh())), inplace)
    probe("copy.deepcopy", copy.deepcopy(fresh()), inplace)
    probe("copy.copy", copy.copy(fresh()), inplace)

    def rebuild_by_hand(s: Scene) -> Scene:
        mine = np.array(s.pair_ids)  # writable, the caller keeps it
        t = Scene(s.model, s.geoms, mine, s.body_names, np.array(s.body_static), s.facets, s.tolerances)
        assert str(certify(t, through).verdict) == "certified"
        mine[0] = wall  # the caller edits its own array
        return t

    t = rebuild_by_hand(fresh())
    v = str(certify(t, through).verdict)
    out.append(
        (
            "Scene(...) by hand, caller edits its array",
            "held" if v == "certified" and t.pair_ids[0].tolist() != wall.tolist() else "BROKEN?",
            f"scene keeps its own copy: {v}",
        )
    )

    def by_hand_bytes(s: Scene) -> bool:
        buf = bytearray(np.array(s.pair_ids).tobytes())
        arr = np.frombuffer(bytes(buf), dtype=np.int64).reshape(s.pair_ids.shape)
        t = Scene(s.model, s.geoms, arr, s.body_names, np.array(s.body_static), s.facets, s.tolerances)
        s.__dict__.update(t.__dict__)
        return inplace(s)

    probe("Scene(...) with an array over bytes (kept as is)", fresh(), by_hand_bytes)

    def attribute(s: Scene) -> bool:
        s.pair_ids = np.array(s.pair_ids)  # a writable array assigned to the attribute
        assert str(certify(s, through).verdict) == "certified"  # caches now keyed by this array
        s.pair_ids[0] = wall  # edited in place after the engine cached from it
        return True

    probe("attribute assigned a writable array, certified, then edited in place", fresh(), attribute)

    def attribute_body_static(s: Scene) -> bool:
        s.body_static = np.array(s.body_static)  # a writable array assigned to the attribute
        assert str(certify(s, through).verdict) == "violation"  # caches now keyed by this array
        s.body_static[:] = True  # edited in place: the ball claimed static
        return True

    against_wall = Scene.from_model(model, pairs=[("b", "wall")])
    assert str(certify(against_wall, through).verdict) == "violation"
    v_ok = None
    try:
        attribute_body_static(against_wall)
        v_ok = str(certify(against_wall, through).verdict)
    except (ValueError, TypeError, AttributeError) as exc:
        out.append(("body_static assigned writable, certified, then all True", "refused", str(exc)[:70]))
    if v_ok is not None:
        out.append(
            (
                "body_static assigned writable (ball-vs-wall scene), certified, then all True in place",
                "BROKEN" if v_ok == "certified" else "held",
                f"after the edit: {v_ok}",
            )
        )
    s2 = Scene.from_model(model, pairs=[("b", "wall")])
    s2.body_static = np.ones_like(s2.body_static)  # a new array: the scene told a lie, no cache involved
    out.append(
        (
            "body_static replaced by an all-True array (no cache)",
            "note",
            f"certify: {certify(s2, through).verdict} (the scene's own claim, like a hand-built scene)",
        )
    )

    def sync_edit(s: Scene) -> bool:
        model.geom_size[0, 0] += 0.0  # no-op; then move 'far' onto the path and sync
        model.geom_pos[model.geom("far").id] = [0.3, 0, 0]
        s.sync()
        ok = inplace(s)
        model.geom_pos[model.geom("far").id] = [-3, 0, 0]
        return ok

    probe("after Scene.sync (model edited)", fresh(), sync_edit)
    for name, status, detail in out:
        print(f"{status:8s} {name}: {detail}")
    return int(any(s == "BROKEN" for _, s, _ in out))


if __name__ == "__main__":
    sys.exit(main())
