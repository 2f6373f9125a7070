"""Which numba dispatchers load during the first rare call (after gate warm steps); argv: case index [warm: ensure_warm first]."""
import time, sys
import gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
from monitor.gym_gate import SafetyGate
import load
caps = load.load()
from loadlog import active
if len(sys.argv) > 2:
    from monitor.warmup import ensure_warm
    ensure_warm()
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=1000); env.action_space.seed(1000)
for _ in range(3): env.step(env.action_space.sample())
import sys as _s
before = set(_s.modules)
c, scene, plan, a, k = caps[int(sys.argv[1])]
active[0] = True
t = time.perf_counter(); r = E.certify(scene, plan, *a, **k); dt = time.perf_counter() - t
print("cold", r.verdict, f"{dt*1e3:.1f} ms wall; new modules:", sorted(set(_s.modules) - before))
