"""Per-step wall time of SafetyGate(monitor/Arm-v0) and of Gate.step on the tunnel (medians, µs).

Run from a tree: ``cd <tree> && PYTHONPATH=<tree> python docs/notes/redteam-3/bench_step.py``.
"""
import time

import gymnasium as gym
import mujoco
import numpy as np

import monitor.envs  # noqa: F401
from monitor.envs.assets import scene
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate

env = SafetyGate(gym.make("monitor/Arm-v0"), log=None)
env.reset(seed=0)
env.action_space.seed(0)
rng = np.random.default_rng(0)
acts = [env.action_space.sample() for _ in range(300)]
ts = []
for a in acts:
    t = time.perf_counter()
    _, _, te, tr, _ = env.step(a)
    ts.append(time.perf_counter() - t)
    if te or tr:
        env.reset(seed=1)
s = env.gate.stats
m = mujoco.MjModel.from_xml_path(str(scene("tunnel")))
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, 0)
g = Gate(m)
tt = []
for k in range(300):
    c = np.array([rng.uniform(-6, 6)]) if k % 20 == 0 else c
    t = time.perf_counter()
    g.step(d, c)
    tt.append(time.perf_counter() - t)
print(f"arm_safetygate_us {np.median(ts) * 1e6:.1f} replaced {s['replaced']} tail_reused {s['tail_reused']} "
      f"committed {s['committed']} differs {s.get('tail_replay_differs')} | tunnel_gate_step_us {np.median(tt) * 1e6:.1f} "
      f"tail_reused {g.stats['tail_reused']}")
