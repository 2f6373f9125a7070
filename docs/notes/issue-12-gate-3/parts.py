"""Per gated step: mean µs of each named part, wrappers of perf_counter (no cProfile).

PYTHONPATH=<tree> python docs/notes/issue-12-gate-3/parts.py Pusher-v5 200 [brake=0]
"""
import sys, time, collections
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
import monitor.gate as G, monitor.gym_gate as GG, monitor.certify.engine as E, monitor.certify.kernels as KK
import monitor.motion.pack as P, monitor.motion.plan as PL, monitor.scene as S
env_id, n = sys.argv[1], int(sys.argv[2]); brake = not (len(sys.argv) > 3 and sys.argv[3] == "brake=0")
pc = time.perf_counter; T = collections.Counter()
def wrap(obj, name, key=None):
    f = getattr(obj, name, None)
    if f is None: return
    key = key or name
    if isinstance(obj, type) and isinstance(obj.__dict__.get(name), classmethod):
        fn = obj.__dict__[name].__func__
        def w(cls, *a, **k):
            t = pc()
            try: return fn(cls, *a, **k)
            finally: T[key] += pc() - t
        setattr(obj, name, classmethod(w)); return
    def w(*a, **k):
        t = pc()
        try: return f(*a, **k)
        finally: T[key] += pc() - t
    setattr(obj, name, w)
for o, nm in [(G.Gate, "decide"), (G.Rollout, "states"), (G.Rollout, "brake_rows"), (G.Gate, "_certify_joint"),
              (G.Gate, "_certify"), (E, "certify"), (PL.Plan, "_trusted"), (KK, "trajectory_pack"),
              (P, "pack_trajectory"), (KK, "_pack_agrees"), (P, "plan_data_agrees"), (P, "static_key"),
              (KK, "window_kernel"), (S.Scene, "sync"), (G.Gate, "_split_reuse"), (G, "_part"),
              (G.StepReport, "info"), (G.Gate, "_write_log"), (G.Gate, "_account"), (G, "hold_ctrl"),
              (G.Rollout, "window_matches"), (G.Rollout, "commit"), (E, "_check_model"),
              (G.Gate, "_sync_scene"), (G.Gate, "_remember"), (G, "safety_info"), (GG.SafetyGate, "_step_env"),
              (GG.SafetyGate, "_check_applied_ctrl"), (GG.SafetyGate, "_as_inner"), (GG.SafetyGate, "_commit_sim"),
              (G.Rollout, "_tail_by_rollout"), (E, "_certify_fast"), (E, "_fast_inputs"), (GG.SafetyGate, "step")]:
    wrap(o, nm)
import monitor.gate_policy as GP
for nm in ("safety_keys", "applied_cost", "block_reason"):
    wrap(GP, nm); wrap(G, nm)
src = [c for c in vars(E).values() if isinstance(c, type) and hasattr(c, "build_pairs")]
for c in src: wrap(c, "build_pairs")
kw = {"pairs": "mujoco"} if "Pusher" in env_id else {}
g = GG.SafetyGate(gym.make(env_id), brake=brake, **kw); u = gym.make(env_id)
u.reset(seed=0); u.action_space.seed(0); acts = [u.action_space.sample() for _ in range(n)]
def run(env, k0=0):
    env.reset(seed=0); t = pc()
    for a in acts:
        _, _, te, tr, _ = env.step(a)
        if te or tr: env.reset(seed=0)
    return (pc() - t) / n
run(g); run(u); T.clear()
ts = []; tus = []
for r in range(3):
    tus.append(run(u)); ts.append(run(g))
steps = 3 * n
print(f"{env_id} brake={brake}: ungated {np.median(tus)*1e6:.0f} us gated {np.median(ts)*1e6:.0f} us ratio {np.median(ts)/np.median(tus):.1f}")
for k, v in sorted(T.items(), key=lambda kv: -kv[1]):
    print(f"  {k:18s} {v/steps*1e6:8.1f} us")
