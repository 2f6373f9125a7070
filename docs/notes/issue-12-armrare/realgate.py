"""In a real gate process (no pickling): ensure_warm, then the bench's seeds; which dispatchers load during the run."""
import time, sys
import gymnasium as gym
from loadlog import active
from monitor.warmup import ensure_warm
ensure_warm()
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
import monitor.certify.fat_kernels as F
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=1000); env.action_space.seed(1000)
for _ in range(3): env.step(env.action_space.sample())
active[0] = True
for ep in range(2):
    env.reset(seed=ep); env.action_space.seed(ep)
    for a in [env.action_space.sample() for _ in range(10)]:
        env.step(a)
print("traj_balls signatures", len(F.traj_balls.signatures))
