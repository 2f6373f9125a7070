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

:func:`warm_up` (``python -m monitor warmup``) does the same with an empty cache on several
cores: two child processes compile every entry point (one the motion packer and then the
whole-window kernel through the certify cases, the other the Scene build's geometry, the
null-set LP, the fat-feature kernels and then the per-pair search kernel on top of the callees
it shares with the whole-window kernel), each waiting for the other's signal file before calling
into its functions; then :func:`ensure_warm` in this process loads what they cached (numba links
a cached callee's stored LLVM module into its caller without typing or lowering it again). numba
writes each cache file by an atomic rename, but its index update (read the index, take the first
free data-file number, write the index, write the data) is not atomic across processes: two
processes adding different signatures of one function can leave the index naming the other's
data file. During the warm-up every save takes an exclusive lock on a file next to the index
(:func:`serialise_cache_saves`).

The report says what was compiled: numba's ``numba:compile`` events during the warm-up
(every function compiled in this process, nested ones included; a function loaded from
the on-disk cache raises none), the entry points that were compiled and their inclusive
seconds.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
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


_SAVE_LOCK_NAME = "monitor-cache-save.lock"
_SAVES_SERIALISED = False


def serialise_cache_saves() -> bool:
    """Make this process's numba cache saves exclusive per cache folder (idempotent; True if active).

    Wraps ``numba.core.caching.IndexDataCacheFile.save`` (read index, pick a data-file number,
    write index, write data) in ``fcntl.flock`` on ``<cache folder>/monitor-cache-save.lock``,
    so a process that also does this never interleaves its index update with another's. False
    (nothing changed) when numba's internals differ from what this expects or ``fcntl`` is
    missing: callers then do not compile in parallel.
    """
    global _SAVES_SERIALISED
    if _SAVES_SERIALISED:
        return True
    try:
        import fcntl

        from numba.core import caching
        cls = caching.IndexDataCacheFile
        original = cls.save
        probe = cls.__init__.__code__.co_names
    except (ImportError, AttributeError):
        return False
    if "_cache_path" not in probe:
        return False

    def save(self, key, data):
        lock_path = os.path.join(self._cache_path, _SAVE_LOCK_NAME)
        with open(lock_path, "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                return original(self, key, data)
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)

    save.__wrapped__ = original
    cls.save = save
    _SAVES_SERIALISED = True
    return True


# Child tasks of the parallel warm-up, longest first. They compile disjoint sets of functions, in
# an order that keeps both cores busy (docs/notes/issue-12-suite-time.md, cold CPU seconds):
#   motion:   pack._derive_and_scale = derive + batch (~12 s) | signal | certify cases: window_kernel
#             with the callees it shares with pair_window (~27 s) | core_distance_batch (~1 s)
#   geometry: Scene build: core_distance (~11 s) | signal | null-set LP kernels (~12 s) | signal |
#             fat-feature kernels (~11 s) | pair_window on the cached callees (~12 s)
# Each task waits, before a step that calls into another task's functions, for that task's
# signal file in the shared folder (the parent writes a task's signals when its child exits,
# whatever happened), or for the cache entries it needs: no function is compiled by both.
# This process then only loads (ensure_warm), instead of compiling window_kernel alone on one core.
_CHILD_TASKS = ("geometry", "motion")
_SCENE_READY = "scene-ready"      # geometry: the warm-up Scene is built (core_distance cached)
_LP_READY = "lp-ready"            # geometry: the null-set LP kernels are cached (the translating case)
_BATCH_READY = "batch-ready"      # motion: the motion packer is cached (every trajectory_pack)
_SIGNALS = {"geometry": (_SCENE_READY, _LP_READY), "motion": (_BATCH_READY,)}
"""The signal files each child task writes (and the parent writes for it when the child exits)."""


def _wait_for(path: str | None, parent: int, timeout: float = 900.0) -> None:
    """Sleep until ``path`` exists, the parent process ``parent`` is gone, or ``timeout`` s passed.

    ``path`` None (no shared folder: the task runs alone): return at once.
    """
    if path is None:
        return
    t_end = time.monotonic() + timeout
    while not os.path.exists(path) and os.getppid() == parent and time.monotonic() < t_end:
        time.sleep(0.05)


def _is_cached(dispatcher: Any) -> bool:
    """True when numba's on-disk cache holds an entry of ``dispatcher`` for its current source.

    A cache this cannot read counts as cached (the caller then stops waiting for it).
    """
    try:
        return bool(dispatcher._cache._cache_file._load_index())
    except Exception:  # noqa: BLE001 - numba internals differ: do not wait
        return True


def _wait_cached(dispatchers: tuple, give_up: str | None, parent: int, timeout: float = 900.0) -> None:
    """Sleep until every dispatcher has an on-disk cache entry (or a condition to stop waiting).

    Stops early when ``give_up`` exists (the process compiling them is gone), the parent
    process is gone, or ``timeout`` s passed.
    """
    t_end = time.monotonic() + timeout
    while not all(_is_cached(d) for d in dispatchers):
        if (give_up is not None and os.path.exists(give_up)) or os.getppid() != parent \
                or time.monotonic() > t_end:
            return
        time.sleep(0.1)


def _warm_distance_batch(scene: Any = None) -> None:
    """Compile ``core_distance_batch`` (many poses of one pair: witness confirmation, sampling).

    A box against a sphere (both compiled cores; a half-space pair would take the per-pose
    path), one pose broadcast against two, so the arrays are the C, writable copies
    :func:`monitor.geometry.distance.shape_distance_batch` always passes: the specialisation
    every scene uses. ``scene`` is unused (kept for the call sites' symmetry).
    """
    import numpy as np

    from monitor.geometry.distance import shape_distance_batch
    from monitor.geometry.polytope import box_polytope, sphere_shape

    R = np.repeat(np.eye(3)[None], 2, axis=0)
    p = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.3]])
    shape_distance_batch(box_polytope(np.array([0.1, 0.1, 0.1])), (np.eye(3), np.zeros(3)), sphere_shape(0.1),
                         (R, p))


