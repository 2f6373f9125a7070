"""The four gated workloads as monitor/bench/targets.py builds them, one gated step at a time.

make(work, horizon=0.25, brake=True) -> W with
  W.gate            the Gate (SafetyGate's .gate for the gym workloads)
  W.model, W.data   the live model / data
  W.steps(n, rep)   generator over n gated steps of block `rep` (yields after each step)
  W.ungated(n, rep) seconds of thread time per step of the same block ungated
  W.gated(n, rep)   seconds of thread time per step of the block gated
work: "Pusher-v5" (pairs='mujoco'), "monitor/Arm-v0", "tunnel", "hand30".
Blocks: gym: env.reset(seed=rep), action_space.seed(rep), sampled actions (bench gym_gate);
tunnel: keyframe 0, the README controller, target side every 100 windows, nstep 1, margin 1e-3
(bench tunnel_gate); hand30: mj_resetData, random joint targets (seed 7) new every 10 windows of 5
substeps (bench hand30_gate).
"""
import time

import mujoco
import numpy as np

pc = time.thread_time


def _scene(name):
    from monitor.bench.targets import _scene_file
    return str(_scene_file(name))


class Gym:
    def __init__(self, work, horizon, brake):
        import gymnasium as gym
        import monitor.envs  # noqa: F401
        from monitor.gym_gate import SafetyGate
        self.env = SafetyGate(gym.make(work), pairs="mujoco", brake=brake, brake_horizon=horizon)
        self.bare = gym.make(work)
        self.gate = self.env.gate
        self.model, self.data = self.env.unwrapped.model, self.env.unwrapped.data

    def _acts(self, env, n, rep):
        env.reset(seed=rep)
        env.action_space.seed(rep)
        return [env.action_space.sample() for _ in range(n)]

    def steps(self, n, rep):
        for a in self._acts(self.env, n, rep):
            _, _, te, tr, _ = self.env.step(a)
            yield self.gate.last_report
            if te or tr:
                self.env.reset()

    def _timed(self, env, n, rep):
        acts = self._acts(env, n, rep)
        t = pc()
        for a in acts:
            _, _, te, tr, _ = env.step(a)
            if te or tr:
                env.reset()
        return (pc() - t) / n

    def ungated(self, n, rep):
        return self._timed(self.bare, n, rep)

    def gated(self, n, rep):
        return self._timed(self.env, n, rep)


class Plain:
    def __init__(self, work, horizon, brake):
        from monitor.gate import Gate
        self.model = m = mujoco.MjModel.from_xml_path(_scene(work))
        if work == "tunnel":
            self.nstep, kw = 1, {"margin": 0.001}

            def reset(d):
                mujoco.mj_resetDataKeyframe(m, d, 0)

            def ctrl(d, k):
                target = 0.3 if (k // 100) % 2 == 0 else -0.3
                return np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        else:
            self.nstep, kw = 5, {}
            lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
            targets = np.random.default_rng(7).uniform(lo, hi, size=(64, m.nu))

            def reset(d):
                mujoco.mj_resetData(m, d)

            def ctrl(d, k):
                return targets[(k // 10) % len(targets)]
        self.reset, self.ctrl = reset, ctrl
        self.gate = Gate(m, brake=brake, brake_horizon=horizon, **kw)
        self.data = mujoco.MjData(m)
        self.du = mujoco.MjData(m)

    def steps(self, n, rep):
        d = self.data
        self.reset(d)
        self.gate.reset()
        for k in range(n):
            yield self.gate.step(d, self.ctrl(d, k), nstep=self.nstep)

    def gated(self, n, rep):
        d = self.data
        self.reset(d)
        self.gate.reset()
        t = pc()
        for k in range(n):
            self.gate.step(d, self.ctrl(d, k), nstep=self.nstep)
        return (pc() - t) / n

    def ungated(self, n, rep):
        d, m = self.du, self.model
        self.reset(d)
        t = pc()
        for k in range(n):
            d.ctrl[:] = self.ctrl(d, k)
            mujoco.mj_step(m, d, nstep=self.nstep)
        return (pc() - t) / n


def make(work, horizon=0.25, brake=True):
    return Plain(work, horizon, brake) if work in ("tunnel", "hand30") else Gym(work, horizon, brake)


# steps per block as the bench's full run uses them (gym 30, tunnel 200, hand30 20)
BLOCK = {"Pusher-v5": 30, "monitor/Arm-v0": 30, "tunnel": 200, "hand30": 20}


def brake_starts(work, blocks, every):
    """Run ``work`` gated at the defaults for ``blocks`` blocks; keep every ``every``-th braking tail's start.

    Returns (W, starts): each start is (the window end's integration state (``Rollout._end_state``),
    the brake control the gate held, mocap_pos, mocap_quat), from which ``mj_setState`` + that
    control + ``mj_step`` reproduce the gate's tail bit for bit.
    """
    import monitor.gate as G

    W = make(work)
    starts, count = [], [0]
    orig = G.Rollout.brake_rows

    def brake_rows(self, *a, **k):
        rows, brake = orig(self, *a, **k)
        count[0] += 1
        if count[0] % every == 0:
            starts.append((self._end_state.copy(), brake.copy(), np.array(a[0].mocap_pos),
                           np.array(a[0].mocap_quat)))
        return rows, brake
    G.Rollout.brake_rows = brake_rows
    try:
        for rep in range(blocks):
            for _ in W.steps(BLOCK[work], rep):
                pass
    finally:
        G.Rollout.brake_rows = orig
    return W, starts
