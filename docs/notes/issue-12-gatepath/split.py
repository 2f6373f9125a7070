"""Plain-timer split of a gated ``SafetyGate(gym.make("monitor/Arm-v0"))`` step (or Pusher) into buckets.

Copied from docs/notes/issue-12-armprof/split.py (helper gatepath added the plain-gate ``tunnel`` and
``hand30`` workloads of ``monitor/bench/targets.py``: 200 / 20 windows a block).

Usage (from the tree root):
    PYTHONPATH=$PWD python docs/notes/issue-12-armprof/split.py arm BLOCKS ROUNDS     (30 steps a block)
    PYTHONPATH=$PWD python docs/notes/issue-12-armprof/split.py pusher BLOCKS ROUNDS

Derived from docs/notes/issue-12-wholestep/split.py (same timer stack, same exclusive times), but
instead of a hand list of ~70 names it wraps, by rebinding every module global in ``monitor.*``
that refers to them (so identity checks such as ``engine.certify is engine._OWN_CERTIFY`` and
``Gate._certify is _GATE_CERTIFY`` still hold):

* every plain function and every method / classmethod / staticmethod (``__init__`` and
  ``__call__`` included, other dunders not) DEFINED in the modules of ``MODULES``;
* every numba dispatcher bound at module level in ``monitor.*`` (label ``K:<name>``; the kernel
  plus its dispatch);
* MuJoCo's C functions the gate calls through the ``mujoco`` module and the C tail
  ``Rollout.rollout`` (label ``C:<fn> < <caller label>``).

Actions: the bench's (``env.action_space.seed(rep)``, 30 samples a block, ``env.reset(seed=rep)``).
The same loop without timers (``nowrap``) is timed in every round, interleaved.
"""
from __future__ import annotations

import functools
import gc
import importlib
import statistics
import sys
import time
import types
from collections import Counter, defaultdict

import mujoco
from numba.core.dispatcher import Dispatcher

from monitor.warmup import ensure_warm

ensure_warm()
ns = time.perf_counter_ns
acc: dict[str, int] = defaultdict(int)
calls: Counter = Counter()
stack: list[list] = []  # [label, child_ns]
ON = [False]

MODULES = [
    "monitor.gate", "monitor.gym_gate", "monitor.certify.engine", "monitor.certify.kernels",
    "monitor.certify.extrusion_swept", "monitor.certify.extrusion", "monitor.certify.ongoing",
    "monitor.certify.certificate", "monitor.certify.common", "monitor.certify.packed", "monitor.certify.types",
    "monitor.certify.request", "monitor.certify.toleranced", "monitor.certify.broadphase",
    "monitor.motion.plan", "monitor.motion.pack", "monitor.motion.base", "monitor.geometry.distance",
    "monitor.scene", "monitor.gate_policy", "monitor.gate_settings", "monitor.tolerances",
]


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
            calls[lab] += 1
            if stack:
                stack[-1][1] += dt
    w.__wrapped_timer__ = True
    return w


def install():
    repl: dict[int, object] = {}   # id(original function or dispatcher) -> wrapper
    mods = []
    for name in MODULES:
        try:
            mods.append(importlib.import_module(name))
        except ImportError:
            pass
    for mod in mods:
        short = mod.__name__.rsplit(".", 1)[-1]
        for an, av in list(vars(mod).items()):
            if isinstance(av, types.FunctionType) and av.__module__ == mod.__name__:
                repl[id(av)] = timed(av, f"{short}.{av.__name__}")
            elif isinstance(av, type) and av.__module__ == mod.__name__:
                for mn, mv in list(vars(av).items()):
                    if mn.startswith("__") and mn not in ("__init__", "__call__"):
                        continue
                    lab = f"{av.__name__}.{mn}"
                    if isinstance(mv, types.FunctionType):
                        w = timed(mv, lab)
                        repl[id(mv)] = w
                        setattr(av, mn, w)
                    elif isinstance(mv, classmethod):
                        setattr(av, mn, classmethod(timed(mv.__func__, lab)))
                    elif isinstance(mv, staticmethod):
                        setattr(av, mn, staticmethod(timed(mv.__func__, lab)))
    nk = 0
    for mname, mod in list(sys.modules.items()):
        if not mname.startswith("monitor") or mod is None:
            continue
        for an, av in list(vars(mod).items()):
            if isinstance(av, Dispatcher):
                if id(av) not in repl:
                    repl[id(av)] = timed(av, f"K:{av.py_func.__name__}")
                    nk += 1
                setattr(mod, an, repl[id(av)])
            elif id(av) in repl:
                setattr(mod, an, repl[id(av)])
    for fn in ("mj_step", "mj_getState", "mj_setState", "mj_copyData", "mj_normalizeQuat", "mj_forward",
               "mj_kinematics", "mj_rnePostConstraint", "mj_stateSize", "mj_fwdPosition", "mj_comPos"):
        if hasattr(mujoco, fn):
            setattr(mujoco, fn, timed(getattr(mujoco, fn), f"C:{fn}", c_call=True))
    from mujoco import _rollout
    real_cls = _rollout.Rollout

    class TimedRollout:
        def __init__(self, *a, **k):
            self._r = real_cls(*a, **k)
            self.rollout = timed(self._r.rollout, "C:rollout", c_call=True)
    _rollout.Rollout = TimedRollout
    return len(repl), nk


