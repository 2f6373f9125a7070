"""Many gated rollouts, on local processes or Ray, summarised in one table.

:func:`rollouts` runs ``episodes`` independent gated episodes of ``steps`` steps
each and returns a :class:`RolloutSummary` (per episode: the counts of
certified, violation, uncertain and blocked windows, and the certify time),
writing one MCAP log per episode.

What is rolled out (``model_or_env_id``):

* a ``mujoco.MjModel``, an MJCF path, or the name of a shipped scene (``"arm"``,
  ``"tunnel"``): plain MuJoCo. Each episode resets an ``MjData`` (to keyframe 0
  when the model has one) and calls :meth:`monitor.Gate.step` with the policy's
  control ``steps`` times. The policy is called as ``policy(data, rng)`` with the
  live ``MjData`` (read it, do not write it) and returns a (nu,) control.
* a registered gymnasium env id (``"monitor/Arm-v0"``, ``"Pusher-v5"``): the env
  is wrapped in :class:`monitor.SafetyGate`, reset with the episode's seed, and
  stepped until ``steps`` steps, termination or truncation. The policy is called
  as ``policy(obs, rng)`` and returns an action.

Policies must be picklable (a module-level function, or an instance of a
module-level class; not a lambda or a closure), because each episode is sent
to a worker process or a Ray task; this is checked up front on every backend.
With ``backend="local", workers>1`` the worker processes are spawned and
re-import the main script: guard a script's top level with
``if __name__ == "__main__":``.
Each episode gets a fresh copy of the policy; a policy with a
``reset(source, seed)`` method has it called at the start of the episode with
the ``MjModel`` (plain MuJoCo) or the gymnasium env. :class:`RandomPolicy` is a
ready-made one. ``rng`` is ``numpy.random.default_rng(seed)`` of the episode.

Determinism: an episode is a function of (model or env, policy, seed,
``gate_kwargs``, steps) only, so the same seeds give the same verdicts on every
backend and worker count (tested: local 1/2 workers and Ray). Exception: a
time budget (``gate_kwargs={"budget": seconds}``) makes verdicts depend on the
machine's load (a test budget, ``budget=<int>``, does not).

Seeds: an int ``s`` gives episodes the seeds ``s, s+1, ...``; a sequence gives
one seed per episode.
"""

from __future__ import annotations

import copy
import hashlib
import math
import os
import pickle
import sys
import time
import types
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from monitor.certify.types import Verdict
from monitor.errors import InvalidInputError

VERDICTS = tuple(Verdict)


# --------------------------------------------------------------------------- policies
class RandomPolicy:
    """Random targets held for ``hold`` steps (picklable; for plain models and Box envs).

    The target is drawn uniformly from the control range of limited actuators
    (``[-1, 1]`` for unlimited ones) or from the env's Box action space.

    Args:
        hold: steps each random target is held.
    """

    def __init__(self, hold: int = 20) -> None:
        if int(hold) < 1:
            raise InvalidInputError(f"hold must be >= 1, got {hold!r}")
        self.hold = int(hold)
        self.low: np.ndarray | None = None
        self.high: np.ndarray | None = None
        self.k = 0
        self.target: np.ndarray | None = None

    def reset(self, source: Any, seed: int) -> None:
        """Take the bounds from the model (``actuator_ctrlrange``) or the env's action space."""
        import mujoco

        self.k, self.target = 0, None
        if isinstance(source, mujoco.MjModel):
            limited = source.actuator_ctrllimited.astype(bool)
            self.low = np.where(limited, source.actuator_ctrlrange[:, 0], -1.0)
            self.high = np.where(limited, source.actuator_ctrlrange[:, 1], 1.0)
        else:
            space = source.action_space
            self.low = np.asarray(space.low, np.float64)
            self.high = np.asarray(space.high, np.float64)

    def __call__(self, observation: Any, rng: np.random.Generator) -> np.ndarray:
        """The current target ((nu,) control or action)."""
        if self.low is None:
            raise InvalidInputError("RandomPolicy.reset(source, seed) must be called before use")
        if self.k % self.hold == 0 or self.target is None:
            self.target = rng.uniform(self.low, self.high)
        self.k += 1
        return self.target.copy()


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class EpisodeResult:
    """One gated episode.

    Attributes:
        episode: index in the batch.
        seed: the episode's seed.
        steps: steps (windows) run; fewer than asked when the episode ended early.
        certified: windows whose proposed motion was certified.
        violation: windows with a confirmed violation.
        uncertain: windows neither certified nor confirmed.
        blocked: proposed controls replaced by the fallback (``on_violation="block"``/``"terminate"``).
        fallback_uncertified: replacements whose own window did not certify.
        terminated: True when the episode ended before ``steps`` (gate ``"terminate"`` or the env).
        certify_s: wall time (s) spent certifying (proposals, brake tails, fallbacks).
        wall_s: wall time (s) of the whole episode.
        verdict_digest: sha256 (16 hex digits) of the sequence of verdicts: equal digests
            mean the same verdict at every step.
        log: the episode's MCAP log, or None.
    """

    episode: int
    seed: int
    steps: int
    certified: int
    violation: int
    uncertain: int
    blocked: int
    fallback_uncertified: int
    terminated: bool
    certify_s: float
    wall_s: float
    verdict_digest: str
    log: str | None = None

    @property
    def mean_certify_us(self) -> float:
        """Mean certify time per window (µs)."""
        return self.certify_s * 1e6 / self.steps if self.steps else 0.0

    def counts(self) -> tuple[int, int, int, int]:
        """(certified, violation, uncertain, blocked): the deterministic part of the result."""
        return (self.certified, self.violation, self.uncertain, self.blocked)


