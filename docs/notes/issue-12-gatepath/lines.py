"""Statement-section timer for one function of the gated Arm / Pusher / tunnel step, in situ.

Copied from docs/notes/issue-12-armprof/lines.py; helper gatepath added the ``tunnel`` workload
(the bench's plain gate, 200 windows a block).

Usage (from the tree root):
    PYTHONPATH=$PWD python docs/notes/issue-12-armprof/lines.py arm MODULE QUALNAME [BLOCKS] [DEPTH]
e.g. ``lines.py arm monitor.gate Gate.decide 20 2``.

The function's source is recompiled (in its module's globals) with a time mark before every
statement down to DEPTH nested blocks (``ast`` line numbers) and an end mark after it returns;
the time between consecutive marks of one call is charged to the earlier mark's statement
(exclusive of nothing: callees are inside the statement that calls them). Bench actions
(``action_space.seed(rep)``, 30 a block); one untimed warm-up block.
"""
from __future__ import annotations

import ast
import functools
import importlib
import inspect
import sys
import textwrap
import time

import numpy as np

from monitor.warmup import ensure_warm

ensure_warm()
kind, modname, qual = sys.argv[1], sys.argv[2], sys.argv[3]
blocks = int(sys.argv[4]) if len(sys.argv) > 4 else 20
depth = int(sys.argv[5]) if len(sys.argv) > 5 else 1
mod = importlib.import_module(modname)
owner = mod
parts = qual.split(".")
for p in parts[:-1]:
    owner = getattr(owner, p)
raw = owner.__dict__[parts[-1]] if isinstance(owner, type) else getattr(owner, parts[-1])
wrapper_kind = None
if isinstance(raw, classmethod):
    wrapper_kind, raw = classmethod, raw.__func__
elif isinstance(raw, staticmethod):
    wrapper_kind, raw = staticmethod, raw.__func__
src = textwrap.dedent(inspect.getsource(raw))
lines = src.split("\n")
tree = ast.parse(src)
fdef = tree.body[0]
marks: list[tuple[int, int, str]] = []   # (line index 0-based, col, text)


def visit(body, d):
    for st in body:
        if isinstance(st, ast.Expr) and isinstance(getattr(st, "value", None), ast.Constant) and \
                isinstance(st.value.value, str):
            continue   # docstring
        if not lines[st.lineno - 1].lstrip().startswith("elif"):   # an elif is its If's orelse
            marks.append((st.lineno - 1, st.col_offset, lines[st.lineno - 1].strip()[:70]))
        if d < depth or lines[st.lineno - 1].lstrip().startswith("elif"):
            for field in ("body", "orelse", "finalbody"):
                sub = getattr(st, field, None)
                if isinstance(sub, list) and sub and isinstance(sub[0], ast.stmt) and \
                        not isinstance(st, (ast.FunctionDef, ast.Lambda)):
                    visit(sub, d + 1)
            for h in getattr(st, "handlers", []) or []:
                visit(h.body, d + 1)


visit(fdef.body, 1)
by_line = {}
for i, (ln, col, txt) in enumerate(marks):
    by_line[ln] = (i, col)
out = []
for j, ln in enumerate(lines):
    if j in by_line:
        i, col = by_line[j]
        out.append(" " * col + f"_T_.append(({i}, _pc_()))")
    out.append(ln)
src2 = "\n".join(out)
g = mod.__dict__
T: list = []
g["_T_"] = T
g["_pc_"] = time.perf_counter_ns
if isinstance(owner, type):
    # a class body so that the method compiles with its class cell (private names, super())
    ns = {}
    exec(compile(textwrap.indent(src2, "    ").join(["class _X_:\n", ""]), modname, "exec"), g, ns)
    new = ns["_X_"].__dict__[fdef.name]
else:
    exec(compile(src2, modname, "exec"), g)
    new = g[fdef.name]
    setattr(mod, fdef.name, raw)   # restored below by the wrapper


@functools.wraps(raw)
def timed(*a, **k):
    try:
        return new(*a, **k)
    finally:
        T.append((-1, time.perf_counter_ns()))


setattr(owner, parts[-1], wrapper_kind(timed) if wrapper_kind else timed)
# rebind module globals that refer to the original function (module-level functions)
for mname, m in list(sys.modules.items()):
    if mname.startswith("monitor") and m is not None:
        for an, av in list(vars(m).items()):
            if av is raw:
                setattr(m, an, timed)

acc = np.zeros(len(marks))
cnt = np.zeros(len(marks))
nsteps = 0


def charge() -> None:
    """Charge one timed step's marks (``T``) to their statements."""
    global nsteps
    for (i, ta), (_, tb) in zip(T, T[1:]):
        if i >= 0:
            acc[i] += tb - ta
            cnt[i] += 1
    nsteps += 1


if kind == "tunnel":
    import mujoco  # noqa: E402

    from monitor.bench.targets import _scene_file  # noqa: E402
    from monitor.gate import Gate  # noqa: E402
    model = mujoco.MjModel.from_xml_path(str(_scene_file("tunnel")))
    gate = Gate(model, margin=0.001)
    d = mujoco.MjData(model)
    for rep in [1000] + list(range(blocks)):
        mujoco.mj_resetDataKeyframe(model, d, 0)
        gate.reset()
        for k in range(200):
            target = 0.3 if (k // 100) % 2 == 0 else -0.3
            T.clear()
            gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
            if rep != 1000:
                charge()
else:
    import gymnasium as gym  # noqa: E402

    import monitor.envs  # noqa: E402,F401
    from monitor.gym_gate import SafetyGate  # noqa: E402

    env = SafetyGate(gym.make({"arm": "monitor/Arm-v0", "pusher": "Pusher-v5"}[kind]), pairs="mujoco")
    for rep in [1000] + list(range(blocks)):
        env.reset(seed=rep)
        env.action_space.seed(rep)
        acts = [env.action_space.sample() for _ in range(30)]
        for a in acts:
            T.clear()
            _, _, te, tr, _ = env.step(a)
            if te or tr:
                env.reset()
            if rep != 1000:
                charge()
print(f"{qual}: {nsteps} steps; µs per STEP (calls per step) by statement (the time until the next mark)")
for i, (ln, col, txt) in enumerate(marks):
    if acc[i] / nsteps / 1e3 >= 0.3:
        print(f"{acc[i] / nsteps / 1e3:8.2f}  ({cnt[i] / nsteps:5.2f})  L{ln + 1:<4d} {' ' * (col - 4)}{txt}")
print(f"{acc.sum() / nsteps / 1e3:8.2f} µs per step in total")
