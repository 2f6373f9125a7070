"""How long until the braked system is at rest (every |qvel| <= tol), per env step, on Pusher and Arm."""
import numpy as np, gymnasium as gym, mujoco
import monitor.envs  # noqa
from monitor.gate import Rollout, hold_ctrl
for env_id in ["Pusher-v5", "monitor/Arm-v0"]:
    env = gym.make(env_id); env.reset(seed=0); u = env.unwrapped
    m, d = u.model, u.data
    ro = Rollout(m); n = u.frame_skip
    tols = [1e-3, 1e-2, 3e-2, 1e-1]
    stops = {t: [] for t in tols}; peak = []
    rng = np.random.default_rng(0)
    for k in range(60):
        a = env.action_space.sample()
        rows, brake = ro.brake_rows(d, np.asarray(a, float), n, lambda s: hold_ctrl(m, s), int(2.0 / m.opt.timestep), 0.0)
        qv = np.abs(rows[:, 1 + m.nq:]).max(axis=1)
        peak.append(qv[0])
        for t in tols:
            idx = np.flatnonzero(qv <= t)
            stops[t].append(idx[0] if idx.size else np.inf)
        env.step(a)
    H = int(np.ceil(0.25 / m.opt.timestep))
    print(env_id, "dt", m.opt.timestep, "frame_skip", n, "H(0.25s) substeps", H, "median |qvel|max at window end", np.median(peak))
    for t in tols:
        s = np.array(stops[t]); print(f"  tol {t:g}: median stop substep {np.median(s)}, share stopped within H {np.mean(s <= H):.2f}")
