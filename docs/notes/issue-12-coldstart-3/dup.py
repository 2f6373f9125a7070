"""How often each function's optimised code is in a library's final (linked) module: the module
passes and the machine-code generation run on every final module, so this is their duplication."""
import re, time, collections
from numba.core import event as ev
disps = []
class L(ev.Listener):
    def on_start(self, e): disps.append(e.data["dispatcher"])
    def on_end(self, e): pass
ev.register("numba:compile", L())
import numpy as np, mujoco, monitor
from monitor._paths import scene_path
model = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
scene = monitor.Scene.from_model(model)
q0 = model.qpos0.copy(); q1 = q0.copy(); q1[0] += 0.05; q1[2] += 0.05
plan = monitor.Plan(np.array([0.0, 0.01]), np.stack([q0, q1]), model=model)
monitor.certify(scene, plan)
seen = set(); total = 0; uniq = {}; per_lib = []
for d in disps:
    if id(d) in seen: continue
    seen.add(id(d))
    for sig, ir in d.inspect_llvm().items():
        sizes = {}; cur = None
        for l in ir.splitlines():
            if l.startswith("define"):
                cur = re.search(r'@"?([^"(]+)', l).group(1); sizes[cur] = 0
            elif l.startswith("}"): cur = None
            elif cur: sizes[cur] += 1
        n = sum(sizes.values()); total += n
        per_lib.append((n, d.py_func.__qualname__))
        for k, v in sizes.items(): uniq[k] = max(uniq.get(k, 0), v)
u = sum(uniq.values())
print(f"libraries {len(per_lib)}; optimised lines in all final modules {total}; distinct functions {len(uniq)} with {u} lines; duplication {total/u:.2f}x")
for n, name in sorted(per_lib, reverse=True)[:12]: print(" ", n, name)
