"""Line profile (line_profiler) of a gated Pusher step: 20 blocks of 30 seeded steps after a warm-up."""

import gc

# line_profiler installed with `pip install --target /tmp/pp line_profiler`; run with PYTHONPATH=$PWD:/tmp/pp
from line_profiler import LineProfiler
import gymnasium as gym
import monitor.gate as G
import monitor.gym_gate as GG
import monitor.certify.engine as E
from monitor.warmup import ensure_warm

ensure_warm()
env = GG.SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")


def block(n, rep):
    env.reset(seed=rep)
    env.action_space.seed(rep)
    acts = [env.action_space.sample() for _ in range(n)]
    for a in acts:
        _, _, te, tr, info = env.step(a)
        if te or tr:
            env.reset()


block(5, 1000)
gc.collect()
lp = LineProfiler()
for f in [
    GG.SafetyGate.step,
    G.Gate.decide,
    G.Gate._certify_joint,
    E.certify,
    E._certify_fast,
    G.Rollout._tail_by_rollout,
    G.Rollout.brake_rows,
]:
    lp.add_function(f)
lp.enable_by_count()
for r in range(20):
    block(30, r)
lp.disable_by_count()
lp.print_stats(output_unit=1e-6, stripzeros=True)
