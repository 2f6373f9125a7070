"""Red team 14: every GeomInfo shape (shared per distinct input) against MuJoCo's own geom poses.

Usage: PYTHONPATH=<tree>:<tree>/tests python geomcheck.py SEED0 NSEEDS [--maxg N]

Per random model (_pair_oracle.random_model, shared sizes / positions / meshes on many bodies) at a
random qpos: the scene's body-frame shape of each geom, moved by MuJoCo's body pose (xpos, xmat),
must be the geom as MuJoCo places it (geom_xpos, geom_xmat): sphere centre, capsule segment,
box corners, mesh vertices (each MuJoCo vertex within the scene's hull, each hull point one of
MuJoCo's vertices), and the support of cylinders / ellipsoids along the geom axes. Tolerance 1e-9 m.
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
    maxg = int(sys.argv[sys.argv.index("--maxg") + 1]) if "--maxg" in sys.argv else 4
    bad = checked = shared = 0
    for seed in range(s0, s0 + n):
        xml, _ = random_model(seed, None, maxg, shared=0.7)
        m = mujoco.MjModel.from_xml_string(xml)
        d = mujoco.MjData(m)
        rng = np.random.default_rng(seed)
        d.qpos[:] = m.qpos0 + rng.normal(0, 0.5, m.nq)
        mujoco.mj_normalizeQuat(m, d.qpos)
        mujoco.mj_kinematics(m, d)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sc = monitor.Scene.from_model(m)
        shared += len(sc.geoms) - len({id(g.shape) for g in sc.geoms})
        for g in sc.geoms:
            if g.shape is None or g.type == "plane":
                continue
            b = g.body_id
            Rb, pb = d.xmat[b].reshape(3, 3), d.xpos[b]
            Rg, pg = d.geom_xmat[g.id].reshape(3, 3), d.geom_xpos[g.id]
            P = np.asarray(g.shape.points) @ Rb.T + pb
            size = m.geom_size[g.id]
            if g.type == "sphere":
                want = pg[None]
            elif g.type == "capsule":
                want = np.stack([pg - Rg[:, 2] * size[1], pg + Rg[:, 2] * size[1]])
            elif g.type == "box":
                c = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * size
                want = c @ Rg.T + pg
            elif g.type == "mesh":
                a, k = m.mesh_vertadr[m.geom_dataid[g.id]], m.mesh_vertnum[m.geom_dataid[g.id]]
                want = m.mesh_vert[a:a + k].astype(float) @ Rg.T + pg
            else:   # cylinder / ellipsoid: circumscribed; support along each geom axis in [s, 1.2 s]
                u = (P - pg) @ Rg
                s3 = size[:3] if g.type == "ellipsoid" else np.array([size[0], size[0], size[1]])
                checked += 1
                if not ((u.max(axis=0) >= s3 - 1e-9).all() and (u.max(axis=0) <= 1.2 * s3).all()
                        and (-u.min(axis=0) >= s3 - 1e-9).all() and (-u.min(axis=0) <= 1.2 * s3).all()):
                    bad += 1
                    print(seed, g.name, g.type, "support", u.max(axis=0), u.min(axis=0), s3, flush=True)
                continue
            checked += 1
            # every MuJoCo point is near one of the scene's points and vice versa (hull points
            # of a mesh are a subset of its vertices)
            dist = np.linalg.norm(want[:, None] - P[None], axis=2)
            tol = 1e-9
            if g.type == "mesh":
                ok = dist.min(axis=0).max() < tol
            else:
                ok = dist.min(axis=0).max() < tol and dist.min(axis=1).max() < tol
            if not ok:
                bad += 1
                print(seed, g.name, g.type, "body", b, "max err", dist.min(axis=0).max(), flush=True)
    print(dict(checked=checked, bad=bad, shared_shape_objects=shared))


if __name__ == "__main__":
    main()
