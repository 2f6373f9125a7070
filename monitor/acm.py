"""Allowed-contact matrix (ACM): geom pairs whose contact belongs to the task.

Modelled on MoveIt's allowed collision matrix (SRDF ``disable_collisions`` and
the Setup Assistant's ``compute_default_collisions``). Every entry is a geom
pair with a :class:`Reason`:

=========  ==========================================================================
Adjacent   parent-child bodies (weld groups; neither the world, the child attached
           without a free joint), or two geoms welded together (same weld group)
Default    in resting contact (static distance <= the pair's MuJoCo contact margin, max of the
           two ``geom_margin``, + ``contact_tol``, and no deeper than ``RESTING_MAX_DEPTH``) in the
           reference pose
           (keyframe K when the model has it, else ``qpos0``: a model's ``qpos0`` may
           put a body inside an obstacle, e.g. ``models/tunnel``; its keyframe does
           not) or at any step while the model settles from it for ``settle`` seconds
           of passive simulation (zero control): resting objects, feet on the floor
Always     in contact in every sampled configuration (a sampling result)
Never      in contact in no sampled configuration (a sampling result)
User       given by the user (``allow=`` patterns or an edited file)
=========  ==========================================================================

An allowed pair (every reason except ``Never``) is never certified or gated; the
certificate lists it with its reason (``Certificate.allowed``) so that a reviewer
can audit what was not checked. ``Never`` is a sampling heuristic, not a proof:
it is recorded (a speed hint) and never removes a pair. ``Always`` is a sampling
heuristic too (as in MoveIt); review the file before relying on it.

Sampling (:func:`compute_acm`): ``samples`` configurations from a seeded RNG;
limited hinge/slide joints uniform in their range, unlimited hinges uniform in
[-pi, pi], unlimited slides ``qpos0 +- 1 m``, free joints at ``qpos0 +- 1 m`` with
a uniform random orientation, ball joints uniform random orientation (within the
cone angle when limited); mocap bodies stay at their model pose. Distances are
the exact static distances of :mod:`monitor.geometry.distance` (batched).

File format (JSON, one pair per line, sorted, so that it diffs well)::

    {
      "format": "monitor-acm",
      "version": 1,
      "model_hash": "<sha256 of the compiled model, or null>",
      "generated": {"pairs": "mujoco", "samples": 200, "seed": 0, "keyframe": 0,
                    "contact_tol": 0.0001},
      "entries": [
        {"geoms": ["object/0", "table"], "reason": "Default"},
        {"geoms": ["link0", "root"], "reason": "Adjacent"}
      ]
    }

``geoms`` are geom names; an unnamed geom is written as its ``body/index``
address (see :mod:`monitor.pairsel`), and ``"geom<id>"`` is accepted on input.
Within a pair the two names are sorted; entries are sorted by (reason, names).
A file loads back into the same pair set (:meth:`ACM.load`). Entries naming
geoms the model does not have raise :class:`~monitor.errors.ModelMismatchError`;
a different ``model_hash`` only logs a warning (names still resolve).
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import Any

import numpy as np

from monitor.errors import InvalidInputError, ModelMismatchError
from monitor.pairsel import ModelNames, pair_mask

_LOG = logging.getLogger("monitor.acm")

FORMAT = "monitor-acm"
VERSION = 1
DEFAULT_SAMPLES = 200
"""Samples of ``python -m monitor acm`` (MoveIt's Setup Assistant uses 10 000 by default)."""
AUTO_SAMPLES = 32
"""Samples of the ACM a gate computes at construction (``allowed="auto"``)."""
CONTACT_TOL = 1e-4
"""Metres: a pair whose exact static distance is at most its MuJoCo contact margin (max of
the two ``geom_margin``; Ant's feet rest 2 cm above the floor because of it) plus this counts
as "in contact" for Default / Always (an upper bound must be below it) and Never (the lower
bound must stay above it). 0.1 mm covers float noise."""
RESTING_MAX_DEPTH = 5e-3
"""Metres: a pair counts as a resting (Default) contact only if its exact static distance is
also provably no deeper than this (lower bound >= -RESTING_MAX_DEPTH). Resting contacts under
MuJoCo's soft contacts penetrate by a fraction of a millimetre to a few millimetres; a deeper
overlap in the reference pose (e.g. a randomised reset that places a body inside a wall) is a
hazard state, not a contact that belongs to the task, and stays checked."""
SETTLE = 0.5
"""Seconds of passive simulation (zero control) from the reference pose whose contacts are
Default: the model's resting contacts (Ant's and Walker's feet on the floor, Pusher's object on
the table). MuJoCo's contact list only proposes pairs; each is confirmed with the exact static
distance at that state."""
_UNLIMITED_SLIDE = 1.0  # m around qpos0 for unlimited slide / free-joint positions


class Reason(StrEnum):
    """Why a pair is in the ACM (MoveIt's reasons)."""

    ADJACENT = "Adjacent"
    DEFAULT = "Default"
    ALWAYS = "Always"
    NEVER = "Never"
    USER = "User"

    @property
    def skips(self) -> bool:
        """True when the pair is not checked (every reason except Never)."""
        return self is not Reason.NEVER


_ORDER = {r: k for k, r in enumerate(Reason)}


def _key(a: str, b: str) -> tuple[str, str]:
    return (a, b) if a <= b else (b, a)


def _reason(x: Any, where: str) -> Reason:
    if isinstance(x, Reason):
        return x
    for r in Reason:
        if isinstance(x, str) and x.lower() == r.value.lower():
            return r
    raise InvalidInputError(f"{where}: unknown reason {x!r}; expected one of "
                            + ", ".join(r.value for r in Reason))


@dataclass(frozen=True)
class ACM:
    """An allowed-contact matrix: {(geom_a, geom_b): Reason}.

    Attributes:
        entries: {(name_a, name_b) sorted: :class:`Reason`}; names are geom names as in
            :class:`monitor.Scene` (``"geom<id>"`` for unnamed geoms).
        model_hash: sha256 of the model it was computed for, or None (hand-written).
        generated: how it was computed (pairs mode, samples, seed, keyframe, contact_tol).
    """

    entries: dict[tuple[str, str], Reason] = field(default_factory=dict)
    model_hash: str | None = None
    generated: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def from_pairs(cls, pairs: Iterable[Any], reason: Reason | str = Reason.USER) -> ACM:
        """ACM from ``[(a, b), ...]`` or ``[(a, b, reason), ...]`` (default reason User)."""
        out: dict[tuple[str, str], Reason] = {}
        for k, p in enumerate(pairs):
            if isinstance(p, str) or not hasattr(p, "__len__") or len(p) not in (2, 3):
                raise InvalidInputError(f"allowed[{k}] must be (geom_a, geom_b) or (geom_a, geom_b, reason), "
                                        f"got {p!r}")
            if not all(isinstance(x, str) for x in p[:2]):
                raise InvalidInputError(f"allowed[{k}]: geoms must be names, got {p!r}")
            r = _reason(p[2] if len(p) == 3 else reason, f"allowed[{k}]")
            out[_key(p[0], p[1])] = r
        return cls(out)

    def reason(self, a: str, b: str) -> Reason | None:
        """The pair's reason, or None when it is not in the matrix."""
        return self.entries.get(_key(a, b))

    def pairs(self, *reasons: Reason | str) -> set[tuple[str, str]]:
        """Pairs with one of ``reasons`` (all pairs when none given)."""
        want = {_reason(r, "reasons") for r in reasons} or set(Reason)
        return {k for k, r in self.entries.items() if r in want}

    @property
    def skipped(self) -> set[tuple[str, str]]:
        """Pairs that are not checked (every reason except Never)."""
        return {k for k, r in self.entries.items() if r.skips}

    def merged(self, other: ACM) -> ACM:
        """Union; on a conflict the earlier reason in Reason order wins (Adjacent first, User last)."""
        out = dict(self.entries)
        for k, r in other.entries.items():
            if k not in out or _ORDER[r] < _ORDER[out[k]]:
                out[k] = r
        return ACM(out, self.model_hash or other.model_hash, dict(self.generated))

    # ------------------------------------------------------------------ file format
    def to_dict(self, names: ModelNames | None = None) -> dict[str, Any]:
        """JSON form; with ``names``, unnamed geoms are written as ``body/index``."""
        def out(n: str) -> str:
            if names is not None and n.startswith("geom") and n[4:].isdigit():
                g = int(n[4:])
                if g < len(names.geom_names) and names.geom_names[g] == n:
                    return names.alias(g)
            return n
        rows = []
        for (a, b), r in self.entries.items():
            x, y = sorted((out(a), out(b)))
            rows.append((_ORDER[r], x, y, r))
        rows.sort()
        return {"format": FORMAT, "version": VERSION, "model_hash": self.model_hash,
                "generated": dict(self.generated),
                "entries": [{"geoms": [x, y], "reason": r.value} for _, x, y, r in rows]}

    def dumps(self, names: ModelNames | None = None) -> str:
        """Human-readable, diffable JSON text (one entry per line)."""
        d = self.to_dict(names)
        head = {k: v for k, v in d.items() if k != "entries"}
        lines = ["{"] + [f"  {json.dumps(k)}: {json.dumps(v, sort_keys=True)}," for k, v in head.items()]
        lines.append('  "entries": [')
        ent = [f"    {json.dumps(e)}" for e in d["entries"]]
        lines.append(",\n".join(ent))
        lines += ["  ]", "}"]
        return "\n".join(x for x in lines if x) + "\n"

    def save(self, path: str | Path, names: ModelNames | None = None) -> None:
        """Write :meth:`dumps` to ``path``."""
        Path(path).write_text(self.dumps(names), encoding="utf-8")

    @classmethod
    def from_dict(cls, d: Any, names: ModelNames | None = None) -> ACM:
        """Inverse of :meth:`to_dict`. With ``names``, ``body/index`` aliases become geom names.

        Raises:
            InvalidInputError: a malformed document (the message names the field).
            ModelMismatchError: with ``names``, an entry names a geom the model does not have.
        """
        if not isinstance(d, dict):
            raise InvalidInputError(f"ACM document must be a JSON object, got {type(d).__name__}")
        if d.get("format") != FORMAT:
            raise InvalidInputError(f"ACM field 'format' must be {FORMAT!r}, got {d.get('format')!r}")
        if d.get("version") != VERSION:
            raise InvalidInputError(f"ACM field 'version' must be {VERSION}, got {d.get('version')!r}")
        ents = d.get("entries")
        if not isinstance(ents, list):
            raise InvalidInputError("ACM field 'entries' must be a list")
        mh = d.get("model_hash")
        if mh is not None and not isinstance(mh, str):
            raise InvalidInputError("ACM field 'model_hash' must be a string or null")
        gen = d.get("generated", {})
        if not isinstance(gen, dict):
            raise InvalidInputError("ACM field 'generated' must be an object")
        lookup = _name_lookup(names) if names is not None else None
        out: dict[tuple[str, str], Reason] = {}
        for k, e in enumerate(ents):
            if not isinstance(e, dict) or not isinstance(e.get("geoms"), list) or len(e["geoms"]) != 2 \
                    or not all(isinstance(x, str) for x in e["geoms"]):
                raise InvalidInputError(
                    f"ACM entries[{k}] must be {{'geoms': [a, b], 'reason': R}}, got {e!r}")
            a, b = e["geoms"]
            if lookup is not None:
                miss = [x for x in (a, b) if x not in lookup]
                if miss:
                    avail = ", ".join(names.label(g) for g in range(len(names.geom_names)))
                    raise ModelMismatchError(f"ACM entries[{k}] names geom(s) {miss} that the model does not "
                                             f"have (available: {avail})")
                a, b = lookup[a], lookup[b]
            out[_key(a, b)] = _reason(e.get("reason"), f"ACM entries[{k}].reason")
        return cls(out, mh, dict(gen))

    @classmethod
    def load(cls, path: str | Path, names: ModelNames | None = None) -> ACM:
        """Read a file written by :meth:`save`.

        Raises:
            InvalidInputError: unreadable file, bad JSON or a malformed document.
        """
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as exc:
            raise InvalidInputError(f"cannot read ACM file {str(path)!r}: {exc}") from exc
        try:
            d = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InvalidInputError(f"ACM file {str(path)!r} is not valid JSON: {exc}") from exc
        return cls.from_dict(d, names)


def _name_lookup(names: ModelNames) -> dict[str, str]:
    """Every accepted spelling of a geom -> its Scene name (name, generated name, body/index)."""
    out = {}
    for g, n in enumerate(names.geom_names):
        out[n] = n
        out[f"geom{g}"] = n
        out[names.alias(g)] = n
    return out


# ---------------------------------------------------------------------- computation
def _random_qpos(model: Any, rng: np.random.Generator) -> np.ndarray:
    import mujoco

    q = np.array(model.qpos0, dtype=np.float64)
    for j in range(int(model.njnt)):
        t, a = int(model.jnt_type[j]), int(model.jnt_qposadr[j])
        lim = bool(model.jnt_limited[j])
        lo, hi = (float(x) for x in model.jnt_range[j])
        if t == int(mujoco.mjtJoint.mjJNT_FREE):
            q[a:a + 3] += rng.uniform(-_UNLIMITED_SLIDE, _UNLIMITED_SLIDE, 3)
            v = rng.normal(size=4)
            q[a + 3:a + 7] = v / np.linalg.norm(v)
        elif t == int(mujoco.mjtJoint.mjJNT_BALL):
            if lim and hi > 0:
                ax = rng.normal(size=3)
                ax /= np.linalg.norm(ax)
                ang = rng.uniform(0.0, hi)
                q[a:a + 4] = np.r_[math.cos(ang / 2), math.sin(ang / 2) * ax]
            else:
                v = rng.normal(size=4)
                q[a:a + 4] = v / np.linalg.norm(v)
        elif t == int(mujoco.mjtJoint.mjJNT_HINGE):
            q[a] = rng.uniform(lo, hi) if lim else rng.uniform(-math.pi, math.pi)
        else:  # slide
            q[a] = rng.uniform(lo, hi) if lim else q[a] + rng.uniform(-_UNLIMITED_SLIDE, _UNLIMITED_SLIDE)
    return q


def _poses(model: Any, qs: list[np.ndarray], key: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Body poses (S, nbody, 3) and (S, nbody, 3, 3) for each qpos (mocap at model/keyframe pose)."""
    import mujoco

    d = mujoco.MjData(model)
    if key is not None:
        mujoco.mj_resetDataKeyframe(model, d, key)
    pos = np.empty((len(qs), int(model.nbody), 3))
    rot = np.empty((len(qs), int(model.nbody), 3, 3))
    for s, q in enumerate(qs):
        d.qpos[:] = q
        mujoco.mj_kinematics(model, d)
        pos[s] = d.xpos
        rot[s] = d.xmat.reshape(-1, 3, 3)
    return pos, rot


def _pair_margin(model: Any, a: int, b: int) -> float:
    """MuJoCo's contact margin of a geom pair (m): contacts are active below it."""
    return float(max(model.geom_margin[a], model.geom_margin[b]))


def _settled_contacts(model: Any, geoms: Any, todo: list[tuple[int, int]], key: int | None,
                      qpos: np.ndarray, settle: float, contact_tol: float) -> set[tuple[int, int]]:
    """Pairs of ``todo`` in confirmed contact at some step of passive settling from ``qpos``."""
    import mujoco

    from monitor.geometry.distance import shape_distance

    want = set(todo)
    found: set[tuple[int, int]] = set()
    d = mujoco.MjData(model)
    if key is not None:
        mujoco.mj_resetDataKeyframe(model, d, key)
    d.qpos[:] = qpos
    d.ctrl[:] = 0.0
    nstep = int(math.ceil(settle / float(model.opt.timestep)))
    for _ in range(nstep):
        mujoco.mj_step(model, d)
        if not d.ncon:
            continue
        g1 = np.asarray(d.contact.geom1[:d.ncon])
        g2 = np.asarray(d.contact.geom2[:d.ncon])
        for a, b in zip(np.minimum(g1, g2).tolist(), np.maximum(g1, g2).tolist()):
            if (a, b) not in want or (a, b) in found:
                continue
            ga, gb = geoms[a], geoms[b]
            X_a = (d.xmat[ga.body_id].reshape(3, 3).copy(), d.xpos[ga.body_id].copy())
            X_b = (d.xmat[gb.body_id].reshape(3, 3).copy(), d.xpos[gb.body_id].copy())
            dist = shape_distance(ga.shape, X_a, gb.shape, X_b)
            if dist.upper <= contact_tol + _pair_margin(model, a, b) and dist.lower >= -RESTING_MAX_DEPTH:
                found.add((a, b))
    return found


def _adjacent(model: Any, ga: int, gb: int) -> bool:
    import mujoco

    weld = np.asarray(model.body_weldid)
    wa, wb = int(weld[model.geom_bodyid[ga]]), int(weld[model.geom_bodyid[gb]])
    if wa == wb:
        return True
    if wa == 0 or wb == 0:
        return False
    for parent, child in ((wa, wb), (wb, wa)):
        if int(weld[model.body_parentid[child]]) == parent:
            jnts = np.flatnonzero(np.asarray(model.jnt_bodyid) == child)
            if not any(int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_FREE) for j in jnts):
                return True
    return False


def compute_acm(model: Any, *, pairs: Any = "mujoco", samples: int = DEFAULT_SAMPLES,
                keyframe: int | None = 0, seed: int = 0, contact_tol: float = CONTACT_TOL,
                settle: float = SETTLE, reference: np.ndarray | None = None,
                progress: Callable[[int, int], None] | None = None) -> ACM:
    """Compute the ACM of ``model`` over the candidate pairs of ``pairs``.

    Args:
        model: ``mujoco.MjModel``.
        pairs: pair universe, as :meth:`monitor.Scene.from_model` (``"mujoco"``, ``"all"``, list).
        samples: random configurations for Always / Never (0: only Adjacent and Default).
        keyframe: keyframe index that is the reference pose for Default (qpos0 when the
            model has fewer keyframes or ``keyframe`` is None).
        seed: RNG seed (the result is deterministic given model, arguments and seed).
        contact_tol: metres; see :data:`CONTACT_TOL`.
        settle: seconds of passive settling whose contacts are Default (:data:`SETTLE`; 0: none).
        reference: optional (nq,) reference pose replacing keyframe / qpos0 (a gate uses the
            first state it sees: an env's reset state).
        progress: optional ``progress(done, total)`` called per sampled pair batch.

    Returns:
        the :class:`ACM` (entries for every reason found; pairs with none are checked).

    Raises:
        InvalidInputError: bad ``samples`` / ``keyframe`` / ``contact_tol``.
    """
    from monitor.geometry.distance import shape_distance_batch
    from monitor.scene import Scene

    if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 0:
        raise InvalidInputError(f"samples must be an integer >= 0, got {samples!r}")
    if keyframe is not None and (isinstance(keyframe, bool) or not isinstance(keyframe, int | np.integer)
                                 or keyframe < 0):
        raise InvalidInputError(f"keyframe must be an integer >= 0 or None, got {keyframe!r}")
    if not (isinstance(settle, int | float) and math.isfinite(settle) and 0 <= settle <= 60):
        raise InvalidInputError(f"settle must be a number of seconds in [0, 60], got {settle!r}")
    if not (isinstance(contact_tol, int | float) and math.isfinite(contact_tol) and contact_tol >= 0):
        raise InvalidInputError(f"contact_tol must be a finite number >= 0, got {contact_tol!r}")
    scene = Scene.from_model(model, pairs=pairs)
    geoms = scene.geoms
    entries: dict[tuple[str, str], Reason] = {}
    todo = []
    for a, b in scene.pair_ids.tolist():
        if _adjacent(model, a, b):
            entries[_key(geoms[a].name, geoms[b].name)] = Reason.ADJACENT
        else:
            todo.append((a, b))
    # Default: keyframe K when the model has it, else qpos0
    use_key = reference is None and keyframe is not None and int(keyframe) < int(model.nkey)
    if reference is not None:
        ref = np.asarray(reference, dtype=np.float64).reshape(-1)
        if ref.shape != (int(model.nq),) or not np.all(np.isfinite(ref)):
            raise InvalidInputError(f"reference must be a finite (nq,) = ({model.nq},) qpos")
        refs = [(None, ref.copy())]
    elif use_key:
        refs = [(int(keyframe), np.array(model.key_qpos[int(keyframe)], dtype=np.float64))]
    else:
        refs = [(None, np.array(model.qpos0, dtype=np.float64))]
    ref_poses = [_poses(model, [q], key) for key, q in refs]
    rest = []
    for a, b in todo:
        ga, gb = geoms[a], geoms[b]
        hit = False
        for pos, rot in ref_poses:
            lo, up = shape_distance_batch(ga.shape, (rot[:, ga.body_id], pos[:, ga.body_id]),
                                          gb.shape, (rot[:, gb.body_id], pos[:, gb.body_id]))
            hit |= bool(up[0] <= contact_tol + _pair_margin(model, a, b) and lo[0] >= -RESTING_MAX_DEPTH)
        if hit:
            entries[_key(ga.name, gb.name)] = Reason.DEFAULT
        else:
            rest.append((a, b))
    if settle > 0 and rest:
        settled = _settled_contacts(model, geoms, rest, refs[0][0], refs[0][1], settle, contact_tol)
        for a, b in settled:
            entries[_key(geoms[a].name, geoms[b].name)] = Reason.DEFAULT
        rest = [p for p in rest if p not in settled]
    if samples and rest:
        rng = np.random.default_rng(seed)
        pos, rot = _poses(model, [_random_qpos(model, rng) for _ in range(int(samples))])
        for k, (a, b) in enumerate(rest):
            ga, gb = geoms[a], geoms[b]
            lo, up = shape_distance_batch(ga.shape, (rot[:, ga.body_id], pos[:, ga.body_id]),
                                          gb.shape, (rot[:, gb.body_id], pos[:, gb.body_id]))
            thr = contact_tol + _pair_margin(model, a, b)
            if bool(np.all(up <= thr)):
                entries[_key(ga.name, gb.name)] = Reason.ALWAYS
            elif bool(np.all(lo > thr)):
                entries[_key(ga.name, gb.name)] = Reason.NEVER
            if progress is not None:
                progress(k + 1, len(rest))
    gen = {"pairs": pairs if isinstance(pairs, str) else "list", "samples": int(samples), "seed": int(seed),
           "keyframe": int(keyframe) if use_key else None, "contact_tol": float(contact_tol),
           "settle": float(settle), "reference": "given" if reference is not None else
           ("keyframe" if use_key else "qpos0")}
    return ACM(entries, scene.model_hash, gen)


_AUTO_CACHE: dict[tuple, ACM] = {}


def auto_acm(model: Any, pairs: Any = "mujoco", reference: np.ndarray | None = None) -> ACM:
    """The gate's default ACM, cached per model hash and pairs mode in-process.

    Adjacent + Default (``reference`` qpos, else keyframe 0, else qpos0, and its settled
    state) + Always/Never from :data:`AUTO_SAMPLES` seeded samples.
    """
    from monitor.scene import model_hash

    mode = pairs if isinstance(pairs, str) else repr(sorted(map(tuple, pairs)))
    ref = None if reference is None else np.asarray(reference, dtype=np.float64).copy()
    key = (model_hash(model), mode, None if ref is None else ref.tobytes())
    if key not in _AUTO_CACHE:
        _AUTO_CACHE[key] = compute_acm(model, pairs=pairs, samples=AUTO_SAMPLES, keyframe=0, seed=0,
                                       reference=ref)
    return _AUTO_CACHE[key]


# ---------------------------------------------------------------------- pair policy
def as_acm(allowed: Any, model: Any, pairs: Any = "mujoco", reference: np.ndarray | None = None
           ) -> ACM | None:
    """Normalise an ``allowed=`` argument to an :class:`ACM` validated against ``model`` (or None).

    Accepted: None, ``"auto"`` (:func:`auto_acm`), an :class:`ACM`, a file path (``Path``, or a
    ``str`` ending in ``.json``) or a list of pairs / (a, b, reason) triples (reason default User).
    """
    if allowed is None:
        return None
    names = ModelNames.from_model(model)
    if isinstance(allowed, ACM):
        return ACM.from_dict(allowed.to_dict(), names)  # validates names against the model
    if isinstance(allowed, str) and allowed == "auto":
        return auto_acm(model, pairs, reference)
    if isinstance(allowed, Path) or (isinstance(allowed, str) and allowed.endswith(".json")):
        acm = ACM.load(allowed, names)
        from monitor.scene import model_hash

        if acm.model_hash is not None and acm.model_hash != model_hash(model):
            _LOG.warning("ACM file %s was computed for a different model (hash %s...); its geom names "
                         "resolve, review it", allowed, acm.model_hash[:12])
        return acm
    if isinstance(allowed, str):
        raise InvalidInputError(f"allowed must be None, 'auto', an ACM, a .json path or a list of pairs, "
                                f"got {allowed!r}")
    acm = ACM.from_pairs(allowed)
    return ACM.from_dict(acm.to_dict(), names)


@dataclass(frozen=True)
class PairPolicy:
    """The resolved pair set: what is monitored and what is allowed (with reasons).

    Attributes:
        monitored: (P, 2) int64 geom id pairs that are checked.
        allowed: ((name_a, name_b, reason), ...) candidate pairs that are NOT checked.
        not_hazard: number of candidate pairs dropped because no ``hazards`` item selects them.
        never: ((name_a, name_b), ...) monitored pairs the ACM marks Never (speed hint only).
    """

    monitored: np.ndarray
    allowed: tuple[tuple[str, str, str], ...]
    not_hazard: int
    never: tuple[tuple[str, str], ...]
    acm: ACM | None = None
    """The resolved matrix (``"auto"`` computed once): a scene rebuilt after a model edit reuses
    it, so an in-place edit (domain randomisation) can never add allowed pairs."""


def _reason_codes(geom_names: Sequence[str], pair_ids: np.ndarray, acm: ACM | None) -> np.ndarray:
    """(P,) int64: per row of ``pair_ids``, ``list(Reason).index(acm.reason(name_a, name_b))`` or -1.

    -1 where the ACM has no entry for the row's two geom names (or there is no ACM).

    The ACM's entries (name pairs) are turned into geom id pairs once and the rows are found
    among them by binary search on ``a * G + b``: no Python per candidate pair. When two geoms
    share a name (a name pair then stands for several id pairs) the rows are looked up one by one.
    """
    P = len(pair_ids)
    out = np.full(P, -1, dtype=np.int64)
    if acm is None or not acm.entries or not P:
        return out
    reasons = list(Reason)
    index = {n: g for g, n in enumerate(geom_names)}
    if len(index) != len(geom_names):
        for k, (a, b) in enumerate(pair_ids.tolist()):
            r = acm.reason(geom_names[a], geom_names[b])
            out[k] = -1 if r is None else reasons.index(r)
        return out
    G = max(len(geom_names), 1)
    ent = [(index[x], index[y], reasons.index(r)) for (x, y), r in acm.entries.items()
           if x in index and y in index]
    if not ent:
        return out
    e = np.array(ent, dtype=np.int64).reshape(-1, 3)
    ekey = np.minimum(e[:, 0], e[:, 1]) * G + np.maximum(e[:, 0], e[:, 1])
    order = np.argsort(ekey, kind="stable")
    ekey, ecode = ekey[order], e[order, 2]
    key = np.minimum(pair_ids[:, 0], pair_ids[:, 1]) * G + np.maximum(pair_ids[:, 0], pair_ids[:, 1])
    at = np.minimum(np.searchsorted(ekey, key), len(ekey) - 1)
    hit = ekey[at] == key
    out[hit] = ecode[at[hit]]
    return out


def apply_policy(model: Any, pair_ids: np.ndarray, pairs: Any = "mujoco", *, allowed: Any = None,
                 hazards: Any = None, allow: Any = None, reference: np.ndarray | None = None) -> PairPolicy:
    """Split candidate pairs into monitored and allowed (see :mod:`monitor.pairsel`).

    Args:
        model: ``mujoco.MjModel``.
        pair_ids: (P, 2) candidate geom id pairs.
        pairs: the pairs mode the candidates came from (for ``allowed="auto"``).
        allowed: see :func:`as_acm`.
        hazards: None (every candidate) or pattern items selecting the checked pairs.
        allow: pattern items whose pairs are allowed with reason User.
        reference: reference qpos for ``allowed="auto"`` (see :func:`auto_acm`).

    Returns:
        the :class:`PairPolicy`.
    """
    names = ModelNames.from_model(model)
    pair_ids = np.asarray(pair_ids, dtype=np.int64).reshape(-1, 2)
    acm = as_acm(allowed, model, pairs, reference)
    keep = np.ones(len(pair_ids), dtype=bool)
    not_hazard = 0
    if hazards is not None:
        keep = pair_mask(names, pair_ids, hazards, arg="hazards")
        not_hazard = int((~keep).sum())
    user = pair_mask(names, pair_ids, allow, arg="allow") if allow is not None else np.zeros(len(keep), bool)
    reasons = list(Reason)
    code = _reason_codes(names.geom_names, pair_ids, acm)  # (P,) index into reasons, -1: not in the ACM
    skips = np.array([r.skips for r in reasons] + [False])   # code -1 reads the last entry: no reason
    code = np.where(user & ((code < 0) | ~skips[code]), reasons.index(Reason.USER), code)
    drop = keep & skips[code]
    never_rows = keep & ~drop & (code == reasons.index(Reason.NEVER))
    gn = np.array(names.geom_names, dtype=object)   # name tuples of the removed / Never rows (the output)
    value = np.array([r.value for r in reasons], dtype=object)
    gone, hint = pair_ids[drop], pair_ids[never_rows]
    allowed_rows = list(zip(gn[gone[:, 0]].tolist(), gn[gone[:, 1]].tolist(), value[code[drop]].tolist()))
    never = list(zip(gn[hint[:, 0]].tolist(), gn[hint[:, 1]].tolist()))
    keep &= ~drop
    return PairPolicy(pair_ids[keep], tuple(allowed_rows), not_hazard, tuple(never), acm)


def describe(policy: PairPolicy, names: ModelNames, *, limit: int | None = None) -> list[str]:
    """Lines listing the monitored pairs and the allowed ones with reasons."""
    lines = [f"monitored: {len(policy.monitored)} pairs"]
    ids = {n: g for g, n in enumerate(names.geom_names)}
    rows = policy.monitored.tolist()
    for a, b in rows[:limit]:
        lines.append(f"  check    {names.label(a)} -- {names.label(b)}")
    if limit is not None and len(rows) > limit:
        lines.append(f"  ... {len(rows) - limit} more")
    lines.append(f"allowed (not checked): {len(policy.allowed)} pairs")
    for a, b, r in policy.allowed[:limit]:
        lines.append(f"  {r:<8} {names.label(ids[a])} -- {names.label(ids[b])}")
    if limit is not None and len(policy.allowed) > limit:
        lines.append(f"  ... {len(policy.allowed) - limit} more")
    if policy.not_hazard:
        lines.append(f"not selected by hazards=: {policy.not_hazard} candidate pairs")
    if policy.never:
        lines.append(f"Never in contact in the samples (still checked): {len(policy.never)} pairs")
    return lines


__all__ = ["ACM", "Reason", "compute_acm", "auto_acm", "as_acm", "apply_policy", "PairPolicy", "describe",
           "DEFAULT_SAMPLES", "AUTO_SAMPLES", "CONTACT_TOL", "FORMAT", "VERSION"]
