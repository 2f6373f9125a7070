"""Crash-tolerant, hostile-file-safe reader of monitor MCAP logs.

:func:`read_log` walks the file record by record with its own length-checked
framing (record bodies are parsed by ``mcap.records``), so that:

* a file cut anywhere (a killed writer, a truncated copy) yields every record
  that lies completely before the cut, and reports how many trailing bytes
  could not be read (``stop_kind="truncated"``);
* a record whose body is damaged but whose framing (opcode + length) is intact
  is skipped and counted in ``bad_records`` and the walk goes on; a damaged
  framing (a reserved opcode, a length beyond the file, a record below its
  minimum size) stops the walk (``stop_kind="corrupt"``);
* a file whose writer closed it (footer + closing magic at the end of the file)
  but that cannot be read up to its footer is reported as corrupt, not as a
  killed writer: bit rot never passes for a crash;
* work is bounded by the file size: reserved opcodes (0x00, 0x10-0x7F) stop the
  walk at once (50 MB of zeros after the magic is read in milliseconds),
  records that review does not need (indexes, statistics, private opcodes) are
  skipped with a seek, never read, the summary section is not walked, at most
  :data:`MAX_SKIPPED_IN_A_ROW` such records in a row are accepted, a record body
  is read only up to :data:`MAX_RECORD_BYTES`, and a chunk decompresses to at
  most :data:`MAX_CHUNK_BYTES` (a decompression bomb is a bad record);
* a file that is not MCAP raises :class:`monitor.errors.LogFormatError`.

JSON payloads are decoded with :func:`json.loads` only (never pickle or eval);
a payload with NaN/Infinity tokens, a duplicated key (parser-differential
forgery), nesting deeper than Python's recursion limit, or more than
:data:`MAX_JSON_BYTES` is a bad payload (skipped and counted).
Foxglove protobuf payloads are counted, not decoded (review does not need them).
Both writer formats are accepted: unchunked (flush per window) and chunked +
indexed (zstd, lz4 or uncompressed chunks); metadata values may be JSON-encoded
strings or plain strings.

The model attached to the log is rebuilt by :func:`load_model`, which compiles
the XML only from the attachments (an asset dict): ``<include>``, directory
attributes and ``file=`` values that are not plain names of attached assets are
rejected before MuJoCo sees the text, so a log can neither open ``/etc/passwd``
nor block on a FIFO.
"""

from __future__ import annotations

import io
import json
import math
import os
import re
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

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

from monitor.errors import InvalidInputError, LogFormatError
from monitor.log import topics
from monitor.log.digest import METADATA_DIGEST, Digest, check_seal
from monitor.log.sign import read_point

MAGIC = b"\x89MCAP0\r\n"
_RECORD_HEAD = 9  # opcode (1) + length (8)
PROGRESS_BYTES = 2 * 1024 * 1024
"""Files larger than this show a tqdm progress bar when ``progress=None`` (~ a few thousand windows)."""

MAX_RECORD_BYTES = 256 * 1024 * 1024
"""Largest record body (bytes) that is read into memory (model attachments, chunks). Larger
records stop the walk as corrupt: a monitor log never writes one, and a crafted length must
not make review allocate gigabytes."""
MAX_CHUNK_BYTES = 256 * 1024 * 1024
"""Largest decompressed chunk (bytes); a chunk that claims or yields more is a bad record."""
MAX_JSON_BYTES = 64 * 1024 * 1024
"""Largest JSON payload (bytes) that is decoded; larger ones are bad payloads."""
MAX_SKIPPED_IN_A_ROW = 10_000
"""Records that review skips (indexes, statistics, private opcodes) accepted in a row before
the walk stops as corrupt: a real log has a handful per chunk, a crafted one millions."""
MAX_BAD_IN_A_ROW = 100
"""Damaged records in a row after which the framing is taken as lost (the walk stops)."""
MAX_PROBLEMS = 20
"""Problems kept verbatim in :attr:`LogContents.problems` (all are counted)."""

_CONTENT = {Opcode.HEADER, Opcode.FOOTER, Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE, Opcode.CHUNK,
            Opcode.ATTACHMENT, Opcode.METADATA, Opcode.DATA_END}
