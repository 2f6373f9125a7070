"""The bench's own gate rows (monitor.bench.targets) in this process's tree, one JSON line each.

usage: PYTHONPATH=<tree> python rows.py ROW [ROW ...]    ROW: pusher | arm | pusher_nobrake | tunnel | tunnel_full | reacher
       env GATE5_REPS (default 3), GATE5_GSTEPS/GATE5_USTEPS (default 10/200: the --quick parameters)
"""
import json
import os
import sys
import types
import warnings

warnings.simplefilter("ignore")
from monitor.bench import targets  # noqa: E402

reps = int(os.environ.get("GATE5_REPS", "3"))
gs, us = int(os.environ.get("GATE5_GSTEPS", "10")), int(os.environ.get("GATE5_USTEPS", "200"))
cfg = types.SimpleNamespace(quick=True, smoke=False, reps=reps, log=None)
for row in sys.argv[1:]:
    if row in ("tunnel", "tunnel_full"):  # tunnel_full: the bench's non-quick tunnel (200-window blocks)
        r = targets.tunnel_gate(cfg if row == "tunnel" else types.SimpleNamespace(**{**vars(cfg), "quick": False}))
    else:
        env_id, brake = {"pusher": ("Pusher-v5", True), "arm": ("monitor/Arm-v0", True),
                         "pusher_nobrake": ("Pusher-v5", False), "reacher": ("Reacher-v5", True)}[row]
        r = targets.gym_gate(env_id, pairs="mujoco", steps_gated=gs, steps_ungated=us, reps=reps, brake=brake)
    print(json.dumps({"row": row, "tree": os.environ.get("PYTHONPATH"),
                      "ratio": r["ratio"], "gated_us": r["gated_s"] * 1e6, "ungated_us": r["ungated_s"] * 1e6,
                      "verdicts": r["verdicts"]}), flush=True)
