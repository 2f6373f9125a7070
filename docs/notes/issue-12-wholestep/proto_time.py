"""Per-step times of the whole-step prototype against the ungated loop, interleaved (issue 12).

Usage: PYTHONPATH=$PWD:$PWD/docs/notes/issue-12-wholestep python docs/notes/issue-12-wholestep/proto_time.py \
           tunnel|pusher STEPS ROUNDS

1. Record: drive the real gate (tunnel: the bench's controller and ``Gate.step``; Pusher:
   ``SafetyGate``, seeded actions) for STEPS steps. Per step keep the live integration state and the
   proposed control, and every call the gate makes into a numba kernel of ``monitor.*`` (each
   dispatcher bound at module level is wrapped), with copies of its arguments (read-only flags
   kept, so the same compiled specialisation is dispatched) and the step's verdict.
2. Replay, ROUNDS rounds (+1 untimed); in each round every variant makes one pass over all the
   recorded steps (the order of the passes rotates from round to round); per step the state is set
   by ``mj_setState`` outside the timer, and the step is timed by ``perf_counter_ns``:
   * ``ungated``: ``data.ctrl[:] = ctrl`` and ``nstep`` x ``mujoco.mj_step`` (the bench's loop);
   * ``ungated_c``: the same ``nstep`` ``mj_step`` calls from one compiled call (``cmj.step_n``);
   * ``gate_physics``: the gate's own ``Rollout._window`` + ``Rollout.brake_rows`` (hold_ctrl);
   * ``a``: ``cmj.Physics.run`` (window + tail in one compiled call);
   * ``a_bind``: the same C calls as ``a`` through the bindings, in a lean Python loop
     (``cmj.Physics.run_bindings``: MuJoCo errors stay ``FatalError``);
   * ``b_pack`` / ``b_cert``: the step's recorded kernel calls replayed from Python, the pack's
     ``_derive_and_scale`` / every other kernel (stage 0 ``window_kernel``, extrusion
     ``swept_pair_kernel``, witness ``core_distance``, ...), each on fresh copies of its arguments
     (copied outside the timer);
   * ``env_step`` (Pusher): ``gym.make("Pusher-v5").step(action)`` from the same state (the bench's
     ungated reference, with the env's own Python);
   * ``ab``: ``a`` then ``b`` back to back (the physics of the step, then its kernels);
   * ``shell``: the least Python a whole-step gate needs around ONE compiled physics call, with the
     gate's own tail policy: cast + shape check, ``Physics.run`` (with the braking tail only on the
     steps where the recording gate simulated one; on replaced steps also the fallback window),
     the commit (``mj_copyData`` from the scratch) and a small report object. No certification.
   Prints medians over rounds of the per-step mean (µs) and each variant / ``ungated``, also split by
   the step's verdict.
"""
from __future__ import annotations

import gc
import statistics
import sys
import time
from collections import defaultdict

import mujoco
import numpy as np
from cmj import Physics, step_n
from numba.core.dispatcher import Dispatcher

from monitor.gate import Rollout, hold_ctrl
from monitor.warmup import ensure_warm

ensure_warm()
ns = time.perf_counter_ns
REC: list | None = None
TAILS: list = []  # the recording gate (its rollout counts the braking tails it simulates)


class Report:
    """A small report object (what a whole-step gate hands back at least)."""
    __slots__ = ("verdict", "applied", "rows")

    def __init__(self, verdict, applied, rows):
        self.verdict, self.applied, self.rows = verdict, applied, rows


def _copy(x):
    if isinstance(x, np.ndarray):
        y = np.array(x, copy=True, order="K")
        if not x.flags.writeable:
            y.setflags(write=False)
        return y
    if isinstance(x, tuple):
        items = [_copy(v) for v in x]
        return type(x)._make(items) if hasattr(type(x), "_make") else tuple(items)
    if isinstance(x, list):
        return [_copy(v) for v in x]
    return x


def recording(disp):
    def w(*a, **k):
        if REC is not None and not k:
            REC.append((disp, _copy(a)))
        return disp(*a, **k)
    return w


def install():
    seen = {}
    for mname, mod in list(sys.modules.items()):
        if mname.startswith("monitor") and mod is not None:
            for an, av in list(vars(mod).items()):
                if isinstance(av, Dispatcher):
                    seen.setdefault(id(av), recording(av))
                    setattr(mod, an, seen[id(av)])


