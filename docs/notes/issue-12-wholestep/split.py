"""Plain-timer split of a gated step (tunnel ``Gate.step`` or Pusher ``SafetyGate.step``) into buckets.

Usage:
    PYTHONPATH=$PWD python docs/notes/issue-12-wholestep/split.py tunnel STEPS ROUNDS
    PYTHONPATH=$PWD python docs/notes/issue-12-wholestep/split.py pusher BLOCKS ROUNDS   (30 steps a block)

Exclusive (self) times with a timer stack (``time.perf_counter_ns``): every wrapped call's time is
charged to its own label minus the wrapped calls it makes. Wrapped:

* the gate's and engine's Python functions below (by name);
* every numba dispatcher bound at module level in ``monitor.*`` (label ``K:<name>``: the compiled
  kernel plus its dispatch, charged to the kernel);
* MuJoCo's C functions the gate calls through the ``mujoco`` module (``mj_step``, ``mj_getState``,
  ``mj_setState``, ``mj_copyData``, ``mj_normalizeQuat``, ...) and the C tail ``Rollout.rollout``:
  label ``C:<fn> < <caller label>``.

Each wrapped call adds ~0.3-0.6 µs of timer; the same loop without wrappers is timed first
(``nowrap``), interleaved with the wrapped rounds. Prints µs per step per label and per bucket
(median over rounds), with the bucket map at the bottom of this file.
"""
from __future__ import annotations

import functools
import gc
import statistics
import sys
import time
from collections import defaultdict

import mujoco
import numpy as np
from numba.core.dispatcher import Dispatcher

import monitor.certify.engine as E
import monitor.certify.kernels as KK
import monitor.gate as G
import monitor.motion.pack as PK
import monitor.motion.plan as P
from monitor.warmup import ensure_warm

ensure_warm()
ns = time.perf_counter_ns
acc: dict[str, int] = defaultdict(int)
stack: list[list] = []  # [label, child_ns]
ON = [False]


def timed(f, label, c_call=False):
    @functools.wraps(f)
    def w(*a, **k):
        if not ON[0]:
            return f(*a, **k)
        lab = (f"{label} < {stack[-1][0] if stack else '-'}") if c_call else label
        fr = [lab, 0]
        stack.append(fr)
        t = ns()
        try:
            return f(*a, **k)
        finally:
            dt = ns() - t
            stack.pop()
            acc[lab] += dt - fr[1]
            if stack:
                stack[-1][1] += dt
    w.__wrapped_timer__ = True
    return w


def wrap(owner, name, label=None):
    raw = owner.__dict__.get(name) if isinstance(owner, type) else getattr(owner, name, None)
    if raw is None:
        return
    label = label or (f"{owner.__name__}.{name}" if isinstance(owner, type) else name)
    if isinstance(raw, classmethod):
        setattr(owner, name, classmethod(timed(raw.__func__, label)))
    elif isinstance(raw, property):
        return
    else:
        setattr(owner, name, timed(raw, label))


PY = [
    (G.Gate, "step"), (G.Gate, "decide"), (G.Gate, "_sync_scene"), (G.Gate, "_note_model"),
    (G.Gate, "_certify_joint"), (G.Gate, "_certify"), (G.Gate, "_plain_request"), (G.Gate, "_write_log"),
    (G.Gate, "_account"), (G.Gate, "_tail_covers"), (G.Gate, "_certify_static"), (G.Gate, "_remember_static"),
    (G.Gate, "_certify_nothing"), (G.Gate, "_brake_ctrl"), (G.Gate, "_tail_refuted"),
    (G.Gate, "_reuse_context"),
    (G.Gate, "_certify_is_own"), (G.Gate, "_brake_active"),
    (G.Rollout, "_window"), (G.Rollout, "brake_rows"), (G.Rollout, "_tail_by_rollout"),
    (G.Rollout, "_tail_by_loop"), (G.Rollout, "commit"), (G.Rollout, "window_matches"),
    (G, "hold_ctrl"), (G, "_check_data"), (G, "_check_ctrl"), (G, "_rollout_is_exact"), (G, "_part"),
    (G._Tail, "__init__", "_Tail()"), (G._WindowRows, "__init__", "_WindowRows()"),
    (G._WindowRows, "plan", None),
    (G.StepReport, "_trusted"), (G.StepReport, "_stepped"),
    (P.Plan, "_trusted"), (P.Plan, "body_poses"), (P.Plan, "translation_segments"),
    (E, "certify"), (E, "_certify_fast"), (E, "_fast_inputs"), (E, "_fast_prep"), (E, "_all_culled"),
    (E, "_extrusion_decided"), (E, "_run_extrusion"), (E, "_checked_result"), (E, "_find_witness"),
    (E, "_confirm"), (E, "_window_certificate"), (E, "extrusion_stats"), (E, "_window_kernel"),
    (E, "_kernel_decided"), (E, "_check_model"), (E, "_remember_call"), (E, "_call_memo"),
    (KK, "trajectory_pack_memo"), (KK, "_pack_agrees"), (PK, "pack_trajectory"),
]


