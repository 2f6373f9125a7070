"""Which numba dispatchers load from the disk cache during the first rare call (after gate warm steps)."""
import time, sys
import gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
from monitor.gym_gate import SafetyGate
from numba.core import dispatcher
import load
caps = load.load()
_orig = dispatcher.Dispatcher._compile_for_args
active = [False]
def cfa(self, *a, **k):
    t = time.perf_counter()
    try: return _orig(self, *a, **k)
    finally:
        if active[0]: print(f"  load {self.py_func.__module__}.{self.py_func.__name__}: {(time.perf_counter()-t)*1e3:.1f} ms")
dispatcher.Dispatcher._compile_for_args = cfa
import builtins
_imp = builtins.__import__
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=1000); env.action_space.seed(1000)
for _ in range(3): env.step(env.action_space.sample())
import sys as _s
before = set(_s.modules)
c, scene, plan, a, k = caps[int(sys.argv[1])]
active[0] = True
t = time.perf_counter(); r = E.certify(scene, plan, *a, **k); dt = time.perf_counter() - t
print("cold", r.verdict, f"{dt*1e3:.1f} ms wall; new modules:", sorted(set(_s.modules) - before))