"""Opcodes whose bodies review reads; every other valid opcode is skipped with a seek."""
_MIN_BODY = {Opcode.HEADER: 8, Opcode.FOOTER: 20, Opcode.SCHEMA: 14, Opcode.CHANNEL: 16,
             Opcode.MESSAGE: 22, Opcode.CHUNK: 40, Opcode.MESSAGE_INDEX: 6, Opcode.CHUNK_INDEX: 56,
             Opcode.ATTACHMENT: 36, Opcode.ATTACHMENT_INDEX: 48, Opcode.STATISTICS: 46,
             Opcode.METADATA: 8, Opcode.METADATA_INDEX: 20, Opcode.SUMMARY_OFFSET: 9, Opcode.DATA_END: 4}
"""Smallest body (bytes) of each MCAP record type (spec field sizes); below it the framing is corrupt."""


def _reserved(opcode: int) -> bool:
    """Opcodes that no MCAP writer emits (0x00 and 0x10-0x7F); 0x80-0xFF are private records."""
    return opcode == 0 or 0x10 <= opcode <= 0x7F


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
        stop_kind: ``"complete"``, ``"truncated"`` (the file ends inside a record and has no
            closing magic: a killed writer or a cut copy) or ``"corrupt"`` (damaged framing,
            or a file closed by its writer that cannot be read to its footer).
        closed_by_writer: the last bytes of the file are the closing MCAP magic.
        library: the MCAP header's library string.
        messages: decoded JSON payloads per JSON topic, in file order; each dict gains
            ``"_log_time"`` (ns) from the record.
        counts: number of complete messages per topic (all topics, foxglove included).
        bad_payloads: JSON messages whose payload could not be decoded (skipped).
        bad_records: records with intact framing whose body is damaged (skipped; a bad
            chunk may hide many messages).
        problems: the first :data:`MAX_PROBLEMS` reasons for bad payloads/records.
        metadata: metadata records merged by name (later records update earlier ones);
            values are JSON-decoded when they are JSON, else kept as strings.
        requests: the decoded ``monitor.request`` records (:data:`topics.METADATA_REQUEST`)
            in file order, one dict per record (NOT merged: two records naming one request
            id stay two entries, so review can see a redefinition).
        model_edits: the decoded ``monitor.model_edit`` records (:data:`topics.METADATA_MODEL_EDIT`)
            in file order, not merged.
        attachments: attachment name -> bytes (attachments with a wrong CRC are dropped
            and counted as bad records).
        schemas: schema name -> (encoding, data bytes) of every schema seen.
        records_walked: records whose header was read (chunk records included): the
            reader's work, bounded by the file size (at most size / 13 + a few).
        bytes_read: bytes read from the file (skipped records are seeked over, not read).
        seal: the ``monitor.digest`` seal record (None when the log is unsealed).
        seal_status: ``"sealed" | "mismatch" | "unsealed"`` and ``seal_detail`` (see
            :mod:`monitor.log.digest`: what a seal proves and what it does not).
        signatures: the signed checkpoints (:data:`topics.SIGNATURE` messages) in file order,
            each with the digest it must sign (:func:`monitor.log.sign.read_point`); checked
            with a key by :func:`monitor.log.sign.check_signatures`.
        digest_counts: (messages, attachments, metadata records) fed to the digest (all read).
    """

    path: str
    size: int = 0
    complete: bool = False
    readable_bytes: int = 0
    unreadable_bytes: int = 0
    stop_reason: str | None = None
    stop_kind: str = "truncated"
    closed_by_writer: bool = False
    library: str | None = None
    messages: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    bad_payloads: int = 0
    bad_records: int = 0
    problems: list[str] = field(default_factory=list)
    metadata: dict[str, dict[str, Any]] = field(default_factory=dict)
    requests: list[dict[str, Any]] = field(default_factory=list)
    model_edits: list[dict[str, Any]] = field(default_factory=list)
    attachments: dict[str, bytes] = field(default_factory=dict)
    schemas: dict[str, tuple[str, bytes]] = field(default_factory=dict)
    records_walked: int = 0
    bytes_read: int = 0
    seal: dict[str, str] | None = None
    seal_status: str = "unsealed"
    seal_detail: str = ""
    signatures: list[Any] = field(default_factory=list)
    digest_counts: tuple[int, int, int] = (0, 0, 0)

    @property
    def run(self) -> dict[str, Any]:
        """The merged ``monitor.run`` metadata (margin, epsilon, pairs, predictor, versions...)."""
        return self.metadata.get(topics.METADATA_RUN, {})

    @property
    def n_messages(self) -> int:
        """Total complete messages recovered (all topics)."""
        return sum(self.counts.values())

    @property
    def damaged(self) -> bool:
        """True when anything was skipped or the file is corrupt (not merely truncated)."""
        return bool(self.bad_payloads or self.bad_records or self.stop_kind == "corrupt")

    def problem(self, text: str) -> None:
        """Remember a problem (the first :data:`MAX_PROBLEMS` verbatim)."""
        if len(self.problems) < MAX_PROBLEMS:
            self.problems.append(text)

    def topic(self, name: str) -> list[dict[str, Any]]:
        """Decoded payloads of a JSON topic (empty list if none)."""
        return self.messages.get(name, [])

    def certificates(self) -> list[dict[str, Any]]:
        """Certificate payloads in window order (payloads without an integer index last)."""
        def key(m: dict[str, Any]) -> tuple[int, int, int]:
            k = m.get("index")
            ok = isinstance(k, int) and not isinstance(k, bool)
            return (0 if ok else 1, k if ok else 0, m["_log_time"])

        return sorted(self.topic(topics.CERTIFICATE), key=key)

    def plans_by_index(self) -> dict[int, dict[str, Any]]:
        """Plan payloads keyed by window index (the first of duplicated indices; see review)."""
        out: dict[int, dict[str, Any]] = {}
        for p in self.topic(topics.PLAN):
            k = p.get("index")
            if isinstance(k, int) and not isinstance(k, bool) and k not in out:
                out[k] = p
        return out


def _reject_constant(name: str) -> Any:
    raise ValueError(f"non-standard JSON constant {name}")


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    d = dict(pairs)
    if len(d) != len(pairs):
        keys = [k for k, _ in pairs]
        dup = next(k for k in keys if keys.count(k) > 1)
        raise ValueError(f"duplicated key {dup!r}")
    return d


_STRICT = json.JSONDecoder(parse_constant=_reject_constant, object_pairs_hook=_no_duplicates)


def loads_strict(data: bytes | str) -> Any:
    """Strict JSON: no NaN/Infinity, no duplicated keys; raises ValueError (also on deep nesting)."""
    try:
        text = data.decode("utf-8") if isinstance(data, (bytes, bytearray, memoryview)) else data
        return _STRICT.decode(text)
    except RecursionError as exc:
        raise ValueError("JSON nested too deeply") from exc


def _decode_metadata_value(v: str) -> Any:
    """A metadata value: JSON-encoded (old writer) or a plain string (new writer)."""
    if len(v) > MAX_JSON_BYTES:
        return v
    try:
        return loads_strict(v)
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
    """Length-checked record walk over a binary file object (or an in-memory chunk)."""

    def __init__(self, f: BinaryIO, size: int, bar: Any, out: LogContents | None = None) -> None:
        self.f, self.size, self.bar, self.out = f, size, bar, out
        self.pos = 0

    def read_exact(self, n: int) -> bytes | None:
        data = self.f.read(n)
        if self.out is not None:
            self.out.bytes_read += len(data)
        if len(data) != n:
            return None
        self.pos += n
        if self.bar is not None:
            self.bar.update(n)
        return data

    def skip(self, n: int) -> None:
        self.f.seek(n, io.SEEK_CUR)
        self.pos += n
        if self.bar is not None:
            self.bar.update(n)


def _parse(opcode: int, body: bytes) -> Any:
    s = ReadDataStream(io.BytesIO(body))
    if opcode == Opcode.MESSAGE:
        return Message.read(s, len(body))
    if opcode == Opcode.ATTACHMENT:
        crc = struct.unpack_from("<I", body, len(body) - 4)[0]
        if crc and zlib.crc32(body[:-4]) != crc:
            raise ValueError("attachment CRC mismatch")
    parsers = {Opcode.SCHEMA: Schema.read, Opcode.CHANNEL: Channel.read, Opcode.CHUNK: Chunk.read,
               Opcode.METADATA: Metadata.read, Opcode.ATTACHMENT: Attachment.read,
               Opcode.HEADER: Header.read, Opcode.FOOTER: Footer.read, Opcode.DATA_END: DataEnd.read}
    return parsers[opcode](s)  # trailing bytes are allowed: the MCAP spec lets records grow new fields


def _chunk_data(chunk: Chunk) -> bytes:
    """Decompressed chunk bytes, bounded by :data:`MAX_CHUNK_BYTES`; ValueError on any defect."""
    n = int(chunk.uncompressed_size)
    if n > MAX_CHUNK_BYTES:
        raise ValueError(f"chunk claims {n} uncompressed bytes (limit {MAX_CHUNK_BYTES})")
    if chunk.compression == "zstd":
        import zstandard

        try:
            with zstandard.ZstdDecompressor().stream_reader(io.BytesIO(chunk.data)) as r:
                data = r.read(n + 1)
        except zstandard.ZstdError as exc:
            raise ValueError(f"zstd: {exc}") from exc
    elif chunk.compression == "lz4":
        import lz4.frame

        try:
            data = lz4.frame.LZ4FrameDecompressor().decompress(chunk.data, max_length=n + 1)
        except RuntimeError as exc:
            raise ValueError(f"lz4: {exc}") from exc
    elif chunk.compression == "":
        data = chunk.data
    else:
        raise ValueError(f"unknown chunk compression {chunk.compression!r}")
    if len(data) != n:
        raise ValueError(f"chunk decompresses to {len(data)}{'+' if len(data) > n else ''} bytes, "
                         f"header says {n}")
    if chunk.uncompressed_crc and zlib.crc32(data) != chunk.uncompressed_crc:
        raise ValueError("chunk CRC mismatch")
    return bytes(data)


_PARSE_ERRORS = (McapError, struct.error, ValueError, UnicodeDecodeError, IndexError, KeyError,
                 OverflowError, MemoryError, EOFError)


def _records(w: _Walker, out: LogContents, *, in_chunk: bool = False) -> Iterator[Any]:
    """Yield parsed records; sets ``out.stop_reason`` / ``stop_kind`` / ``complete``.

    Inside a chunk (``in_chunk``) only schemas, channels and messages are yielded and a
    framing error ends the chunk (counted as a bad record), not the file.
    """
    skipped = bad_row = 0
    where = "chunk record" if in_chunk else "record"

    def corrupt(reason: str) -> None:
        if in_chunk:
            out.bad_records += 1
            out.problem(reason)
        else:
            out.stop_reason, out.stop_kind = reason, "corrupt"

    while True:
        start = w.pos
        if in_chunk and start >= w.size:
            return
        head = w.read_exact(_RECORD_HEAD)
        out.records_walked += 1
        if head is None:
            if in_chunk:
                corrupt(f"chunk ends inside a record header at chunk byte {start}")
            elif start >= w.size:
                out.stop_reason = "file ends without the MCAP footer (writer killed before close?)"
            else:
                out.stop_reason = f"file ends inside a record header at byte {start} (truncated)"
            return
        opcode, length = struct.unpack("<BQ", head)
        if _reserved(opcode):
            corrupt(f"reserved opcode {opcode:#04x} at {where} byte {start}: not MCAP framing")
            return
        if length > w.size - w.pos:
            msg = (f"{where} at byte {start} (opcode {opcode:#04x}) claims {length} bytes but only "
                   f"{w.size - w.pos} remain")
            if in_chunk:
                corrupt(msg)
            else:
                out.stop_reason = msg + " (truncated or corrupt)"
            return
        if length < _MIN_BODY.get(opcode, 0):
            corrupt(f"{where} at byte {start} (opcode {opcode:#04x}) has {length} bytes, below the "
                    f"{_MIN_BODY[opcode]} of its type")
            return
        wanted = opcode in _CONTENT and not (in_chunk and opcode not in
                                             (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE))
        if not wanted:
            skipped += 1
            if skipped > MAX_SKIPPED_IN_A_ROW:
                corrupt(f"more than {MAX_SKIPPED_IN_A_ROW} index/private records in a row at byte {start}")
                return
            w.skip(length)
            if not in_chunk:
                out.readable_bytes = w.pos
            continue
        skipped = 0
        if length > MAX_RECORD_BYTES:
            corrupt(f"{where} at byte {start} (opcode {opcode:#04x}) claims {length} bytes, above the "
                    f"{MAX_RECORD_BYTES}-byte limit")
            return
        body = w.read_exact(length)
        if body is None:
            out.stop_reason = f"short read in record at byte {start}"
            return
        try:
            rec = _parse(opcode, body)
            inner = None
            if isinstance(rec, Chunk):
                data = _chunk_data(rec)
                inner = list(_records(_Walker(io.BytesIO(data), len(data), None), out, in_chunk=True))
        except _PARSE_ERRORS as exc:
            out.bad_records += 1
            out.problem(f"damaged {where} at byte {start} (opcode {opcode:#04x}): {type(exc).__name__}: "
                        f"{str(exc)[:200]}")
            bad_row += 1
            if not in_chunk:
                out.readable_bytes = w.pos
            if bad_row >= MAX_BAD_IN_A_ROW:
                corrupt(f"{MAX_BAD_IN_A_ROW} damaged records in a row up to byte {w.pos}: framing lost")
                return
            continue
        bad_row = 0
        if not in_chunk:
            out.readable_bytes = w.pos
        if inner is not None:
            yield from inner
        else:
            yield rec
        if isinstance(rec, DataEnd):  # the summary section follows: jump to the footer
            _read_footer(w, out)
            return
        if isinstance(rec, Footer):
            _closing_magic(w, out)
            return


_FOOTER_RECORD = _RECORD_HEAD + 20


def _read_footer(w: _Walker, out: LogContents) -> None:
    """After DataEnd: skip the summary section (never walked) and check footer + closing magic."""
    if not out.closed_by_writer:  # cut inside the summary: every data record was read
        out.stop_reason = "file ends inside the summary section (every data record was read)"
        out.readable_bytes = w.pos
        return
    tail = w.size - len(MAGIC) - _FOOTER_RECORD
    if tail < w.pos:
        out.stop_reason, out.stop_kind = "no room for the footer after the data section", "corrupt"
        return
    w.skip(tail - w.pos)
    head = w.read_exact(_RECORD_HEAD)
    if head is None or struct.unpack("<BQ", head) != (Opcode.FOOTER, 20):
        out.stop_reason, out.stop_kind = "data section not followed by a footer at the end", "corrupt"
        return
    w.read_exact(20)
    _closing_magic(w, out)


def _closing_magic(w: _Walker, out: LogContents) -> None:
    magic = w.read_exact(len(MAGIC))
    if magic == MAGIC:
        out.readable_bytes = w.pos
        out.complete = True
        out.stop_kind = "complete"
        if w.pos != w.size:
            out.stop_reason = f"{w.size - w.pos} byte(s) after the closing magic"
            out.stop_kind = "corrupt"
            out.complete = False
    else:
        out.stop_reason, out.stop_kind = "footer not followed by the closing MCAP magic", "corrupt"


def _ends_with_magic(f: BinaryIO, size: int) -> bool:
    """True when the file's last bytes are the closing MCAP magic (restores the position)."""
    if size < 2 * len(MAGIC) + _FOOTER_RECORD:
        return False
    here = f.tell()
    f.seek(size - len(MAGIC))
    closed = f.read(len(MAGIC)) == MAGIC
    f.seek(here)
    return closed


