"""In a process warmed like the bench (gate steps that never reach the Python stage), time the rare call cold."""
import time, sys, cProfile, pstats, io
import gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
from monitor.gym_gate import SafetyGate
import load
caps = load.load()
n_py = [0]
_ps = E._python_stages
def ps(*a, **k):
    n_py[0] += 1
    return _ps(*a, **k)
E._python_stages = ps
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=1000); env.action_space.seed(1000)
for _ in range(3): env.step(env.action_space.sample())
print("python stages during warm steps:", n_py[0])
which = int(sys.argv[1]) if len(sys.argv) > 1 else 0
c, scene, plan, a, k = caps[which]
mode = sys.argv[2] if len(sys.argv) > 2 else "time"
if mode == "prof":
    pr = cProfile.Profile(); pr.enable()
t = time.perf_counter(); r = E.certify(scene, plan, *a, **k); dt = time.perf_counter() - t
if mode == "prof":
    pr.disable(); s = io.StringIO(); pstats.Stats(pr, stream=s).sort_stats("cumulative").print_stats(45); print(s.getvalue())
print("cold", r.verdict, dt * 1e3, "ms wall")
for rep in range(3):
    t = time.perf_counter(); r = E.certify(scene, plan, *a, **k); print("warm", r.verdict, (time.perf_counter() - t) * 1e3, "ms wall")
