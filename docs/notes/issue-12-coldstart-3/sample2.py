"""Sampling (5 ms) of the cold first certify, attributed to the dispatcher being compiled x category."""
import sys, threading, time, collections, os
from numba.core import event as ev
main_id = threading.get_ident()
stack = []
class L(ev.Listener):
    def on_start(self, e):
        d = e.data["dispatcher"].py_func
        stack.append(d.__qualname__ + ":" + d.__module__.split(".")[-1])
    def on_end(self, e):
        stack.pop()
ev.register("numba:compile", L())
per = collections.defaultdict(collections.Counter)
stop = False
def category(fr):
    names = []
    f = fr
    while f is not None:
        names.append((f.f_code.co_filename, f.f_code.co_name)); f = f.f_back
    fn0, n0 = names[0]
    allf = [a + ":" + b for a, b in names]
    if "llvmlite/binding" in fn0:
        for a in allf:
            if "_optimize_functions" in a: return "llvm fn-passes"
            if "_optimize_final_module" in a: return "llvm module-passes"
            if "finalize_object" in a or "_finalize_specific" in a or "get_pointer_to_function" in a: return "llvm codegen"
            if "parse_assembly" in a:
                for b in allf:
                    if "get_abi_size" in b: return "llvm abi-size parse"
                return "llvm parse"
            if "link_in" in a or "clone" in a: return "llvm link/clone"
        return "llvm other"
    for a in allf:
        if "inline_closurecall" in a or "InlineInlinables" in a or "inline_ir" in a or "run_untyped_passes" in a: return "inline (untyped)"
        if "typeinfer" in a: return "typing"
        if "numba/core/lowering" in a or "get_abi_size" in a: return "lowering"
        if "llvmlite/ir" in a: return "llvmlite ir"
    return "other"
def sampler():
    while not stop:
        fr = sys._current_frames().get(main_id)
        if fr is not None:
            top = stack[-1] if stack else "-"
            per[top][category(fr)] += 1
        time.sleep(0.005)
th = threading.Thread(target=sampler, daemon=True); th.start()
t0 = time.process_time()
import numpy as np, mujoco, monitor
from monitor._paths import scene_path
model = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
scene = monitor.Scene.from_model(model)
q0 = model.qpos0.copy(); q1 = q0.copy(); q1[0] += 0.05; q1[2] += 0.05
plan = monitor.Plan(np.array([0.0, 0.01]), np.stack([q0, q1]), model=model)
c1 = time.process_time()
cert = monitor.certify(scene, plan)
c2 = time.process_time()
stop = True
tot = collections.Counter()
for k, c in per.items(): tot.update(c)
n = sum(tot.values())
print(f"first certify cpu {c2-c1:.2f}  samples {n}")
print("categories:", ", ".join(f"{k} {100*v/n:.1f}%" for k, v in tot.most_common()))
rows = sorted(per.items(), key=lambda kv: -sum(kv[1].values()))
for k, c in rows[:15]:
    s = sum(c.values())
    print(f"{100*s/n:5.1f}% {k}: " + ", ".join(f"{a} {100*v/n:.1f}" for a, v in c.most_common(6)))
