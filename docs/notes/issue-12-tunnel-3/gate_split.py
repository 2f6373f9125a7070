"""Unprofiled split of the bench tunnel_gate step by timing wrappers on Gate / Rollout / engine.certify / Plan._trusted.

PYTHONPATH=<tree> python docs/notes/issue-12-tunnel-3/gate_split.py   (3 x 400 steps after 100; us per step)
"""
import collections, time
import mujoco, numpy as np
from monitor import gate as G
from monitor.certify import engine
from monitor.motion import plan as P
acc = collections.Counter(); cnt = collections.Counter()
def wrap(obj, name, label):
    f = getattr(obj, name)
    def w(*a, **k):
        t = time.perf_counter()
        try: return f(*a, **k)
        finally: acc[label] += time.perf_counter() - t; cnt[label] += 1
    setattr(obj, name, w)
for n in ("decide", "_certify", "_certify_joint", "_split_reuse", "_certify_subset", "_remember", "_brake_active", "predict", "_account", "_sync_scene", "_tail_covers", "_stepped" ):
    if hasattr(G.Gate, n): wrap(G.Gate, n, "Gate." + n)
for n in ("states", "_window", "commit", "plan", "brake_tail", "brake_rows", "check_tail", "_tail_by_loop", "_tail_by_rollout"):
    if hasattr(G.Rollout, n): wrap(G.Rollout, n, "Rollout." + n)
wrap(engine, "certify", "engine.certify")
wrap(P.Plan, "_trusted", "Plan._trusted")
wrap(G, "safety_info", "safety_info")

m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml"); gate = G.Gate(m, margin=0.001); d = mujoco.MjData(m)
def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0); gate.reset()
    t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
    return time.perf_counter() - t
run(100)
acc.clear(); cnt.clear()
N = 1200
tot = 0
for _ in range(3): tot += run(400)
print(f"step {tot / N * 1e6:.0f} us (wrappers included)")
for k, v in sorted(acc.items(), key=lambda kv: -kv[1]):
    print(f"  {k:26s} {v / N * 1e6:7.1f}  calls/step {cnt[k] / N:.2f}")