def record_tunnel(steps):
    from monitor.gate import Gate
    m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
    gate = Gate(m, margin=0.001)
    TAILS.append(gate)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    for k in range(20):  # warm-up, not recorded
        gate.step(d, [0.0], nstep=1)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    out = []
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        out.append(_record_one(m, d, ctrl, lambda: gate.step(d, ctrl, nstep=1)))
    return m, 1, gate, out


def record_pusher(steps):
    import gymnasium as gym

    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")
    env.reset(seed=100)
    for _ in range(10):
        env.step(env.action_space.sample())
    env.reset(seed=0)
    env.action_space.seed(0)
    u = env.unwrapped
    TAILS.append(env.gate)
    out = []
    for k in range(steps):
        a = env.action_space.sample()
        res = {}

        def go():
            res["r"] = env.step(a)
            return env.gate.last_report
        out.append(_record_one(u.model, u.data, np.asarray(a, np.float64), go))
        if res["r"][2] or res["r"][3]:
            env.reset()
    return u.model, u.frame_skip, env.gate, out


def _record_one(m, d, ctrl, do_step):
    global REC
    st = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, d, st, mujoco.mjtState.mjSTATE_INTEGRATION)
    REC = []
    tails0 = TAILS[0]._rollout.tails if TAILS else 0
    rep = do_step()
    calls, REC = REC, None
    kind = str(rep.verdict) + ("/replaced" if rep.replaced else "")
    tail_built = bool(TAILS and TAILS[0]._rollout.tails != tails0)
    applied = np.array(rep.applied_ctrl, np.float64) if rep.replaced else None
    return st, np.array(ctrl, np.float64), calls, kind, tail_built, applied


