"""Red team 14: a live Gate sees an in-place contype edit that makes a pair a candidate.

Usage: PYTHONPATH=<tree> python gateedit.py

models/tunnel: the ball's contype/conaffinity set to 0 before the Gate is made (no candidate pair:
the gate lets it pass through the wall), then restored in place after 100 steps. Crossings of the
wall's slab (|x| < 0.005 + 0.01 at a step, or a sign change of x between steps) are counted with
the gate before and after the edit; after it there must be none.
"""
from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

import monitor

ROOT = Path(monitor.__file__).resolve().parents[1]


def main() -> None:
    """Run the seeds given on the command line; print the counts."""
    m = mujoco.MjModel.from_xml_path(str(ROOT / "models" / "tunnel" / "scene.xml"))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    ball = m.geom("ball").id
    ct, ca = int(m.geom_contype[ball]), int(m.geom_conaffinity[ball])
    m.geom_contype[ball] = 0
    m.geom_conaffinity[ball] = 0
    gate = monitor.Gate(m, margin=0.001, on_violation="block")
    cross = [0, 0]
    for k in range(400):
        if k == 100:
            m.geom_contype[ball], m.geom_conaffinity[ball] = ct, ca
        target = 0.3 if (k // 50) % 2 == 0 else -0.3
        ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        x0 = float(d.qpos[0])
        gate.step(d, ctrl)
        x1 = float(d.qpos[0])
        if np.sign(x0) != np.sign(x1) or abs(x1) < 0.015:
            cross[k >= 100] += 1
    s = gate.summary()
    print(f"crossings before the edit {cross[0]}, after {cross[1]}; summary certified {s['certified']} "
          f"violation {s['violation']} uncertain {s['uncertain']} replaced {s['replaced']}")
    print("HELD" if cross[1] == 0 else "BROKEN")


if __name__ == "__main__":
    main()
