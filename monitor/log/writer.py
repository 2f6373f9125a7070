"""MCAP certificate logs: :class:`MonitorLog` and :func:`finalise_log`.

File layout (one MCAP file per run; timestamps and payload fields: :mod:`monitor.log.topics`):

* header, then the ``monitor.run`` metadata (package and MuJoCo versions, margin,
  epsilon, pair policy, predictor, ...; strings stored as is, other values as JSON
  text listed under ``_json_keys``; a gate's log also holds ``"request"``, its
  :meth:`monitor.certify.request.CertifyRequest.to_json`: request id 0) and the model
  attachments (``model.xml`` +
  ``assets/*.stl`` + ``model.mjb``, ``log_time``/``create_time`` = wall clock at open)
  **first**, so that even a killed writer leaves a log that review can re-verify;
* per distinct request (a gate setting changed mid-run, a log given to a gate, a user's own
  ``certify`` calls): one ``monitor.request`` metadata record before the first certificate that
  answers it; every certificate names its request by ``request_id`` and ``review --verify``
  re-derives the window with that request (:data:`topics.METADATA_REQUEST`);
* per window: ``/monitor/plan``, ``/monitor/certificate``, ``/monitor/violation``
  (violation or uncertain only), ``/monitor/action``, ``/monitor/log`` (``foxglove.Log``
  for violations, uncertain windows and replaced actions) and with foxglove-sdk
  ``/monitor/tf`` (+ ``/monitor/scene`` for the geoms once, ``/monitor/markers`` for witnesses).

Two phases (crash tolerance *and* an indexed file):

1. **Journal.** While the run lasts, records go to ``path`` **unchunked**
   (``use_chunking=False``) and the file is flushed at the end of every
   :meth:`MonitorLog.write_window`. A process killed between two windows loses nothing;
   one killed inside ``write_window`` loses at most the messages of that window
   (:data:`MAX_MESSAGES_PER_WINDOW`). :func:`monitor.log.reader.read_log` recovers every
   complete record of such a file; ``fsync=True`` additionally survives power loss (not measured).
2. **Finalisation.** :meth:`MonitorLog.close` rewrites the journal into a chunked
   (zstd), indexed MCAP file with a summary (chunk, message, attachment and metadata
   indexes, statistics) next to it and atomically renames it over ``path``
   (:func:`finalise_log`; ``index=False`` keeps the journal). A journal left by a
   killed writer is finalised by ``python -m monitor review --reindex FILE``.

Integrity and authenticity: every record is fed to a SHA-256 chain (:mod:`monitor.log.digest`),
sealed at close (unkeyed: tamper evidence against accidents, not against a forger). With a key
(``key=`` or ``$MONITOR_LOG_KEY_FILE``) the log also holds HMAC-SHA256 checkpoints of that chain
(:mod:`monitor.log.sign`): one at open, one after every window (inside the per-window flush, so a
killed writer leaves every finished window signed) and a final one at close.

Model export: the exact compiled model is always attached as MJB
(``mj_saveModel``; loadable by the same MuJoCo version). The MJCF XML comes from an
``MjSpec`` (pass ``model_source=`` a path or spec) or, failing that, from
``mj_saveLastXML`` (which only works when ``model`` is the last model MuJoCo
compiled); every mesh is replaced by its compiled vertices/faces as a binary STL
asset and its geoms get the compiled poses, so the XML needs no original files.
The XML is recompiled before it is attached and kept only if its world geometry
matches the model within :data:`XML_GEOMETRY_TOL` (MuJoCo writes 6 significant digits).
"""

from __future__ import annotations

import datetime as _dt
import importlib.metadata
import json
import math
import os
import platform
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from mcap.records import Attachment, Channel, Header, Message, Metadata, Schema
from mcap.writer import CompressionType, Writer

from monitor._json import jsonable
from monitor.certify.types import Verdict
from monitor.errors import InvalidInputError, LogFormatError
from monitor.log import replay, sign, topics
from monitor.log.digest import METADATA_DIGEST, Digest

MAX_MESSAGES_PER_WINDOW = 8
"""Upper bound on records one window writes (plan, certificate, violation, action,
log, tf, and up to two scene updates on the first window): the most a killed writer can
lose under the per-window flush policy. A signing log writes one more, its checkpoint
(:mod:`monitor.log.sign`), as the window's last record."""

FINAL_CHUNK_BYTES = 1 << 20
"""Chunk size (bytes, before compression) of a finalised log."""

UNKNOWN_ABS = 1e308
"""Floats at least this large in magnitude are the certificate's JSON stand-in for an
infinite (unknown) bound; the log writes them as ``null``."""

XML_GEOMETRY_TOL = 1e-4
"""Largest world-frame geometry difference (m) accepted between the attached XML
(after recompilation) and the live model. MuJoCo's XML writer keeps 6 significant
digits, i.e. ~1e-6 relative; 1e-4 m also tolerates scenes a few tens of metres wide."""

DEFAULT_LOG_DIR = "logs"


def default_path(env_id: str | None = None, log_dir: str | os.PathLike[str] = DEFAULT_LOG_DIR) -> Path:
    """``logs/<env-id>-<UTC timestamp>.mcap`` (creates the folder; never reuses a name)."""
    d = Path(log_dir)
    d.mkdir(parents=True, exist_ok=True)
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in (env_id or "monitor"))
    stamp = _dt.datetime.now(_dt.UTC).strftime("%Y%m%dT%H%M%S.%fZ")
    p = d / f"{safe}-{stamp}.mcap"
    k = 1
    while p.exists():
        p = d / f"{safe}-{stamp}-{k}.mcap"
        k += 1
    return p


def _jsonable(x: Any) -> Any:
    """Numpy -> Python, non-finite floats -> None (strict JSON)."""
    return jsonable(x, "null")