def read_log(path: str | os.PathLike[str], *, progress: bool | None = None) -> LogContents:
    """Read every complete record of a (possibly truncated or damaged) monitor MCAP log.

    Args:
        path: the ``.mcap`` file.
        progress: show a tqdm bar on stderr; None = only for files over
            :data:`PROGRESS_BYTES`.

    Returns:
        The recovered :class:`LogContents`; ``complete`` says whether the file was
        finished, ``stop_kind`` whether an early stop looks like a cut (``"truncated"``)
        or damage (``"corrupt"``), ``unreadable_bytes`` how much of the tail was lost,
        ``bad_payloads``/``bad_records`` what was skipped.

    Raises:
        LogFormatError: the file is missing, not a regular file, empty, or does not
            start with the MCAP magic.
    """
    p = Path(path)
    if not p.is_file():  # also refuses FIFOs and devices (a read would block or never end)
        raise LogFormatError(f"{p}: no such file (or not a regular file)")
    size = p.stat().st_size
    out = LogContents(path=str(p), size=size)
    if progress is None:
        progress = size > PROGRESS_BYTES
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=size, unit="B", unit_scale=True, desc=f"reading {p.name}", leave=False)
    channels: dict[int, Channel] = {}
    digest = Digest(keep_prefixes=True)
    try:
        with open(p, "rb") as f:
            w = _Walker(f, size, bar, out)
            magic = w.read_exact(len(MAGIC))
            if magic != MAGIC:
                kind = "empty file" if size == 0 else "does not start with the MCAP magic"
                raise LogFormatError(f"{p}: not an MCAP file ({kind}; {size} bytes)")
            out.closed_by_writer = _ends_with_magic(f, size)
            out.readable_bytes = w.pos
            for rec in _records(w, out):
                if isinstance(rec, Header):
                    out.library = rec.library
                elif isinstance(rec, Schema):
                    out.schemas[rec.name] = (rec.encoding, rec.data)
                elif isinstance(rec, Channel):
                    channels[rec.id] = rec
                elif isinstance(rec, Message):
                    ch = channels.get(rec.channel_id)
                    if ch is not None and ch.topic == topics.SIGNATURE:  # before the digest takes it
                        out.signatures.append(read_point(rec.data, digest,
                                                         len(out.messages.get(topics.CERTIFICATE, ()))))
                    digest.message(ch.topic if ch else "", rec.log_time, rec.publish_time, rec.sequence,
                                   rec.data)
                    _take_message(out, channels, rec)
                elif isinstance(rec, Metadata):
                    if rec.name == METADATA_DIGEST:
                        out.seal = dict(rec.metadata)
                        continue
                    digest.metadata(rec.name, rec.metadata)
                    decoded = _decode_metadata(rec.metadata)
                    if rec.name == topics.METADATA_REQUEST:
                        out.requests.append(decoded)
                    elif rec.name == topics.METADATA_MODEL_EDIT:
                        out.model_edits.append(decoded)
                    merged = out.metadata.setdefault(rec.name, {})
                    merged.update(decoded)
                elif isinstance(rec, Attachment):
                    digest.attachment(rec.name, rec.media_type, rec.data)
                    out.attachments[rec.name] = bytes(rec.data)
    finally:
        if bar is not None:
            bar.close()
    if not out.complete and out.closed_by_writer and out.stop_kind != "corrupt":
        # the writer closed this file, yet it cannot be read up to its footer: damage, not a crash
        out.stop_kind = "corrupt"
        out.stop_reason = (f"{out.stop_reason}; but the file ends with the closing MCAP magic, so its "
                           f"writer finished it: the file is damaged, not cut")
    out.unreadable_bytes = 0 if out.complete else size - out.readable_bytes
    out.seal_status, out.seal_detail = check_seal(out.seal, digest)
    out.digest_counts = (digest.n_messages, digest.n_attachments, digest.n_metadata)
    return out


