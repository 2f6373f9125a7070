"""Every engine.certify certificate of seeded SafetyGate steps on Arm-v0 and Pusher-v5 (to_dict minus wall time)."""
import hashlib
import sys

import gymnasium as gym
import numpy as np

import monitor
import monitor.envs  # noqa: F401
from monitor import SafetyGate
from monitor.certify import engine

out = sys.argv[1]
lines = []
_orig = engine.certify
def rec(*a, **k):
    c = _orig(*a, **k)
    d = c.to_dict(); d["stats"].pop("wall_seconds", None)
    lines.append(f"  {c.verdict} {d!r}")
    return c
engine.certify = rec
engine._OWN_CERTIFY = rec
for env_id in ("monitor/Arm-v0", "Pusher-v5"):
    env = SafetyGate(gym.make(env_id), pairs="mujoco")
    obs, _ = env.reset(seed=5)
    rng = np.random.default_rng(11)
    for k in range(int(sys.argv[2]) if len(sys.argv) > 2 else 100):
        a = rng.uniform(env.action_space.low, env.action_space.high) * (3.0 if k % 7 == 3 else 1.0)
        a = np.clip(a, env.action_space.low, env.action_space.high)
        obs, r, term, trunc, info = env.step(a)
        lines.append(f"{env_id} {k} {np.asarray(obs).tobytes().hex()} {term} {trunc}")
        if term or trunc:
            obs, _ = env.reset(seed=k)
    env.close()
text = "\n".join(lines) + "\n"
open(out, "w").write(text)
print(hashlib.md5(text.encode()).hexdigest(), len(lines), "lines", sum(1 for l in lines if l.startswith("  ")), "certificates")
