"""One process: the bench's own ``monitor.bench.targets.gym_gate`` on one env; prints one JSON line.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-armprof/ab_one.py ENV_ID STEPS_GATED STEPS_UNGATED REPS
"""
import json
import sys

from monitor.bench.targets import gym_gate

env_id, gs, us, reps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
r = gym_gate(env_id, steps_gated=gs, steps_ungated=us, reps=reps)
print(json.dumps({"env": env_id, "gated_us": r["gated_s"] * 1e6, "ungated_us": r["ungated_s"] * 1e6,
                  "ratio": r["ratio"], "verdicts": r["verdicts"]}))
