"""Batch execution on local processes or Ray, and parallel re-verification of logs.

One small task runner serves every batch job of the package (gated rollouts,
plan libraries, log re-verification):

* ``backend="local"``, ``workers=1``: the tasks run one after the other in this
  process (no pickling, no start-up cost).
* ``backend="local"``, ``workers>1``: a :class:`concurrent.futures.ProcessPoolExecutor`
  with the ``spawn`` start method (safe with MuJoCo, numba and threads). The task
  function and its arguments are pickled, so they must be picklable: module-level
  functions and classes, not lambdas or closures. As with any ``spawn`` pool, a
  script that starts one must guard its top-level code with
  ``if __name__ == "__main__":`` (workers re-import the main module).
* ``backend="ray"``: one Ray task per item (``num_cpus=1``). If Ray is already
  initialised (e.g. the user called ``ray.init(address="ray://...")`` to use an
  existing cluster) that cluster is used; otherwise a local Ray instance is
  started (``ray.init(num_cpus=workers)``) and left running for later calls, as
  Ray's own auto-init does. On a multi-node cluster every node needs ``monitor``
  installed and the file paths handed to tasks (models, logs) must be on storage
  that the nodes share.

Results always come back in the order of the items, whatever order the tasks
finish in, so a batch gives the same output on every backend. A tqdm progress
bar (stderr) counts finished tasks.

Ray is an optional extra (``pip install "monitor[ray]"``); it is imported only
when ``backend="ray"`` is asked for, and its absence raises
:class:`monitor.errors.DependencyNotInstalled`.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from monitor.errors import DependencyNotInstalled, InvalidInputError

BACKENDS = ("local", "ray")
RAY_INSTALL_HINT = 'pip install "monitor[ray]"  (or: pip install "ray>=2.9")'


# --------------------------------------------------------------------------- Ray
def require_ray() -> Any:
    """Import Ray, or raise :class:`DependencyNotInstalled` with the install hint.

    Returns:
        the ``ray`` module.
    """
    try:
        import ray
    except ImportError as exc:
        raise DependencyNotInstalled(
            f"backend='ray' needs the optional dependency 'ray', which is not installed ({exc}); "
            f"install it with: {RAY_INSTALL_HINT}") from exc
    return ray


def ensure_ray(num_cpus: int | None = None) -> Any:
    """Ray, initialised: the running instance/cluster if any, else a new local instance.

    Args:
        num_cpus: CPUs of a newly started local instance (ignored when Ray is
            already initialised); None lets Ray count the machine's cores.

    Returns:
        the ``ray`` module.
    """
    ray = require_ray()
    if not ray.is_initialized():
        ray.init(num_cpus=num_cpus, include_dashboard=False, ignore_reinit_error=True,
                 log_to_driver=False, configure_logging=False)
    return ray


# --------------------------------------------------------------------------- task runner
def _check_backend(backend: str, workers: int | None) -> None:
    if backend not in BACKENDS:
        raise InvalidInputError(f"backend must be one of {BACKENDS}, got {backend!r}")
    if workers is not None and (isinstance(workers, bool) or int(workers) != workers or workers < 1):
        raise InvalidInputError(f"workers must be an integer >= 1 (or None), got {workers!r}")


def _bar(total: int, desc: str, progress: bool | None) -> Any:
    from tqdm import tqdm

    # progress=None: tqdm decides (shown on a terminal, silent when stderr is redirected).
    return tqdm(total=total, desc=desc, unit="task", disable=None if progress is None else not progress,
                leave=False, dynamic_ncols=True)


def run_tasks(fn: Callable[[Any], Any], items: Sequence[Any], *, backend: str = "local",
              workers: int | None = 1, desc: str = "tasks", progress: bool | None = None) -> list[Any]:
    """Apply ``fn`` to every item on the chosen backend; results in item order.

    Args:
        fn: a picklable (module-level) function of one argument.
        items: the arguments, one task each (picklable for ``workers>1`` and Ray).
        backend: ``"local"`` or ``"ray"``.
        workers: local processes (1 = in this process); for Ray the most tasks in
            flight at once and the CPUs of a newly started local instance
            (None = submit everything, Ray's CPU count).
        desc: progress bar label.
        progress: True/False to force the bar on/off; None = on when stderr is a terminal.

    Returns:
        ``[fn(item) for item in items]``.

    Raises:
        InvalidInputError: unknown backend or bad ``workers``.
        DependencyNotInstalled: ``backend="ray"`` without Ray.
        Exception: the first exception raised by a task (the others are cancelled).
    """
    _check_backend(backend, workers)
    items = list(items)
    if backend == "ray":
        return _run_ray(fn, items, workers, desc, progress)
    n_workers = 1 if workers is None else int(workers)
    bar = _bar(len(items), desc, progress)
    try:
        if n_workers == 1 or len(items) <= 1:
            out = []
            for item in items:
                out.append(fn(item))
                bar.update(1)
            return out
        results: list[Any] = [None] * len(items)
        ctx = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=min(n_workers, len(items)), mp_context=ctx) as pool:
            futures = {pool.submit(fn, item): i for i, item in enumerate(items)}
            pending = set(futures)
            try:
                while pending:
                    done, pending = wait(pending, return_when=FIRST_COMPLETED)
                    for f in done:
                        results[futures[f]] = f.result()
                        bar.update(1)
            except BrokenProcessPool as exc:
                raise BrokenProcessPool(
                    f"a worker process died ({exc}). Workers are started with 'spawn', which re-imports "
                    "the main script: guard the script's top-level code with `if __name__ == \"__main__\":`"
                ) from exc
            except BaseException:
                for f in pending:
                    f.cancel()
                raise
        return results
    finally:
        bar.close()


def _run_ray(fn: Callable[[Any], Any], items: list[Any], workers: int | None, desc: str,
             progress: bool | None) -> list[Any]:
    ray = ensure_ray(workers)
    remote = ray.remote(num_cpus=1, max_retries=0)(fn)
    bar = _bar(len(items), desc, progress)
    limit = len(items) if workers is None else int(workers)
    refs: list[Any] = [None] * len(items)
    index: dict[Any, int] = {}
    nxt = 0
    in_flight: list[Any] = []
    try:
        while nxt < len(items) or in_flight:
            while nxt < len(items) and len(in_flight) < max(limit, 1):
                ref = remote.remote(items[nxt])
                refs[nxt], index[ref] = ref, nxt
                in_flight.append(ref)
                nxt += 1
            done, in_flight = ray.wait(in_flight, num_returns=1)
            ray.get(done)  # raise a task's exception as soon as it is known
            bar.update(len(done))
    except BaseException:
        for ref in in_flight:
            ray.cancel(ref, force=True)
        raise
    finally:
        bar.close()
    return ray.get(refs)


# --------------------------------------------------------------------------- log verification
def expand_logs(paths: Sequence[str | os.PathLike[str]]) -> list[str]:
    """Expand directories into their ``*.mcap`` files (sorted); files are kept as given.

    Args:
        paths: log files and/or directories.

    Returns:
        list of file paths (a directory without logs contributes nothing).
    """
    out: list[str] = []
    for p in paths:
        q = Path(p)
        if q.is_dir():
            out += [str(f) for f in sorted(q.glob("*.mcap")) if f.is_file()]
        else:
            out.append(str(p))
    return out


def _verify_task(job: tuple[str, str, int | None, dict[str, Any]]) -> dict[str, Any]:
    """Re-verify one log (runs in a worker); errors come back as ``{"error": ...}``.

    ``job`` = (path, model_source, limit, the auditor's options for :func:`monitor.review.verify`).
    """
    path, model_source, limit, options = job
    from monitor.errors import LogFormatError, MonitorError
    from monitor.log.reader import read_log
    from monitor.review import verify

    try:
        contents = read_log(path, progress=False)
    except (LogFormatError, OSError) as exc:
        return {"error": str(exc)}
    try:
        return verify(contents, model_source=model_source, progress=False, limit=limit, **options)
    except ImportError as exc:
        return {"error": f"verification needs the certification engine: {exc}"}
    except (MonitorError, ValueError) as exc:
        return {"error": str(exc)}
    except Exception as exc:  # noqa: BLE001 - one bad log must not abort the other tasks
        return {"error": f"{path}: unexpected {type(exc).__name__}: {exc}"}


def verify_logs(paths: Sequence[str | os.PathLike[str]], *, backend: str = "ray", workers: int | None = None,
                model_source: str = "auto", limit: int | None = None,
                progress: bool | None = None, tolerances: dict[str, Any] | None = None,
                expect_pairs: str | None = None, max_penetration: float | None = None,
                trust_model_edits: bool = False) -> list[dict[str, Any]]:
    """Re-verify many logs in parallel, one task per log.

    Each task reads its log and runs :func:`monitor.review.verify` on it, so every
    element is exactly what the serial ``review --verify`` computes for that log
    (``checked``, ``mismatches``, ``critical``, ...). A log that cannot be read
    or verified gives ``{"error": message}`` (the serial review reports the same
    message). Logs are read by path in the workers: on a multi-node Ray cluster
    they must be on shared storage.

    Args:
        paths: log files and/or directories (expanded by :func:`expand_logs`).
        backend: ``"ray"`` (default) or ``"local"``.
        workers: see :func:`run_tasks` (local default when None: one per CPU).
        model_source: ``"auto" | "xml" | "mjb"`` (see :func:`monitor.log.reader.load_model`).
        limit: verify only the first ``limit`` windows of each log.
        progress: progress bar over logs (None: on a terminal).
        tolerances, expect_pairs, max_penetration, trust_model_edits: the auditor's options,
            passed to :func:`monitor.review.verify` in every task unchanged (see there).

    Returns:
        one verification dict per log, in the order of :func:`expand_logs`.
    """
    files = expand_logs(paths)
    options = {"tolerances": tolerances, "expect_pairs": expect_pairs, "max_penetration": max_penetration,
               "trust_model_edits": bool(trust_model_edits)}
    if backend == "local" and workers is None:
        workers = os.cpu_count() or 1
    return run_tasks(_verify_task, [(f, model_source, limit, options) for f in files], backend=backend,
                     workers=workers, desc="verifying logs", progress=progress)


__all__ = ["BACKENDS", "RAY_INSTALL_HINT", "require_ray", "ensure_ray", "run_tasks", "expand_logs",
           "verify_logs"]
