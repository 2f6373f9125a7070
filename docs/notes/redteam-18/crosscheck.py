"""Cross-check of red team 18's oracle distances against MuJoCo's and the library's static distance.

At seeded random configurations of each audited model, for every monitored pair: the oracle's
(lower, upper) signed distance, MuJoCo's ``mj_geomDistance`` and ``monitor.geometry.distance.
shape_distance`` (lower, upper). Two rigorous intervals must overlap: a pair where the oracle's lower
below the library's lower by more than 1e-7 m is counted as ``inconsistent`` (the library claims more
clearance than a verified witness allows); the opposite (``library_closer``: the library's upper below
the oracle's lower) is the library's conservative over-approximation (circumscribed shapes,
``scene.approximations``). MuJoCo is counted apart (``mj_outside``: MuJoCo's
value outside the oracle's interval by more than 1e-6 m; MuJoCo 4.0.0 misses some capsule-box
overlaps, and its mesh distances use the mesh's own hull).

    PYTHONPATH=. python docs/notes/redteam-18/crosscheck.py [--configs 40]
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import gymnasium as gym
import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from oracle18 import PathOracle, geom_model  # noqa: E402

import monitor  # noqa: E402
import monitor.envs  # noqa: E402,F401
from monitor.geometry.distance import shape_distance  # noqa: E402


def random_qpos(model: mujoco.MjModel, rng: np.random.Generator, q0: np.ndarray) -> np.ndarray:
    """A seeded random configuration (joint ranges, random unit quaternions)."""
    q = np.array(q0, float)
    for j in range(model.njnt):
        a, t = int(model.jnt_qposadr[j]), int(model.jnt_type[j])
        if t in (2, 3):
            lo, hi = model.jnt_range[j] if model.jnt_limited[j] else (-np.pi, np.pi)
            q[a] = rng.uniform(lo, hi)
        elif t == 0:
            q[a:a + 3] += rng.uniform(-0.3, 0.3, 3)
            v = rng.normal(size=4)
            q[a + 3:a + 7] = v / np.linalg.norm(v)
        elif t == 1:
            v = rng.normal(size=4)
            q[a:a + 4] = v / np.linalg.norm(v)
    return q


def check(name: str, model: mujoco.MjModel, scene, configs: int, seed: int) -> dict:
    """Compare the three distances over ``configs`` random configurations."""
    rng = np.random.default_rng(seed)
    orc = PathOracle(model)
    pairs = [tuple(int(x) for x in p) for p in scene.pair_ids]
    out = {"pairs": 0, "inconsistent": 0, "library_closer": 0, "max_library_closer": 0.0,
           "conservative_library": 0, "mj_outside": 0, "unsupported": 0, "max_oracle_gap": 0.0}
    d = mujoco.MjData(model)
    for _ in range(configs):
        q = random_qpos(model, rng, model.qpos0)
        b = orc.start_distance(q, pairs)
        d.qpos[:] = q
        mujoco.mj_kinematics(model, d)
        for (a, c), (lo, up) in zip(pairs, b):
            if not np.isfinite(up):
                continue  # culled by bounding spheres (5 cm apart): nothing to compare
            out["pairs"] += 1
            out["max_oracle_gap"] = max(out["max_oracle_gap"], float(up - lo) if np.isfinite(lo) else 0.0)
            ga, gc = scene.geoms[a], scene.geoms[c]
            if ga.shape is None or gc.shape is None:
                out["unsupported"] += 1
                continue
            ba, bc = ga.body_id, gc.body_id
            Xa = (d.xmat[ba].reshape(3, 3).copy(), d.xpos[ba].copy())
            Xc = (d.xmat[bc].reshape(3, 3).copy(), d.xpos[bc].copy())
            r = shape_distance(ga.shape, Xa, gc.shape, Xc)
            if up < r.lower - 1e-7 - ga.shape.approx_error - gc.shape.approx_error:
                out["conservative_library"] += 0  # (never: listed for symmetry)
            if lo > r.upper + 1e-7:  # the library says closer than the geoms can be: conservative
                out["library_closer"] += 1
                out["max_library_closer"] = max(out["max_library_closer"], float(lo - r.upper))
            if up < r.lower - 1e-7:  # the library says farther than a verified witness: unsound
                out["inconsistent"] += 1
                if out["inconsistent"] <= 3:
                    print(f"  {name}: {ga.name}|{gc.name} oracle [{lo:.9f}, {up:.9f}] library "
                          f"[{r.lower:.9f}, {r.upper:.9f}]")
            mjd = mujoco.mj_geomDistance(model, d, a, c, 10.0, None)
            if mjd < lo - 1e-6 or mjd > up + 1e-6:
                out["mj_outside"] += 1
    return out


def main() -> int:
    """Run every model."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", type=int, default=40)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    models = []
    for env_id in ["Pusher-v5", "Ant-v5", "HalfCheetah-v5", "Hopper-v5", "Walker2d-v5", "Humanoid-v5",
                   "HumanoidStandup-v5", "monitor/Arm-v0"]:
        m = gym.make(env_id).unwrapped.model
        models.append((env_id, m, monitor.Scene.from_model(m, pairs="mujoco")))
    root = Path(monitor.__file__).resolve().parents[1] / "models"
    for sc in ("tunnel", "hand30"):
        m = mujoco.MjModel.from_xml_path(str(root / sc / "scene.xml"))
        models.append((sc, m, monitor.Scene.from_model(m, pairs="mujoco")))
    bad = 0
    for i, (name, m, scene) in enumerate(models):
        for g in {int(x) for p in scene.pair_ids for x in p}:
            geom_model(m, g)  # raises for a type the oracle does not handle
        r = check(name, m, scene, args.configs, i)
        bad += r["inconsistent"]
        print(f"{name:22s} {r}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
