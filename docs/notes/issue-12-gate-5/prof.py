"""cProfile of gated steps (shape only: cProfile inflates small calls).

usage: PYTHONPATH=<tree> python prof.py WORKLOAD STEPS [N_LINES]
WORKLOAD: tunnel | Pusher-v5 | monitor/Arm-v0 | Reacher-v5
"""
import cProfile
import pstats
import sys
import warnings

import numpy as np

warnings.simplefilter("ignore")
work, steps = sys.argv[1], int(sys.argv[2])
nlines = int(sys.argv[3]) if len(sys.argv) > 3 else 40


def tunnel_runner():
    import mujoco

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


def gym_runner(env_id):
    import gymnasium as gym
    if env_id.startswith("monitor/"):
        import monitor.envs  # noqa: F401
    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make(env_id))

    def run(n):
        env.reset(seed=0)
        env.action_space.seed(0)
        for _ in range(n):
            _, _, te, tr, _ = env.step(env.action_space.sample())
            if te or tr:
                env.reset()
    return run


from monitor.warmup import ensure_warm  # noqa: E402

ensure_warm()
run = tunnel_runner() if work == "tunnel" else gym_runner(work)
run(20)
pr = cProfile.Profile()
pr.enable()
run(steps)
pr.disable()
st = pstats.Stats(pr)
st.sort_stats("tottime").print_stats(nlines)
st.sort_stats("cumtime").print_stats(nlines)
