"""Shared seeded scenes for the screw / Bézier false-negative hunts (tests/test_screw.py,
tests/test_bezier_motion.py): one moving body (box + capsule, offset from its origin so the
rotation matters) among static obstacles, and an oracle loop over tests/redteam_oracle.py."""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from redteam_oracle import geom_pose, motion_min, quat_mat  # noqa: E402

XML = """<mujoco><worldbody>
<geom name="obs_sphere" type="sphere" size="{r}" pos="{s0} {s1} {s2}"/>
<geom name="obs_box" type="box" size=".12 .08 .1" pos="{b0} {b1} {b2}" euler="10 20 30"/>
<body name="mover" mocap="true">
  <geom name="mv_box" type="box" size=".1 .05 .08" pos=".3 0 0"/>
  <geom name="mv_cap" type="capsule" size=".04 .1" pos="0 .2 .1" euler="0 90 0"/>
</body></worldbody></mujoco>"""
MOVING = (2, 3)
STATIC = (0, 1)


def scene_model(rng: np.random.Generator) -> mujoco.MjModel:
    s = rng.uniform(-0.5, 0.5, size=3)
    b = rng.uniform(-0.5, 0.5, size=3)
    xml = XML.format(r=round(float(rng.uniform(0.05, 0.15)), 4), s0=s[0], s1=s[1], s2=s[2],
                     b0=b[0], b1=b[1], b2=b[2])
    return mujoco.MjModel.from_xml_string(xml)


class PoseOracle:
    """World geom poses from an independent body-pose function ``pose(t) -> (x (3,), R (3, 3))``."""

    def __init__(self, model: mujoco.MjModel, pose, body: int = 1):
        self.model, self.pose, self.body = model, pose, body

    def geoms(self, t: float, ids: tuple[int, ...]):
        x, R = self.pose(t)
        out = []
        for g in ids:
            m = self.model
            if int(m.geom_bodyid[g]) == self.body:
                out.append(geom_pose(m, g, R @ quat_mat(m.geom_quat[g]), x + R @ m.geom_pos[g]))
            else:
                out.append(geom_pose(m, g, quat_mat(m.geom_quat[g]), np.array(m.geom_pos[g], float)))
        return out


def hunt(make_case, n_cases: int, seed: int, label: str) -> dict:
    """Run ``n_cases`` seeded cases; return counts. ``make_case(rng) -> (model, traj, pose_fn)``."""
    from monitor import Scene, certify

    rng = np.random.default_rng(seed)
    counts = {"cases": 0, "certified": 0, "violation": 0, "uncertain": 0, "oracle_contact": 0,
              "false_negatives": 0, "targeted": 0, "targeted_fn": 0}
    fns = []
    for k in range(n_cases):
        model, traj, pose = make_case(rng)
        oracle = PoseOracle(model, pose)
        scene = Scene.from_model(model, pairs="all")
        margin = float(rng.choice([0.0, 0.01]))
        cert = certify(scene, traj, margin, 1e-3)
        counts["cases"] += 1
        counts[str(cert.verdict)] += 1
        ups = [motion_min(oracle, ga, gb, traj.t0, traj.t1, n=120, refine=2).upper
               for ga in MOVING for gb in STATIC]
        low = min(ups)
        if low < margin:
            counts["oracle_contact"] += 1
            if cert.verdict == "certified":
                counts["false_negatives"] += 1
                fns.append((label, k, margin, low))
        elif k % 3 == 0 and np.isfinite(low):
            # targeted: a margin just above the oracle's verified minimum must not certify
            counts["targeted"] += 1
            c2 = certify(scene, traj, low + 1e-4, 1e-3)
            if c2.verdict == "certified":
                counts["targeted_fn"] += 1
                fns.append((label, k, low + 1e-4, low))
    counts["fn_cases"] = fns
    return counts