PACK_KERNEL_MODULES = ("monitor.motion.",)
WINDOW_PY = ("Rollout._window", "Rollout.states", "Rollout.plan", "_WindowRows.__init__")
TAIL_PY = ("Rollout.brake_rows", "Rollout.brake_tail", "Rollout._tail_by_rollout", "Rollout._tail_by_loop",
           "Rollout.check_tail", "gate.hold_ctrl", "gate._hold_plan", "gate._rollout_is_exact",
           "Gate._brake_ctrl", "_Tail.__init__")
PACK_PY_PREFIX = ("pack.", "Plan._trusted", "Plan._setup", "Plan.__init__", "plan._", "_ModelStructure",
                  "kernels.trajectory_pack_memo", "kernels._pack_agrees", "_WindowRows.plan", "_Tail.plan",
                  "_Tail.plan_qpos_row", "_Tail.plan_mocap_quat", "Plan._scale", "Plan._times_ok")
CERT_PY_PREFIX = ("engine.", "kernels.", "extrusion_swept.", "extrusion.", "ongoing.", "distance.",
                  "certificate.", "common.", "packed.", "types.", "request.", "toleranced.", "broadphase.", "Plan.", "Certificate", "PairResult", "Witness", "Gate._certify",
                  "Gate._plain_request", "gate._part", "Gate._tail_refuted", "Gate._joint_poses_at_tail_start",
                  "Gate._split_reuse", "Gate._certify_subset", "Gate._remember", "Gate._pair_bodies",
                  "Gate.certify_plan", "scene.", "Scene")
ENV_PY = ("SafetyGate._step_env", "SafetyGate._commit_sim")


def bucket(label, kernel_mod):
    if label.startswith("C:"):
        fn, _, caller = label.partition(" < ")
        if caller in WINDOW_PY:
            return "window physics (C)"
        if caller in TAIL_PY:
            return "tail physics (C)"
        if caller == "Rollout.commit":
            return "commit (C copy)"
        if caller in ENV_PY or caller.startswith("SafetyGate") or caller == "-":
            return "env step / commit (C)"
        return "other C (" + caller + ")"
    if label.startswith("K:"):
        return "pack (compiled)" if kernel_mod.get(label, "").startswith(PACK_KERNEL_MODULES) \
            else "certify (compiled kernels)"
    if label in WINDOW_PY:
        return "window physics (Python)"
    if label in TAIL_PY:
        return "tail physics (Python)"
    if label.startswith(PACK_PY_PREFIX):
        return "plan build + pack (Python)"
    if label.startswith(CERT_PY_PREFIX):
        return "certify (Python)"
    if label in ENV_PY:
        return "env step (Python: gymnasium wrappers, obs, reward)"
    if label == "Gate._write_log":
        return "logging (off)"
    return "gate checks and plumbing (Python)"


