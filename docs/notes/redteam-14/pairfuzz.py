"""Red team 14: Scene.from_model's candidate pairs against the independent oracles (tests/_pair_oracle.py).

Usage: PYTHONPATH=<tree>:<tree>/tests python pairfuzz.py SEED0 NSEEDS [--chunk N] [--nbody N]

Per seed: the scene's pairs for "mujoco" and "all" vs oracle_pairs (documented rules); for "mujoco"
also vs MuJoCo's own contacts with huge margins (models with at most 400 geoms). "all": oracle
pairs missing from the scene are accepted only when they are world-vs-world-child pairs whose child
has rotational joints only (the documented anchor drop); those are listed separately.
"""

from __future__ import annotations

import sys
import warnings

import mujoco
from _pair_oracle import anchor_dropped, mujoco_contact_pairs, oracle_pairs, random_model

import monitor
from monitor import scene as S


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    if "--chunk" in sys.argv:
        S._CHUNK = int(sys.argv[sys.argv.index("--chunk") + 1])
    nbody = int(sys.argv[sys.argv.index("--nbody") + 1]) if "--nbody" in sys.argv else None
    maxg = int(sys.argv[sys.argv.index("--maxg") + 1]) if "--maxg" in sys.argv else 4
    stats = dict(models=0, compile_err=0, scene_err=0, missing_mujoco=0, extra_mujoco=0, missing_all=0,
                 extra_all=0, dropped_all=0, mj_missing=0, mj_extra=0, pairs_mujoco=0, pairs_all=0,
                 mj_checked=0)
    for seed in range(s0, s0 + n):
        xml, info = random_model(seed, nbody, maxg)
        try:
            m = mujoco.MjModel.from_xml_string(xml)
        except ValueError:
            stats["compile_err"] += 1
            continue
        stats["models"] += 1
        for mode in ("mujoco", "all"):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    sc = monitor.Scene.from_model(m, pairs=mode)
            except monitor.errors.MonitorError as exc:
                stats["scene_err"] += 1
                print(seed, mode, "scene error", type(exc).__name__, str(exc)[:100])
                continue
            got = set(map(tuple, sc.pair_ids.tolist()))
            want = oracle_pairs(m, info, mode)
            stats[f"pairs_{mode}"] += len(want)
            miss, extra = want - got, got - want
            if mode == "all" and miss:
                ok = anchor_dropped(m, miss)
                stats["dropped_all"] += len(ok)
                miss -= ok
            if miss or extra:
                print(seed, mode, "MISSING", sorted(miss)[:8], "EXTRA", sorted(extra)[:8], flush=True)
            stats[f"missing_{mode}"] += len(miss)
            stats[f"extra_{mode}"] += len(extra)
            if mode == "mujoco" and m.ngeom <= 120:
                xm, _ = random_model(seed, nbody, maxg, margin=100.0)
                try:
                    mj = mujoco_contact_pairs(xm)
                except mujoco.FatalError:
                    stats["mj_skipped"] = stats.get("mj_skipped", 0) + 1
                    continue
                mj = {p for p in mj if p[0] != p[1]}
                stats["mj_checked"] += 1
                if mj - got or got - mj:
                    print(seed, "vs mj_collision: MISSING", sorted(mj - got)[:8], "EXTRA",
                          sorted(got - mj)[:8], flush=True)
                stats["mj_missing"] += len(mj - got)
                stats["mj_extra"] += len(got - mj)
    print(stats)


if __name__ == "__main__":
    main()
