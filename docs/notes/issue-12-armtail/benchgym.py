"""The bench's own gym_gate workload (monitor.bench.targets.gym_gate) for Arm-v0; prints ratio and times."""
import sys
import monitor
from monitor.bench.targets import gym_gate
brake = sys.argv[1] != "nobrake"
steps, reps = int(sys.argv[2]), int(sys.argv[3])
r = gym_gate("monitor/Arm-v0", steps_gated=steps, steps_ungated=200, reps=reps, brake=brake)
tree = monitor.__file__.split("/monitor/")[0]
print(f"{tree} brake={brake} ratio {r['ratio']:.2f} gated {r['gated_s']*1e6:.0f} us ungated {r['ungated_s']*1e6:.0f} us "
      f"floor {r.get('physics_floor_ratio', float('nan')):.2f} verdicts {r['verdicts']}")