def _pair_search(scene: Any, plan: Any) -> str | None:
    """Call the per-pair search entry as the engine's ``_full_search`` does; its verdict (None: no pack)."""
    from monitor.certify import kernels

    gp, mp = kernels.scene_pack(scene).geoms, kernels.trajectory_pack(plan)
    if mp is None:
        return None
    ga, gb = (int(g) for g in scene.pair_ids[0])
    return str(kernels.check_pair_window(gp, mp, ga, gb, (0.0, 0.1), 0.001, 1e-3, max_tests=8)["verdict"])


def _child_task(task: str, shared: str | None = None) -> dict[str, str | None]:
    """Compile one group of entry points (in a child process of :func:`warm_up`); the verdicts.

    ``shared``: the folder of the children's signal files (None: no waiting, no signals).
    Returns ``{case: verdict}`` of the certify cases ("motion") or ``{"pair search entry":
    verdict}`` ("geometry"; None when the plan has no motion pack).
    """
    import mujoco
    import numpy as np

    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    parent = os.getppid()

    def signal_file(name: str) -> str | None:
        return None if shared is None else os.path.join(shared, name)

    def signal(name: str) -> None:
        if shared is not None:
            open(os.path.join(shared, name), "w").close()

    model = mujoco.MjModel.from_xml_string(_XML)
    q0 = np.zeros(model.nq)
    if task == "geometry":
        scene = Scene.from_model(model, pairs="all")      # halfspace_distance, core_distance
        signal(_SCENE_READY)
        from monitor.certify.extrusion_null import warm_small_lp

        warm_small_lp()                                    # simplex, min-norm and first-contact kernels
        signal(_LP_READY)
        from monitor.certify.toleranced import warm_kernels

        warm_kernels()                                     # fat-feature levels, trajectory balls, screws
        # pair_window on top of the callees it shares with window_kernel (compiled by "motion")
        from monitor.certify import kernels
        from monitor.motion import kernel as motion_kernel

        _wait_for(signal_file(_BATCH_READY), parent)
        if shared is not None:
            _wait_cached((kernels.posed_distance, kernels.separated_beyond, motion_kernel.body_pose),
                         os.path.join(shared, "motion-exited"), parent)
        plan = Plan(np.array([0.0, 0.1]), q0 + np.array(_CASES["rotating clear"]), model)
        return {"pair search entry": _pair_search(scene, plan)}
    if task == "motion":
        from monitor.certify import kernels

        plans = {name: Plan(np.array([0.0, 0.1]), q0 + np.array(q), model) for name, q in _CASES.items()}
        kernels.trajectory_pack(plans["rotating clear"])  # pack._derive_and_scale (derive, batch)
        signal(_BATCH_READY)
        _wait_for(signal_file(_SCENE_READY), parent)
        scene = Scene.from_model(model, pairs="all")
        out = {}
        for name in _CASES:                                # window_kernel (+ its callees)
            if name == "translating":                      # the extrusion path: the LP kernels
                _wait_for(signal_file(_LP_READY), parent)
            out[name] = _certify_case(scene, plans[name])
        _warm_distance_batch()
        return out
    raise ValueError(f"task: unknown warm-up task {task!r}")