@dataclass(frozen=True)
class RolloutSummary:
    """Per-episode table of a batch of gated rollouts.

    Attributes:
        episodes: one :class:`EpisodeResult` per episode, in episode order.
        source: what was rolled out (scene path, model or env id).
        backend: ``"local"`` or ``"ray"``.
        workers: worker processes / Ray tasks in flight (None: Ray's choice).
        wall_s: wall time (s) of the batch, including starting workers (not Ray itself).
        log_dir: folder of the logs, or None.
    """

    episodes: tuple[EpisodeResult, ...]
    source: str
    backend: str
    workers: int | None
    wall_s: float
    log_dir: str | None = None

    def totals(self) -> dict[str, Any]:
        """Sums over episodes (and the mean certify µs per window)."""
        keys = ("steps", "certified", "violation", "uncertain", "blocked", "fallback_uncertified")
        out: dict[str, Any] = {k: int(sum(getattr(e, k) for e in self.episodes)) for k in keys}
        out["certify_s"] = float(sum(e.certify_s for e in self.episodes))
        out["mean_certify_us"] = out["certify_s"] * 1e6 / out["steps"] if out["steps"] else 0.0
        out["episodes"] = len(self.episodes)
        return out

    @property
    def episodes_per_minute(self) -> float:
        """Throughput of the batch (episodes per minute of wall time)."""
        return 60.0 * len(self.episodes) / self.wall_s if self.wall_s > 0 else math.inf

    def counts(self) -> list[tuple[int, int, int, int]]:
        """Per episode (certified, violation, uncertain, blocked)."""
        return [e.counts() for e in self.episodes]

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form: ``episodes`` (list of row dicts), ``totals`` and run info."""
        rows = []
        for e in self.episodes:
            d = asdict(e)
            d["mean_certify_us"] = e.mean_certify_us
            rows.append(d)
        return {"source": self.source, "backend": self.backend, "workers": self.workers,
                "wall_s": self.wall_s, "episodes_per_minute": self.episodes_per_minute,
                "log_dir": self.log_dir, "episodes": rows, "totals": self.totals()}

    def __str__(self) -> str:
        head = (f"{'episode':>7} {'seed':>6} {'steps':>6} {'certified':>9} {'violation':>9} {'uncertain':>9} "
                f"{'blocked':>7} {'certify s':>9} {'us/window':>10}")
        lines = [f"gated rollouts of {self.source}: {len(self.episodes)} episode(s), backend {self.backend}, "
                 f"workers {self.workers if self.workers is not None else 'auto'}, {self.wall_s:.1f} s "
                 f"({self.episodes_per_minute:.1f} episodes/min)", head]
        for e in self.episodes:
            lines.append(f"{e.episode:>7} {e.seed:>6} {e.steps:>6} {e.certified:>9} {e.violation:>9} "
                         f"{e.uncertain:>9} {e.blocked:>7} {e.certify_s:>9.2f} {e.mean_certify_us:>10.0f}")
        t = self.totals()
        lines.append(f"{'total':>7} {'':>6} {t['steps']:>6} {t['certified']:>9} {t['violation']:>9} "
                     f"{t['uncertain']:>9} {t['blocked']:>7} {t['certify_s']:>9.2f} "
                     f"{t['mean_certify_us']:>10.0f}")
        if self.log_dir:
            lines.append(f"logs: {self.log_dir}/episode-*.mcap")
        return "\n".join(lines)


# --------------------------------------------------------------------------- sources
def _resolve_source(source: Any) -> tuple[str, Any, str]:
    """(kind "model" | "env", what a worker needs, display name)."""
    import mujoco

    if isinstance(source, mujoco.MjModel):
        return "model", source, "MjModel"
    if not isinstance(source, (str, os.PathLike)):
        raise InvalidInputError(f"model_or_env_id must be an MjModel, an MJCF path, a shipped scene name or "
                                f"a gymnasium env id; got {type(source).__name__}")
    s = str(source)
    p = Path(s)
    if p.is_file():
        return "model", str(p.resolve()), s
    from monitor._paths import models_dir

    scene = models_dir() / s / "scene.xml"
    if "/" not in s and "\\" not in s and scene.is_file():
        return "model", str(scene), s
    if _is_env_id(s):
        return "env", s, s
    raise InvalidInputError(f"{s!r} is neither an MJCF file, a shipped scene (models/<name>/scene.xml) "
                            f"nor a registered gymnasium env id")


def _register_envs(env_id: str) -> None:
    if env_id.startswith("monitor/"):
        import monitor.envs  # noqa: F401  (registers monitor/*)


def _is_env_id(s: str) -> bool:
    try:
        import gymnasium
    except ImportError:
        return False
    try:
        _register_envs(s)
    except ImportError:
        return False
    return s in gymnasium.registry


def _load_model(ref: Any) -> Any:
    import mujoco

    if isinstance(ref, mujoco.MjModel):
        return ref
    if str(ref).endswith(".mjb"):
        return mujoco.MjModel.from_binary_path(str(ref))
    return mujoco.MjModel.from_xml_path(str(ref))


# --------------------------------------------------------------------------- one episode (worker)
def _digest(verdicts: list[str]) -> str:
    return hashlib.sha256(",".join(verdicts).encode()).hexdigest()[:16]


def run_episode(job: dict[str, Any]) -> EpisodeResult:
    """Run one gated episode (the task sent to workers; see :func:`rollouts`).

    Args:
        job: ``kind``, ``source``, ``policy``, ``steps``, ``seed``, ``episode``,
            ``log`` (path or None) and ``gate_kwargs``.

    Returns:
        the :class:`EpisodeResult`.
    """
    t_start = time.perf_counter()
    policy = copy.deepcopy(job["policy"])
    seed = int(job["seed"])
    rng = np.random.default_rng(seed)
    if job["kind"] == "model":
        verdicts, stats, ended = _model_episode(job, policy, rng, seed)
    else:
        verdicts, stats, ended = _env_episode(job, policy, rng, seed)
    return EpisodeResult(
        episode=int(job["episode"]), seed=seed, steps=len(verdicts), certified=stats["certified"],
        violation=stats["violation"], uncertain=stats["uncertain"], blocked=stats["replaced"],
        fallback_uncertified=stats["fallback_uncertified"], terminated=ended,
        certify_s=stats["certify_us"] * 1e-6, wall_s=time.perf_counter() - t_start,
        verdict_digest=_digest(verdicts), log=job["log"])


def _step_bar(job: dict[str, Any]) -> Any:
    """A tqdm bar (stderr) over the steps of one episode; None when off.

    ``job["step_progress"]``: False (off: pools and Ray, where bars of parallel
    episodes would overwrite each other), True (on) or None (on when stderr is a terminal).
    """
    flag = job.get("step_progress", False)
    if flag is False:
        return None
    from tqdm import tqdm

    return tqdm(total=int(job["steps"]), desc=f"episode {job['episode']} (seed {job['seed']})", unit="step",
                leave=False, file=sys.stderr, disable=None if flag is None else not flag)


def _model_episode(job: dict[str, Any], policy: Any, rng: np.random.Generator, seed: int
                   ) -> tuple[list[str], dict[str, Any], bool]:
    import mujoco

    from monitor.gate import Gate

    model = _load_model(job["source"])
    data = mujoco.MjData(model)
    if model.nkey > 0:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    else:
        mujoco.mj_resetData(model, data)
    mujoco.mj_forward(model, data)
    if callable(getattr(policy, "reset", None)):
        policy.reset(model, seed)
    kw = dict(job["gate_kwargs"])
    if isinstance(job["source"], str) and job["log"] is not None:
        kw.setdefault("log_options", {"model_source": job["source"]})
    verdicts: list[str] = []
    ended = False
    bar = _step_bar(job)
    try:
        with Gate(model, log=job["log"], **kw) as gate:
            for _ in range(int(job["steps"])):
                report = gate.step(data, policy(data, rng))
                verdicts.append(report.verdict)
                if bar is not None:
                    bar.update(1)
                if report.terminated:
                    ended = True
                    break
            stats = dict(gate.stats)
    finally:
        if bar is not None:
            bar.close()
    return verdicts, stats, ended


def _env_episode(job: dict[str, Any], policy: Any, rng: np.random.Generator, seed: int
                 ) -> tuple[list[str], dict[str, Any], bool]:
    import gymnasium

    from monitor.gym_gate import SafetyGate

    _register_envs(job["source"])
    env = SafetyGate(gymnasium.make(job["source"]), log=job["log"], **job["gate_kwargs"])
    verdicts: list[str] = []
    ended = False
    bar = _step_bar(job)
    try:
        obs, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        if callable(getattr(policy, "reset", None)):
            policy.reset(env, seed)
        for _ in range(int(job["steps"])):
            obs, _, terminated, truncated, info = env.step(policy(obs, rng))
            verdicts.append(str(info["safety"]["verdict"]))
            if bar is not None:
                bar.update(1)
            if terminated or truncated:
                ended = True
                break
        stats = dict(env.gate.stats)
    finally:
        if bar is not None:
            bar.close()
        env.close()
    return verdicts, stats, ended


# --------------------------------------------------------------------------- batch
def _seeds(seeds: int | Sequence[int], episodes: int) -> list[int]:
    if isinstance(seeds, (int, np.integer)) and not isinstance(seeds, bool):
        return [int(seeds) + i for i in range(episodes)]
    try:
        out = [int(s) for s in seeds]
    except TypeError as exc:
        raise InvalidInputError(f"seeds must be an int or a sequence of {episodes} ints, "
                                f"got {seeds!r}") from exc
    if len(out) != episodes:
        raise InvalidInputError(f"seeds has {len(out)} entries, expected one per episode ({episodes})")
    return out


def _default_log_dir() -> Path:
    return Path("logs") / time.strftime("rollouts-%Y%m%dT%H%M%SZ", time.gmtime())


def rollouts(model_or_env_id: Any, policy: Callable[[Any, np.random.Generator], Any] | None = None, *,
             episodes: int, steps: int, seeds: int | Sequence[int] = 0, workers: int | None = 1,
             backend: str = "local", log_dir: str | os.PathLike[str] | None | bool = True,
             gate_kwargs: dict[str, Any] | None = None, progress: bool | None = None) -> RolloutSummary:
    """Run many gated rollouts and summarise them (see the module docstring).

    Args:
        model_or_env_id: ``MjModel``, MJCF path, shipped scene name, or gymnasium env id.
        policy: picklable ``policy(data_or_obs, rng) -> control``; None = :class:`RandomPolicy`.
        episodes: number of episodes (>= 1).
        steps: gated steps per episode (>= 1).
        seeds: first seed (int) or one seed per episode.
        workers: local processes (1 = this process) or Ray tasks in flight
            (None: all at once, Ray's CPU count).
        backend: ``"local"`` (spawned processes) or ``"ray"`` (Ray tasks; an existing
            ``ray.init(address=...)`` is used, else a local instance is started).
        log_dir: folder for one MCAP log per episode (``episode-<i>-seed<s>.mcap``);
            True (default) = ``logs/rollouts-<UTC stamp>/``; None or False = no logs.
            On a multi-node Ray cluster this must be shared storage.
        gate_kwargs: keyword arguments for :class:`monitor.Gate` (plain MuJoCo) or
            :class:`monitor.SafetyGate` (env ids), e.g. ``{"margin": 0.005, "frame_skip": 10}``.
        progress: progress bar over episodes, and over the steps of each episode when they run
            one at a time in this process (backend "local", workers=1); None: on a terminal.

    Returns:
        the :class:`RolloutSummary`.

    Raises:
        InvalidInputError: bad counts, seeds, backend, source or an unpicklable policy.
        DependencyNotInstalled: ``backend="ray"`` without Ray (``pip install "monitor[ray]"``).
    """
    from monitor.distributed import _check_backend, run_tasks

    _check_backend(backend, workers)
    for name, v in (("episodes", episodes), ("steps", steps)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise InvalidInputError(f"{name} must be an integer >= 1, got {v!r}")
    seed_list = _seeds(seeds, int(episodes))
    kind, ref, name = _resolve_source(model_or_env_id)
    if policy is None:
        policy = RandomPolicy()
    if not callable(policy):
        raise InvalidInputError(f"policy must be callable, got {type(policy).__name__}")
    try:
        pickle.dumps(policy)
    except Exception as exc:  # noqa: BLE001 - any pickling failure means the same thing
        raise InvalidInputError(
            f"policy {policy!r} is not picklable ({type(exc).__name__}: {exc}); rollouts send it to worker "
            "processes: use a module-level function or an instance of a module-level class") from exc
    gate_kwargs = dict(gate_kwargs or {})
    if "log" in gate_kwargs:
        raise InvalidInputError("gate_kwargs must not contain 'log': rollouts writes one log per episode "
                                "(use log_dir)")
    if log_dir is True:
        log_dir = _default_log_dir()
    elif log_dir is False:
        log_dir = None
    if log_dir is not None:
        log_dir = Path(log_dir).resolve()
        log_dir.mkdir(parents=True, exist_ok=True)
    # a step bar inside the episode only when episodes run one at a time in this process
    step_progress = progress if backend == "local" and (workers or 1) == 1 else False
    jobs = [{"kind": kind, "source": ref, "policy": policy, "steps": int(steps), "seed": s, "episode": i,
             "gate_kwargs": gate_kwargs, "step_progress": step_progress,
             "log": None if log_dir is None else str(log_dir / f"episode-{i:04d}-seed{s}.mcap")}
            for i, s in enumerate(seed_list)]
    if backend == "ray":
        from monitor.distributed import ensure_ray

        ensure_ray(workers)  # started outside the timed part
    t0 = time.perf_counter()
    results = run_tasks(run_episode, jobs, backend=backend, workers=workers, desc="gated rollouts",
                        progress=progress)
    wall = time.perf_counter() - t0
    return RolloutSummary(tuple(results), name, backend, workers, wall,
                          None if log_dir is None else str(log_dir))


# --------------------------------------------------------------------------- benchmark
def bench_rollouts(model_or_env_id: Any = "tunnel", policy: Any = None, *, episodes: int = 4,
                   steps: int = 100, seeds: int | Sequence[int] = 0,
                   configs: Sequence[tuple[str, int | None]] = (("local", 1), ("local", 2), ("ray", 2)),
                   repeat: int = 2, gate_kwargs: dict[str, Any] | None = None, log: bool = False,
                   progress: bool | None = False) -> list[dict[str, Any]]:
    """Episodes per minute of the same batch on several backends (for ``monitor/bench``).

    First one short episode runs in this process (numba compiles or loads its
    cache, so no configuration pays the compilation). Then every configuration
    runs the same seeded batch ``repeat`` times: the first run is *cold* (a local
    pool spawns its processes, which import MuJoCo and load the numba cache; Ray
    workers do the same on their first task), later runs are *warm* for Ray and
    for ``workers=1`` (both keep their processes) but not for a local pool, which
    is started anew by every :func:`rollouts` call. ``ray.init`` is not timed
    (reported as ``ray_init_s``, paid once per session). Each row also says
    whether the per-episode verdict counts and digests equal those of the first
    configuration's first run.

    Args:
        model_or_env_id, policy, episodes, steps, seeds, gate_kwargs: as for :func:`rollouts`.
        configs: (backend, workers) pairs; a Ray config is skipped (row with
            ``skipped`` set) when Ray is not installed.
        repeat: runs per configuration (>= 1).
        log: write logs (to a temporary folder, deleted afterwards).
        progress: progress bars.

    Returns:
        one dict per config: backend, workers, episodes, steps, windows, runs_s (wall s
        of every run), wall_s (cold, first run), warm_wall_s (best later run, or None),
        episodes_per_min and windows_per_s (cold), warm_episodes_per_min (or None),
        identical (bool, every run), ray_init_s (Ray rows), skipped (str, only when
        skipped), cpus (``os.cpu_count()``), load_avg (1-min load average before the row).
    """
    import tempfile

    from monitor.errors import DependencyNotInstalled

    if int(repeat) < 1:
        raise InvalidInputError(f"repeat must be >= 1, got {repeat!r}")
    rollouts(model_or_env_id, policy, episodes=1, steps=2, seeds=seeds if isinstance(seeds, int) else 0,
             gate_kwargs=gate_kwargs, log_dir=None, progress=False)  # warm-up: numba compile / cache
    rows: list[dict[str, Any]] = []
    ref_counts = None
    with tempfile.TemporaryDirectory(prefix="monitor-bench-rollouts-") as tmp:
        for k, (backend, workers) in enumerate(configs):
            row: dict[str, Any] = {"backend": backend, "workers": workers, "episodes": episodes,
                                   "steps": steps, "cpus": os.cpu_count(),
                                   "load_avg": os.getloadavg()[0] if hasattr(os, "getloadavg") else None}
            if backend == "ray":
                from monitor.distributed import ensure_ray

                try:
                    ray_mod = __import__("ray")
                    already = ray_mod.is_initialized()
                    t0 = time.perf_counter()
                    ensure_ray(workers)
                    row["ray_init_s"] = 0.0 if already else time.perf_counter() - t0
                except (ImportError, DependencyNotInstalled) as exc:
                    row["skipped"] = f"ray not installed ({exc})"
                    rows.append(row)
                    continue
            runs, identical = [], True
            for r in range(int(repeat)):
                summary = rollouts(model_or_env_id, policy, episodes=episodes, steps=steps, seeds=seeds,
                                   workers=workers, backend=backend, gate_kwargs=gate_kwargs,
                                   log_dir=Path(tmp) / f"cfg{k}-{r}" if log else None, progress=progress)
                got = [(e.counts(), e.verdict_digest) for e in summary.episodes]
                if ref_counts is None:
                    ref_counts = got
                identical = identical and got == ref_counts
                runs.append(summary.wall_s)
            windows = summary.totals()["steps"]
            warm = min(runs[1:]) if len(runs) > 1 else None
            row.update(windows=windows, runs_s=runs, wall_s=runs[0], warm_wall_s=warm,
                       episodes_per_min=60.0 * episodes / runs[0],
                       windows_per_s=windows / runs[0],
                       warm_episodes_per_min=None if warm is None else 60.0 * episodes / warm,
                       identical=identical)
            rows.append(row)
    return rows


def format_bench(rows: Sequence[dict[str, Any]]) -> str:
    """Markdown table of :func:`bench_rollouts` rows."""
    out = ["| backend | workers | episodes x steps | cold wall s | cold episodes/min | warm wall s "
           "| warm episodes/min | same verdicts | load avg |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("skipped"):
            out.append(f"| {r['backend']} | {r['workers']} | - | - | - | - | - | "
                       f"skipped: {r['skipped']} | - |")
            continue
        warm = "-" if r["warm_wall_s"] is None else f"{r['warm_wall_s']:.1f}"
        warm_epm = "-" if r["warm_episodes_per_min"] is None else f"{r['warm_episodes_per_min']:.1f}"
        load = "-" if r.get("load_avg") is None else f"{r['load_avg']:.1f}"
        out.append(f"| {r['backend']} | {r['workers']} | {r['episodes']} x {r['steps']} | "
                   f"{r['wall_s']:.1f} | {r['episodes_per_min']:.1f} | {warm} | {warm_epm} | "
                   f"{r['identical']} | {load} |")
    return "\n".join(out)


class _CallableModule(types.ModuleType):
    """Module type forwarding calls to :func:`rollouts`.

    ``monitor.rollouts`` is both this module and the public function: importing
    the module (``from monitor.rollouts import RandomPolicy``) rebinds the package
    attribute ``monitor.rollouts`` to the module, which must stay callable.
    """

    def __call__(self, *args: Any, **kwargs: Any) -> RolloutSummary:
        return rollouts(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

__all__ = ["rollouts", "RolloutSummary", "EpisodeResult", "RandomPolicy", "run_episode", "bench_rollouts",
           "format_bench"]
