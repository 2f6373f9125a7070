"""Crash-tolerant reader of monitor MCAP logs.

:func:`read_log` walks the file record by record with its own length-checked
framing (the records themselves are parsed by ``mcap.records``), so that:

* a file cut anywhere (a killed writer, a truncated copy) yields every record
  that lies completely before the cut, and reports how many trailing bytes
  could not be read;
* a record whose body is damaged stops the walk at that record (everything
  before it is kept);
* a file that is not MCAP raises :class:`monitor.errors.LogFormatError`.

JSON payloads are decoded with :func:`json.loads` only (never pickle or eval).
Foxglove protobuf payloads are counted, not decoded (review does not need them).

The model attached to the log is rebuilt by :func:`load_model`.
"""

from __future__ import annotations

import io
import json
import math
import os
import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    Channel,
    Chunk,
    DataEnd,
    Footer,
    Header,
    Message,
    Metadata,
    Schema,
)
from mcap.stream_reader import breakup_chunk

from monitor.errors import InvalidInputError, LogFormatError
from monitor.log import topics

MAGIC = b"\x89MCAP0\r\n"
_RECORD_HEAD = 9  # opcode (1) + length (8)
PROGRESS_BYTES = 2 * 1024 * 1024
"""Files larger than this show a tqdm progress bar when ``progress=None`` (~ a few thousand windows)."""


@dataclass
class LogContents:
    """Everything recovered from one log file.

    Attributes:
        path: file path.
        size: file size (bytes).
        complete: True when the footer and closing magic were read (the writer finished).
        readable_bytes: offset (bytes) just past the last complete record.
        unreadable_bytes: ``size - readable_bytes`` (0 for a complete file).
        stop_reason: why reading stopped early (None for a complete file).
        library: the MCAP header's library string.
        messages: decoded JSON payloads per JSON topic, in file order; each dict gains
            ``"_log_time"`` (ns) from the record.
        counts: number of complete messages per topic (all topics, foxglove included).
        bad_payloads: JSON messages whose payload could not be decoded (skipped).
        metadata: metadata records merged by name (later records update earlier ones);
            values are JSON-decoded.
        attachments: attachment name -> bytes.
        schemas: schema name -> (encoding, data bytes) of every schema seen.
    """

    path: str
    size: int = 0
    complete: bool = False
    readable_bytes: int = 0
    unreadable_bytes: int = 0
    stop_reason: str | None = None
    library: str | None = None
    messages: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    bad_payloads: int = 0
    metadata: dict[str, dict[str, Any]] = field(default_factory=dict)
    attachments: dict[str, bytes] = field(default_factory=dict)
    schemas: dict[str, tuple[str, bytes]] = field(default_factory=dict)

    @property
    def run(self) -> dict[str, Any]:
        """The merged ``monitor.run`` metadata (margin, epsilon, pairs, predictor, versions...)."""
        return self.metadata.get(topics.METADATA_RUN, {})

    @property
    def n_messages(self) -> int:
        """Total complete messages recovered (all topics)."""
        return sum(self.counts.values())

    def topic(self, name: str) -> list[dict[str, Any]]:
        """Decoded payloads of a JSON topic (empty list if none)."""
        return self.messages.get(name, [])

    def certificates(self) -> list[dict[str, Any]]:
        """Certificate payloads in window order."""
        return sorted(self.topic(topics.CERTIFICATE), key=lambda m: (m.get("index", 0), m["_log_time"]))

    def plans_by_index(self) -> dict[int, dict[str, Any]]:
        """Plan payloads keyed by window index."""
        return {int(p["index"]): p for p in self.topic(topics.PLAN) if "index" in p}


def _decode_metadata_value(v: str) -> Any:
    try:
        return json.loads(v)
    except ValueError:
        return v


def _decode_metadata(values: dict[str, str]) -> dict[str, Any]:
    """Decode one metadata record's values.

    Version 2 records list their JSON-text keys under ``_json_keys`` (other values are
    plain strings); version 1 records stored every value as JSON text.
    """
    if topics.METADATA_JSON_KEYS in values:
        json_keys = set(filter(None, values[topics.METADATA_JSON_KEYS].split(",")))
        return {k: _decode_metadata_value(v) if k in json_keys else v
                for k, v in values.items() if k != topics.METADATA_JSON_KEYS}
    return {k: _decode_metadata_value(v) for k, v in values.items()}


class _Walker:
    """Length-checked record walk over a binary file object."""

    def __init__(self, f: io.BufferedReader, size: int, bar: Any) -> None:
        self.f, self.size, self.bar = f, size, bar
        self.pos = 0

    def read_exact(self, n: int) -> bytes | None:
        data = self.f.read(n)
        if len(data) != n:
            return None
        self.pos += n
        if self.bar is not None:
            self.bar.update(n)
        return data


