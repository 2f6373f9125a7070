"""Plain-timer split of a gated step: exclusive thread time per wrapped function (us per step).

usage: PYTHONPATH=<tree> python excl.py tunnel|Pusher-v5|monitor/Arm-v0|Reacher-v5 STEPS [--pack]
Each wrapped function's time excludes the wrapped functions it calls (a stack of timers);
"rest" = the step minus every wrapped function. The timers add ~1 us per wrapped call.
"""
import collections
import sys
import time
import warnings

import mujoco
import numpy as np

warnings.simplefilter("ignore")
import monitor.certify.engine as E  # noqa: E402
import monitor.gate as G  # noqa: E402
import monitor.gym_gate as GG  # noqa: E402
from monitor.motion.plan import Plan  # noqa: E402
from monitor.warmup import ensure_warm  # noqa: E402

work, n = sys.argv[1], int(sys.argv[2])
pc = time.thread_time
T = collections.Counter()
C = collections.Counter()
stack = []


def timed(key, f):
    def w(*a, **k):
        stack.append(0.0)
        t = pc()
        try:
            return f(*a, **k)
        finally:
            dt = pc() - t
            inner = stack.pop()
            T[key] += dt - inner
            C[key] += 1
            if stack:
                stack[-1] += dt
    return w


def wrap(obj, name, key=None):
    setattr(obj, name, timed(key or name, getattr(obj, name)))


_mj_step, _mj_copy, _mj_get = mujoco.mj_step, mujoco.mj_copyData, mujoco.mj_getState
E.certify = timed("certify", E.certify)
for name in ("_window", "brake_rows", "_tail_by_rollout", "commit", "window_matches"):
    wrap(G.Rollout, name)
# (not Gate._certify: a replaced _certify turns the gate's shortcuts off, see Gate._certify_is_own)
for name in ("_certify_joint", "_split_reuse", "_certify_subset", "_tail_covers", "decide", "step",
             "_write_log", "_account", "_sync_scene", "_certify_nothing", "_tail_refuted"):
    if hasattr(G.Gate, name):
        wrap(G.Gate, name, "Gate." + name)
wrap(G, "hold_ctrl")
wrap(G.StepReport, "info", "StepReport.info")
for name in ("step", "_commit_sim", "_check_window_ran", "_check_applied_ctrl", "_check_geometry", "_as_inner"):
    wrap(GG.SafetyGate, name, "SafetyGate." + name)
if "--pack" in sys.argv:  # the motion pack's parts inside certify (booked apart from "certify")
    import monitor.certify.kernels as KS
    import monitor.motion.pack as MP
    KS.trajectory_pack_memo = timed("pack: trajectory_pack_memo", KS.trajectory_pack_memo)
    KS._pack_agrees = timed("pack: _pack_agrees", KS._pack_agrees)
    MP.pack_trajectory = timed("pack: pack_trajectory", MP.pack_trajectory)
    wrap(Plan, "body_poses", "Plan.body_poses")
_tr = Plan.__dict__["_trusted"].__func__
Plan._trusted = classmethod(timed("Plan._trusted", _tr))
mujoco.mj_step = timed("mj_step", _mj_step)
mujoco.mj_copyData = timed("mj_copyData", _mj_copy)
G.mujoco = mujoco

ensure_warm()
sys.path.insert(0, __file__.rsplit("/", 1)[0])
from runners import runner  # noqa: E402

run = runner(work)
run(20)
T.clear()
C.clear()
t = pc()
run(n)
total = (pc() - t) / n * 1e6
print(f"{work}: {total:.0f} us per step (thread time, timers on)")
for k, v in T.most_common():
    print(f"  {k:32s} {v / n * 1e6:8.1f} us  {C[k] / n:6.2f} calls")