def _default(x: Any) -> Any:
    """``json.dumps`` hook for numpy values (fast path; non-finite values raise ValueError)."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"not JSON-serialisable: {type(x).__name__}")


def _dumps(obj: Any) -> bytes:
    """Strict JSON bytes; floats are written with repr, so they round-trip exactly."""
    try:
        return json.dumps(obj, allow_nan=False, separators=(",", ":"), default=_default).encode("utf-8")
    except ValueError:  # NaN/inf somewhere: sanitise (-> null) and retry
        return json.dumps(_jsonable(obj), allow_nan=False, separators=(",", ":")).encode("utf-8")


def _null_unknown(x: Any) -> Any:
    """Replace the +-1e308 stand-ins of ``Certificate.to_dict`` by None, recursively.

    Tuples become lists. Dispatches on the exact type first (the plain dict / list /
    float / str / int / None that ``to_dict`` produces); subclasses (numpy floats, ...)
    take the general ``isinstance`` path, with the same result.
    """
    t = type(x)
    if t is float:
        return x if abs(x) < UNKNOWN_ABS else None
    if t is dict:
        return {k: _null_unknown(v) for k, v in x.items()}
    if t is list or t is tuple:
        return [_null_unknown(v) for v in x]
    if x is None or t is str or t is int or t is bool:
        return x
    if isinstance(x, dict):
        return {k: _null_unknown(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_null_unknown(v) for v in x]
    if isinstance(x, float) and not abs(x) < UNKNOWN_ABS:
        return None
    return x


def _ns(seconds: float) -> int:
    return int(round(float(seconds) * 1e9))


def package_versions() -> dict[str, str]:
    """Versions of monitor, mujoco, numpy, scipy, mcap, foxglove-sdk (if installed), Python."""
    out = {"python": platform.python_version()}
    for dist in ("monitor", "mujoco", "numpy", "scipy", "numba", "mcap", "foxglove-sdk", "gymnasium"):
        try:
            out[dist] = importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            continue
    if "monitor" not in out:
        import monitor

        out["monitor"] = monitor.__version__
    return out


# --------------------------------------------------------------------------- model edits
_OPT = "opt."
_DISABLEFLAGS = _OPT + "disableflags"


def _model_fields(model: Any, names: Any = None) -> dict[str, np.ndarray]:
    """Copies of the model arrays a certificate or a re-simulation depends on, and of every option.

    ``names``: the keys to read (those of an earlier call on the attached model); default the
    arrays of :func:`monitor.log.replay.model_fields` (``SYNC_FIELDS`` first) and ``opt.<field>``
    for every :func:`monitor.log.replay.option_fields` entry (``opt.disableflags`` among them).
    """
    if names is None:
        names = [*replay.model_fields(model), *(_OPT + n for n in replay.option_fields(model))]
    opt = model.opt
    return {k: np.array(getattr(opt, k[len(_OPT):]) if k.startswith(_OPT) else getattr(model, k), ndmin=1)
            for k in names}


# --------------------------------------------------------------------------- model export


@dataclass
class ModelExport:
    """A model ready to attach.

    Attributes:
        mjb: exact compiled model (``mj_saveModel``) bytes.
        xml: self-contained MJCF text or None when it could not be produced.
        assets: file name referenced by ``xml`` -> bytes (binary STL meshes).
        info: how the XML was produced, its geometry deviation (m), or why it failed.
    """

    mjb: bytes
    xml: str | None = None
    assets: dict[str, bytes] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)


def _stl_bytes(V: np.ndarray, F: np.ndarray) -> bytes:
    """Binary STL of triangles F (n, 3) over vertices V (m, 3), written by trimesh.

    Binary STL stores float32 coordinates, so MuJoCo's float32 ``mesh_vert`` round-trips
    exactly; ``process=False`` keeps every vertex and face as compiled (no merging).
    """
    import trimesh

    mesh = trimesh.Trimesh(vertices=np.asarray(V, np.float64), faces=np.asarray(F, np.int64), process=False,
                           validate=False)
    return mesh.export(file_type="stl")


def _mesh_arrays(model: Any, i: int) -> tuple[np.ndarray, np.ndarray]:
    va, nv = model.mesh_vertadr[i], model.mesh_vertnum[i]
    fa, nf = model.mesh_faceadr[i], model.mesh_facenum[i]
    return model.mesh_vert[va:va + nv], model.mesh_face[fa:fa + nf]


def _spec_from(model: Any, source: Any) -> tuple[Any, str]:
    import mujoco

    if isinstance(source, mujoco.MjSpec):
        return source.copy(), "MjSpec (given)"
    if source is not None:
        return mujoco.MjSpec.from_file(str(source)), f"MjSpec.from_file({Path(source).name})"
    with tempfile.TemporaryDirectory() as td:
        tmp = os.path.join(td, "last.xml")
        mujoco.mj_saveLastXML(tmp, model)  # raises FatalError when model is not the last compiled one
        return mujoco.MjSpec.from_file(tmp), "mj_saveLastXML"


def _self_contained_xml(model: Any, spec: Any) -> tuple[str, dict[str, bytes]]:
    """Replace every mesh of ``spec`` by the compiled one (STL asset) and pin mesh geom poses."""
    import mujoco

    assets: dict[str, bytes] = {}
    for k, ms in enumerate(spec.meshes):
        mid = k
        if ms.name:
            found = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MESH, ms.name)
            mid = found if found >= 0 else k
        V, F = _mesh_arrays(model, mid)
        fname = f"mesh{mid}.stl"
        assets[fname] = _stl_bytes(V, F)
        ms.file = fname
        ms.content_type = "model/stl"
        ms.scale = [1.0, 1.0, 1.0]
        ms.refpos = [0.0, 0.0, 0.0]
        ms.refquat = [1.0, 0.0, 0.0, 0.0]
        ms.uservert = []
        ms.userface = []
    for tex in spec.textures:  # visual only: textures from files become flat builtins
        if tex.file:
            tex.file = ""
            tex.builtin = mujoco.mjtBuiltin.mjBUILTIN_FLAT
            tex.width = tex.height = 8
    spec.meshdir = ""
    spec.texturedir = ""
    spec.assets = dict(assets)
    from monitor.scene import geom_frame

    spec.compile()  # assigns compiled ids to spec elements
    for g in spec.geoms:
        if g.type == mujoco.mjtGeom.mjGEOM_MESH and 0 <= g.id < model.ngeom:
            # where MuJoCo places it (geom_sameframe: the body or inertial frame), not geom_pos/geom_quat
            R_BG, p_BG = geom_frame(model, g.id)
            quat = np.empty(4)
            mujoco.mju_mat2Quat(quat, np.ascontiguousarray(R_BG).ravel())
            g.pos = p_BG
            g.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT
            g.quat = quat
    return spec.to_xml(), assets


def export_model(model: Any, source: Any = None) -> ModelExport:
    """Exact MJB plus (when possible) a self-contained MJCF XML of ``model``.

    Args:
        model: the compiled ``mujoco.MjModel``.
        source: optional ``mujoco.MjSpec`` or path of the MJCF the model was loaded
            from (most robust); otherwise ``mj_saveLastXML`` is tried.

    Returns:
        :class:`ModelExport`; ``xml`` is None (with ``info["xml_error"]``) if no XML
        could be produced whose recompiled geometry matches ``model``.
    """
    import mujoco

    from monitor.log.reader import geometry_deviation

    buf = np.zeros(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    out = ModelExport(mjb=buf.tobytes())
    try:
        spec, how = _spec_from(model, source)
        xml, assets = _self_contained_xml(model, spec)
        back = mujoco.MjModel.from_xml_string(xml, assets=assets)
        dev = geometry_deviation(model, back)
        q = np.random.default_rng(0).uniform(-1.0, 1.0, model.nq) if model.nq else None
        if q is not None:
            dev = max(dev, geometry_deviation(model, back, qpos=_valid_qpos(model, q)))
        out.info = {"xml_from": how, "xml_geometry_deviation_m": dev}
        if dev <= XML_GEOMETRY_TOL:
            out.xml, out.assets = xml, assets
        else:
            out.info["xml_error"] = f"recompiled XML differs from the model by {dev:.3g} m"
    except (mujoco.FatalError, ValueError, TypeError, OSError) as exc:
        out.info["xml_error"] = f"{type(exc).__name__}: {exc}"
    return out


def _valid_qpos(model: Any, q: np.ndarray) -> np.ndarray:
    """qpos0 perturbed by ``q`` on hinge/slide coordinates (quaternions left valid)."""
    import mujoco

    qpos = model.qpos0.copy()
    for j in range(model.njnt):
        if model.jnt_type[j] in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            a = model.jnt_qposadr[j]
            qpos[a] += 0.5 * q[a]
    return qpos


# --------------------------------------------------------------------------- writer


def _plan_payload(plan: Any) -> dict[str, Any]:
    if hasattr(plan, "qpos"):
        return {"kind": "plan", "times": np.asarray(plan.times, np.float64),
                "qpos": np.asarray(plan.qpos, np.float64),
                "mocap_pos": getattr(plan, "mocap_pos", None),
                "mocap_quat": getattr(plan, "mocap_quat", None)}
    if hasattr(plan, "pos") and hasattr(plan, "quat"):
        return {"kind": "bodymotion", "times": np.asarray(plan.times, np.float64),
                "pos": np.asarray(plan.pos, np.float64), "quat": np.asarray(plan.quat, np.float64),
                "interpolation": str(getattr(plan, "interpolation", "lerp_slerp"))}
    raise InvalidInputError(f"plan must be a monitor.Plan or BodyMotion, got {type(plan).__name__}")


class MonitorLog:
    """MCAP log of certificates, violations, plans and actions (context manager).

    Args:
        path: output file; default ``logs/<env-id>-<UTC timestamp>.mcap``. An existing
            file is overwritten.
        model: the ``mujoco.MjModel`` to attach (else taken from the first plan's
            ``plan.model``).
        metadata: run metadata (margin, epsilon, pairs, predictor, tolerances,
            budget, ...); JSON-serialisable values.
        env_id: used in the default file name and the metadata.
        foxglove: also write foxglove ``SceneUpdate``/``FrameTransforms`` (skipped
            silently when foxglove-sdk is not installed).
        model_source: optional ``MjSpec`` or MJCF path of ``model`` (robust XML export).
        fsync: ``os.fsync`` after every window (power-loss durability; slower).
        index: on :meth:`close`, rewrite the journal into a chunked, indexed file
            (:func:`finalise_log`); False leaves the unchunked journal.
        key: sign the log (:mod:`monitor.log.sign`): bytes (at least 16; random), an HMAC-SHA256
            checkpoint after opening, after every window and at close. None: the key in the file
            named by ``$MONITOR_LOG_KEY_FILE`` when that is set, else an unsigned log. False:
            unsigned whatever the environment says.

    Raises:
        LogKeyError: an unusable ``key`` or key file (before the file is created).

    Example:
        >>> with MonitorLog("run.mcap", model=model, metadata={"margin": 0.01}) as log:
        ...     log.write_window(data.time, plan, cert)
    """

    logs_rollouts = True
    """:meth:`write_window` takes ``rollout=`` (a gate logs, for every window, where its rows come from
    and, for its own MuJoCo rollouts, what re-simulates them: see :data:`monitor.log.topics.ROLLOUTS_KEY`)."""

    logs_applied_motions = True
    """:meth:`write_window` takes ``applied_window=`` / ``applied=`` (a gate logs, for every replaced
    action, the motion that ran: see :data:`monitor.log.topics.APPLIED_MOTIONS_KEY`)."""

    def __init__(self, path: str | os.PathLike[str] | None = None, *, model: Any = None,
                 metadata: dict[str, Any] | None = None, env_id: str | None = None, foxglove: bool = True,
                 model_source: Any = None, fsync: bool = False, index: bool = True,
                 key: bytes | bool | None = None) -> None:
        self._signer = _signer(key)  # before the file is created: a bad key leaves nothing behind
        self.path = Path(path) if path is not None else default_path(env_id)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._fsync = bool(fsync)
        self._index_on_close = bool(index)
        self.finalise_error: str | None = None
        self._f = open(self.path, "wb")  # noqa: SIM115 - closed in close()
        self._w = Writer(self._f, use_chunking=False, compression=CompressionType.NONE,
                         enable_crcs=True, enable_data_crcs=False)
        self._w.start(profile=topics.PROFILE, library=f"{topics.LIBRARY}/{package_versions()['monitor']}")
        self._digest = Digest()  # tamper-evidence seal, written at close (monitor.log.digest)
        self._channels: dict[str, int] = {}
        for topic, (name, _) in topics.JSON_TOPICS.items():
            sid = self._w.register_schema(name=name, encoding="jsonschema",
                                          data=topics.schema_text(topic).encode("utf-8"))
            self._channels[topic] = self._w.register_channel(topic=topic, message_encoding="json",
                                                             schema_id=sid)
        if self._signer is not None:
            sid = self._w.register_schema(name=topics.SIGNATURE_SCHEMA[0], encoding="jsonschema",
                                          data=topics.schema_text(topics.SIGNATURE).encode("utf-8"))
            self._channels[topics.SIGNATURE] = self._w.register_channel(
                topic=topics.SIGNATURE, message_encoding="json", schema_id=sid)
        self._index = 0
        self._seq = 0
        self._episode = 0
        self._last_sim_time: float | None = None
        self._open_ns = time.time_ns()
        self._last_log_ns = 0
        self._closed = False
        self._model = None
        self._model_source = model_source
        self._rollout_sizes: tuple[Any, int, int, int] | None = None  # (model, state spec, nstate, nu)
        self._scene = None
        self._want_foxglove = bool(foxglove)
        self.foxglove_enabled = False
        self.foxglove_error: str | None = None
        run = {"env_id": env_id, "created_utc": _dt.datetime.now(_dt.UTC).isoformat(),
               "format_version": topics.FORMAT_VERSION,
               "flush_policy": "journal: unchunked; flush per window" + ("; fsync" if fsync else "")
               + ("; finalised into a chunked, indexed file on close" if index else ""),
               "max_messages_lost_on_kill": MAX_MESSAGES_PER_WINDOW + (self._signer is not None)}
        versions = package_versions()
        run.update({f"version.{k}": v for k, v in versions.items()})
        run["mujoco_version"] = versions.get("mujoco")
        run.update(metadata or {})
        if self._signer is not None:
            run[sign.RUN_KEY] = self._signer.claim()
        # requests the certificates answer: key text -> id (monitor.request records, see topics);
        # a "request" in the run metadata (a gate's, at open) is id 0 and gets no record of its own
        self._requests: dict[str, int] = {}
        self._last_request: Any = None
        self._last_request_id: int | None = None
        if isinstance(run.get("request"), dict):
            self._requests[_request_key(run["request"])] = 0
        self.add_metadata(run)
        self._model_base: dict[str, np.ndarray] | None = None  # _model_fields as attached / last recorded
        self._model_watch: replay.ModelWatch | None = None  # quick "unchanged since _model_base" test
        if model is not None:
            self._attach_model(model)
            self._model_base = _model_fields(model)
        self._sign(self._open_ns, 0)
        self._flush()

    # ----------------------------------------------------------------- context manager
    def __enter__(self) -> MonitorLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def note_model(self, model: Any) -> list[str]:
        """Record an in-place edit of the attached model (a ``monitor.model_edit`` record), if any.

        Compares every :data:`monitor.scene.SYNC_FIELDS` array, every other array a
        re-simulation depends on (:func:`monitor.log.replay.model_fields`: masses, gains,
        damping, ...) and every option of ``model`` with the attached model (or the last
        record) and, when some differ, writes their full new values, tagged with the index of
        the next window (see :data:`topics.METADATA_MODEL_EDIT`; options other than
        ``disableflags`` under ``"options"``). Call it before writing a window certified or
        simulated on an edited model; a gate calls it whenever its scene was rebuilt and, when
        it logs rollouts, before every window. An unchanged model costs a few µs
        (:class:`monitor.log.replay.ModelWatch`).

        Args:
            model: the ``MjModel`` the next window was certified on (the attached one, edited).

        Returns:
            the names of the fields recorded (empty: nothing changed or no model attached).

        Raises:
            InvalidInputError: ``model`` does not have the attached model's array shapes.
        """
        self._check_open()
        base = self._model_base
        if base is None:
            return []
        watch = self._model_watch
        if watch is not None and watch.model is model and watch.unchanged():
            return []
        try:
            now = _model_fields(model, base)
        except AttributeError as exc:
            raise InvalidInputError(f"model: not an MjModel like the one attached to the log "
                                    f"({exc})") from exc
        if any(now[k].shape != v.shape for k, v in base.items()):
            raise InvalidInputError("model: its arrays do not have the shapes of the model attached to the "
                                    "log (another model, not an in-place edit)")
        self._model_watch = replay.ModelWatch(model)
        changed = [k for k, v in base.items() if now[k].tobytes() != v.tobytes()]
        if not changed:
            return []
        fields = {k: {"shape": list(now[k].shape), "values": now[k].ravel().tolist()}
                  for k in changed if not k.startswith(_OPT)}
        rec: dict[str, Any] = {"window": self._index, "fields": fields}
        if _DISABLEFLAGS in changed:
            rec["disableflags"] = int(now[_DISABLEFLAGS][0])
        options = {}
        for k in changed:
            if k.startswith(_OPT) and k != _DISABLEFLAGS:
                v = getattr(model.opt, k[len(_OPT):])
                options[k[len(_OPT):]] = v.tolist() if isinstance(v, np.ndarray) else v
        if options:
            rec["options"] = options
        self.add_metadata(rec, name=topics.METADATA_MODEL_EDIT)
        self._model_base = now
        return changed

    @property
    def windows(self) -> int:
        """Number of windows written so far."""
        return self._index

    @property
    def episode(self) -> int:
        """Episode index the next window gets unless its ``sim_time`` goes back."""
        return self._episode

    @property
    def closed(self) -> bool:
        """True after :meth:`close`."""
        return self._closed

    def new_episode(self) -> int:
        """Start a new episode (the next window gets the next episode index); returns it.

        Not needed after an ordinary reset: a window whose ``sim_time`` is earlier than
        the previous window's starts a new episode by itself.
        """
        self._check_open()
        if self._last_sim_time is not None:
            self._episode += 1
            self._last_sim_time = None
        return self._episode

    def add_metadata(self, values: dict[str, Any], name: str = topics.METADATA_RUN) -> None:
        """Write a metadata record; readers merge records of one name.

        Strings are stored as they are; every other value (numbers, bools, None, lists,
        dicts) as JSON text, and its key is listed in :data:`topics.METADATA_JSON_KEYS`.
        """
        self._check_open()
        enc = encode_metadata(values)
        self._w.add_metadata(name, enc)
        self._digest.metadata(name, enc)
        self._flush()

    def _request_id(self, request: Any) -> int:
        """Id of ``request`` in this log, writing its ``monitor.request`` record the first time.

        ``request`` is a :class:`~monitor.certify.request.CertifyRequest` (frozen: the previous
        window's object is recognised by identity, so a gate's unchanged request costs one ``is``
        per window) or its :meth:`~monitor.certify.request.CertifyRequest.to_json` dict. Its
        ``window`` is not recorded (review re-derives each window on its plan's span), so
        requests differing only in their window share one id.
        """
        if request is self._last_request and self._last_request_id is not None:
            return self._last_request_id
        d = request.to_json() if callable(getattr(request, "to_json", None)) else request
        if not isinstance(d, dict):
            raise InvalidInputError(f"request must be a CertifyRequest or its to_json() dict, got "
                                    f"{type(request).__name__}")
        d = {**d, "window": None}
        key = _request_key(d)
        rid = self._requests.get(key)
        if rid is None:
            rid = len(self._requests)
            self.add_metadata({"id": rid, "request": d}, name=topics.METADATA_REQUEST)
            self._requests[key] = rid
        if not isinstance(request, dict):  # a dict may be edited in place: never cached by identity
            self._last_request, self._last_request_id = request, rid
        return rid

    def _attach_model(self, model: Any) -> None:
        exp = export_model(model, self._model_source)
        self._model = model
        if exp.xml is not None:
            self._attach(topics.ATTACHMENT_XML, "application/xml", exp.xml.encode("utf-8"))
            for fname, data in exp.assets.items():
                self._attach(topics.ASSET_PREFIX + fname, "model/stl", data)
        self._attach(topics.ATTACHMENT_MJB, "application/x-mujoco-mjb", exp.mjb)
        info = dict(exp.info)
        info.update({"nq": int(model.nq), "nbody": int(model.nbody), "ngeom": int(model.ngeom),
                     "nmocap": int(model.nmocap), "assets": sorted(exp.assets)})
        self.add_metadata(info, name=topics.METADATA_MODEL)
        if self._want_foxglove:
            try:
                from monitor.log.foxglove_scene import FoxgloveScene

                self._scene = FoxgloveScene(model)
            except ImportError as exc:
                self.foxglove_error = f"foxglove-sdk not installed ({exc}); pip install 'monitor[foxglove]'"
                return
            sids: dict[str, int] = {}
            for topic, (name, enc, data) in self._scene.schemas().items():
                if name not in sids:  # each schema once
                    sids[name] = self._w.register_schema(name=name, encoding=enc, data=data)
                sid = sids[name]
                self._channels[topic] = self._w.register_channel(topic=topic, message_encoding="protobuf",
                                                                 schema_id=sid)
            self.foxglove_enabled = True

    def _attach(self, name: str, media_type: str, data: bytes) -> None:
        t = self._open_ns
        self._w.add_attachment(create_time=t, log_time=t, name=name, media_type=media_type, data=data)
        self._digest.attachment(name, media_type, data)

    # ----------------------------------------------------------------- writing
    def _check_open(self) -> None:
        if self._closed:
            raise InvalidInputError(f"MonitorLog {self.path} is closed")

    def _put(self, topic: str, log_ns: int, sim_ns: int, data: bytes) -> None:
        self._w.add_message(self._channels[topic], log_time=log_ns, data=data, publish_time=sim_ns,
                            sequence=self._seq)
        self._digest.message(topic, log_ns, sim_ns, self._seq, data)
        self._seq += 1

    def _sign(self, log_ns: int, sim_ns: int, final: bool = False) -> None:
        """A signed checkpoint over everything written so far (a signing log only)."""
        if self._signer is not None:
            payload = self._signer.checkpoint(self._digest, self._index, final)
            self._put(topics.SIGNATURE, log_ns, sim_ns, payload)

    @property
    def key_id(self) -> str | None:
        """Id of the signing key (:func:`monitor.log.sign.key_id`); None for an unsigned log."""
        return None if self._signer is None else self._signer.key_id

    def _flush(self) -> None:
        self._f.flush()
        if self._fsync:
            os.fsync(self._f.fileno())

    def write_window(self, sim_time: float, plan: Any, certificate: Any, proposed_action: Any = None,
                     applied_action: Any = None, replaced: bool = False,
                     wall_time: float | None = None, episode: int | None = None,
                     reason: str | None = None, request: Any = None, applied_window: int | None = None,
                     applied: dict[str, Any] | None = None, rollout: Any = None) -> int:
        """Log one certified window; flushes the file before returning.

        Args:
            sim_time: simulation time (s) at which the window was certified (``data.time``).
            plan: the certified ``monitor.Plan`` (times (K,), qpos (K, nq), mocap_pos
                (nmocap, 3), mocap_quat (nmocap, 4)) or ``BodyMotion``; None to skip.
            certificate: the ``Certificate`` (or its ``to_dict()``).
            proposed_action: (nu,) action proposed by the policy, or None.
            applied_action: (nu,) action actually applied, or None.
            replaced: True if the gate replaced/blocked the proposed action.
            wall_time: Unix seconds of the window; default ``time.time()``. The MCAP
                ``log_time`` is this in ns, raised to 1 ns past the previous window's if needed.
            episode: episode index (>= the current one); default: the current episode,
                or the next one when ``sim_time`` is earlier than the previous window's.
            reason: why the action was replaced (e.g. ``"braking tail uncertain"``); default:
                the window's verdict when it is not certified, else a generic text.
            request: the :class:`~monitor.certify.request.CertifyRequest` (or its ``to_json()``
                dict) the certificate answers; default ``certificate.request`` (every
                certificate ``certify`` returns has one). Logged once per distinct request
                (a ``monitor.request`` metadata record); the certificate payload names it by
                ``request_id``. Review re-derives the window with it. None and no
                ``certificate.request``: no ``request_id`` (review then uses the run's).
            applied_window: for a replaced action, the index of the window (this log) that holds
                the motion actually applied (its plan and certificate: an ``applied`` record,
                written by this call's successor or earlier for a committed braking tail);
                stored in the action payload. Review checks that record's certificate covers
                this window's span.
            applied: marks this window as an *applied-motion record* (the motion a replaced step
                ran, not a proposal): ``{"kind": "fallback" | "brake_tail", "covered_by": i}``
                with ``i`` the index of the window whose certification covers it (a fallback:
                this window itself; a committed braking tail: the accepted window it was
                certified with, one step earlier). Stored in the certificate payload.
            rollout: where the plan's rows come from (a joint-space Plan only), stored in the plan
                payload (:mod:`monitor.log.replay`): ``(state, ((ctrl, substeps), ...), rows_from)``
                for rows simulated by MuJoCo from ``state`` (the ``mjSTATE_INTEGRATION`` state,
                (nstate,) float64 bytes or array) under each ctrl ((nu,) bytes or array) in turn,
                from substep ``rows_from`` on (``source: "rollout"``, re-simulated by review);
                ``"user"`` for rows made by user code (``source: "user"``); None: not stated.

        Returns:
            The window index in this log.

        Raises:
            InvalidInputError: non-finite or negative ``sim_time``, bad ``episode``,
                closed log, bad plan.
        """
        self._check_open()
        t = float(sim_time)
        if not math.isfinite(t) or t < 0:
            raise InvalidInputError(f"sim_time must be finite and >= 0, got {sim_time!r}")
        if episode is not None:
            bad_type = isinstance(episode, bool) or not isinstance(episode, int | np.integer)
            if bad_type or episode < self._episode:
                raise InvalidInputError(f"episode must be an int >= {self._episode} (the current episode), "
                                        f"got {episode!r}")
            if episode > self._episode:
                self._episode, self._last_sim_time = int(episode), None
        elif self._last_sim_time is not None and t < self._last_sim_time:
            self._episode += 1
        wall = time.time() if wall_time is None else float(wall_time)
        if not math.isfinite(wall) or wall < 0:
            raise InvalidInputError(f"wall_time must be finite Unix seconds >= 0, got {wall_time!r}")
        cert = certificate.to_dict() if hasattr(certificate, "to_dict") else dict(certificate)
        if cert.get("verdict") not in tuple(Verdict):
            raise InvalidInputError(f"certificate verdict must be certified/violation/uncertain, "
                                    f"got {cert.get('verdict')!r}")
        if plan is not None:
            plan_msg = _plan_payload(plan)  # validates before anything is written
            if rollout is not None:
                plan_msg.update(self._rollout_payload(rollout, plan_msg, getattr(plan, "model", None)))
        elif rollout is not None:
            raise InvalidInputError("rollout needs the plan whose rows it made")
        if applied_window is not None and not _is_index(applied_window):
            raise InvalidInputError(f"applied_window must be a window index (int >= 0), "
                                    f"got {applied_window!r}")
        if applied is not None:
            applied = _applied_record(applied, self._index)
        if request is None:
            request = getattr(certificate, "request", None)
        rid = None if request is None else self._request_id(request)
        cert = _null_unknown(cert)
        if rid is not None:
            cert["request_id"] = rid
        if applied is not None:
            cert["applied"] = applied
        log_ns = max(_ns(wall), self._last_log_ns + 1)
        sim_ns = _ns(t)
        k = self._index
        if self._model is None and plan is not None and getattr(plan, "model", None) is not None:
            self._attach_model(plan.model)
        head = {"index": k, "episode": self._episode, "sim_time": t, "wall_time": wall}
        if plan is not None:
            self._put(topics.PLAN, log_ns, sim_ns, _dumps({**head, **plan_msg}))
        self._put(topics.CERTIFICATE, log_ns, sim_ns, _dumps({**head, **cert}))
        if cert["verdict"] != Verdict.CERTIFIED:
            bad = [p for p in cert.get("pairs", []) if p.get("verdict") != Verdict.CERTIFIED]
            self._put(topics.VIOLATION, log_ns, sim_ns, _dumps({
                **head, "verdict": cert["verdict"], "window": cert.get("window"),
                "margin": cert.get("margin"), "earliest_time": cert.get("earliest_time"),
                "clearance": cert.get("clearance"),
                "witness": cert.get("witness"), "pairs": bad, "replaced": bool(replaced)}))
        if replaced and reason is None:
            reason = (cert["verdict"] if cert["verdict"] != Verdict.CERTIFIED
                      else "replaced although the window is certified (e.g. its braking tail is not)")
        if proposed_action is not None or applied_action is not None or replaced:
            self._put(topics.ACTION, log_ns, sim_ns, _dumps({
                "reason": str(reason) if replaced else None,
                **head, "proposed": None if proposed_action is None else np.ravel(proposed_action),
                "applied": None if applied_action is None else np.ravel(applied_action),
                "replaced": bool(replaced),
                **({} if applied_window is None else {"applied_window": int(applied_window)})}))
        if cert["verdict"] != Verdict.CERTIFIED or replaced:
            level, text = log_line(k, self._episode, t, cert, reason if replaced else None)
            self._put(topics.LOG, log_ns, sim_ns, _dumps({
                "timestamp": {"sec": log_ns // 1_000_000_000, "nsec": log_ns % 1_000_000_000},
                "level": level, "message": text, "name": "monitor", "file": "", "line": 0, **head}))
        if self._scene is not None and plan is not None and hasattr(plan, "qpos"):
            for topic, data in self._scene.window_messages(log_ns, plan, cert):
                self._put(topic, log_ns, sim_ns, data)
        self._index += 1
        self._last_sim_time = t
        self._last_log_ns = log_ns
        self._sign(log_ns, sim_ns)
        self._flush()
        return k

    def _rollout_payload(self, rollout: Any, plan_msg: dict[str, Any], plan_model: Any) -> dict[str, Any]:
        """The plan payload's ``source`` (and ``rollout``) for ``write_window(rollout=)``."""
        if isinstance(rollout, str) and rollout == "user":
            return {"source": "user"}
        if plan_msg["kind"] != "plan":
            raise InvalidInputError("rollout: only a joint-space Plan's rows come from a MuJoCo rollout")
        model = self._model if self._model is not None else plan_model  # (attached below from the plan)
        if model is None:
            raise InvalidInputError("rollout needs the log's model (attached at open or from the plan)")
        sizes = self._rollout_sizes
        if sizes is None or sizes[0] is not model:
            import mujoco

            spec = int(mujoco.mjtState.mjSTATE_INTEGRATION)
            sizes = self._rollout_sizes = (model, spec, mujoco.mj_stateSize(model, spec), int(model.nu))
        return {"source": "rollout", "rollout": replay.encode(rollout, *sizes[1:])}

    def close(self) -> None:
        """Finish the journal, then (``index=True``) finalise it into an indexed file (idempotent).

        If finalisation fails, the complete journal stays at ``path`` and the reason is
        in :attr:`finalise_error` (``review --reindex`` can retry).
        """
        if self._closed:
            return
        self._closed = True
        try:
            self._sign(max(self._last_log_ns, self._open_ns), 0, final=True)
            self._w.add_metadata(METADATA_DIGEST, self._digest.seal())
            self._w.finish()
        finally:
            self._f.close()
        if self._index_on_close:
            try:
                finalise_log(self.path)
            except (OSError, LogFormatError) as exc:
                self.finalise_error = f"{type(exc).__name__}: {exc}"


# --------------------------------------------------------------------------- helpers


def _signer(key: Any) -> sign.Signer | None:
    """The log's signer: ``key`` bytes, None (``$MONITOR_LOG_KEY_FILE`` if set) or False (none)."""
    if key is False:
        return None
    if key is None:
        key = sign.key_from_env()
        if key is None:
            return None
    return sign.Signer(key)


APPLIED_KINDS = ("fallback", "brake_tail")
"""Kinds of applied-motion records (:meth:`MonitorLog.write_window` ``applied=``)."""


def _is_index(x: Any) -> bool:
    return isinstance(x, int | np.integer) and not isinstance(x, bool) and x >= 0


def _applied_record(applied: Any, index: int) -> dict[str, Any]:
    """The validated ``applied`` field of window ``index`` (see :meth:`MonitorLog.write_window`)."""
    if not isinstance(applied, dict) or applied.get("kind") not in APPLIED_KINDS:
        raise InvalidInputError(f"applied must be a dict with kind in {APPLIED_KINDS}, got {applied!r}")
    by = applied.get("covered_by")
    if not _is_index(by) or by > index:
        raise InvalidInputError(f"applied['covered_by'] must be a window index <= {index} (this window), "
                                f"got {by!r}")
    return {**applied, "kind": str(applied["kind"]), "covered_by": int(by)}


def _request_key(d: dict[str, Any]) -> str:
    """Canonical text of a request record (the dedup key of :meth:`MonitorLog._request_id`)."""
    return json.dumps(_jsonable({**d, "window": None}), sort_keys=True, allow_nan=False)


def encode_metadata(values: dict[str, Any]) -> dict[str, str]:
    """MCAP metadata map: strings as is, other values as JSON text listed under ``_json_keys``."""
    out: dict[str, str] = {}
    json_keys = []
    for k, v in values.items():
        key = str(k)
        if key == topics.METADATA_JSON_KEYS:
            raise InvalidInputError(f"metadata key {key!r} is reserved")
        if isinstance(v, str):
            out[key] = v
        else:
            out[key] = json.dumps(_jsonable(v), allow_nan=False)
            json_keys.append(key)
    out[topics.METADATA_JSON_KEYS] = ",".join(json_keys)
    return out


LOG_LEVEL_WARNING = 3
LOG_LEVEL_ERROR = 4


def _fmt(x: Any, unit: str = "") -> str:
    return "unknown" if x is None else f"{float(x):.4g}{unit}"


def log_line(index: int, episode: int, sim_time: float, cert: dict[str, Any],
             replaced_reason: str | None) -> tuple[int, str]:
    """(foxglove.Log level, one-line message) for a non-certified window or a replaced action.

    ``replaced_reason`` is None when the action was not replaced.
    """
    where = f"window {index} (episode {episode}, t={sim_time:.4f} s)"
    verdict = cert.get("verdict")
    wit = cert.get("witness")
    if verdict == Verdict.VIOLATION and wit:
        ga, gb = wit.get("geoms", ["?", "?"])
        text = (f"{where}: violation {ga} / {gb} at t={_fmt(wit.get('time'), ' s')}, "
                f"distance {_fmt(wit.get('distance'), ' m')} < margin {_fmt(cert.get('margin'), ' m')}")
        level = LOG_LEVEL_ERROR
    elif verdict in (Verdict.VIOLATION, Verdict.UNCERTAIN):
        n = sum(1 for p in cert.get("pairs", []) if p.get("verdict") != Verdict.CERTIFIED)
        text = (f"{where}: {verdict} from t={_fmt(cert.get('earliest_time'), ' s')} "
                f"({n} pair(s) not certified; clearance {_fmt(cert.get('clearance'), ' m')})")
        level = LOG_LEVEL_ERROR if verdict == Verdict.VIOLATION else LOG_LEVEL_WARNING
    else:
        text, level = f"{where}: certified", LOG_LEVEL_WARNING
    if replaced_reason is not None:
        text += f"; action replaced ({replaced_reason})"
    return level, text


@dataclass
class FinaliseResult:
    """What :func:`finalise_log` did.

    Attributes:
        path: the rewritten file.
        messages: messages copied.
        windows: certificate messages copied.
        source_complete: the source had its footer (a cleanly closed journal or log).
        dropped_bytes: trailing bytes of the source that held no complete record (lost).
        stop_reason: why reading the source stopped early (None when complete).
    """

    path: Path
    messages: int
    windows: int
    source_complete: bool
    dropped_bytes: int
    stop_reason: str | None


def finalise_log(path: str | os.PathLike[str], *, chunk_bytes: int = FINAL_CHUNK_BYTES) -> FinaliseResult:
    """Rewrite a monitor log (journal, killed writer's file, or finished log) as a chunked, indexed MCAP.

    Every complete record is copied in file order (messages keep their ``log_time``,
    ``publish_time`` and ``sequence``; attachments and metadata keep theirs) into a
    zstd-chunked file with a full summary, written next to ``path`` and atomically
    renamed over it. A record cut by a crash is dropped (reported in the result and in
    a ``monitor.finalise`` metadata record).

    Raises:
        LogFormatError: ``path`` is missing or not an MCAP file.
    """
    from monitor.log.reader import MAGIC, LogContents, _ends_with_magic, _records, _Walker

    src = Path(path)
    if not src.is_file():
        raise LogFormatError(f"{src}: no such file")
    size = src.stat().st_size
    state = LogContents(path=str(src), size=size)
    tmp = src.with_name(src.name + ".finalise.tmp")
    n_msg = n_cert = 0
    try:
        with open(src, "rb") as fi, open(tmp, "wb") as fo:
            walk = _Walker(fi, size, None)
            if walk.read_exact(len(MAGIC)) != MAGIC:
                raise LogFormatError(f"{src}: not an MCAP file ({size} bytes)")
            state.closed_by_writer = _ends_with_magic(fi, size)
            w = Writer(fo, chunk_size=int(chunk_bytes), compression=CompressionType.ZSTD)
            started = False
            smap: dict[int, int] = {}
            cmap: dict[int, int] = {}
            cert_channels: set[int] = set()
            for rec in _records(walk, state):
                if isinstance(rec, Header):
                    w.start(profile=rec.profile, library=rec.library)
                    started = True
                elif not started:
                    raise LogFormatError(f"{src}: no MCAP header record")
                elif isinstance(rec, Schema):
                    if rec.id not in smap:
                        smap[rec.id] = w.register_schema(rec.name, rec.encoding, bytes(rec.data))
                elif isinstance(rec, Channel):
                    if rec.id not in cmap:
                        cmap[rec.id] = w.register_channel(rec.topic, rec.message_encoding,
                                                          smap.get(rec.schema_id, 0), dict(rec.metadata))
                        if rec.topic == topics.CERTIFICATE:
                            cert_channels.add(rec.id)
                elif isinstance(rec, Message):
                    if rec.channel_id in cmap:
                        w.add_message(cmap[rec.channel_id], rec.log_time, bytes(rec.data), rec.publish_time,
                                      rec.sequence)
                        n_msg += 1
                        n_cert += rec.channel_id in cert_channels
                elif isinstance(rec, Metadata):
                    if rec.name != topics.METADATA_FINALISE:
                        w.add_metadata(rec.name, dict(rec.metadata))
                elif isinstance(rec, Attachment):
                    w.add_attachment(rec.create_time, rec.log_time, rec.name, rec.media_type, bytes(rec.data))
            if not started:
                raise LogFormatError(f"{src}: no MCAP header record")
            dropped = 0 if state.complete else size - state.readable_bytes
            w.add_metadata(topics.METADATA_FINALISE, encode_metadata({
                "finalised_utc": _dt.datetime.now(_dt.UTC).isoformat(), "source_bytes": size,
                "source_complete": state.complete, "dropped_bytes": dropped, "messages": n_msg,
                "stop_reason": state.stop_reason}))
            w.finish()
            fo.flush()
            os.fsync(fo.fileno())
        os.replace(tmp, src)
    finally:
        if tmp.exists():
            tmp.unlink()
    return FinaliseResult(src, n_msg, n_cert, state.complete, dropped, state.stop_reason)


__all__ = ["MonitorLog", "ModelExport", "FinaliseResult", "export_model", "finalise_log", "default_path",
           "package_versions", "encode_metadata", "log_line", "MAX_MESSAGES_PER_WINDOW", "XML_GEOMETRY_TOL"]
