"""Compile the certification path once per process, before any budget clock runs.

The checkers' kernels are numba functions compiled on first use (``cache=True`` keeps
the machine code on disk, so later processes only load it). Compilation is not
certification work: with an empty cache it takes about 50 s of CPU on this project's
2-core machine (docs/notes/issue-12-coldstart.md: the whole-window kernel, the motion
kernels, GJK, the null-set LP), and inside a budgeted ``certify`` call it would turn the first windows of a
fresh process ``uncertain`` (the demo's first action was blocked for this reason).

:func:`ensure_warm` certifies a few tiny motions on a built-in scene (a hinged capsule arm
with a cylinder hand, a box post, a sphere sliding over the post, a plane) with an unlimited
budget: a rotating clear pass (compiled whole-shape stage), a colliding swing (witness and
depth paths) and a translating pass (extrusion).
:func:`monitor.certify` calls it before starting its *default* budget; a caller-given
budget counts compilation as the caller's time (call :func:`ensure_warm`, or
``python -m monitor warmup``, first). Idempotent and cheap after the first call
(a few hundred milliseconds when the kernels load from the on-disk cache).

The report says what was compiled: numba's ``numba:compile`` events during the warm-up
(every function compiled in this process, nested ones included; a function loaded from
the on-disk cache raises none), the entry points that were compiled and their inclusive
seconds.
"""

from __future__ import annotations

import threading
import time
from typing import Any

_XML = """<mujoco model="monitor-warmup">
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <geom name="post" type="box" size="0.05 0.05 0.3" pos="0.42 0 0.3"/>
    <body name="arm" pos="0 0 0.3">
      <joint name="yaw" type="hinge" axis="0 0 1"/>
      <geom name="link" type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
      <body name="tip" pos="0.4 0 0">
        <joint name="pitch" type="hinge" axis="0 1 0"/>
        <geom name="hand" type="cylinder" size="0.03 0.05"/>
      </body>
    </body>
    <body name="ball" pos="0.42 0 0.66">
      <joint name="slide" type="slide" axis="0 1 0"/>
      <geom name="ball" type="sphere" size="0.05"/>
    </body>
  </worldbody>
</mujoco>"""

_LOCK = threading.Lock()


def _compile_log() -> Any:
    """A numba ``numba:compile`` listener: counts and times the compiles, keeps the outermost ones.

    numba compiles a callee inside its caller's compile (nested events); the outermost
    events are the entry points compiled, their durations inclusive. ``.report()`` gives
    ``{"functions": compiles, "seconds": sum over entry points, "entry_points": {name: s}}``.
    """
    from numba.core import event

    class CompileLog(event.Listener):
        def __init__(self) -> None:
            self.count = 0
            self.top: dict[str, float] = {}
            self._starts: list[float] = []

        def on_start(self, ev: Any) -> None:
            self._starts.append(time.perf_counter())

        def on_end(self, ev: Any) -> None:
            seconds = time.perf_counter() - self._starts.pop()
            self.count += 1
            if not self._starts:
                d = (ev.data or {}).get("dispatcher")
                fn = getattr(d, "py_func", None)
                name = f"{getattr(fn, '__module__', '?')}.{getattr(fn, '__qualname__', d)}"
                self.top[name] = self.top.get(name, 0.0) + seconds

        def report(self) -> dict[str, Any]:
            return {"functions": self.count, "seconds": sum(self.top.values()),
                    "entry_points": dict(self.top)}

    return CompileLog()


_REPORT: dict[str, Any] | None = None


def ensure_warm() -> dict[str, Any]:
    """Compile (or load from the numba cache) every kernel of the certify path; once per process.

    Returns:
        ``{"seconds": wall time of the first call, "cases": {case: (verdict, seconds)},
        "compiled": {"functions": numba compiles, "seconds": their wall time, "entry_points":
        {qualified name: inclusive seconds}}}`` (no compiles: everything came from the on-disk
        cache); later calls return the same dict at once.
    """
    global _REPORT
    if _REPORT is not None:
        return _REPORT
    with _LOCK:
        if _REPORT is not None:
            return _REPORT
        _REPORT = {"seconds": 0.0, "cases": {}, "running": True}  # re-entrant calls return at once
        from numba.core import event

        log = _compile_log()
        t_start = time.perf_counter()
        with event.install_listener("numba:compile", log):
            out = _run_cases()
        _REPORT = {"seconds": time.perf_counter() - t_start, "cases": out, "compiled": log.report()}
        return _REPORT


def _run_cases() -> dict[str, tuple[str, float]]:
    """Certify the warm-up motions and compile the null-set LP: ``{case: (verdict, seconds)}``."""
    import mujoco
    import numpy as np

    from monitor.certify.common import Budget
    from monitor.certify.engine import certify
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    model = mujoco.MjModel.from_xml_string(_XML)
    scene = Scene.from_model(model, pairs="all")
    q0 = np.zeros(model.nq)
    cases = {
        "rotating clear": np.array([[-1.0, 0.0, -0.5], [-0.3, 0.0, -0.5]]),   # stops short of the post
        "colliding swing": np.array([[-0.6, 0.0, -0.5], [0.6, 0.0, -0.5]]),  # the link hits the post
        "translating": np.array([[-1.0, 0.0, -0.3], [-1.0, 0.0, 0.3]]),      # the ball passes over it
    }
    out = {}
    for name, q in cases.items():
        t = time.perf_counter()
        plan = Plan(np.array([0.0, 0.1]), q0 + q, model)
        cert = certify(scene, plan, margin=0.001, epsilon=1e-3, budget=Budget())
        out[name] = (str(cert.verdict), time.perf_counter() - t)
    # the per-pair search entry, called from Python by the engine when the window kernel leaves a
    # colliding pair open (engine._full_search): same argument types, so the same specialisation
    from monitor.certify import kernels

    t = time.perf_counter()
    gp, mp = kernels.scene_pack(scene).geoms, kernels.trajectory_pack(plan)
    if mp is not None:
        ga, gb = (int(g) for g in scene.pair_ids[0])
        r = kernels.check_pair_window(gp, mp, ga, gb, (0.0, 0.1), 0.001, 1e-3, max_tests=8)
        out["pair search entry"] = (str(r["verdict"]), time.perf_counter() - t)
    from monitor.certify.extrusion_null import warm_small_lp  # the null-set test's compiled simplex

    t = time.perf_counter()
    warm_small_lp()
    out["null-set LP kernel"] = ("compiled", time.perf_counter() - t)
    return out


__all__ = ["ensure_warm"]
