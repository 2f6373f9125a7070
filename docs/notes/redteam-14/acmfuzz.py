"""Red team 14: Scene.from_model's ACM / allow= / hazards= split against a per-pair reference.

Usage: PYTHONPATH=<tree>:<tree>/tests python acmfuzz.py SEED0 NSEEDS

Per random model (tests/_pair_oracle.py) and mode ("mujoco", "all"): an ACM given as (a, b, reason) triples
(names in random order, some unnamed geoms as "geom<id>", candidate and non-candidate pairs, every
reason), random allow= / hazards= patterns. Reference, pair by pair from the module docstring of
monitor.acm: a hazard-selected candidate is monitored unless its ACM reason skips (every reason but
Never) or an allow= pattern matches it and its ACM reason is not a skipping one (then User).
Pattern matching is pairsel.pair_mask (unchanged tonight); the ACM lookup is a dict on sorted names.
"""
from __future__ import annotations

import fnmatch
import sys
import warnings

import mujoco
import numpy as np
from _pair_oracle import random_model

import monitor
from monitor.acm import Reason
from monitor.pairsel import ModelNames, pair_mask


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    st = dict(cases=0, wrong=0, allowed_wrong=0)
    reasons = list(Reason)
    for seed in range(s0, s0 + n):
        rng = np.random.default_rng(seed)
        xml, _ = random_model(seed)
        m = mujoco.MjModel.from_xml_string(xml)
        names = ModelNames.from_model(m)
        gn = names.geom_names
        for mode in ("mujoco", "all"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                cand = monitor.Scene.from_model(m, pairs=mode).pair_ids
            if not len(cand):
                continue
            ent = []
            pick = rng.choice(len(cand), min(len(cand), int(rng.integers(1, 40))), replace=False)
            for a, b in cand[pick].tolist():
                x, y = (gn[a], gn[b]) if rng.random() < 0.5 else (gn[b], gn[a])
                ent.append((x, y, str(rng.choice([r.value for r in reasons]))))
            for _ in range(3):   # pairs that are not candidates
                a, b = rng.choice(m.ngeom, 2, replace=False) if m.ngeom >= 2 else (0, 0)
                if a != b:
                    ent.append((gn[a], gn[b], "User"))
            seen = {}
            for x, y, r in ent:   # one reason per pair (the list form's conflict rule is not under test)
                seen.setdefault(tuple(sorted((x, y))), (x, y, r))
            ent = list(seen.values())
            pats = [p for p in ("g1*", "g2*", "g3*", "geom*", "*") if any(fnmatch.fnmatch(x, p) for x in gn)]
            hazards = None if rng.random() < 0.5 else [str(rng.choice(pats))]
            allow = None if rng.random() < 0.5 else [[str(rng.choice(pats)), str(rng.choice(pats))]]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sc = monitor.Scene.from_model(m, pairs=mode, allowed=ent, hazards=hazards, allow=allow)
            st["cases"] += 1
            table = {tuple(sorted((x, y))): Reason(r) for x, y, r in ent}
            keep = (np.ones(len(cand), bool) if hazards is None
                    else pair_mask(names, cand, hazards, arg="hazards"))
            user = np.zeros(len(cand), bool) if allow is None else pair_mask(names, cand, allow, arg="allow")
            want, want_allowed = [], set()
            for k, (a, b) in enumerate(cand.tolist()):
                if not keep[k]:
                    continue
                r = table.get(tuple(sorted((gn[a], gn[b]))))
                if user[k] and (r is None or r is Reason.NEVER):
                    r = Reason.USER
                if r is not None and r is not Reason.NEVER:
                    want_allowed.add((gn[a], gn[b], r.value))
                else:
                    want.append((a, b))
            if sorted(want) != sorted(map(tuple, sc.pair_ids.tolist())):
                st["wrong"] += 1
                got = set(map(tuple, sc.pair_ids.tolist()))
                print(seed, mode, "MONITORED differ: missing", sorted(set(want) - got)[:5], "extra",
                      sorted(got - set(want))[:5], flush=True)
            # "all": apply_policy runs before the world-children drop (as on ca04081), so a dropped
            # adjacent pair can still be listed as allowed; counted apart (cosmetic)
            cset = {(gn[a], gn[b]) for a, b in cand.tolist()}
            listed = {r for r in sc.allowed_pairs if (r[0], r[1]) in cset}
            st["listed_not_candidate"] = st.get("listed_not_candidate", 0) + len(
                set(sc.allowed_pairs) - listed)
            if want_allowed != listed:
                st["allowed_wrong"] += 1
                print(seed, mode, "allowed rows differ", sorted(want_allowed ^ set(sc.allowed_pairs))[:4])
    print(st)


if __name__ == "__main__":
    main()