_JSON_ONLY = frozenset(topics.JSON_TOPICS) | {topics.SIGNATURE}
"""Topics the writer writes only as JSON: a message of theirs on another encoding is a bad payload
(the digest chain covers a message's topic, times, sequence and bytes, not its channel record)."""


def _take_message(out: LogContents, channels: dict[int, Channel], rec: Message) -> None:
    ch = channels.get(rec.channel_id)
    if ch is None:  # a message before its channel: corrupt writer, skip it
        out.bad_payloads += 1
        out.problem(f"message on unknown channel {rec.channel_id} (log time {rec.log_time})")
        return
    out.counts[ch.topic] = out.counts.get(ch.topic, 0) + 1
    if ch.message_encoding != "json":
        if ch.topic in _JSON_ONLY:  # a forger's twin channel: the digest and signatures do not cover channels
            out.bad_payloads += 1
            out.problem(f"{ch.topic} message (sequence {rec.sequence}) on a channel with message encoding "
                        f"{ch.message_encoding[:40]!r}, not json: not decoded (the writer writes json)")
        return
    try:
        if len(rec.data) > MAX_JSON_BYTES:
            raise ValueError(f"{len(rec.data)} bytes, above the {MAX_JSON_BYTES}-byte limit")
        obj = loads_strict(rec.data)
    except (ValueError, UnicodeDecodeError) as exc:
        out.bad_payloads += 1
        out.problem(f"{ch.topic} message (sequence {rec.sequence}): undecodable JSON: {str(exc)[:200]}")
        return
    if not isinstance(obj, dict):
        out.bad_payloads += 1
        out.problem(f"{ch.topic} message (sequence {rec.sequence}): payload is not a JSON object")
        return
    obj["_log_time"] = int(rec.log_time)
    out.messages.setdefault(ch.topic, []).append(obj)