_CHILD_CODE = """
import json, resource, sys, time
sys.path[:] = json.loads(sys.argv[3])
from numba.core import event
import monitor.warmup as w
assert w.serialise_cache_saves()
log = w._compile_log()
t = time.perf_counter()
with event.install_listener("numba:compile", log):
    w._child_task(sys.argv[1], sys.argv[2])
ru = resource.getrusage(resource.RUSAGE_SELF)
print("WARMUP-CHILD " + json.dumps({"seconds": time.perf_counter() - t, "cpu": ru.ru_utime + ru.ru_stime,
                                    "compiled": log.report()}))
"""


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def warm_up(processes: int | str = "auto") -> dict[str, Any]:
    """:func:`ensure_warm`, with every entry point first compiled in child processes (two cores).

    Args:
        processes: child processes run at once (``"auto"``: the usable cores, at most
            ``len(_CHILD_TASKS)``); 0 or 1, a single usable core, or numba internals that
            :func:`serialise_cache_saves` cannot wrap: no children, plain :func:`ensure_warm`.

    Returns:
        :func:`ensure_warm`'s report plus ``"children"``: ``{task: {"seconds", "cpu",
        "compiled", "ok", "error"}}`` (empty when none ran) and ``"total_seconds"``, the wall
        time of children and this process together. A failed child is reported, not raised:
        this process then compiles what it left.
    """
    if processes == "auto":
        n = min(_cores(), len(_CHILD_TASKS))
    elif isinstance(processes, int) and not isinstance(processes, bool) and processes >= 0:
        n = min(processes, len(_CHILD_TASKS))
    else:
        from monitor.errors import InvalidInputError

        raise InvalidInputError(f"processes: expected 'auto' or an int >= 0, got {processes!r}")
    t0 = time.perf_counter()
    children: dict[str, dict[str, Any]] = {}
    if n >= 2 and _REPORT is None and not _children_cached() and serialise_cache_saves():
        children = _run_children(n)
    rep = dict(ensure_warm())
    rep["children"] = children
    rep["total_seconds"] = time.perf_counter() - t0
    return rep


def _children_cached() -> bool:
    """True when every entry point the children compile has an on-disk cache entry of this source.

    Then the children would only load (about 2 s of CPU each to import and load): skipped. A
    cache this cannot read counts as not cached (the children run; nothing is lost but time).
    """
    try:
        from monitor.certify import extrusion_kernels, extrusion_null, fat_kernels, kernels
        from monitor.geometry import _gjk
        from monitor.motion import kernel as motion_kernel
        from monitor.motion import pack as motion_pack

        entry_points = (_gjk.core_distance, _gjk.core_distance_batch, _gjk.halfspace_distance,
                        motion_kernel.batch, motion_kernel.derive, motion_pack._derive_and_scale,
                        kernels.pair_window, kernels.window_kernel,
                        extrusion_null._dual_simplex_kernel, extrusion_kernels.min_norm_kernel,
                        extrusion_kernels.first_time_kernel,
                        fat_kernels.fat_level, fat_kernels.traj_balls, fat_kernels.screw_poses_bounds)
        return all(bool(d._cache._cache_file._load_index()) for d in entry_points)
    except Exception:  # noqa: BLE001 - numba internals differ: assume cold
        return False


