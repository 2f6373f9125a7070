"""SafetyGate(monitor/Arm-v0) with a default log, seeded random actions: median µs per env.step.

Accepted and replaced steps apart (about half the random Arm actions are blocked); the log has
default options (foxglove on when installed).

  for r in 1 2 3; do for t in /tmp/h12ac_main /work/wt/h12ac; do \
    (cd $t && PYTHONPATH=$t python /work/wt/h12ac/docs/notes/review-applied/bench_safetygate.py); \
  done; done
"""
import statistics
import tempfile
import time
from pathlib import Path

import gymnasium as gym

import monitor
import monitor.envs  # noqa: F401
from monitor.gym_gate import SafetyGate

env = SafetyGate(gym.make("monitor/Arm-v0"), log=Path(tempfile.mkdtemp()) / "a.mcap")
env.reset(seed=0)
env.action_space.seed(0)
acc, rep = [], []
for k in range(330):
    a = env.action_space.sample()
    t0 = time.perf_counter()
    _, _, term, trunc, info = env.step(a)
    us = (time.perf_counter() - t0) * 1e6
    if k >= 30:
        (rep if env.gate.last_report.replaced else acc).append(us)
    if term or trunc:
        env.reset()
windows = env.gate._log.windows
env.close()
tree = monitor.__file__.split('/monitor/')[0]
print(f"{tree:20} accepted {statistics.median(acc):8.1f} us (n={len(acc)})  "
      f"replaced {statistics.median(rep):8.1f} us (n={len(rep)})  log windows {windows}")
