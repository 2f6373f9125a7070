"""Red team 14 (coldtrim): the two compile orders of the per-pair search entry on a cold numba cache.

Usage: NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=<tree> python coldorder.py entry-first|certify-first

``entry-first`` compiles ``check_pair_window`` (warmup's "pair search entry") before any certify, the
reverse of ``monitor warmup``'s order; then prints the Arm certificate and 12 per-pair results,
which must not depend on the order (diff the last 12 lines of the two runs).
"""
import sys
import time
from pathlib import Path

import mujoco
import numpy as np

import monitor
from monitor import warmup
from monitor.certify import kernels

ARM = Path(monitor.__file__).resolve().parents[1] / "models" / "arm" / "scene.xml"


def main() -> None:
    """Compile in the order given on the command line; print the results with cumulative CPU."""
    m = mujoco.MjModel.from_xml_path(str(ARM))
    sc = monitor.Scene.from_model(m)
    q = np.repeat(m.qpos0[None], 3, axis=0)
    q[:, 0] += np.linspace(0, 1.0, 3)
    plan = monitor.Plan(np.linspace(0, 0.5, 3), q, m)
    t = time.process_time()

    def entry() -> None:
        print("entry", warmup._pair_search(sc, plan), time.process_time() - t, flush=True)

    def cert() -> None:
        c = monitor.certify(sc, plan)
        print("certify", c.verdict, c.clearance, time.process_time() - t, flush=True)

    for step in ((entry, cert) if sys.argv[1] == "entry-first" else (cert, entry)):
        step()
    gp, mp = kernels.scene_pack(sc).geoms, kernels.trajectory_pack(plan)
    for ga, gb in sc.pair_ids[:12].tolist():
        r = kernels.check_pair_window(gp, mp, ga, gb, (0.0, 0.5), 0.0, 1e-3, max_tests=4096)
        print(ga, gb, r["verdict"], r.get("clearance"), r.get("witness_time"))


if __name__ == "__main__":
    main()