def _run_children(n: int) -> dict[str, dict[str, Any]]:
    """Run :data:`_CHILD_TASKS` in at most ``n`` child processes at once; their reports."""
    import tempfile

    out: dict[str, dict[str, Any]] = {}
    todo = list(_CHILD_TASKS)
    running: dict[str, tuple[subprocess.Popen, Any]] = {}
    def terminated(signum: int, frame: Any) -> None:
        raise SystemExit(128 + signum)   # runs the finally below: the children are killed too

    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, terminated) if main else None
    with tempfile.TemporaryDirectory(prefix="monitor-warmup-") as shared:
        for task in set(_SIGNALS) - set(todo):  # a task that does not run here signals nothing: no waiting
            for name in (*_SIGNALS[task], f"{task}-exited"):
                open(os.path.join(shared, name), "a").close()
        try:
            while todo or running:
                while todo and len(running) < n:
                    task = todo.pop(0)
                    log = tempfile.TemporaryFile("w+")   # a file, not a pipe: a chatty child never blocks
                    argv = [sys.executable, "-c", _CHILD_CODE, task, shared, json.dumps(sys.path)]
                    proc = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, text=True)
                    running[task] = (proc, log)
                done = [task for task, (proc, _) in running.items() if proc.poll() is not None]
                if not done:
                    time.sleep(0.05)
                    continue
                for task in done:
                    proc, log = running.pop(task)
                    # whatever happened, nobody waits for this child any more
                    for name in (*_SIGNALS.get(task, ()), f"{task}-exited"):
                        open(os.path.join(shared, name), "a").close()
                    log.seek(0)
                    text = log.read()
                    log.close()
                    line = [x for x in text.splitlines() if x.startswith("WARMUP-CHILD ")]
                    if proc.returncode == 0 and line:
                        out[task] = dict(json.loads(line[-1].split(" ", 1)[1]), ok=True, error="")
                    else:
                        out[task] = {"ok": False, "error": f"exit {proc.returncode}: " + text.strip()[-400:]}
        finally:   # interrupted (an exception, Ctrl-C, SIGTERM): do not leave children compiling
            for proc, log in running.values():
                proc.kill()
                proc.wait()
                log.close()
            if main:
                signal.signal(signal.SIGTERM, previous)
    return out


_CASES = {
    "rotating clear": [[-1.0, 0.0, -0.5], [-0.3, 0.0, -0.5]],   # stops short of the post
    "colliding swing": [[-0.6, 0.0, -0.5], [0.6, 0.0, -0.5]],  # the link hits the post
    "translating": [[-1.0, 0.0, -0.3], [-1.0, 0.0, 0.3]],      # the ball passes over it
}
"""Joint waypoints (yaw, pitch, slide) of the warm-up motions, at t = 0 and 0.1 s."""


def _certify_case(scene: Any, plan: Any) -> str:
    """Certify one warm-up motion with an unlimited budget; its verdict."""
    from monitor.certify.common import Budget
    from monitor.certify.engine import certify

    return str(certify(scene, plan, margin=0.001, epsilon=1e-3, budget=Budget()).verdict)


def _run_cases() -> dict[str, tuple[str, float]]:
    """Certify the warm-up motions and compile the null-set LP: ``{case: (verdict, seconds)}``."""
    import mujoco
    import numpy as np

    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    model = mujoco.MjModel.from_xml_string(_XML)
    scene = Scene.from_model(model, pairs="all")
    q0 = np.zeros(model.nq)
    out = {}
    for name, q in _CASES.items():
        t = time.perf_counter()
        plan = Plan(np.array([0.0, 0.1]), q0 + np.array(q), model)
        out[name] = (_certify_case(scene, plan), time.perf_counter() - t)
    # the per-pair search entry, called from Python by the engine when the window kernel leaves a
    # colliding pair open (engine._full_search): same argument types, so the same specialisation
    t = time.perf_counter()
    verdict = _pair_search(scene, plan)
    if verdict is not None:
        out["pair search entry"] = (verdict, time.perf_counter() - t)
    from monitor.certify.extrusion_null import warm_small_lp  # the null-set test's compiled simplex

    t = time.perf_counter()
    warm_small_lp()
    out["null-set LP kernel"] = ("compiled", time.perf_counter() - t)
    t = time.perf_counter()
    _warm_distance_batch(scene)
    out["distance batch"] = ("compiled", time.perf_counter() - t)
    from monitor.certify.toleranced import warm_kernels  # fat-feature levels, trajectory balls, screw bounds

    t = time.perf_counter()
    warm_kernels()
    out["fat-feature kernels"] = ("compiled", time.perf_counter() - t)
    return out


__all__ = ["ensure_warm", "serialise_cache_saves", "warm_up"]
