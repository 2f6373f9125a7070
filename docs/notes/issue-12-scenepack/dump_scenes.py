"""Digest of every Scene.from_model output and pack, for comparing two trees bit for bit.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-scenepack/dump_scenes.py OUT.json [--quick]
Models: tests/assets/*.xml, models/*/scene*.xml, gymnasium's bundled MJCF, 60 seeded random MJCF
(tests/_scene_cases.py) and the bench's sparse / dense scaling scenes (100, 1000 bodies); pairs
"mujoco" and "all", plus hazards= / allow= / an explicit ACM on the random ones.
Per scene: sha256 of pair_ids (bytes, dtype, shape), candidate_pairs, allowed_pairs, each GeomInfo
(fields + shape arrays), geom_frames, approximations and every GeomPack array of pack_scene.
"""
import hashlib
import json
import sys
import warnings
from pathlib import Path

import mujoco
import numpy as np

REPO = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(REPO / "tests"))
from _scene_cases import random_mjcf  # noqa: E402

import monitor  # noqa: E402
from monitor.bench.suites import scaling_scene  # noqa: E402
from monitor.certify.packed import pack_scene  # noqa: E402


def h(*parts) -> str:
    """Short sha256 of arrays (dtype, shape, bytes) and reprs."""
    d = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            d.update(f"{p.dtype.str}{p.shape}".encode())
            d.update(np.ascontiguousarray(p).tobytes())
        else:
            d.update(repr(p).encode())
    return d.hexdigest()[:16]


def digest(scene) -> dict:
    """Digests of everything a Scene holds and of its pack."""
    out = {"pair_ids": h(scene.pair_ids), "candidate_pairs": h(scene.candidate_pairs),
           "allowed": h(scene.allowed_pairs), "approx": h(sorted(scene.approximations.items())),
           "static": h(scene.body_static), "names": h(scene.body_names)}
    gs = []
    for g in scene.geoms:
        s = g.shape
        parts = [g.name, g.id, g.body, g.body_id, g.type, g.margin, g.static, g.mocap]
        if s is not None:
            parts += [s.kind, s.radius, s.approx_error, s.points, s.edges, s.normals, s.offsets, *s.faces]
        gs.append(h(*parts))
    out["geoms"] = h(gs)
    out["frames"] = h(*[a for f in scene.geom_frames for a in f])
    pk = pack_scene(scene)
    out["pack"] = {f: h(getattr(pk.geoms, f)) for f in pk.geoms._fields}
    out["pack_pairs"] = h(pk.pair_ids)
    return out


def models(quick: bool):
    """(name, MjModel) of every model compared."""
    for p in sorted((REPO / "tests" / "assets").glob("*.xml")):
        yield f"assets/{p.name}", mujoco.MjModel.from_xml_path(str(p))
    for p in sorted((REPO / "models").glob("*/scene*.xml")):
        yield str(p.relative_to(REPO)), mujoco.MjModel.from_xml_path(str(p))
    import gymnasium
    root = Path(gymnasium.__file__).parent / "envs" / "mujoco" / "assets"
    for p in sorted(root.glob("*.xml")):
        yield f"gym/{p.name}", mujoco.MjModel.from_xml_path(str(p))
    for s in range(20 if quick else 60):
        yield f"random/{s}", mujoco.MjModel.from_xml_string(random_mjcf(s))
    for n in (100,) if quick else (100, 1000):
        for dens in ("sparse", "dense"):
            yield f"scaling/{dens}/{n}", scaling_scene(n, dens, "translating")[0]


def main():
    """Dump the digests to the JSON file named on the command line."""
    out_path, quick = sys.argv[1], "--quick" in sys.argv
    res = {"_tree": monitor.__file__}
    warnings.simplefilter("ignore")
    for name, model in models(quick):
        variants = [("mujoco", {}), ("all", {})]
        if name.startswith("random/"):
            variants += [("all", {"hazards": ["g1*"]}), ("mujoco", {"allow": [["g2*", "*"]]}),
                         ("all", {"allowed": [("w1", "g5"), ("g4", "g7", "adjacent")], "allow": ["w2"]})]
        for pairs, kw in variants:
            key = f"{name} {pairs} {sorted(kw)}"
            try:
                res[key] = digest(monitor.Scene.from_model(model, pairs=pairs, **kw))
            except Exception as exc:  # noqa: BLE001 - the error is part of the output
                res[key] = f"{type(exc).__name__}: {exc}"
    Path(out_path).write_text(json.dumps(res, indent=1, sort_keys=True))
    print(f"{len(res)} scenes -> {out_path}")


if __name__ == "__main__":
    main()
