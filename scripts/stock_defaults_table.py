"""Defaults table of issue 13: SafetyGate(gym.make(env_id)) with no arguments on stock envs.

For each env: pairs monitored by default (and allowed by reason), share of seeded random
actions blocked over N steps, blocks by reason, and wall time per step gated / ungated
(ratio measured in the same run, same seeded actions). Usage::

    PYTHONPATH=. python scripts/stock_defaults_table.py [--steps 200] [ENV_ID ...]
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections import Counter

import gymnasium as gym
import numpy as np

from monitor.gym_gate import SafetyGate

STOCK = ["Reacher-v5", "Pusher-v5", "Ant-v5", "HalfCheetah-v5", "Hopper-v5", "Walker2d-v5", "Swimmer-v5",
         "InvertedPendulum-v5", "InvertedDoublePendulum-v5", "Humanoid-v5", "HumanoidStandup-v5"]


def run(env_id: str, steps: int, seed: int = 0) -> dict:
    """Gated and ungated runs of the same seeded random actions."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = SafetyGate(gym.make(env_id))
    gate = env.gate
    allowed = Counter(r for *_x, r in gate.scene.allowed_pairs)
    rng = np.random.default_rng(seed)
    acts = rng.uniform(env.action_space.low, env.action_space.high, size=(steps,) + env.action_space.shape)
    acts = acts.astype(env.action_space.dtype)
    env.reset(seed=seed)
    blocked, reasons, verdicts, cost = 0, Counter(), Counter(), 0.0
    t = time.perf_counter()
    for a in acts:
        _o, _r, term, trunc, info = env.step(a)
        s = info["safety"]
        verdicts[s["verdict"]] += 1
        if s["intervened"]:
            blocked += 1
            reasons[s["block_reason"]] += 1
        cost += info["cost"]
        if term or trunc:
            env.reset()
    gated = (time.perf_counter() - t) / steps
    raw = gym.make(env_id)
    raw.reset(seed=seed)
    t = time.perf_counter()
    for a in acts:
        _o, _r, term, trunc, _i = raw.step(a)
        if term or trunc:
            raw.reset()
    plain = (time.perf_counter() - t) / steps
    return {"env": env_id, "monitored": gate.npairs, "allowed": dict(allowed), "blocked": blocked / steps,
            "reasons": dict(reasons), "verdicts": dict(verdicts), "cost": cost, "gated_ms": gated * 1e3,
            "plain_ms": plain * 1e3, "ratio": gated / plain}


def main() -> None:
    """Print the markdown table."""
    ap = argparse.ArgumentParser()
    ap.add_argument("envs", nargs="*", default=STOCK)
    ap.add_argument("--steps", type=int, default=200)
    args = ap.parse_args()
    print("| env | pairs monitored | allowed (reason) | blocked | block reasons | verdicts | ms/step gated | "
          "ungated | ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    for e in args.envs:
        r = run(e, args.steps)
        al = ", ".join(f"{v} {k}" for k, v in sorted(r["allowed"].items())) or "0"
        rs = ", ".join(f"{k}: {v}" for k, v in sorted(r["reasons"].items())) or "-"
        vs = ", ".join(f"{k}: {v}" for k, v in sorted(r["verdicts"].items()))
        print(f"| {e} | {r['monitored']} | {al} | {100 * r['blocked']:.1f} % | {rs} | {vs} | "
              f"{r['gated_ms']:.2f} | {r['plain_ms']:.3f} | {r['ratio']:.0f}x |", flush=True)


if __name__ == "__main__":
    main()
