import os
import sys

import monitor
from monitor.bench.targets import gym_gate

env = sys.argv[1]
r = gym_gate(env, pairs="mujoco", steps_gated=30, steps_ungated=1000, reps=int(sys.argv[2]) if len(sys.argv) > 2 else 5, brake=True)
print(f"GYM {os.path.basename(os.path.dirname(os.path.dirname(monitor.__file__)))} {env} gated_us {r['gated_s']*1e6:.1f} ungated_us {r['ungated_s']*1e6:.2f} ratio {r['ratio']:.2f}")