def plain_runner(kind):
    """The bench's tunnel / hand30 workloads (``monitor.bench.targets``): plain ``Gate.step`` blocks."""
    import mujoco
    import numpy as np

    from monitor.bench.targets import _scene_file
    from monitor.gate import Gate
    model = mujoco.MjModel.from_xml_path(str(_scene_file(kind)))
    if kind == "tunnel":
        nstep, nblock, kw = 1, 200, {"margin": 0.001}

        def reset(d):
            mujoco.mj_resetDataKeyframe(model, d, 0)

        def controller(d, k):
            target = 0.3 if (k // 100) % 2 == 0 else -0.3
            return np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
    else:
        lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
        targets = np.random.default_rng(0).uniform(lo, hi, size=(64, model.nu))
        nstep, nblock, kw = 5, 20, {}

        def reset(d):
            mujoco.mj_resetData(model, d)

        def controller(d, k):
            return targets[(k // 10) % len(targets)]
    gate = Gate(model, **kw)
    dg, du = mujoco.MjData(model), mujoco.MjData(model)
    verdicts: Counter = Counter()

    def run(blocks, first=0, env=gate):
        tot = 0
        for _ in range(blocks):
            d = dg if env is gate else du
            reset(d)
            if env is gate:
                gate.reset()
            for k in range(nblock):
                ctrl = controller(d, k)
                t = ns()
                if env is gate:
                    rep = gate.step(d, ctrl, nstep=nstep)
                    verdicts[str(rep.verdict)] += 1
                else:
                    d.ctrl[:] = ctrl
                    for _ in range(nstep):
                        mujoco.mj_step(model, d)
                tot += ns() - t
        return tot / (nblock * blocks) / 1e3, nblock * blocks
    return run, verdicts, None


def runner(kind):
    if kind in ("tunnel", "hand30"):
        return plain_runner(kind)
    import gymnasium as gym

    import monitor.envs  # noqa: F401
    from monitor.gym_gate import SafetyGate
    env_id = {"arm": "monitor/Arm-v0", "pusher": "Pusher-v5"}[kind]
    gated = SafetyGate(gym.make(env_id), pairs="mujoco")
    ungated = gym.make(env_id)
    verdicts: Counter = Counter()

    def run(blocks, first=0, env=gated):
        tot = 0
        for rep in range(first, first + blocks):
            env.reset(seed=rep)
            env.action_space.seed(rep)
            acts = [env.action_space.sample() for _ in range(30)]
            t = ns()
            for a in acts:
                _, _, te, tr, info = env.step(a)
                if env is gated:
                    verdicts[str(info.get("safety", {}).get("verdict", "?"))] += 1
                if te or tr:
                    env.reset()
            tot += ns() - t
        return tot / (30 * blocks) / 1e3, 30 * blocks
    return run, verdicts, ungated


def main():
    kind, n, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    nw, nk = install()
    kernel_mod = {}
    for mname, mod in list(sys.modules.items()):
        if mname.startswith("monitor") and mod is not None:
            for av in vars(mod).values():
                inner = getattr(av, "__wrapped__", None)
                if isinstance(inner, Dispatcher):
                    kernel_mod[f"K:{inner.py_func.__name__}"] = inner.py_func.__module__
    run, verdicts, ungated = runner(kind)
    if ungated is None:
        ungated = "ungated"
    run(1, 1000)
    run(1, 1000, ungated)
    gc.collect()
    bare, wrapped, per, ncalls, plain = [], [], [], [], []
    for r in range(rounds):
        gc.collect()
        plain.append(run(n, 100 * r, ungated)[0])
        gc.collect()
        ON[0] = False
        bare.append(run(n, 100 * r)[0])
        gc.collect()
        acc.clear()
        calls.clear()
        ON[0] = True
        w, steps = run(n, 100 * r)      # the same seeds as the bare round
        ON[0] = False
        wrapped.append(w)
        per.append({k: v / steps / 1e3 for k, v in acc.items()})
        ncalls.append({k: v / steps for k, v in calls.items()})
    med = {k: statistics.median(p.get(k, 0.0) for p in per) for k in set().union(*per)}
    cps = {k: statistics.median(p.get(k, 0.0) for p in ncalls) for k in med}
    print(f"{kind}: {nw} functions and {nk} dispatchers wrapped; step without timers median "
          f"{statistics.median(bare):.1f} µs (rounds {[round(x, 1) for x in bare]}), with timers "
          f"{statistics.median(wrapped):.1f} µs; verdicts {dict(verdicts)}")
    u = statistics.median(plain)
    print(f"ungated step median {u:.1f} µs (rounds {[round(x, 1) for x in plain]}): gated/ungated "
          f"{statistics.median(bare) / u:.1f}x; per-round ratios {[round(b / p, 1) for b, p in zip(bare, plain)]}")
    b = defaultdict(float)
    for k, v in med.items():
        b[bucket(k, kernel_mod)] += v
    tot = sum(b.values())
    print(f"\n{'bucket':52s} µs/step   share (of the timed {tot:.1f})   x ungated")
    for k, v in sorted(b.items(), key=lambda kv: -kv[1]):
        print(f"{k:52s} {v:8.1f}  {100 * v / tot:5.1f} %   {v / u:6.2f}")
    print(f"\n{'label (exclusive)':64s} µs/step  calls/step  x ungated  bucket")
    for k, v in sorted(med.items(), key=lambda kv: -kv[1]):
        if v >= 0.5:
            print(f"{k:64s} {v:8.2f}  {cps[k]:8.2f}  {v / u:6.2f}  {bucket(k, kernel_mod)}")


if __name__ == "__main__":
    main()
