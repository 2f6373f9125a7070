"""Red team 14: certify(pairs=subset) on from_model's pair arrays (pairs_sorted=True: binary search).

Usage: PYTHONPATH=<tree>:<tree>/tests python subsetprobe.py SEED0 NSEEDS

Per random model (tests/_pair_oracle.py), for "mujoco", "all" and an explicit list: a random subset of the
candidate pairs, names in random order (a, b) or (b, a); certify on a still plan must check
exactly those pairs (cert.stats["pairs"], the certificate's pair names); a non-candidate pair
must raise InvalidInputError.
"""
from __future__ import annotations

import sys
import warnings

import mujoco
import numpy as np
from _pair_oracle import random_model

import monitor


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    st = dict(calls=0, wrong=0, untyped=0, typed=0)
    for seed in range(s0, s0 + n):
        rng = np.random.default_rng(seed)
        xml, _ = random_model(seed)
        m = mujoco.MjModel.from_xml_string(xml)
        names = [m.geom(g).name or f"geom{g}" for g in range(m.ngeom)]
        q = np.repeat(m.qpos0[None], 2, axis=0)
        plan = monitor.Plan(np.array([0.0, 0.1]), q, m)
        for mode in ("mujoco", "all", "explicit"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                base = monitor.Scene.from_model(m, pairs="all")
                if mode == "explicit":
                    k = min(len(base.pair_ids), 30)
                    pick = rng.choice(len(base.pair_ids), k, replace=False)
                    rows = base.pair_ids[pick] if k else base.pair_ids
                    sc = monitor.Scene.from_model(m, pairs=[(names[b], names[a]) for a, b in rows.tolist()])
                else:
                    sc = monitor.Scene.from_model(m, pairs=mode)
            P = len(sc.pair_ids)
            if not P:
                continue
            k = int(rng.integers(1, min(P, 25) + 1))
            rows = sc.pair_ids[rng.choice(P, k, replace=False)].tolist()
            sub = [(names[a], names[b]) if rng.random() < 0.5 else (names[b], names[a]) for a, b in rows]
            st["calls"] += 1
            try:
                c = monitor.certify(sc, plan, margin=0.0, pairs=sub)
            except monitor.errors.MonitorError as exc:
                st["typed"] += 1
                print(seed, mode, "typed error on a valid subset", exc)
                continue
            got = {tuple(sorted(p.geoms)) for p in c.pairs} if c.pairs is not None else set()
            want = {tuple(sorted(p)) for p in sub}
            if c.stats["pairs"] != len(want) or got != want:
                st["wrong"] += 1
                print(seed, mode, "WRONG", c.stats["pairs"], len(want), sorted(want ^ got)[:4], flush=True)
            # a pair that is not a candidate
            cand = set(map(tuple, sc.pair_ids.tolist()))
            non = [(a, b) for a in range(m.ngeom) for b in range(a + 1, m.ngeom) if (a, b) not in cand]
            if non:
                a, b = non[int(rng.integers(len(non)))]
                try:
                    monitor.certify(sc, plan, margin=0.0, pairs=[(names[a], names[b])])
                    st["wrong"] += 1
                    print(seed, mode, "non-candidate pair accepted", names[a], names[b])
                except monitor.errors.InvalidInputError:
                    pass
                except Exception as exc:   # noqa: BLE001
                    st["untyped"] += 1
                    print(seed, mode, "UNTYPED", type(exc).__name__, exc)
    print(st)


if __name__ == "__main__":
    main()
