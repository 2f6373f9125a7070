"""Test helper: copy a monitor log record by record, as a forger's or a repair tool would.

Shared by the review, forgery and hostile-reader tests (one copy of the MCAP plumbing).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from monitor.log.digest import METADATA_DIGEST
from monitor.log.reader import _decode_metadata
from monitor.log.writer import encode_metadata


def _compact(obj: Any) -> bytes:
    """JSON bytes in the writer's compact form (byte patterns stay comparable with genuine logs)."""
    return json.dumps(obj, separators=(",", ":")).encode()


def rewrite(src: Path, dst: Path, *, msg: Callable[[str, dict], Any] | None = None,
            metadata: Callable[[str, dict], dict] | None = None,
            attachments: Callable[[str, bytes], bytes | None] | None = None,
            chunked: bool = False, append: list[tuple[str, dict]] | None = None,
            encoding: Callable[[str, dict], str | None] | None = None) -> None:
    """Copy ``src`` to ``dst`` record by record; the digest seal is stripped (as a forger would).

    ``msg(topic, payload)`` (JSON channels) returns the payload (edited in place or new; raw bytes
    are written as they are), None to drop it, or a list of payloads to write several;
    ``metadata(name, values)`` edits decoded metadata values (without it the stored strings are
    copied unchanged); ``attachments(name, data)`` returns new bytes or None to drop;
    ``append``: ``(topic, payload)`` messages written after every other message (1 ns later each);
    ``encoding(topic, payload)`` (JSON channels): a message encoding other than json moves the message,
    unchanged, to a twin channel (same topic and schema) with that encoding; None keeps it.
    """
    with open(src, "rb") as fi, open(dst, "wb") as fo:
        r = make_reader(fi)
        w = Writer(fo, use_chunking=chunked,
                   compression=CompressionType.ZSTD if chunked else CompressionType.NONE)
        w.start(library=r.get_header().library)
        s = r.get_summary()
        smap = {sid: w.register_schema(x.name, x.encoding, x.data) for sid, x in s.schemas.items()}
        cmap = {cid: w.register_channel(c.topic, c.message_encoding, smap.get(c.schema_id, 0), c.metadata)
                for cid, c in s.channels.items()}
        twins: dict[tuple[int, str], int] = {}
        for m in r.iter_metadata():
            if m.name == METADATA_DIGEST:
                continue
            if metadata is None:
                w.add_metadata(m.name, dict(m.metadata))
            else:
                w.add_metadata(m.name, encode_metadata(metadata(m.name, _decode_metadata(dict(m.metadata)))))
        for a in r.iter_attachments():
            data = a.data if attachments is None else attachments(a.name, a.data)
            if data is not None:
                w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, data)
        for _, ch, m in r.iter_messages(log_time_order=False):
            outs: Any = [m.data]
            if ch.message_encoding == "json" and msg is not None:
                res = msg(ch.topic, json.loads(m.data))
                res = [] if res is None else (res if isinstance(res, list) else [res])
                outs = [o if isinstance(o, bytes) else _compact(o) for o in res]
            cid = cmap[ch.id]
            enc = None
            if encoding is not None and ch.message_encoding == "json":
                enc = encoding(ch.topic, json.loads(m.data))
            if enc is not None:
                if (ch.id, enc) not in twins:
                    twins[(ch.id, enc)] = w.register_channel(ch.topic, enc, smap.get(ch.schema_id, 0),
                                                             ch.metadata)
                cid = twins[(ch.id, enc)]
            for data in outs:
                w.add_message(cid, m.log_time, data, m.publish_time, m.sequence)
            last = (m.log_time, m.publish_time, m.sequence)
        by_topic = {c.topic: cid for cid, c in s.channels.items()}
        for k, (topic, payload) in enumerate(append or []):
            w.add_message(cmap[by_topic[topic]], last[0] + 1 + k, _compact(payload), last[1], last[2] + 1 + k)
        w.finish()


def file_records(src: Path) -> list:
    """Every schema, channel, message, metadata and attachment record of ``src`` in FILE order
    (chunks opened; the digest seal dropped): a forger's view, where metadata sit among messages."""
    from mcap.records import Attachment, Channel, Message, Metadata, Schema
    from mcap.stream_reader import StreamReader

    with open(src, "rb") as f:
        recs = [r for r in StreamReader(f, emit_chunks=False).records
                if isinstance(r, (Schema, Channel, Message, Metadata, Attachment))]
    return [r for r in recs if not (type(r).__name__ == "Metadata" and r.name == METADATA_DIGEST)]


def write_records(dst: Path, recs: list, *, chunked: bool = False) -> None:
    """Write ``recs`` (as :func:`file_records` returns them, reordered / edited at will) in that order."""
    from mcap.records import Attachment, Channel, Message, Metadata, Schema

    with open(dst, "wb") as fo:
        w = Writer(fo, use_chunking=chunked,
                   compression=CompressionType.ZSTD if chunked else CompressionType.NONE)
        w.start(library="rewrite")
        smap: dict[int, int] = {}
        cmap: dict[int, int] = {}
        for r in recs:
            if isinstance(r, Schema) and r.id not in smap:
                smap[r.id] = w.register_schema(r.name, r.encoding, r.data)
            elif isinstance(r, Channel) and r.id not in cmap:
                cmap[r.id] = w.register_channel(r.topic, r.message_encoding, smap.get(r.schema_id, 0),
                                                r.metadata)
            elif isinstance(r, Message):
                w.add_message(cmap[r.channel_id], r.log_time, r.data, r.publish_time, r.sequence)
            elif isinstance(r, Metadata):
                w.add_metadata(r.name, dict(r.metadata))
            elif isinstance(r, Attachment):
                w.add_attachment(r.create_time, r.log_time, r.name, r.media_type, r.data)
        w.finish()