def main():
    which, steps, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    install()
    m, nstep, gate, recs = (record_tunnel if which == "tunnel" else record_pusher)(steps)
    d = mujoco.MjData(m)
    sig = mujoco.mjtState.mjSTATE_INTEGRATION
    ref = Rollout(m)
    proto = Physics(m, nstep, gate.brake_steps, gate.brake_vel_tol)
    proto0 = Physics(m, nstep, 0, gate.brake_vel_tol)  # window only (steps where the gate built no tail)
    nu = m.nu
    names = defaultdict(int)
    for _, _, calls, *_ in recs:
        for disp, _a in calls:
            names[disp.py_func.__name__] += 1
    print(f"{which}: {len(recs)} steps; kernel calls per step: "
          + ", ".join(f"{k} {v / len(recs):.2f}" for k, v in sorted(names.items(), key=lambda kv: -kv[1])))
    maddr, daddr = m._address, d._address
    variants = ["ungated", "ungated_c", "gate_physics", "a", "a_bind", "b_pack", "b_cert", "ab", "shell"]
    if which == "pusher":
        variants.append("env_step")
    per_round = defaultdict(list)
    per_kind = defaultdict(lambda: defaultdict(list))
    counts = defaultdict(int)
    for _, _, _, kind, *_ in recs:
        counts[kind] += 1

    def one(v, st, ctrl, copies, tail_built=True, applied=None):
        """Time variant ``v`` on one recorded step (state set outside the timer)."""
        mujoco.mj_setState(m, d, st, sig)
        if v == "ungated":
            t0 = ns()
            d.ctrl[:] = ctrl
            for _ in range(nstep):
                mujoco.mj_step(m, d)
            return ns() - t0, 0
        if v == "ungated_c":
            d.ctrl[:] = ctrl
            t0 = ns()
            step_n(maddr, daddr, nstep)
            return ns() - t0, 0
        if v == "gate_physics":
            t0 = ns()
            ref._window(d, ctrl, nstep)
            ref.brake_rows(d, ctrl, nstep, lambda s: hold_ctrl(m, s), gate.brake_steps, gate.brake_vel_tol,
                           window_fresh=True)
            return ns() - t0, 0
        if v == "a":
            t0 = ns()
            proto.run(d, ctrl)
            return ns() - t0, 0
        if v == "a_bind":
            t0 = ns()
            proto.run_bindings(d, ctrl)
            return ns() - t0, 0
        if v == "b":
            tp = tc = 0
            for disp, a in copies:
                t0 = ns()
                disp(*a)
                dt = ns() - t0
                if disp.py_func.__name__ == "_derive_and_scale":
                    tp += dt
                else:
                    tc += dt
            return tp, tc
        if v == "env_step":  # Pusher only: the bench's ungated reference, gym's env.step from this state
            mujoco.mj_setState(m, env_plain.unwrapped.data, st, sig)
            t0 = ns()
            env_plain.step(ctrl)
            return ns() - t0, 0
        if v == "shell":
            t0 = ns()
            c = np.asarray(ctrl, dtype=np.float64)
            if c.shape != (nu,):
                raise ValueError("shape")
            w, tail, status = (proto if tail_built else proto0).run(d, c)
            if applied is not None:  # replaced: the fallback window too (no tail), then it is committed
                proto0.run(d, applied)
                mujoco.mj_copyData(d, m, proto0.s)
            else:
                mujoco.mj_copyData(d, m, (proto if tail_built else proto0).s)
            Report(kind_of[0], c, w)
            return ns() - t0, 0
        t0 = ns()  # "ab"
        proto.run(d, ctrl)
        for disp, a in copies:
            disp(*a)
        return ns() - t0, 0

    env_plain = None
    passes = ("ungated", "ungated_c", "gate_physics", "a", "a_bind", "b", "ab", "shell")
    if which == "pusher":
        import gymnasium as gym
        env_plain = gym.make("Pusher-v5")
        env_plain.reset(seed=0)
        passes += ("env_step",)
    kind_of = ["certified"]
    for r in range(rounds + 1):
        order = passes[r % len(passes):] + passes[:r % len(passes)]  # rotate the order per round
        tot = defaultdict(int)
        kt = defaultdict(lambda: defaultdict(int))
        for v in order:
            copies = ([[(disp, _copy(a)) for disp, a in calls] for _, _, calls, *_ in recs]
                      if v in ("b", "ab") else None)
            gc.collect()
            gc.disable()
            for i, (st, ctrl, calls, kind, tail_built, applied) in enumerate(recs):
                t1, t2 = one(v, st, ctrl, copies[i] if copies else None, tail_built, applied)
                if v == "b":
                    tot["b_pack"] += t1
                    tot["b_cert"] += t2
                    kt[kind]["b_pack"] += t1
                    kt[kind]["b_cert"] += t2
                else:
                    tot[v] += t1
                    kt[kind][v] += t1
            gc.enable()
        if r == 0:
            continue  # warm-up round
        for v in variants:
            per_round[v].append(tot[v] / len(recs) / 1e3)
            for kind in kt:
                per_kind[kind][v].append(kt[kind][v] / counts[kind] / 1e3)
    med = {v: statistics.median(per_round[v]) for v in variants}
    u = med["ungated"]
    print(f"{'variant':14s} {'µs/step':>9s} {'x ungated':>10s}   rounds")
    for v in variants:
        print(f"{v:14s} {med[v]:9.2f} {med[v] / u:10.2f}   {[round(x, 1) for x in per_round[v]]}")
    b = med["b_pack"] + med["b_cert"]
    print(f"b (pack + cert) {b:8.2f} {b / u:10.2f}")
    if which == "pusher":  # the gated step also runs the env's own Python (obs, reward, wrappers)
        ref_s = med["env_step"]
        proj = ref_s + med["shell"] - u + b
        print(f"projected whole step = env_step + (shell - ungated) + b = {proj:.1f} µs = "
              f"{proj / ref_s:.2f}x env_step (physics alone: (env_step + a - ungated) / env_step = "
              f"{(ref_s + med['a'] - u) / ref_s:.2f}x)")
    else:
        print(f"projected whole step = shell + b = {med['shell'] + b:.1f} µs = "
              f"{(med['shell'] + b) / u:.2f}x ungated")
    for kind, dv in per_kind.items():
        mk = {v: statistics.median(dv[v]) for v in variants}
        print(f"  {kind} ({counts[kind]} steps): " + ", ".join(
            f"{v} {mk[v]:.1f}" for v in variants) + f"  | ab/ungated {mk['ab'] / mk['ungated']:.1f}x")


if __name__ == "__main__":
    main()
