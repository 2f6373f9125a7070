"""sha256 of SafetyGate(Reacher-v5) (no candidate pair) reports, info["safety"] and states, timings excluded.

PYTHONPATH=<tree> python docs/notes/issue-12-gate-5/digest_zero.py [steps]
(the zero-pair counterpart of docs/notes/issue-12-gate-3/digest.py; compare two trees' output)
"""
import hashlib
import sys
import warnings

import gymnasium as gym
import numpy as np

from monitor.gym_gate import SafetyGate

warnings.simplefilter("ignore")
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 300
for env_id in ("Reacher-v5", "InvertedPendulum-v5", "Swimmer-v5"):
    env = SafetyGate(gym.make(env_id))
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(steps)]
    env.reset(seed=0)
    h = hashlib.sha256()
    for a in acts:
        obs, rew, te, tr, info = env.step(a)
        r = env.gate.last_report
        c = r.certificate.to_dict()
        c["stats"].pop("wall_seconds")
        h.update(repr((str(r.verdict), r.replaced, str(r.brake_verdict), r.time, c, obs.tobytes(), rew,
                       {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in sorted(info["safety"].items())
                        if k != "certify_us"})).encode())
        h.update(env.unwrapped.data.qpos.tobytes() + env.unwrapped.data.qvel.tobytes())
        if te or tr:
            env.reset(seed=1)
    print(f"{env_id:22s} steps {steps} {env.gate.summary()['certified']} certified {h.hexdigest()[:16]}")