# --------------------------------------------------------------------------- models


_INCLUDE = re.compile(rb"<\s*include\b", re.IGNORECASE)
_DIR_ATTR = re.compile(rb"\b(meshdir|texturedir|assetdir)\s*=\s*(\"[^\"]*\"|'[^']*')", re.IGNORECASE)
_FILE_ATTR = re.compile(rb"\b(file\w*)\s*=\s*(\"[^\"]*\"|'[^']*')", re.IGNORECASE)
_PLAIN_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]{0,200}")


def check_xml_safe(xml: bytes, assets: dict[str, bytes]) -> None:
    """Refuse MJCF text that could make MuJoCo read anything but the given asset dict.

    Rejected: any ``<include`` (an include of a FIFO blocks forever, of ``/etc/passwd`` reads
    it), a non-empty ``meshdir``/``texturedir``/``assetdir`` (would move lookups out of the
    asset dict), and any ``file*=`` value that is not a plain name (letters, digits, ``_.-``;
    no separators, no entity references) of an attached asset. The scan is on the raw text
    (comments included), so it can only err towards rejecting.

    Raises:
        LogFormatError: naming the offending construct.
    """
    if _INCLUDE.search(xml):
        raise LogFormatError("model.xml contains <include>: refused (a log must be self-contained)")
    for m in _DIR_ATTR.finditer(xml):
        if m.group(2)[1:-1].strip():
            raise LogFormatError(f"model.xml sets {m.group(1).decode('ascii', 'replace')}="
                                 f"{m.group(2)[:80].decode('utf-8', 'replace')}: refused (assets come only "
                                 f"from the log's attachments)")
    for m in _FILE_ATTR.finditer(xml):
        value = m.group(2)[1:-1].decode("utf-8", "replace")
        if not _PLAIN_NAME.fullmatch(value) or value not in assets:
            raise LogFormatError(f"model.xml {m.group(1).decode('ascii', 'replace')}={value[:80]!r} is not "
                                 f"the plain name of an attached asset: refused")


