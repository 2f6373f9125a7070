import sys, time, numpy as np
import mod
from numba.core import event as ev
names = []
class L(ev.Listener):
    def on_start(self, e): names.append(e.data["dispatcher"].py_func.__name__)
    def on_end(self, e): pass
ev.register("numba:compile", L())
a = np.random.default_rng(0).random((5, 3)); b = np.random.default_rng(1).random((4, 3))
t0 = time.process_time()
mod.caller_fc.compile((mod.heavy_t, mod.arr2, mod.arr2))
t1 = time.process_time()
r = mod.caller_fc(mod.heavy, a, b)
t2 = time.process_time()
print("caller compile", round(t1 - t0, 3), "call(+heavy)", round(t2 - t1, 3), r, "compiled", names)
