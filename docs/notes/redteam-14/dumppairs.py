"""Red team 14: digest of Scene.from_model's pair arrays per random model (run on two trees, compare).

Usage: PYTHONPATH=<tree>:<tree>/tests python dumppairs.py SEED0 NSEEDS [--maxg N] [--nbody N] > out.txt
"""
from __future__ import annotations

import hashlib
import sys
import warnings

import mujoco
from _pair_oracle import random_model

import monitor


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    s0, n = int(sys.argv[1]), int(sys.argv[2])
    maxg = int(sys.argv[sys.argv.index("--maxg") + 1]) if "--maxg" in sys.argv else 4
    nbody = int(sys.argv[sys.argv.index("--nbody") + 1]) if "--nbody" in sys.argv else None
    for seed in range(s0, s0 + n):
        xml, info = random_model(seed, nbody, maxg)
        m = mujoco.MjModel.from_xml_string(xml)
        for mode in ("mujoco", "all"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    p = monitor.Scene.from_model(m, pairs=mode).pair_ids
                    out = hashlib.sha256(p.astype("<i8").tobytes()).hexdigest()[:16] + f" {len(p)}"
                except Exception as exc:   # noqa: BLE001
                    out = f"{type(exc).__name__}: {exc}"
            print(seed, mode, out)


if __name__ == "__main__":
    main()
