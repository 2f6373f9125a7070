"""Section timer for engine._extrusion_decided on the replayed tunnel calls (warm; exclusive sections)."""
import inspect
import os
import re
import sys
import textwrap
import time

import mujoco
import numpy as np

from monitor.certify import engine
from monitor.gate import Gate

tree = os.environ["PYTHONPATH"].split(":")[0]
calls = []
real = engine.certify
def rec(scene, plan, **kw):
    calls.append((scene, plan, kw))
    return real(scene, plan, **kw)
engine.certify = rec
engine._OWN_CERTIFY = rec
m = mujoco.MjModel.from_xml_path(os.path.join(tree, "models/tunnel/scene.xml"))
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, 0)
for k in range(300):
    target = 0.3 if (k // 100) % 2 == 0 else -0.3
    gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), nstep=1)
engine.certify = real
engine._OWN_CERTIFY = real
fname = sys.argv[1] if len(sys.argv) > 1 else "_extrusion_decided"
src = textwrap.dedent(inspect.getsource(getattr(engine, fname)))
lines = src.split("\n")
# insert a mark before every top-level statement of the body (indent 4) after the signature
out, marks, body, indoc = [], [], False, False
for i, ln in enumerate(lines):
    if not body and ln.rstrip().endswith(":") and "->" in ln:
        body = True
        out.append(ln)
        continue
    if body and ln.strip().startswith('"""'):
        indoc = not indoc if ln.strip().count('"""') == 1 else indoc
        out.append(ln)
        continue
    if body and not indoc and re.match(r"^    [^ #)\]]", ln) and not re.match(r"^    (else|elif|except|finally)\b", ln):
        marks.append(ln.strip()[:60])
        out.append(f"    _T.append(({len(marks) - 1}, _pc()))")
    out.append(ln)
src2 = "\n".join(out)
# returns: mark the end
src2 = re.sub(r"^(\s+)return (.*)$", lambda mm: f"{mm.group(1)}_T.append((-1, _pc()))\n{mm.group(1)}return {mm.group(2)}", src2, flags=re.M)
g = engine.__dict__
g["_T"] = T = []
g["_pc"] = time.perf_counter
exec(compile(src2, "x", "exec"), g)
setattr(engine, fname, g[fname])
acc = np.zeros(len(marks))
n = 0
for _ in range(int(sys.argv[2]) if len(sys.argv) > 2 else 3):
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    for k in range(600):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        T.clear()
        gate.step(d, ctrl, nstep=1)
        # several calls per step possible: pair consecutive marks within each call (end marks -1)
        for (a, ta), (b, tb) in zip(T, T[1:]):
            if a >= 0:
                acc[a] += tb - ta
        n += 1
for i, mk in enumerate(marks):
    print(f"{acc[i] / n * 1e6:8.2f} us  {mk}")
print(f"{acc.sum() / n * 1e6:8.2f} us total per STEP over {n} steps")
