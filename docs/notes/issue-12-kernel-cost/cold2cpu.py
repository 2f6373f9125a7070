import time, sys
from numba.core import event
stack = []; rows = []
class L(event.Listener):
    def on_start(self, ev):
        stack.append([time.perf_counter(), 0.0])
    def on_end(self, ev):
        t0, child = stack.pop()
        dur = time.perf_counter() - t0
        if stack: stack[-1][1] += dur
        d = ev.data.get("dispatcher") if ev.data else None
        rows.append((dur - child, dur, getattr(d, "__qualname__", str(d)), getattr(getattr(d, "py_func", None), "__module__", ""), ev.kind))
event.register("numba:compile", L())
for k in ("numba:llvm_lock", "numba:run_pass"):
    pass
import numpy as np, mujoco, monitor
from monitor._paths import scene_path
model = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
scene = monitor.Scene.from_model(model)
q0 = model.qpos0.copy(); q1 = q0.copy(); q1[0] += 0.05; q1[2] += 0.05
plan = monitor.Plan(np.array([0.0, 0.01]), np.stack([q0, q1]), model=model)
t = time.time(); c = time.process_time(); cert = monitor.certify(scene, plan); print("first call", time.time() - t, "cpu", time.process_time() - c, cert.verdict)
for ex, tot, n, m, k in sorted(rows, reverse=True)[:30]:
    print(f"excl {ex:7.2f} s  incl {tot:7.2f}  {m}.{n}")
print("n compiles", len(rows))
