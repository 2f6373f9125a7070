"""Red team 19, part 2b: whole gate runs with the c935623 cuts against the fa269d6 forms, in one process.

Usage: PYTHONPATH=<tree> python docs/notes/redteam-19/gate_ab.py [STEPS]

The old forms are the fa269d6 sources of ``hold_ctrl``, ``_first_at_rest``, ``Rollout._tail_by_rollout``,
``Gate._split_reuse`` (``monitor/gate.py``) and ``SafetyGate._as_inner`` / ``_check_applied_ctrl``
(``monitor/gym_gate.py``), read with ``git show`` and compiled into the modules' namespaces. Each
stream runs twice (new, old); every report / step result / exception (type and message) is compared.
Streams: Arm-v0 and Pusher-v5 SafetyGates with odd actions (NaN, +-inf, -0.0, ints, 2-D, 0-d, lists,
out of range), tunnel and hand30 plain gates with odd controls, and a tunnel gate whose model is edited
and whose braking tail is long (brake_vel_tol 0 / huge).
"""
import ast
import subprocess
import sys
import textwrap

import gymnasium as gym
import mujoco
import numpy as np

import monitor.envs  # noqa: F401
from monitor import SafetyGate
from monitor import gate as G
from monitor import gym_gate as GG

STEPS = int(sys.argv[1]) if len(sys.argv) > 1 else 40
BASE = "fa269d6"


def old_source(path, qualname):
    src = subprocess.run(["git", "show", f"{BASE}:{path}"], capture_output=True, text=True, check=True).stdout
    tree = ast.parse(src)
    parts = qualname.split(".")
    body = tree.body
    for p in parts:
        node = next(n for n in body if getattr(n, "name", None) == p)
        body = getattr(node, "body", [])
    return textwrap.dedent(ast.get_source_segment(src, node, padded=True))


def compile_old(module, path, qualname):
    ns = dict(vars(module))
    exec(compile(old_source(path, qualname), f"{BASE}:{path}:{qualname}", "exec"), ns)  # noqa: S102
    return ns[qualname.split(".")[-1]]


OLD = {
    (G, "hold_ctrl"): compile_old(G, "monitor/gate.py", "hold_ctrl"),
    (G, "_first_at_rest"): compile_old(G, "monitor/gate.py", "_first_at_rest"),
    (G.Rollout, "_tail_by_rollout"): compile_old(G, "monitor/gate.py", "Rollout._tail_by_rollout"),
    (G.Gate, "_split_reuse"): compile_old(G, "monitor/gate.py", "Gate._split_reuse"),
    (GG.SafetyGate, "_as_inner"): compile_old(GG, "monitor/gym_gate.py", "SafetyGate._as_inner"),
    (GG.SafetyGate, "_check_applied_ctrl"): compile_old(GG, "monitor/gym_gate.py", "SafetyGate._check_applied_ctrl"),
}
NEW = {k: getattr(*k) for k in OLD}
OLD[(GG.SafetyGate, "_as_inner")]._model_untouched = True


def use(table):
    for (owner, name), fn in table.items():
        setattr(owner, name, fn)


def key(c):
    if c is None:
        return "None"
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    return repr(d)


def safe(fn, *a, **k):
    try:
        return fn(*a, **k), None
    except Exception as exc:  # noqa: BLE001
        return None, f"RAISE {type(exc).__name__}: {exc}"


def odd_actions(space, rng, n):
    lo, hi = space.low, space.high
    for k in range(n):
        a = rng.uniform(lo, hi)
        j = k % 12
        if j == 1:
            a[0] = np.nan
        elif j == 2:
            a[-1] = np.inf
        elif j == 3:
            a = -0.0 * np.abs(a)
        elif j == 4:
            a = np.round(a).astype(np.int64)
        elif j == 5:
            a = a[None, :]
        elif j == 6:
            a = np.asarray(a[0])
        elif j == 7:
            a = a.tolist()
        elif j == 8:
            a = a * 5.0
        elif j == 9:
            a = a.astype(np.float32)
        yield a


def gym_stream(env_id, out):
    env = SafetyGate(gym.make(env_id), pairs="mujoco")
    env.reset(seed=5)
    for k, a in enumerate(odd_actions(env.action_space, np.random.default_rng(11), STEPS)):
        res, err = safe(env.step, a)
        if err:
            out.append(f"{env_id} {k} {err}")
            continue
        obs, r, term, trunc, info = res
        rep = env.gate.last_report
        out.append(f"{env_id} {k} {np.asarray(obs).tobytes().hex()} {r!r} {term} {trunc} "
                   f"{np.asarray(rep.applied_ctrl).tobytes().hex()} {rep.verdict} {key(rep.certificate)} "
                   f"{sorted((k2, repr(v)) for k2, v in info['safety'].items() if k2 != 'certify_us')}")
        if term or trunc:
            env.reset(seed=k)
    out.append(f"{env_id} stats {sorted((k, v) for k, v in env.gate.stats.items() if k != 'certify_us')}")
    env.close()


def plain_stream(kind, out, **gate_kw):
    from monitor.bench.targets import _scene_file
    m = mujoco.MjModel.from_xml_path(str(_scene_file(kind)))
    d = mujoco.MjData(m)
    if m.nkey:
        mujoco.mj_resetDataKeyframe(m, d, 0)
    g = G.Gate(m, **gate_kw)
    rng = np.random.default_rng(2)
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    for k in range(STEPS):
        c = rng.uniform(lo, hi)
        j = k % 10
        if j == 1:
            c[0] = np.nan
        elif j == 2:
            c = c[None, :]
        elif j == 3:
            c = np.asarray(c[0]) if m.nu == 1 else c.astype(np.int64)
        elif j == 4:
            c = c * 10.0
        elif j == 5:
            c = -0.0 * np.abs(c)
        if k == STEPS // 2:
            m.geom_size[-1] *= 1.2
        rep, err = safe(g.step, d, c, nstep=3)
        out.append(f"{kind} {gate_kw} {k} " + (err or f"{rep.verdict} {rep.replaced} "
                   f"{np.asarray(rep.applied_ctrl).tobytes().hex()} {key(rep.certificate)} "
                   f"{d.qpos.tobytes().hex()} {d.qvel.tobytes().hex()}"))
    out.append(f"{kind} stats {sorted((k, v) for k, v in g.stats.items() if k != 'certify_us')}")


STREAMS = [("Arm", lambda o: gym_stream("monitor/Arm-v0", o)), ("Pusher", lambda o: gym_stream("Pusher-v5", o)),
           ("tunnel", lambda o: plain_stream("tunnel", o, margin=0.001)),
           ("tunnel vel_tol 0", lambda o: plain_stream("tunnel", o, margin=0.001, brake_vel_tol=0.0)),
           ("tunnel vel_tol 1e9", lambda o: plain_stream("tunnel", o, margin=0.001, brake_vel_tol=1e9)),
           ("hand30", lambda o: plain_stream("hand30", o))]
bad = 0
for name, run in STREAMS:
    outs = []
    for table in (NEW, OLD):
        use(table)
        o = []
        run(o)
        outs.append(o)
    use(NEW)
    same = outs[0] == outs[1]
    bad += not same
    errs = sum(" RAISE " in x for x in outs[0])
    print(f"{name}: {len(outs[0])} lines ({errs} refused steps), new == old: {same}")
    if not same:
        for a, b in zip(*outs):
            if a != b:
                print("   first difference:\n   new", a[:300], "\n   old", b[:300])
                break
print("streams differing:", bad)
