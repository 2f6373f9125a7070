"""Print every numba dispatcher load (cache load or compile) while ``active[0]`` is True."""
import time
from numba.core import dispatcher
_orig = dispatcher.Dispatcher._compile_for_args
active = [False]


def _cfa(self, *a, **k):
    t = time.perf_counter()
    try:
        return _orig(self, *a, **k)
    finally:
        if active[0]:
            print(f"  load {self.py_func.__module__}.{self.py_func.__name__}: {(time.perf_counter()-t)*1e3:.1f} ms")


dispatcher.Dispatcher._compile_for_args = _cfa
