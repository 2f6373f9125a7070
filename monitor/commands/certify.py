"""``python -m monitor certify PLANS.npz --model scene.xml``: certify a library of plans.

Every plan of the ``.npz`` file is certified against the scene with
:func:`monitor.certify`; one line per plan is printed (verdict, clearance,
witness, checker mix, time) and, with ``--log``, one window per plan is written
to an MCAP log that ``python -m monitor review --verify`` can re-derive.

The ``.npz`` layout (read with ``allow_pickle=False``; nothing is unpickled).
Times are seconds of simulation time, strictly increasing; qpos rows follow the
model's ``qpos`` layout (``nq`` columns, quaternions (w, x, y, z)). Either

* **one entry per plan**: ``plan<i>_times`` (K_i,) and ``plan<i>_qpos`` (K_i, nq)
  for i = 0 .. P-1 (no gaps; plans may have different K_i), optionally
  ``plan<i>_mocap_pos`` (nmocap, 3) and ``plan<i>_mocap_quat`` (nmocap, 4); or
* **stacked**: ``qpos`` (P, K, nq) (or (K, nq) for one plan) with ``times`` (K,)
  shared by all plans or (P, K), optionally ``mocap_pos`` (P, nmocap, 3) and
  ``mocap_quat`` (P, nmocap, 4);

and in both layouts an optional ``names`` (P,) string array. Any other key is an
error (a misspelt key is never silently ignored). Arrays are numeric (integer or
float; no structured, object or complex dtypes); ``names`` is a string array.

Limits (checked from the array headers before any data is read, so a crafted file
cannot make the command allocate): at most 100 000 plans, 100 000 waypoints per
plan, 1 000 000 waypoints in total, 256 MiB of array data in total; plan indices
have at most 6 digits and no leading zeros. Example::

    np.savez("plans.npz", times=np.linspace(0, 1, 11), qpos=qpos_PKn)

Exit codes: 0 every plan certified; 1 some plan is "violation" or "uncertain";
2 bad input (unreadable file, wrong layout or shapes, model that does not load).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from monitor.certify.types import Method, Verdict

_PER_PLAN = re.compile(r"^plan(0|[1-9]\d{0,5})_(times|qpos|mocap_pos|mocap_quat)$")
_STACKED = ("times", "qpos", "mocap_pos", "mocap_quat")

MAX_PLANS = 100_000
"""Most plans in one ``.npz`` library."""
MAX_WAYPOINTS_PER_PLAN = 100_000
"""Most waypoints (rows of times/qpos) in one plan."""
MAX_WAYPOINTS_TOTAL = 1_000_000
"""Most waypoints over all plans of one library (a 20 M-waypoint file is refused up front)."""
MAX_NPZ_DATA_BYTES = 256 * 1024 * 1024
"""Most array data (bytes, as the headers declare it) read from one ``.npz``."""


def add_parser(p: argparse.ArgumentParser) -> None:
    """Options of the ``certify`` subcommand (``-h`` shows the .npz layout)."""
    p.description = __doc__
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument("plans", metavar="PLANS.npz", help="plan library (layout above)")
    p.add_argument("--model", required=True, metavar="scene.xml",
                   help="MJCF scene (a path, or the name of a shipped scene such as 'arm')")
    p.add_argument("--pairs", choices=("mujoco", "all"), default="mujoco",
                   help="candidate pairs: MuJoCo's contact filter (default) or every pair of bodies")
    p.add_argument("--margin", type=float, default=0.0, help="clearance (m) that counts as safe (default 0)")
    p.add_argument("--epsilon", type=float, default=1e-3, help="certification tolerance (m, default 1e-3)")
    p.add_argument("--method", choices=[m.value for m in Method], default=Method.AUTO.value,
                   help="checker (default auto)")
    p.add_argument("--backend", choices=("local", "ray"), default="local",
                   help="local processes or Ray tasks (Ray: existing ray.init() or a new local instance)")
    p.add_argument("--workers", type=int, default=None,
                   help="local processes (default 1 = this process) or Ray tasks in flight (default: all)")
    p.add_argument("--log", metavar="OUT.mcap", default=None, help="write one logged window per plan")
    p.add_argument("--json", action="store_true", help="print the certificates as JSON")
    p.add_argument("--progress", dest="progress", action="store_true", default=None,
                   help="always show the progress bar (default: on a terminal)")
    p.add_argument("--no-progress", dest="progress", action="store_false", help="never show the progress bar")


# --------------------------------------------------------------------------- input
def resolve_model_path(spec: str) -> Path:
    """An MJCF path, or ``models/<spec>/scene.xml`` for a shipped scene name.

    Raises:
        InvalidInputError: neither exists.
    """
    from monitor.errors import InvalidInputError

    p = Path(spec)
    if p.is_file():
        return p.resolve()
    if re.fullmatch(r"[A-Za-z0-9_]+", spec):
        from monitor._paths import scene_path

        try:
            return scene_path(spec)
        except FileNotFoundError:
            pass
    raise InvalidInputError(f"model {spec!r}: no such MJCF file or shipped scene")


def _read_npz(path: str | Path) -> dict[str, np.ndarray]:
    """Arrays of an ``.npz`` read member by member with every header checked before its data.

    Raises:
        InvalidInputError: not a regular file, an ``.npy`` instead of an ``.npz``, a damaged
            zip (truncated, bad CRC), a member that is not an ``.npy`` array, a non-numeric
            dtype, a header whose size disagrees with the member, or data beyond the limits.
    """
    import zipfile

    from monitor.errors import InvalidInputError

    p = Path(path)
    if not p.is_file():
        raise InvalidInputError(f"{path}: no such file (or not a regular file)")
    with open(p, "rb") as f:
        head = f.read(6)
    if head == b"\x93NUMPY":
        raise InvalidInputError(f"{path}: is a single .npy array, not an .npz library (save the plans with "
                                f"np.savez(..., times=..., qpos=...))")
    if not zipfile.is_zipfile(p):  # a text file, a pickle, ...: one line, no numpy "allow_pickle" hint
        raise InvalidInputError(f"{path}: not a readable .npz file (not a zip archive); save the plans with "
                                f"np.savez(..., times=..., qpos=...)")
    arrays: dict[str, np.ndarray] = {}
    try:
        with zipfile.ZipFile(p) as z:
            members = z.infolist()
            if len(members) > 4 * MAX_PLANS + 1:
                raise InvalidInputError(f"{path}: {len(members)} arrays, more than the limit "
                                        f"({4 * MAX_PLANS + 1})")
            headers = [_npz_header(path, z, info) for info in members]  # pass 1: headers only
            _check_sizes(path, headers)
            for info, (key, shape, fortran, dtype, offset) in zip(members, headers):  # pass 2: data
                nbytes = info.file_size - offset
                with z.open(info) as m:
                    m.read(offset)
                    data = m.read(nbytes)
                    if len(data) != nbytes or m.read(1):
                        raise InvalidInputError(f"{path}: {key!r} is truncated")
                order = "F" if fortran else "C"
                arrays[key] = np.frombuffer(data, dtype=dtype).reshape(shape, order=order).copy()
    except InvalidInputError:
        raise
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, ValueError, EOFError, KeyError,
            NotImplementedError, RuntimeError) as exc:  # RuntimeError: encrypted members
        raise InvalidInputError(f"{path}: not a readable .npz file ({type(exc).__name__}: "
                                f"{str(exc)[:200]})") from exc
    return arrays


def _npz_header(path: Any, z: Any, info: Any) -> tuple[str, tuple[int, ...], bool, np.dtype, int]:
    """(key, shape, fortran order, dtype, data offset) of one ``.npz`` member, from its header only."""
    from monitor.errors import InvalidInputError

    if not info.filename.endswith(".npy"):
        raise InvalidInputError(f"{path}: member {info.filename[:60]!r} is not an .npy array")
    key = info.filename[:-4]
    with z.open(info) as m:
        version = np.lib.format.read_magic(m)
        if version == (1, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_1_0(m)
        elif version == (2, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_2_0(m)
        else:
            raise InvalidInputError(f"{path}: {key[:60]!r} uses .npy format {version}")
        offset = m.tell()
    want = "US" if key == "names" else "fiu"
    odd = dtype.fields is not None or dtype.subdtype is not None
    if odd or dtype.kind not in want or dtype.itemsize > 4096:
        raise InvalidInputError(f"{path}: {key[:60]!r} has dtype {dtype}; expected "
                                f"{'strings' if key == 'names' else 'integers or floats'}")
    nbytes = math.prod(int(n) for n in shape) * dtype.itemsize
    if nbytes != info.file_size - offset:
        raise InvalidInputError(f"{path}: {key[:60]!r} header claims shape {shape} ({nbytes} bytes) but the "
                                f"member holds {info.file_size - offset} bytes")
    return key, tuple(int(n) for n in shape), bool(fortran), dtype, offset


def _check_sizes(path: Any, headers: list[tuple[str, tuple[int, ...], bool, np.dtype, int]]) -> None:
    """Waypoint and byte limits from the headers alone (before any array data is read)."""
    from monitor.errors import InvalidInputError

    total_bytes = total_waypoints = 0
    for key, shape, _, dtype, _ in headers:
        total_bytes += math.prod(shape) * dtype.itemsize
        kind = key.rsplit("_", 1)[-1] if key.startswith("plan") else key
        if kind not in ("times", "qpos"):
            continue
        lead = shape[:-1] if kind == "qpos" else shape  # (..., K) waypoints
        per_plan = lead[-1] if lead else 1
        if per_plan > MAX_WAYPOINTS_PER_PLAN:
            raise InvalidInputError(f"{path}: {key!r} has {per_plan} waypoints, more than the limit "
                                    f"{MAX_WAYPOINTS_PER_PLAN} per plan")
        if kind == "times":
            total_waypoints += math.prod(lead) if key.startswith("plan") or len(shape) > 1 else 0
        if math.prod(lead) > MAX_WAYPOINTS_TOTAL:
            raise InvalidInputError(f"{path}: {key!r} holds {math.prod(lead)} waypoints, more than the limit "
                                    f"{MAX_WAYPOINTS_TOTAL} in total")
    if total_waypoints > MAX_WAYPOINTS_TOTAL:
        raise InvalidInputError(f"{path}: {total_waypoints} waypoints in total, more than the limit "
                                f"{MAX_WAYPOINTS_TOTAL}")
    if total_bytes > MAX_NPZ_DATA_BYTES:
        raise InvalidInputError(f"{path}: the arrays hold {total_bytes} bytes, more than the limit "
                                f"{MAX_NPZ_DATA_BYTES}")


def load_plan_arrays(path: str | Path) -> list[dict[str, Any]]:
    """Read the plans of an ``.npz`` library (layout and limits in the module docstring).

    Args:
        path: the ``.npz`` file.

    Returns:
        one dict per plan: ``name`` (str), ``times`` (K,), ``qpos`` (K, nq),
        ``mocap_pos`` ((nmocap, 3) or None), ``mocap_quat`` ((nmocap, 4) or None).

    Raises:
        InvalidInputError: unreadable or damaged file, both or neither layout, a gap in
            the plan numbering, unknown keys, inconsistent stacked shapes, non-numeric
            arrays, or more plans/waypoints/bytes than the limits.
    """
    from monitor.errors import InvalidInputError

    arrays = _read_npz(path)
    names = arrays.pop("names", None)
    per = {k: v for k, v in arrays.items() if _PER_PLAN.match(k)}
    stacked = {k: v for k, v in arrays.items() if k in _STACKED}
    unknown = sorted(set(arrays) - set(per) - set(stacked))
    if unknown:
        raise InvalidInputError(f"{path}: unknown key(s) {[k[:60] for k in unknown[:5]]}; expected "
                                f"plan<i>_times/plan<i>_qpos (+ _mocap_pos/_mocap_quat; i < {MAX_PLANS}, no "
                                f"leading zeros), or stacked times/qpos, and optional names")
    if per and stacked:
        raise InvalidInputError(f"{path}: mixes per-plan keys ({sorted(per)[0]}, ...) and stacked keys "
                                f"({sorted(stacked)}); use one layout")
    if per:
        plans = _per_plan(path, per)
    elif stacked:
        plans = _stacked(path, stacked)
    else:
        raise InvalidInputError(f"{path}: no plans (expected plan0_times/plan0_qpos or stacked times/qpos)")
    if len(plans) > MAX_PLANS:
        raise InvalidInputError(f"{path}: {len(plans)} plans, more than the limit {MAX_PLANS}")
    total = 0
    for p in plans:
        k = int(np.shape(p["times"])[0]) if np.ndim(p["times"]) else 1
        if k > MAX_WAYPOINTS_PER_PLAN:
            raise InvalidInputError(f"{path}: {p['name']} has {k} waypoints, more than the limit "
                                    f"{MAX_WAYPOINTS_PER_PLAN} per plan")
        total += k
    if total > MAX_WAYPOINTS_TOTAL:
        raise InvalidInputError(f"{path}: {total} waypoints in total, more than the limit "
                                f"{MAX_WAYPOINTS_TOTAL}")
    if names is not None:
        names = np.atleast_1d(names)
        if names.shape != (len(plans),) or names.dtype.kind not in "US":
            raise InvalidInputError(f"{path}: names must be a ({len(plans)},) string array, got "
                                    f"{names.dtype} {names.shape}")
        for p, n in zip(plans, names):
            p["name"] = str(n)
    return plans


def _per_plan(path: Any, per: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    from monitor.errors import InvalidInputError

    by_index: dict[int, dict[str, np.ndarray]] = {}
    for k, v in per.items():
        m = _PER_PLAN.match(k)
        by_index.setdefault(int(m.group(1)), {})[m.group(2)] = v
    n = max(by_index) + 1
    if n > len(by_index):  # a gap: found without walking a range as long as the largest index
        missing = [i for i in range(len(by_index) + 1) if i not in by_index]
    else:
        missing = []
    if missing:
        raise InvalidInputError(f"{path}: plan numbering has gaps: no plan{missing[0]}_* keys "
                                f"(plans must be numbered 0..{n - 1})")
    plans = []
    for i in range(n):
        d = by_index[i]
        for need in ("times", "qpos"):
            if need not in d:
                raise InvalidInputError(f"{path}: plan{i}_{need} is missing")
        plans.append({"name": f"plan{i}", "times": d["times"], "qpos": d["qpos"],
                      "mocap_pos": d.get("mocap_pos"), "mocap_quat": d.get("mocap_quat")})
    return plans


def _stacked(path: Any, st: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    from monitor.errors import InvalidInputError

    for need in ("times", "qpos"):
        if need not in st:
            raise InvalidInputError(f"{path}: stacked layout needs '{need}'")
    qpos, times = st["qpos"], st["times"]
    if qpos.ndim == 2:
        qpos = qpos[None]
    if qpos.ndim != 3:
        raise InvalidInputError(f"{path}: stacked qpos must be (P, K, nq) or (K, nq), "
                                f"got shape {st['qpos'].shape}")
    n_plans, k = qpos.shape[:2]
    if times.ndim == 1:
        times = np.broadcast_to(times, (n_plans, times.shape[0]))
    if times.shape != (n_plans, k):
        raise InvalidInputError(f"{path}: stacked times must be ({k},) or ({n_plans}, {k}) to match qpos "
                                f"{qpos.shape}, got {st['times'].shape}")
    mocap = {}
    for key, width in (("mocap_pos", 3), ("mocap_quat", 4)):
        a = st.get(key)
        if a is not None and (a.ndim != 3 or a.shape[0] != n_plans or a.shape[2] != width):
            raise InvalidInputError(f"{path}: stacked {key} must be ({n_plans}, nmocap, {width}), "
                                    f"got {a.shape}")
        mocap[key] = a
    return [{"name": f"plan{i}", "times": times[i], "qpos": qpos[i],
             "mocap_pos": None if mocap["mocap_pos"] is None else mocap["mocap_pos"][i],
             "mocap_quat": None if mocap["mocap_quat"] is None else mocap["mocap_quat"][i]}
            for i in range(n_plans)]


def build_plan(model: Any, p: dict[str, Any]) -> Any:
    """A :class:`monitor.Plan` from one plan dict; errors name the plan."""
    from monitor.errors import InvalidInputError
    from monitor.motion.plan import Plan

    kw = {k: np.asarray(p[k], np.float64) for k in ("mocap_pos", "mocap_quat") if p.get(k) is not None}
    try:
        return Plan(np.asarray(p["times"], np.float64), np.asarray(p["qpos"], np.float64), model=model, **kw)
    except (InvalidInputError, ValueError) as exc:
        raise InvalidInputError(f"plan {p['name']!r}: {exc}") from exc


# --------------------------------------------------------------------------- work (runs in workers)
_WORKER_CACHE: dict[tuple[str, str], tuple[Any, Any]] = {}


def _scene_for(model_path: str, pairs: str) -> tuple[Any, Any]:
    """(MjModel, Scene) of a model file, cached per worker process."""
    key = (model_path, pairs)
    if key not in _WORKER_CACHE:
        import mujoco

        from monitor.scene import Scene

        model = mujoco.MjModel.from_xml_path(model_path)
        _WORKER_CACHE[key] = (model, Scene.from_model(model, pairs=pairs))
    return _WORKER_CACHE[key]


def certify_task(job: dict[str, Any]) -> tuple[Any, float]:
    """Certify one plan (a worker task).

    Args:
        job: ``model_path`` (str), ``pairs``, ``margin``, ``epsilon``, ``method`` and
            ``plan`` (a plan dict of :func:`load_plan_arrays`).

    Returns:
        (:class:`monitor.Certificate`, wall time of the certification in µs).
    """
    from monitor.certify.engine import certify

    model, scene = _scene_for(job["model_path"], job["pairs"])
    plan = build_plan(model, job["plan"])
    t0 = time.perf_counter()
    cert = certify(scene, plan, margin=job["margin"], epsilon=job["epsilon"], method=job["method"])
    return cert, (time.perf_counter() - t0) * 1e6


# --------------------------------------------------------------------------- command
def _mix(cert: Any) -> str:
    counts: dict[str, int] = {}
    for p in cert.pairs:
        counts[p.method] = counts.get(p.method, 0) + 1
    return " ".join(f"{k}:{v}" for k, v in sorted(counts.items()))


def _line(i: int, name: str, cert: Any, us: float) -> str:
    w = cert.witness
    wit = "-" if w is None else f"t={w.time:.4f} {w.geoms[0]}/{w.geoms[1]} d={w.distance:.3g}"
    clr = f"{cert.clearance:.4g}"  # keeps the sign: "-inf" when no lower bound is known
    return (f"{i:>4} {name[:16]:16} [{cert.window[0]:.4f}, {cert.window[1]:.4f}] {cert.verdict:10} "
            f"{clr:>10} {us / 1e3:9.1f}  {_mix(cert):28} {wit}")


def run(args: argparse.Namespace) -> int:
    """Run the command; returns the exit code (0 all certified, 1 some not, 2 bad input)."""
    import mujoco

    from monitor.distributed import run_tasks
    from monitor.errors import InvalidInputError, MonitorError

    try:
        model_path = resolve_model_path(args.model)
        try:
            model = mujoco.MjModel.from_xml_path(str(model_path))
        except (ValueError, RuntimeError) as exc:
            raise InvalidInputError(f"model {str(model_path)!r} does not load: {exc}") from exc
        plans = load_plan_arrays(args.plans)
        built = [build_plan(model, p) for p in plans]  # validate everything before any work
        if not (math.isfinite(args.margin) and args.margin >= 0):
            raise InvalidInputError(f"--margin must be a finite number >= 0, got {args.margin}")
        if not (math.isfinite(args.epsilon) and args.epsilon > 0):
            raise InvalidInputError(f"--epsilon must be a finite number > 0, got {args.epsilon}")
        jobs = [{"model_path": str(model_path), "pairs": args.pairs, "margin": float(args.margin),
                 "epsilon": float(args.epsilon), "method": args.method, "plan": p} for p in plans]
        t_start = time.perf_counter()
        workers = args.workers if args.workers is not None else (1 if args.backend == "local" else None)
        results = run_tasks(certify_task, jobs, backend=args.backend, workers=workers,
                            desc="certifying plans", progress=args.progress)
        wall = time.perf_counter() - t_start
    except (MonitorError, OSError) as exc:  # includes DependencyNotInstalled (no Ray)
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"error: {args.plans}: out of memory while certifying (see the limits in 'certify --help')",
              file=sys.stderr)
        return 2

    if args.log:
        try:
            _write_log(args, model, model_path, built, results)
        except (MonitorError, OSError) as exc:
            print(f"error: cannot write log {args.log}: {exc}", file=sys.stderr)
            return 2
    counts = {v: sum(c.verdict == v for c, _ in results) for v in Verdict}
    if args.json:
        out = {"model": str(model_path), "plans": [{"name": p["name"], "certify_us": us, **c.to_dict()}
                                                     for p, (c, us) in zip(plans, results)],
               "counts": counts, "wall_s": wall}
        print(json.dumps(out, indent=1))
    else:
        print(f"certify {args.plans}: {len(plans)} plan(s) on {model_path.name} (pairs {args.pairs}, "
              f"margin {args.margin} m, epsilon {args.epsilon} m, backend {args.backend})")
        print(f"{'#':>4} {'plan':16} {'window (s)':20} {'verdict':10} {'clearance':>10} {'ms':>9}  "
              f"{'checkers':28} witness")
        for i, (p, (c, us)) in enumerate(zip(plans, results)):
            print(_line(i, p["name"], c, us))
        print(f"certified {counts[Verdict.CERTIFIED]}, violation {counts[Verdict.VIOLATION]}, "
              f"uncertain {counts[Verdict.UNCERTAIN]} in {wall:.2f} s"
              + (f"; log {args.log}" if args.log else ""))
    return 0 if counts[Verdict.CERTIFIED] == len(plans) else 1


def _write_log(args: argparse.Namespace, model: Any, model_path: Path, plans: list[Any],
               results: list[tuple[Any, float]]) -> None:
    from monitor.log.writer import MonitorLog

    meta = {"margin": float(args.margin), "epsilon": float(args.epsilon), "pairs": args.pairs,
            "predictor": "plan library", "method": args.method, "source": str(args.plans),
            "model_path": str(model_path)}
    with MonitorLog(args.log, model=model, metadata=meta, model_source=str(model_path)) as log:
        for plan, (cert, _) in zip(plans, results):
            log.write_window(max(float(plan.times[0]), 0.0), plan, cert)


__all__ = ["add_parser", "run", "load_plan_arrays", "build_plan", "certify_task", "resolve_model_path",
           "MAX_PLANS", "MAX_WAYPOINTS_PER_PLAN", "MAX_WAYPOINTS_TOTAL", "MAX_NPZ_DATA_BYTES"]
