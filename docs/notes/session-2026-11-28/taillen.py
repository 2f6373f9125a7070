"""Tail lengths (substeps until every |qvel| <= brake_vel_tol, or the horizon) on the bench workloads."""
import collections, numpy as np, mujoco, gymnasium as gym
import monitor, monitor.envs  # noqa
from monitor.gate import Rollout, Gate
from monitor.gym_gate import SafetyGate
lens = []
orig = Rollout.brake_rows
def rec(self, *a, **k):
    rows, b = orig(self, *a, **k); lens.append((len(rows) - 1, a[4])); return rows, b
Rollout.brake_rows = rec
def report(name):
    n = np.array([x for x, _ in lens]); h = lens[0][1] if lens else 0
    print(f"{name}: tails {len(n)}, horizon {h} substeps, full-length {np.mean(n == h):.0%}, median {np.median(n) if len(n) else 0:.0f}, mean {n.mean() if len(n) else 0:.1f}")
    lens.clear()
for env_id in ("monitor/Arm-v0", "Pusher-v5"):
    env = SafetyGate(gym.make(env_id), pairs="mujoco"); env.reset(seed=0); env.action_space.seed(0)
    for _ in range(100):
        _, _, te, tr, _ = env.step(env.action_space.sample())
        if te or tr: env.reset()
    report(env_id); env.close()
m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml"); d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, 0); g = Gate(m, margin=0.001)
for k in range(100):
    t = 0.3 if (k // 25) % 2 == 0 else -0.3
    g.step(d, np.clip([12.0 * (t - d.qpos[0])], -6.0, 6.0), nstep=1)
report("tunnel")
m = mujoco.MjModel.from_xml_path("/work/main/models/hand30/scene.xml"); d = mujoco.MjData(m); g = Gate(m)
tg = np.random.default_rng(7).uniform(m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1], size=(64, m.nu))
for k in range(20):
    g.step(d, tg[(k // 10) % 64], nstep=5)
report("hand30")