def _compile(kind: str, att: dict[str, bytes]) -> tuple[Any, str]:
    import mujoco

    if kind == "mjb":
        if topics.ATTACHMENT_MJB not in att:
            raise LogFormatError("no model.mjb attachment")
        m = mujoco.MjModel.from_binary_path("model.mjb", {"model.mjb": att[topics.ATTACHMENT_MJB]})
        return m, "model.mjb (exact compiled model)"
    if topics.ATTACHMENT_XML not in att:
        raise LogFormatError("no model.xml attachment")
    assets = {k[len(topics.ASSET_PREFIX):]: v for k, v in att.items() if k.startswith(topics.ASSET_PREFIX)}
    xml = att[topics.ATTACHMENT_XML]
    check_xml_safe(xml, assets)
    m = mujoco.MjModel.from_xml_string(xml.decode("utf-8"), assets=assets)
    return m, f"model.xml + {len(assets)} asset(s)"


def load_model(contents: LogContents, source: str = "auto") -> tuple[Any, str]:
    """Rebuild the logged MuJoCo model from the log's attachments (never from the file system).

    Args:
        contents: a read log.
        source: ``"xml"`` (``model.xml`` plus ``assets/*`` through
            ``MjModel.from_xml_string`` with an asset dict, after :func:`check_xml_safe`),
            ``"mjb"`` (the exact compiled binary; needs the same MuJoCo version), or
            ``"auto"``: mjb when it loads (bit-exact geometry), else xml. The logged
            ``mujoco_version`` is a claim and is not used to choose.

    Returns:
        (model, description of the source used).

    Raises:
        LogFormatError: the log has no usable model attachment.
        InvalidInputError: ``source`` is not one of the three.
    """
    import mujoco

    if source not in ("auto", "xml", "mjb"):
        raise InvalidInputError(f"model source must be 'auto', 'xml' or 'mjb', got {source!r}")
    order = [source] if source != "auto" else ["mjb", "xml"]
    errors = []
    for kind in order:
        try:
            return _compile(kind, contents.attachments)
        except (LogFormatError, ValueError, TypeError, UnicodeDecodeError, mujoco.FatalError) as exc:
            errors.append(f"{kind}: {exc}")
    raise LogFormatError(f"{contents.path}: cannot rebuild the model ({'; '.join(errors)})")


