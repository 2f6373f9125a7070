"""Braking-tail horizon vs outcome on monitor/Arm-v0 (data for the horizon decision, issue 12).

For each horizon: 500 gated steps of (a) the acceptance policy that drives the stretched arm into
post_a and (b) seeded uniform random actions; MuJoCo arm/obstacle contacts after each step,
blocked steps, and the gated step time against the ungated one (same run, interleaved).
Usage: python horizon_sweep.py [steps]
"""
import sys
import time

import gymnasium as gym
import numpy as np

import monitor.envs  # noqa: F401
from monitor.gym_gate import SafetyGate

STEPS = int(sys.argv[1]) if len(sys.argv) > 1 else 500


def ncon_between(m, d, a, b):
    n = 0
    for i in range(d.ncon):
        g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
        if (g1 in a and g2 in b) or (g1 in b and g2 in a):
            n += 1
    return n


def run(policy, horizon):
    env = gym.make("monitor/Arm-v0", max_episode_steps=STEPS + 1)
    if horizon is not None:
        kw = {"brake_horizon": horizon} if horizon else {"brake": False}
        env = SafetyGate(env, on_violation="block", **kw)
    u = env.unwrapped
    m = u.model
    body_of = [m.body(int(m.geom_bodyid[g])).name for g in range(m.ngeom)]
    arm = {g for g, b in enumerate(body_of) if b in ("link1", "link2", "link3", "gripper")}
    obst = {g for g, b in enumerate(body_of) if b in ("post_a", "post_b", "shelf")}
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    env.action_space.seed(0)
    into_post = np.array([np.arctan2(0.25, 0.45), 0.0, 0.0], dtype=np.float32)
    lo, hi = env.action_space.low, env.action_space.high
    contacts = blocked = 0
    t = time.perf_counter()
    for _ in range(STEPS):
        a = into_post if policy == "post" else rng.uniform(lo, hi).astype(np.float32)
        _, _, term, trunc, info = env.step(a)
        contacts += ncon_between(m, u.data, arm, obst)
        if horizon is not None:
            blocked += int(info["safety"]["replaced"])
        if term or trunc:
            env.reset()
    dt = (time.perf_counter() - t) / STEPS
    env.close()
    return contacts, blocked, dt


if __name__ == "__main__":
    dt_env = gym.make("monitor/Arm-v0").unwrapped.dt
    print(f"Arm-v0 env dt {dt_env} s, {STEPS} steps per run")
    for policy in ("post", "random"):
        c0, _, tu = run(policy, None)
        print(f"{policy:6s} ungated: contacts {c0}, {1e6 * tu:.0f} us/step")
        for h in (0, dt_env, 2 * dt_env, 0.1, 0.25):
            c, b, tg = run(policy, h)
            _, _, tu = run(policy, None)
            print(f"{policy:6s} horizon {h:6.3f} s: contacts {c:4d}  blocked {b:4d}  gated/ungated {tg / tu:6.1f}x")