def _parse(opcode: int, body: bytes) -> Any:
    s = ReadDataStream(io.BytesIO(body))
    if opcode == Opcode.MESSAGE:
        return Message.read(s, len(body))
    parsers = {Opcode.SCHEMA: Schema.read, Opcode.CHANNEL: Channel.read, Opcode.CHUNK: Chunk.read,
               Opcode.METADATA: Metadata.read, Opcode.ATTACHMENT: Attachment.read,
               Opcode.HEADER: Header.read, Opcode.FOOTER: Footer.read, Opcode.DATA_END: DataEnd.read}
    p = parsers.get(opcode)
    return p(s) if p is not None else None  # indexes, statistics, ...: not needed


def _records(w: _Walker, out: LogContents) -> Iterator[Any]:
    """Yield parsed records; sets ``out.stop_reason`` / ``out.complete``."""
    while True:
        start = w.pos
        head = w.read_exact(_RECORD_HEAD)
        if head is None:
            if start >= w.size:
                out.stop_reason = "file ends without the MCAP footer (writer killed before close?)"
            else:
                out.stop_reason = f"file ends inside a record header at byte {start} (truncated)"
            return
        opcode, length = struct.unpack("<BQ", head)
        if length > w.size - w.pos:
            out.stop_reason = (f"record at byte {start} (opcode {opcode:#04x}) claims {length} bytes but "
                               f"only {w.size - w.pos} remain (truncated or corrupt)")
            return
        body = w.read_exact(length)
        if body is None:
            out.stop_reason = f"short read in record at byte {start}"
            return
        try:
            rec = _parse(opcode, body)
            inner = breakup_chunk(rec, validate_crc=True) if isinstance(rec, Chunk) else None
        except (McapError, struct.error, ValueError, UnicodeDecodeError, IndexError, KeyError,
                OverflowError, MemoryError) as exc:
            out.stop_reason = f"corrupt record at byte {start} (opcode {opcode:#04x}): {type(exc).__name__}"
            return
        out.readable_bytes = w.pos
        if inner is not None:
            yield from inner
        elif rec is not None:
            yield rec
        if isinstance(rec, Footer):
            magic = w.read_exact(len(MAGIC))
            if magic == MAGIC:
                out.readable_bytes = w.pos
                out.complete = True
            else:
                out.stop_reason = "footer not followed by the closing MCAP magic"
            return


def read_log(path: str | os.PathLike[str], *, progress: bool | None = None) -> LogContents:
    """Read every complete record of a (possibly truncated) monitor MCAP log.

    Args:
        path: the ``.mcap`` file.
        progress: show a tqdm bar on stderr; None = only for files over
            :data:`PROGRESS_BYTES`.

    Returns:
        The recovered :class:`LogContents`; ``complete`` says whether the file was
        finished, ``unreadable_bytes`` how much of the tail was lost.

    Raises:
        LogFormatError: the file is missing, empty, or does not start with the MCAP magic.
    """
    p = Path(path)
    if not p.is_file():
        raise LogFormatError(f"{p}: no such file")
    size = p.stat().st_size
    out = LogContents(path=str(p), size=size)
    if progress is None:
        progress = size > PROGRESS_BYTES
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=size, unit="B", unit_scale=True, desc=f"reading {p.name}", leave=False)
    channels: dict[int, Channel] = {}
    schemas: dict[int, Schema] = {}
    try:
        with open(p, "rb") as f:
            w = _Walker(f, size, bar)
            magic = w.read_exact(len(MAGIC))
            if magic != MAGIC:
                kind = "empty file" if size == 0 else "does not start with the MCAP magic"
                raise LogFormatError(f"{p}: not an MCAP file ({kind}; {size} bytes)")
            out.readable_bytes = w.pos
            for rec in _records(w, out):
                if isinstance(rec, Header):
                    out.library = rec.library
                elif isinstance(rec, Schema):
                    schemas[rec.id] = rec
                    out.schemas[rec.name] = (rec.encoding, rec.data)
                elif isinstance(rec, Channel):
                    channels[rec.id] = rec
                elif isinstance(rec, Message):
                    _take_message(out, channels, rec)
                elif isinstance(rec, Metadata):
                    merged = out.metadata.setdefault(rec.name, {})
                    merged.update(_decode_metadata(rec.metadata))
                elif isinstance(rec, Attachment):
                    out.attachments[rec.name] = bytes(rec.data)
    finally:
        if bar is not None:
            bar.close()
    out.unreadable_bytes = 0 if out.complete else size - out.readable_bytes
    return out


def _take_message(out: LogContents, channels: dict[int, Channel], rec: Message) -> None:
    ch = channels.get(rec.channel_id)
    if ch is None:  # a message before its channel: corrupt writer, skip it
        out.bad_payloads += 1
        return
    out.counts[ch.topic] = out.counts.get(ch.topic, 0) + 1
    if ch.message_encoding != "json":
        return
    try:
        obj = json.loads(rec.data)
    except (ValueError, UnicodeDecodeError):
        out.bad_payloads += 1
        return
    if not isinstance(obj, dict):
        out.bad_payloads += 1
        return
    obj["_log_time"] = int(rec.log_time)
    out.messages.setdefault(ch.topic, []).append(obj)


# --------------------------------------------------------------------------- models