def model_consistency(contents: LogContents) -> dict[str, Any]:
    """Do the attached ``model.xml`` and ``model.mjb`` describe the same model?

    The XML is MuJoCo's 6-significant-digit rendering, so the check is the writer's own
    acceptance test: same structure and names, and world geometry (geoms and mesh vertices)
    within :data:`monitor.log.writer.XML_GEOMETRY_TOL` at ``qpos0`` and at a seeded
    perturbed configuration, plus identical collision-filter fields (contype, conaffinity,
    explicit pairs and excludes), which decide the candidate pair set.

    Returns:
        dict with ``status``: ``"consistent"``, ``"inconsistent"`` (both compiled and
        differ: a forged or damaged attachment) or ``"unchecked"`` (one is missing or
        does not load here, e.g. an MJB from another MuJoCo version), and ``detail``.
    """
    import mujoco
    import numpy as np

    from monitor.log.writer import XML_GEOMETRY_TOL, _valid_qpos

    att = contents.attachments
    models = {}
    for kind in ("xml", "mjb"):
        try:
            models[kind] = _compile(kind, att)[0]
        except (LogFormatError, ValueError, TypeError, UnicodeDecodeError, mujoco.FatalError) as exc:
            models[kind] = f"{type(exc).__name__}: {exc}"
    missing = {k: v for k, v in models.items() if isinstance(v, str)}
    if missing:
        return {"status": "unchecked",
                "detail": "model.xml cannot be cross-checked against model.mjb: "
                          + "; ".join(f"{k}: {v}" for k, v in missing.items())}
    a, b = models["xml"], models["mjb"]
    dev = geometry_deviation(a, b)
    if math.isfinite(dev) and a.nq:
        q = np.random.default_rng(0).uniform(-1.0, 1.0, a.nq)
        dev = max(dev, geometry_deviation(a, b, qpos=_valid_qpos(b, q)))
    fields = ("geom_contype", "geom_conaffinity", "pair_geom1", "pair_geom2", "exclude_signature",
              "body_weldid", "body_parentid", "body_mocapid", "jnt_type", "jnt_qposadr", "body_dofnum")
    differ = [f for f in fields if not np.array_equal(getattr(a, f), getattr(b, f))]
    if int(a.opt.disableflags) != int(b.opt.disableflags):
        differ.append("opt.disableflags")
    if not (dev <= XML_GEOMETRY_TOL) or differ:
        why = [f"geometry differs by {dev:.3g} m (tolerance {XML_GEOMETRY_TOL} m)"] if not (
            dev <= XML_GEOMETRY_TOL) else []
        why += [f"{f} differs" for f in differ]
        return {"status": "inconsistent", "detail": "model.xml and model.mjb are different models: "
                + "; ".join(why)}
    return {"status": "consistent", "detail": f"model.xml matches model.mjb within {dev:.3g} m"}


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


__all__ = ["LogContents", "read_log", "load_model", "model_consistency", "check_xml_safe", "loads_strict",
           "geometry_deviation", "MAGIC", "PROGRESS_BYTES", "MAX_RECORD_BYTES", "MAX_CHUNK_BYTES",
           "MAX_JSON_BYTES"]
