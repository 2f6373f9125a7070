"""``python -m monitor demo``: a gated rollout on the arm env with a scripted policy.

The policy alternates between reaching random targets and deliberately aiming
the stretched arm at a post or the shelf. Every step is certified by
:class:`monitor.SafetyGate` (``on_violation="block"``); unsafe actions are
replaced by a hold-position fallback. The run is written to an MCAP log
(``logs/<env-id>-<UTC timestamp>.mcap`` unless ``--out`` / ``--no-log``) and a summary is printed.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from monitor.certify.types import Verdict

# Joint targets (yaw, pitch, elbow) that point the stretched arm into an obstacle.
_INTO_OBSTACLES = {
    "post_a": np.array([np.arctan2(0.25, 0.45), 0.0, 0.0]),
    "post_b": np.array([np.arctan2(-0.45, 0.25), 0.05, 0.0]),
    "shelf": np.array([np.arctan2(0.35, -0.35), 0.15, 0.3]),
}


def add_parser(p: argparse.ArgumentParser) -> None:
    """Options of the ``demo`` subcommand."""
    p.add_argument("--steps", type=int, default=150, help="env steps to run (default 150)")
    p.add_argument("--seed", type=int, default=0, help="seed of env and policy (default 0)")
    p.add_argument("--no-log", action="store_true", help="do not write an MCAP log")
    p.add_argument("--out", type=Path, default=None,
                   help="log file, or a folder for logs/<env-id>-<UTC timestamp>.mcap (default: logs/)")
    p.add_argument("--margin", type=float, default=0.005, help="clearance (m) that counts as safe")
    p.add_argument("--progress", dest="progress", action="store_true", default=None,
                   help="always show the progress bar on stderr (default: only on a terminal)")
    p.add_argument("--no-progress", dest="progress", action="store_false", help="never show the progress bar")


class ScriptedPolicy:
    """Holds a joint target for a while; every other target aims into an obstacle.

    Args:
        rng: numpy Generator.
        low: (3,) lower action bounds (rad).
        high: (3,) upper action bounds (rad).
        hold: steps per target.
    """

    def __init__(self, rng: np.random.Generator, low: np.ndarray, high: np.ndarray, hold: int = 40) -> None:
        self.rng, self.low, self.high, self.hold = rng, low, high, hold
        self.k, self.target, self.aim = 0, None, ""

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """Next action (3,) float32."""
        if self.k % self.hold == 0:
            if (self.k // self.hold) % 2 == 1:
                self.aim = str(self.rng.choice(sorted(_INTO_OBSTACLES)))
                self.target = _INTO_OBSTACLES[self.aim] + self.rng.normal(0.0, 0.03, 3)
            else:
                self.aim = "free"
                self.target = self.rng.uniform([-1.2, -0.8, -0.2], [1.2, 0.4, 1.6])
        self.k += 1
        return np.clip(self.target, self.low, self.high).astype(np.float32)


def _obstacle_contacts(model: Any, data: Any, arm_geoms: set[int], obstacle_geoms: set[int]) -> int:
    n = 0
    for i in range(data.ncon):
        g1, g2 = int(data.contact[i].geom[0]), int(data.contact[i].geom[1])
        if (g1 in arm_geoms and g2 in obstacle_geoms) or (g2 in arm_geoms and g1 in obstacle_geoms):
            n += 1
    return n


def run(args: argparse.Namespace) -> int:
    """Run the demo; returns 0 on success."""
    import gymnasium as gym

    import monitor.envs  # noqa: F401  (registers monitor/Arm-v0)
    from monitor.gym_gate import SafetyGate

    t_start = time.perf_counter()
    log_path = None
    if not args.no_log:
        try:
            import monitor.log.writer  # noqa: F401
        except ImportError as exc:
            print(f"note: MCAP logging unavailable ({exc}); running without a log")
        else:
            from monitor.log.writer import default_path

            out = args.out
            if out is None or out.is_dir() or out.suffix != ".mcap":
                log_path = default_path("monitor/Arm-v0", out if out is not None else Path("logs"))
            else:
                log_path = out
                log_path.parent.mkdir(parents=True, exist_ok=True)

    env = gym.make("monitor/Arm-v0", max_episode_steps=max(args.steps, 1))
    gated = SafetyGate(env, margin=args.margin, on_violation="block", log=log_path)
    u = env.unwrapped
    m = u.model
    arm_bodies = {m.body(n).id for n in ("link1", "link2", "link3", "gripper")}
    obstacle_bodies = {m.body(n).id for n in ("post_a", "post_b", "shelf")}
    arm_geoms = {g for g in range(m.ngeom) if int(m.geom_bodyid[g]) in arm_bodies}
    obstacle_geoms = {g for g in range(m.ngeom) if int(m.geom_bodyid[g]) in obstacle_bodies}

    policy = ScriptedPolicy(np.random.default_rng(args.seed), env.action_space.low, env.action_space.high)
    from tqdm import tqdm

    progress = getattr(args, "progress", None)
    bar = tqdm(total=args.steps, desc="gated steps", unit="step", file=sys.stderr, leave=False,
               disable=None if progress is None else not progress)
    bar.set_postfix_str("first step compiles the numba kernels (cached afterwards)")
    obs, _ = gated.reset(seed=args.seed)
    contacts = 0
    aims: dict[str, int] = {}
    for k in range(args.steps):
        action = policy(obs)
        obs, _, terminated, truncated, info = gated.step(action)
        if info["safety"]["replaced"]:
            aims[policy.aim] = aims.get(policy.aim, 0) + 1
        contacts += _obstacle_contacts(m, u.data, arm_geoms, obstacle_geoms)
        bar.update(1)
        if k == 0:
            bar.set_postfix_str("")
        if terminated or truncated:
            obs, _ = gated.reset()
    bar.close()
    s = gated.gate.summary()
    gated.close()

    print(f"monitor demo: arm among obstacles, {args.steps} gated steps (seed {args.seed}, "
          f"margin {args.margin} m, {gated.gate.npairs} candidate pairs)")
    print(f"  verdicts        certified {s[Verdict.CERTIFIED]}, violation {s[Verdict.VIOLATION]}, "
          f"uncertain {s[Verdict.UNCERTAIN]}")
    blocked_by = ", ".join(f"{k} {v}" for k, v in sorted(aims.items())) or "none"
    print(f"  blocked actions {s['replaced']} (policy aiming at: {blocked_by}); "
          f"uncertified fallbacks {s['fallback_uncertified']}")
    print(f"  certification   {s['mean_certify_us']:.0f} us per step on average "
          f"(proposal, braking tail, fallback), {s['reused_pairs']} pair results reused")
    print(f"  MuJoCo contacts arm/obstacles: {contacts}")
    print(f"  log             {log_path if log_path else 'none'}")
    print(f"  wall time       {time.perf_counter() - t_start:.1f} s")
    return 0


__all__ = ["add_parser", "run", "ScriptedPolicy"]