def load_model(contents: LogContents, source: str = "auto") -> tuple[Any, str]:
    """Rebuild the logged MuJoCo model from the log's attachments.

    Args:
        contents: a read log.
        source: ``"xml"`` (``model.xml`` plus ``assets/*`` through
            ``MjModel.from_xml_string``), ``"mjb"`` (the exact compiled binary; needs
            the same MuJoCo version), or ``"auto"``: mjb when the log was written by
            this MuJoCo version (bit-exact geometry), else xml.

    Returns:
        (model, description of the source used).

    Raises:
        LogFormatError: the log has no usable model attachment.
        InvalidInputError: ``source`` is not one of the three.
    """
    import mujoco

    if source not in ("auto", "xml", "mjb"):
        raise InvalidInputError(f"model source must be 'auto', 'xml' or 'mjb', got {source!r}")
    att = contents.attachments
    logged_version = str(contents.run.get("mujoco_version", ""))
    order = [source] if source != "auto" else (
        ["mjb", "xml"] if logged_version == mujoco.__version__ else ["xml", "mjb"])
    errors = []
    for kind in order:
        try:
            if kind == "mjb":
                if topics.ATTACHMENT_MJB not in att:
                    raise LogFormatError("no model.mjb attachment")
                if logged_version and logged_version != mujoco.__version__:
                    raise LogFormatError(f"model.mjb was written by MuJoCo {logged_version}, "
                                         f"this is {mujoco.__version__}")
                m = mujoco.MjModel.from_binary_path("model.mjb", {"model.mjb": att[topics.ATTACHMENT_MJB]})
                return m, "model.mjb (exact compiled model)"
            if topics.ATTACHMENT_XML not in att:
                raise LogFormatError("no model.xml attachment")
            assets = {k[len(topics.ASSET_PREFIX):]: v for k, v in att.items()
                      if k.startswith(topics.ASSET_PREFIX)}
            m = mujoco.MjModel.from_xml_string(att[topics.ATTACHMENT_XML].decode("utf-8"), assets=assets)
            return m, f"model.xml + {len(assets)} asset(s)"
        except (LogFormatError, ValueError, TypeError, UnicodeDecodeError, mujoco.FatalError) as exc:
            errors.append(f"{kind}: {exc}")
    raise LogFormatError(f"{contents.path}: cannot rebuild the model ({'; '.join(errors)})")


def geometry_deviation(model_a: Any, model_b: Any, qpos: Any = None) -> float:
    """Max world-position difference (m) of geoms and mesh vertices between two models.

    Both models must have the same structure (nq, nbody, ngeom, geom types, body,
    geom and joint names, mesh vertex counts); otherwise ``inf``. Evaluated at ``qpos`` (default ``qpos0``).
    Mesh vertex sets are compared as sorted clouds (re-compiled meshes may reorder).
    """
    import mujoco
    import numpy as np

    a, b = model_a, model_b
    if (a.nq, a.nbody, a.ngeom, a.nmesh, a.nmocap) != (b.nq, b.nbody, b.ngeom, b.nmesh, b.nmocap):
        return math.inf
    if not np.array_equal(a.geom_type, b.geom_type) or not np.array_equal(a.geom_bodyid, b.geom_bodyid):
        return math.inf
    for obj, n in ((mujoco.mjtObj.mjOBJ_GEOM, a.ngeom), (mujoco.mjtObj.mjOBJ_BODY, a.nbody),
                   (mujoco.mjtObj.mjOBJ_JOINT, a.njnt)):
        if any(mujoco.mj_id2name(a, obj, i) != mujoco.mj_id2name(b, obj, i) for i in range(n)):
            return math.inf  # names are how certificates refer to geoms
    da, db = mujoco.MjData(a), mujoco.MjData(b)
    if qpos is not None:
        da.qpos[:] = qpos
        db.qpos[:] = qpos
    mujoco.mj_kinematics(a, da)
    mujoco.mj_kinematics(b, db)
    dev = float(np.max(np.abs(da.geom_xpos - db.geom_xpos), initial=0.0))
    nonmesh = a.geom_type != mujoco.mjtGeom.mjGEOM_MESH
    dev = max(dev, float(np.max(np.abs(a.geom_size[nonmesh] - b.geom_size[nonmesh]), initial=0.0)))
    for g in np.flatnonzero(~nonmesh):
        clouds = []
        for m, d in ((a, da), (b, db)):
            i = m.geom_dataid[g]
            v = m.mesh_vert[m.mesh_vertadr[i]:m.mesh_vertadr[i] + m.mesh_vertnum[i]].astype(np.float64)
            clouds.append(d.geom_xpos[g] + v @ d.geom_xmat[g].reshape(3, 3).T)
        if clouds[0].shape != clouds[1].shape:
            return math.inf
        # match vertices by nearest neighbour (order may differ after re-compilation)
        from scipy.spatial import cKDTree

        dist, _ = cKDTree(clouds[1]).query(clouds[0])
        dist2, _ = cKDTree(clouds[0]).query(clouds[1])
        dev = max(dev, float(dist.max(initial=0.0)), float(dist2.max(initial=0.0)))
    return dev


__all__ = ["LogContents", "read_log", "load_model", "geometry_deviation", "MAGIC", "PROGRESS_BYTES"]
