"""Log every certify call that reaches the engine's Python stages: wall ms (and the GC passes > 1 ms inside it)."""
import gc
import time

import monitor.certify.engine as E

gc_ms: list = []
_tg: dict = {}


def _gccb(phase, info):
    if phase == "start":
        _tg["t"] = time.perf_counter()
    else:
        gc_ms.append((info["generation"], round((time.perf_counter() - _tg["t"]) * 1e3, 1)))


def install(with_gc: bool = False) -> list:
    """Wrap ``engine.certify`` and ``engine._python_stages``; returns the list the rare calls go to."""
    if with_gc:
        gc.callbacks.append(_gccb)
    log, n = [], [0]
    _c, _ps = E.certify, E._python_stages

    def c(scene, plan, *a, **k):
        n0, g0 = n[0], len(gc_ms)
        t = time.perf_counter()
        r = _c(scene, plan, *a, **k)
        dt = round((time.perf_counter() - t) * 1e3, 2)
        if n[0] > n0:
            log.append((dt, [g for g in gc_ms[g0:] if g[1] > 1]) if with_gc else dt)
        return r

    def ps(*a, **k):
        n[0] += 1
        return _ps(*a, **k)

    E.certify, E._python_stages = c, ps
    return log
