"""Statement-section timer for one function of the gated Arm, Pusher or tunnel step, in situ.

Usage (from the tree root):
    PYTHONPATH=$PWD python docs/notes/issue-12-gatechecks/lines.py arm|pusher|tunnel MODULE QUALNAME [BLOCKS] [DEPTH]

docs/notes/issue-12-armprof/lines.py run as it is for ``arm`` / ``pusher``; for ``tunnel`` its set-up
(the recompiled function with a time mark before every statement) and its report are run, and the
steps between them are the bench's ``tunnel_gate`` windows (``Gate.step`` on models/tunnel, margin
0.001, the README controller, nstep 1; a block is 200 windows; one untimed warm-up block).
"""
import os
import sys

import numpy as np

path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "issue-12-armprof", "lines.py")
src = open(path).read()
g = {"__name__": "__main__", "__file__": path}
if sys.argv[1] != "tunnel":
    exec(compile(src, path, "exec"), g)
    sys.exit(0)
setup, _, rest = src.partition("import gymnasium as gym")
_, _, report = rest.partition("\nprint(f\"{qual}: {nsteps} steps")
exec(compile(setup, path, "exec"), g)

import mujoco  # noqa: E402

from monitor.gate import Gate  # noqa: E402

m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
T, marks = g["T"], g["marks"]
acc, cnt, nsteps = np.zeros(len(marks)), np.zeros(len(marks)), 0
for rep in [1000] + list(range(g["blocks"])):
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    for k in range(200):
        T.clear()
        gate.step(d, np.clip([12.0 * ((0.3 if (k // 100) % 2 == 0 else -0.3) - d.qpos[0])], -6.0, 6.0), nstep=1)
        if rep == 1000:
            continue
        for (i, ta), (_, tb) in zip(T, T[1:]):
            if i >= 0:
                acc[i] += tb - ta
                cnt[i] += 1
        nsteps += 1
g.update(acc=acc, cnt=cnt, nsteps=nsteps)
exec(compile("print(f\"{qual}: {nsteps} steps" + report, path, "exec"), g)