def install(kind):
    import monitor.certify.extrusion_swept as XS
    import monitor.geometry.distance as D
    PY.extend([(XS, "decide_pair"), (D, "shape_distance")])
    if kind == "pusher":
        import monitor.gym_gate as GG
        PY.extend([(GG.SafetyGate, n) for n in (
            "step", "_step_env", "_commit_sim", "_check_window_ran", "_live_frame_skip",
            "_check_applied_ctrl",
            "_check_elapsed", "_predict_fn", "_fallback_fn", "_as_inner", "_as_action", "_inner_action")])
        PY.append((G.StepReport, "info"))
    for t in PY:
        wrap(*t)
    # every numba dispatcher bound at module level in monitor.* (the same wrapper for every binding)
    wrapped = {}
    for mname, mod in list(sys.modules.items()):
        if not mname.startswith("monitor") or mod is None:
            continue
        for an, av in list(vars(mod).items()):
            if isinstance(av, Dispatcher):
                if id(av) not in wrapped:
                    wrapped[id(av)] = timed(av, f"K:{av.py_func.__name__}")
                setattr(mod, an, wrapped[id(av)])
    for fn in ("mj_step", "mj_getState", "mj_setState", "mj_copyData", "mj_normalizeQuat", "mj_forward",
               "mj_kinematics", "mj_rnePostConstraint", "mj_stateSize"):
        setattr(mujoco, fn, timed(getattr(mujoco, fn), f"C:{fn}", c_call=True))
    from mujoco import _rollout
    real_cls = _rollout.Rollout

    class TimedRollout:
        def __init__(self, *a, **k):
            self._r = real_cls(*a, **k)
            self.rollout = timed(self._r.rollout, "C:rollout", c_call=True)
    _rollout.Rollout = TimedRollout
    return len(wrapped)


def bucket(label):
    """The brief's buckets for a label."""
    if label.startswith("C:"):
        fn, _, caller = label.partition(" < ")
        if caller in ("Rollout._window",):
            return "window physics (C)"
        if caller in ("Rollout.brake_rows", "Rollout._tail_by_rollout", "Rollout._tail_by_loop"):
            return "tail physics (C)"
        if caller in ("Rollout.commit",):
            return "commit (C copy)"
        if caller.startswith("SafetyGate"):
            return "env step / commit (C)"
        return "other C (" + caller + ")"
    if label in ("Rollout._window",):
        return "window physics (Python)"
    if label in ("Rollout.brake_rows", "Rollout._tail_by_rollout", "Rollout._tail_by_loop", "hold_ctrl",
                 "Gate._brake_ctrl", "_rollout_is_exact"):
        return "tail physics (Python)"
    if label in ("K:_derive_and_scale",):
        return "pack (compiled)"
    if label in ("Plan._trusted", "_fast_inputs", "trajectory_pack_memo", "_pack_agrees", "pack_trajectory",
                 "_WindowRows.plan", "_Tail()", "_WindowRows()"):
        return "pack (Python)"
    if label.startswith("K:"):
        return "certify (compiled kernels)"
    if label in ("certify", "_certify_fast", "_fast_prep", "_all_culled", "_extrusion_decided",
                 "_run_extrusion", "_checked_result", "_find_witness", "_confirm", "_window_certificate",
                 "extrusion_stats", "_window_kernel", "_kernel_decided", "_check_model", "_remember_call",
                 "_call_memo", "decide_pair",
                 "shape_distance", "Plan.body_poses", "Plan.translation_segments", "Gate._certify", "_part",
                 "Gate._certify_joint", "Gate._plain_request"):
        return "certify (Python)"
    if label in ("Gate._write_log",):
        return "logging (off)"
    if label.startswith("SafetyGate._step_env") or label == "SafetyGate._commit_sim":
        return "env step / commit (Python)"
    return "gate checks and plumbing (Python)"


def tunnel_runner():
    from monitor.gate import Gate
    m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
    gate = Gate(m, margin=0.001)
    d = mujoco.MjData(m)

    def run(steps):
        mujoco.mj_resetDataKeyframe(m, d, 0)
        gate.reset()
        t = ns()
        for k in range(steps):
            target = 0.3 if (k // 100) % 2 == 0 else -0.3
            gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
        return (ns() - t) / steps / 1e3, steps
    return run


def pusher_runner():
    import gymnasium as gym

    from monitor.gym_gate import SafetyGate
    env = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")

    def run(blocks):
        tot = 0
        for rep in range(blocks):
            env.reset(seed=rep)
            env.action_space.seed(rep)
            acts = [env.action_space.sample() for _ in range(30)]
            t = ns()
            for a in acts:
                _, _, te, tr, _ = env.step(a)
                if te or tr:
                    env.reset()
            tot += ns() - t
        return tot / (30 * blocks) / 1e3, 30 * blocks
    return run


def main():
    kind, n, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    nk = install(kind)
    run = tunnel_runner() if kind == "tunnel" else pusher_runner()
    run(max(1, n // 4))
    bare, wrapped, per = [], [], []
    for _ in range(rounds):
        gc.collect()
        ON[0] = False
        bare.append(run(n)[0])
        gc.collect()
        acc.clear()
        ON[0] = True
        w, steps = run(n)
        ON[0] = False
        wrapped.append(w)
        per.append({k: v / steps / 1e3 for k, v in acc.items()})
    med = {k: statistics.median(p.get(k, 0.0) for p in per) for k in set().union(*per)}
    print(f"{kind}: {nk} dispatchers wrapped; step without timers median {statistics.median(bare):.1f} µs "
          f"(rounds {[round(x, 1) for x in bare]}), with timers {statistics.median(wrapped):.1f} µs")
    b = defaultdict(float)
    for k, v in med.items():
        b[bucket(k)] += v
    tot = sum(b.values())
    print(f"\n{'bucket':44s} µs/step   share (of the timed {tot:.1f})")
    for k, v in sorted(b.items(), key=lambda kv: -kv[1]):
        print(f"{k:44s} {v:8.1f}  {100 * v / tot:5.1f} %")
    print(f"\n{'label (exclusive)':60s} µs/step   bucket")
    for k, v in sorted(med.items(), key=lambda kv: -kv[1]):
        if v >= 0.05:
            print(f"{k:60s} {v:8.2f}   {bucket(k)}")


if __name__ == "__main__":
    main()
