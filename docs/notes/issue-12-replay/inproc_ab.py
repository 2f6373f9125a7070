"""In-process A/B of the rollout logging's per-step cost: MonitorLog.logs_rollouts toggled in alternating
blocks of steps (off = the base's logging path: no rollout payload, note_model only on a scene change).
Usage: inproc_ab.py tunnel|arm BLOCKS STEPS_PER_BLOCK"""
import sys, time
import numpy as np, mujoco
from monitor.log.writer import MonitorLog
which, blocks, per = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
times = {True: [], False: []}
if which == "tunnel":
    from monitor.gate import Gate
    from monitor._paths import scene_path
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0)
    rng = np.random.default_rng(0)
    g = Gate(m, log="/tmp/replay/inproc_tunnel.mcap", frame_skip=5, allowed=None)
    def step():
        c = rng.uniform(-6, 6, 1)
        t = time.perf_counter(); g.step(d, c); dt = time.perf_counter() - t
        if abs(d.qpos[0]) > 0.4:
            mujoco.mj_resetDataKeyframe(m, d, 0); g.reset()
        return dt
    close = g.close
else:
    import gymnasium as gym
    import monitor.envs  # noqa
    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make("monitor/Arm-v0"), log="/tmp/replay/inproc_arm.mcap")
    env.reset(seed=0); env.action_space.seed(0)
    def step():
        a = env.action_space.sample()
        t = time.perf_counter(); _, _, term, trunc, _ = env.step(a); dt = time.perf_counter() - t
        if term or trunc:
            env.reset()
        return dt
    close = env.close
for _ in range(30):
    step()
for b in range(blocks):
    on = b % 2 == 0
    MonitorLog.logs_rollouts = on
    times[on].extend(step() for _ in range(per))
close()
on, off = np.median(times[True]) * 1e6, np.median(times[False]) * 1e6
print(f"{which}: rollouts logged {on:.1f} us, not logged {off:.1f} us per gated step (medians of "
      f"{len(times[True])} / {len(times[False])} steps), difference {on - off:+.1f} us ({on / off - 1:+.2%})")
