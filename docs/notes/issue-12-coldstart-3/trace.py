"""Cold first certify (the bench start-up script's arm scene and call) with numba compile events (exclusive CPU)."""
import json, os, sys, time, resource
from collections import defaultdict
from numba.core import event as ev

stack = []  # [name, start, child_time]
excl = defaultdict(float); count = defaultdict(int)
class L(ev.Listener):
    def on_start(self, e):
        stack.append([e.data["dispatcher"].py_func.__qualname__ + ":" + e.data["dispatcher"].py_func.__module__.split(".")[-1], time.process_time(), 0.0])
    def on_end(self, e):
        name, t0, child = stack.pop()
        dt = time.process_time() - t0
        excl[name] += dt - child; count[name] += 1
        if stack: stack[-1][2] += dt
ev.register("numba:compile", L())
t0 = time.time(); c0 = time.process_time()
import numpy as np, mujoco, monitor
from monitor._paths import scene_path
model = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
scene = monitor.Scene.from_model(model)
q0 = model.qpos0.copy(); q1 = q0.copy(); q1[0] += 0.05; q1[2] += 0.05
plan = monitor.Plan(np.array([0.0, 0.01]), np.stack([q0, q1]), model=model)
t1 = time.time(); c1 = time.process_time()
cert = monitor.certify(scene, plan)
t2 = time.time(); c2 = time.process_time()
later = []
for _ in range(3):
    a = time.perf_counter(); monitor.certify(scene, plan); later.append(time.perf_counter() - a)
tot = sum(excl.values())
print(f"import+scene wall {t1-t0:.2f} cpu {c1-c0:.2f}; first certify wall {t2-t1:.2f} cpu {c2-c1:.2f}; total cpu {c2-c0:.2f}; later {np.median(later)*1e3:.2f} ms; verdict {cert.verdict}; compiles {sum(count.values())} fns {len(count)} sum_excl {tot:.2f}")
for k, v in sorted(excl.items(), key=lambda kv: -kv[1])[:int(os.environ.get('TOPN', 40))]:
    print(f"  {v:7.2f} s {100*v/tot:5.1f}% x{count[k]} {k}")
