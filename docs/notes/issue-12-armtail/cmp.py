"""Per-step records of SafetyGate(Arm-v0) on seeded episodes: verdicts, certificates, state.

PYTHONPATH=<tree> python cmp.py OUT.pkl EPISODES STEPS [nobrake]
"""
import sys, pickle
import numpy as np, gymnasium as gym
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
out, eps, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
brake = not (len(sys.argv) > 4 and sys.argv[4] == "nobrake")
def cert_rec(c):
    if c is None: return None
    w = c.witness
    return (str(c.verdict), tuple(c.window), c.earliest_time, c.clearance,
            None if w is None else (w.time, w.geoms, float(w.distance)))
env = SafetyGate(gym.make("monitor/Arm-v0"), brake=brake)
recs = []
for ep in range(eps):
    env.reset(seed=ep); env.action_space.seed(ep)
    for a in [env.action_space.sample() for _ in range(n)]:
        _, _, te, tr, info = env.step(a)
        r = env.gate.last_report; d = env.unwrapped.data
        recs.append(dict(key=(str(r.verdict), r.applied_ctrl.tobytes(), r.replaced, str(r.applied_verdict),
                              str(r.brake_verdict), r.terminated, r.unsafe, r.fallback_certified),
                         cert=cert_rec(r.certificate), fb=cert_rec(r.fallback_certificate),
                         state=(d.qpos.tobytes(), d.qvel.tobytes()), safety=info["safety"]["verdict"]))
s = env.gate.summary()
pickle.dump((recs, s), open(out, "wb"))
print({k: v for k, v in s.items() if k not in ("certify_us", "mean_certify_us")})
