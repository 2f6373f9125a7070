import warnings; warnings.simplefilter("ignore")
import gymnasium as gym, numpy as np, mujoco
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
from monitor import review
from monitor.log import read_log
def rep(tag, path):
    v = review.verify(read_log(path), progress=False)
    print(tag, "exit", review.verify_exit_code(v), {k: v.get(k) for k in ("windows", "replayed", "replay_failed", "replay_user", "continuity_checked")},
          [(f["severity"], f["index"], f["reason"][:160]) for f in v["findings"]][:4], flush=True)
# 1 tunnel with short episodes, resets, DR of the model in reset
for seed in range(2):
    path = f"/tmp/rt11/fa_tunnel{seed}.mcap"
    env = SafetyGate(gym.make("monitor/Tunnel-v0", max_episode_steps=7, reset_noise=0.05), margin=0.002, log=path)
    env.reset(seed=seed); env.action_space.seed(seed)
    m = env.unwrapped.model; rng = np.random.default_rng(seed)
    for k in range(40):
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        if term or trunc:
            m.dof_damping[:] = rng.uniform(0, 0.1, m.nv); m.opt.timestep = float(rng.choice([m.opt.timestep, m.opt.timestep]))
            env.reset(seed=seed * 100 + k)
    env.close(); rep(f"tunnel{seed}", path)
# 2 a vector env, each sub-env its own log
def mk(i):
    def f():
        return SafetyGate(gym.make("monitor/Tunnel-v0", max_episode_steps=9, reset_noise=0.05), margin=0.002, log=f"/tmp/rt11/fa_vec{i}.mcap")
    return f
venv = gym.vector.SyncVectorEnv([mk(0), mk(1)])
venv.reset(seed=[1, 2]); venv.action_space.seed(0)
for _ in range(30): venv.step(venv.action_space.sample())
venv.close()
for i in range(2): rep(f"vec{i}", f"/tmp/rt11/fa_vec{i}.mcap")
# 3 Gate: user sets state by hand then gate.reset() but keeps time going forward
from monitor.gate import Gate
m = mujoco.MjModel.from_xml_path(str(__import__("monitor").models_dir() / "tunnel.xml")) if False else None
