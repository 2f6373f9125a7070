"""Timing of the compiled motion kernels against Plan.motion_bounds (issue 12, motion half).

Usage (about a minute with a warm numba cache):
    PYTHONPATH=$PWD python scripts/bench_motion_kernel.py            # arm + Pusher-v5
    PYTHONPATH=$PWD python scripts/bench_motion_kernel.py --cold     # + cold compile in a fresh cache

All figures are medians; ratios are from the same run. Not a test.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time

import mujoco
import numpy as np
from numba import njit

from monitor.motion import kernel as KN
from monitor.motion.pack import pack_trajectory, poses_and_bounds
from monitor.motion.plan import Plan

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _model(name: str) -> mujoco.MjModel:
    if name == "arm":
        return mujoco.MjModel.from_xml_path(os.path.join(ROOT, "models", "arm", "scene.xml"))
    import gymnasium as gym

    return gym.make("Pusher-v5").unwrapped.model


def _median_us(f, n: int) -> float:
    ts = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)) * 1e6


@njit
def _loop_tree(mp, n, p, R, tr, an):
    for i in range(n):
        KN.tree_bounds(mp, 0.01, 0.02 + 1e-12 * i, p, R, tr, an)


@njit
def _loop_body(mp, n, b, p, R):
    s = 0.0
    for i in range(n):
        s += KN.body_bound(mp, b, 0.01, 0.02 + 1e-12 * i, p, R)[0]
    return s


def bench(name: str) -> None:
    """Print the per-call figures for one model ("arm" or "pusher")."""
    m = _model(name)
    rng = np.random.default_rng(0)
    q0 = np.array(m.qpos0)
    q1 = q0 + 0.05 * rng.normal(size=m.nq)
    for j in range(m.njnt):
        if m.jnt_type[j] in (0, 1):
            a = m.jnt_qposadr[j] + (3 if m.jnt_type[j] == 0 else 0)
            q1[a:a + 4] /= np.linalg.norm(q1[a:a + 4])
    times = np.array([0.0, 0.05])
    Q = np.stack([q0, q1])
    plan = Plan(times, Q, model=m)
    mp = pack_trajectory(plan)
    nb = m.nbody
    p = np.empty((nb, 3))
    R = np.empty((nb, 3, 3))
    tr = np.empty(nb)
    an = np.empty(nb)
    p1 = np.empty(3)
    R1 = np.empty((3, 3))
    _loop_tree(mp, 1, p, R, tr, an)
    _loop_body(mp, 1, nb - 1, p1, R1)
    cnt = [0]

    def plan_one():  # a distinct interval each call (defeats the per-plan memo); scale cached
        cnt[0] += 1
        a = 0.01 + 1e-9 * cnt[0]
        plan.motion_bounds(np.array([a]), np.array([a + 0.01]))

    edges = np.linspace(0.0, 0.05, 9)

    def plan_step():  # what a gated step pays for motion: a new Plan, poses + bounds of 8 sub-intervals
        pl = Plan(times, Q, model=m)
        pl.body_poses(0.5 * (edges[:-1] + edges[1:]))
        pl.motion_bounds(edges[:-1], edges[1:])

    def kernel_step():
        pl = Plan(times, Q, model=m)
        poses_and_bounds(pack_trajectory(pl), edges[:-1], edges[1:])

    t_plan = _median_us(plan_one, 300)
    n = 2000
    t_tree = _median_us(lambda: _loop_tree(mp, n, p, R, tr, an), 7) / n
    t_body = _median_us(lambda: _loop_body(mp, n, nb - 1, p1, R1), 7) / n
    t_tree_py = _median_us(lambda: KN.tree_bounds(mp, 0.01, 0.02, p, R, tr, an), 2000)
    t_pack = _median_us(lambda: pack_trajectory(plan), 300)
    t_ps = _median_us(plan_step, 100)
    t_ks = _median_us(kernel_step, 100)
    t_new = _median_us(lambda: Plan(times, Q, model=m), 200)
    print(f"{name}: nbody={nb} njnt={m.njnt}")
    print(f"  Plan.motion_bounds, 1 interval:        {t_plan:9.1f} us")
    print(f"  tree_bounds, all bodies (in numba):     {t_tree:9.2f} us  ratio {t_plan / t_tree:7.0f}x")
    print(f"  body_bound, deepest body (in numba):    {t_body:9.2f} us  ratio {t_plan / t_body:7.0f}x")
    print(f"  tree_bounds called from Python:         {t_tree_py:9.2f} us  ratio {t_plan / t_tree_py:7.0f}x")
    print(f"  pack_trajectory(plan):                  {t_pack:9.1f} us")
    print(f"  step: Plan + poses + bounds (8 sub-int) {t_ps:9.1f} us vs Plan + pack + poses_and_bounds "
          f"{t_ks:.1f} us  ratio {t_ps / t_ks:.1f}x  (Plan() alone {t_new:.1f} us)")


COLD = """
import numpy as np, mujoco
from monitor.motion.plan import Plan
from monitor.motion.pack import pack_trajectory, poses_and_bounds, body_poses
from monitor.motion import kernel as KN
m = mujoco.MjModel.from_xml_path({xml!r})
q0 = np.array(m.qpos0)
mp = pack_trajectory(Plan(np.array([0, .05]), np.stack([q0, q0 + .05]), model=m))
poses_and_bounds(mp, [0.0], [0.05]); body_poses(mp, [0.01])
p = np.empty(3); R = np.empty((3, 3)); KN.body_bound(mp, 1, 0.0, 0.05, p, R); KN.body_pose(mp, 1, 0.0, p, R)
"""


def cold() -> None:
    """Cold (empty numba cache) and warm first call in a subprocess: wall and CPU seconds."""
    src = COLD.format(xml=os.path.join(ROOT, "models", "arm", "scene.xml"))
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=ROOT)
        for label in ("cold (empty numba cache)", "warm"):
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t = time.perf_counter()
            subprocess.run([sys.executable, "-c", src], env=env, check=True)
            wall = time.perf_counter() - t
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
            print(f"  {label}: wall {wall:.1f} s, CPU {cpu:.1f} s (process incl. imports)")


if __name__ == "__main__":
    for model_name in ("arm", "pusher"):
        bench(model_name)
    if "--cold" in sys.argv:
        cold()
    print(f"load average: {os.getloadavg()}")
