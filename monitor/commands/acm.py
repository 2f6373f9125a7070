"""``python -m monitor acm MODEL [--samples N] [--keyframe K] -o acm.json``: allowed-contact matrix.

Computes the allowed-contact matrix of a model (:mod:`monitor.acm`): every
candidate pair gets a reason when it has one

  Adjacent  parent-child bodies or bodies welded together
  Default   in contact in the reference pose (keyframe K if the model has it, else qpos0)
  Always    in contact in every sampled configuration (sampling result: review it)
  Never     in contact in no sample (a speed hint only: these pairs are still checked)

and writes a human-readable, diffable JSON file (one pair per line; unnamed geoms
as ``body/index``) that ``Scene.from_model(..., allowed=FILE)``, ``Gate`` and
``SafetyGate`` accept. Edit it by hand to add ``"User"`` entries.

MODEL is an MJCF path, the name of a shipped scene (``arm``, ``tunnel``,
``agv_trays``) or a Gymnasium env id (``Pusher-v5``: its model).

Exit codes: 0 written; 2 bad input.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any


def add_parser(p: argparse.ArgumentParser) -> None:
    """Options of the ``acm`` subcommand."""
    p.description = __doc__
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument("model", metavar="MODEL", help="MJCF path, shipped scene name or Gymnasium env id")
    p.add_argument("--samples", type=int, default=None,
                   help="random configurations for Always/Never (default 200)")
    p.add_argument("--keyframe", type=int, default=0, help="keyframe used as reference pose (default 0)")
    p.add_argument("--seed", type=int, default=0, help="RNG seed (default 0)")
    p.add_argument("--pairs", choices=("mujoco", "all"), default="mujoco",
                   help="pair universe: MuJoCo's contact filter (default) or every pair of bodies")
    p.add_argument("-o", "--output", metavar="acm.json", default=None,
                   help="output file (default: print to stdout)")
    p.add_argument("--no-progress", dest="progress", action="store_false", default=True,
                   help="do not report sampling progress on stderr")


def load_model(spec: str) -> tuple[Any, str]:
    """(MjModel, description) from an MJCF path, a shipped scene name or a Gymnasium env id.

    Raises:
        InvalidInputError: none of these.
    """
    import mujoco

    from monitor._paths import scene_path
    from monitor.errors import InvalidInputError

    p = Path(spec)
    if p.is_file():
        try:
            return mujoco.MjModel.from_xml_path(str(p)), str(p)
        except ValueError as exc:
            raise InvalidInputError(f"MODEL {spec!r} does not load: {exc}") from exc
    try:
        path = scene_path(spec)
        return mujoco.MjModel.from_xml_path(str(path)), str(path)
    except (FileNotFoundError, OSError):
        pass
    if "-v" in spec:
        import warnings

        import gymnasium as gym

        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                env = gym.make(spec)
        except Exception as exc:  # noqa: BLE001 - any registry/construct failure is bad input
            raise InvalidInputError(f"MODEL {spec!r}: not a file, shipped scene or loadable env id ({exc})") \
                from exc
        model = getattr(env.unwrapped, "model", None)
        if isinstance(model, mujoco.MjModel):
            return model, f"{spec} ({getattr(env.unwrapped, 'fullpath', 'env')})"
        raise InvalidInputError(f"MODEL {spec!r}: the env has no MuJoCo model")
    raise InvalidInputError(f"MODEL {spec!r}: no such file, shipped scene (models/<name>/scene.xml) "
                            "or env id")


def reset_qpos(spec: str) -> Any:
    """The qpos after ``env.reset(seed=0)`` when ``spec`` is a Gymnasium env id, else None.

    That is the reference pose a :class:`monitor.SafetyGate` uses for its default ACM.
    """
    import warnings

    from monitor._paths import scene_path

    if Path(spec).is_file() or "-v" not in spec:
        return None
    try:
        scene_path(spec)
        return None
    except (FileNotFoundError, OSError):
        pass
    import gymnasium as gym
    import numpy as np

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = gym.make(spec)
        env.reset(seed=0)
    return np.array(env.unwrapped.data.qpos)


def run(args: argparse.Namespace) -> int:
    """Compute and write the ACM; returns the exit code."""
    from monitor.acm import DEFAULT_SAMPLES, compute_acm
    from monitor.errors import MonitorError
    from monitor.pairsel import ModelNames

    samples = DEFAULT_SAMPLES if args.samples is None else args.samples
    last = [0.0]

    def progress(done: int, total: int) -> None:
        now = time.monotonic()
        if args.progress and (now - last[0] > 0.5 or done == total):
            last[0] = now
            print(f"\rsampling {samples} configurations: pair {done}/{total}",
                  end="\n" if done == total else "", file=sys.stderr, flush=True)

    try:
        model, desc = load_model(args.model)
        acm = compute_acm(model, pairs=args.pairs, samples=samples, keyframe=args.keyframe, seed=args.seed,
                          progress=progress)
    except MonitorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    names = ModelNames.from_model(model)
    text = acm.dumps(names)
    counts: dict[str, int] = {}
    for r in acm.entries.values():
        counts[r.value] = counts.get(r.value, 0) + 1
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items())) or "no entries"
    if args.output:
        try:
            Path(args.output).write_text(text, encoding="utf-8")
        except OSError as exc:
            print(f"error: cannot write {args.output!r}: {exc}", file=sys.stderr)
            return 2
        print(f"{desc}: {summary}; written to {args.output}")
    else:
        sys.stdout.write(text)
        print(f"{desc}: {summary}", file=sys.stderr)
    return 0
