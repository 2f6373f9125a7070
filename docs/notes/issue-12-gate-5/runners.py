"""Workload runners shared by prof.py and excl.py: ``runner(work)(n)`` runs n gated steps.

tunnel: ``Gate.step`` with the bench's tunnel controller (target switches every 100 windows);
anything else: ``SafetyGate(gym.make(work))`` with seeded sampled actions.
"""
import mujoco
import numpy as np


def runner(work):
    """The n-step runner of ``work``."""
    if work == "tunnel":
        from monitor.bench.targets import _scene_file
        from monitor.gate import Gate
        model = mujoco.MjModel.from_xml_path(str(_scene_file("tunnel")))
        gate = Gate(model, margin=0.001)
        d = mujoco.MjData(model)

        def run(n):
            mujoco.mj_resetDataKeyframe(model, d, 0)
            gate.reset()
            for k in range(n):
                target = 0.3 if (k // 100) % 2 == 0 else -0.3
                gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
        return run
    import gymnasium as gym

    import monitor.envs  # noqa: F401
    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make(work))

    def run(n):
        env.reset(seed=0)
        env.action_space.seed(0)
        acts = [env.action_space.sample() for _ in range(n)]
        for a in acts:
            _, _, te, tr, _ = env.step(a)
            if te or tr:
                env.reset()
    return run
