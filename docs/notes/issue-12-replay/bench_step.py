"""Per-step wall time of a gated step with a log (median over steps, after warm-up), tunnel Gate.step or
SafetyGate(monitor/Arm-v0); then verify time of the log. Usage: bench_step.py tunnel|arm STEPS OUT.mcap"""
import sys, time, os
import numpy as np, mujoco
which, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
ts = []
if which == "tunnel":
    from monitor.gate import Gate
    from monitor._paths import scene_path
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0)
    rng = np.random.default_rng(0)
    g = Gate(m, log=out, frame_skip=5, allowed=None)
    for k in range(n):
        c = rng.uniform(-6, 6, 1)
        t = time.perf_counter(); g.step(d, c); ts.append(time.perf_counter() - t)
        if abs(d.qpos[0]) > 0.4:
            mujoco.mj_resetDataKeyframe(m, d, 0); g.reset()
    g.close()
else:
    import gymnasium as gym
    import monitor.envs  # noqa
    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make("monitor/Arm-v0"), log=out)
    env.reset(seed=0); env.action_space.seed(0)
    for k in range(n):
        a = env.action_space.sample()
        t = time.perf_counter(); _, _, term, trunc, _ = env.step(a); ts.append(time.perf_counter() - t)
        if term or trunc:
            env.reset()
    env.close()
from monitor.log import read_log
from monitor import review
c = read_log(out)
t = time.perf_counter(); v = review.verify(c, progress=False); tv = time.perf_counter() - t
nw = v["windows"]
print(f"{which} step_us {np.median(ts[50:]) * 1e6:.1f} windows {nw} bytes_per_window {os.path.getsize(out) / nw:.0f} "
      f"verify_ms_per_window {tv / nw * 1e3:.3f} critical {v['critical']} unverifiable {v['unverifiable']} "
      f"replayed {v.get('replayed', '-')}")
