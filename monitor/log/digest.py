"""Tamper evidence for monitor logs: a SHA-256 digest over every record, sealed at close.

The writer feeds every message, attachment and metadata record it writes to a
:class:`Digest` and, when it closes the file, writes :meth:`Digest.seal` as one last
metadata record named :data:`METADATA_DIGEST`. The reader feeds the same records, in
file order, to its own :class:`Digest`; review compares the two.

What a matching seal proves: the messages (topic, times, sequence, payload bytes, in
their order), the attachments (name, media type, bytes) and the metadata (raw stored
values) are exactly what the sealing writer wrote: no record was edited, dropped,
added or reordered since, whether by bit rot or by a tool that rewrites records.

What it does **not** prove: who wrote the log, or that the run happened. The seal
is not signed; anyone with this module can regenerate a consistent log (or strip the
seal, which makes the log look like one from a killed writer: review then says the
log is unsealed). Authenticity needs a key that the forger does not have: a log
written with a key holds HMAC-SHA256 checkpoints over this digest chain
(:mod:`monitor.log.sign`, ``review --key-file``). Whatever the seal says, ``review
--verify`` still recomputes every window from the model and the plan.

Independent of the file layout: messages are chained in order (chunked and
unchunked files keep the order of ``add_message``), attachments are chained in
order (they are never chunked), metadata records are hashed as a sorted set
(their position relative to chunked messages depends on chunk flushing).

Signed checkpoints (:mod:`monitor.log.sign`) use :meth:`Digest.checkpoint`: the message chain
at the checkpoint message and the attachment and metadata chains (metadata chained in their
own order, which chunking keeps) after the first ``a`` attachments and ``m`` metadata records.
A reader (``keep_prefixes=True``) keeps the chains' state after every attachment and metadata
record, because a chunked file may hold metadata written after a checkpoint before it.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

from monitor.log.topics import METADATA_FINALISE  # added after sealing by finalise_log: not covered

METADATA_DIGEST = "monitor.digest"
"""Metadata record holding the seal (written last, excluded from the digest itself)."""
ALGORITHM = "monitor-sha256-chain/1"
CHECKPOINT_ALGORITHM = "monitor-sha256-checkpoint/1"
"""Domain of :meth:`Digest.checkpoint` (the digest a signed checkpoint's HMAC covers)."""


def _field(h: Any, data: bytes) -> None:
    h.update(len(data).to_bytes(8, "little"))
    h.update(data)


class Digest:
    """Running digest of a log's records (feed in file order, then :meth:`seal` or compare).

    Example (the writer hook):
        >>> d = Digest()
        >>> d.message("/monitor/certificate", 0, 0, 0, b"{}")
        >>> seal = d.seal()  # add_metadata(METADATA_DIGEST, seal) before finish()
    """

    def __init__(self, keep_prefixes: bool = False) -> None:
        self._messages = hashlib.sha256(ALGORITHM.encode())
        self._attachments = hashlib.sha256(ALGORITHM.encode())
        self._metadata: list[bytes] = []
        self._metadata_chain = hashlib.sha256(ALGORITHM.encode())  # in record order (checkpoints)
        self.n_messages = 0
        self.n_attachments = 0
        self._keep = bool(keep_prefixes)
        # state (32 bytes) of the attachment / metadata chain after the first i records (readers only)
        self._att_states = [self._attachments.digest()] if self._keep else []
        self._meta_states = [self._metadata_chain.digest()] if self._keep else []
        self._att_now: tuple[int, bytes] | None = None  # (count, state): the writer's cache
        self._meta_now: tuple[int, bytes] | None = None

    def message(self, topic: str, log_time: int, publish_time: int, sequence: int, data: bytes) -> None:
        """One message record: channel topic, log/publish time (ns), sequence, payload bytes."""
        h = self._messages
        _field(h, topic.encode("utf-8", "surrogatepass"))
        h.update(int(log_time).to_bytes(8, "little", signed=False))
        h.update(int(publish_time).to_bytes(8, "little", signed=False))
        h.update(int(sequence).to_bytes(4, "little", signed=False))
        _field(h, bytes(data))
        self.n_messages += 1

    def attachment(self, name: str, media_type: str, data: bytes) -> None:
        """One attachment record: name, media type, bytes."""
        h = self._attachments
        _field(h, name.encode("utf-8", "surrogatepass"))
        _field(h, media_type.encode("utf-8", "surrogatepass"))
        _field(h, hashlib.sha256(bytes(data)).digest())
        self.n_attachments += 1
        if self._keep:
            self._att_states.append(h.digest())

    def metadata(self, name: str, values: dict[str, str]) -> None:
        """One metadata record with its raw (stored) string values; the seal record is ignored."""
        if name in (METADATA_DIGEST, METADATA_FINALISE):
            return
        rec = json.dumps([name, sorted(values.items())], ensure_ascii=True).encode()
        self._metadata.append(rec)
        _field(self._metadata_chain, rec)
        if self._keep:
            self._meta_states.append(self._metadata_chain.digest())

    @property
    def n_metadata(self) -> int:
        """Metadata records fed (the seal and the finalise record excluded)."""
        return len(self._metadata)

    def checkpoint(self, n_attachments: int | None = None, n_metadata: int | None = None) -> bytes:
        """32-byte digest of every message so far and of the first attachments / metadata records.

        Args:
            n_attachments, n_metadata: how many attachment / metadata records (in their own
                order) the checkpoint covers; None: all fed so far. Fewer than fed needs
                ``keep_prefixes=True``.

        Raises:
            IndexError: a count above the records fed, or a prefix without ``keep_prefixes``.
        """
        na = self.n_attachments if n_attachments is None else int(n_attachments)
        nm = self.n_metadata if n_metadata is None else int(n_metadata)
        att = self._state(na, self.n_attachments, self._attachments, self._att_states, "_att_now")
        meta = self._state(nm, self.n_metadata, self._metadata_chain, self._meta_states, "_meta_now")
        h = hashlib.sha256(CHECKPOINT_ALGORITHM.encode())
        h.update(self._messages.digest())
        h.update(att)
        h.update(meta)
        h.update(f"{self.n_messages}/{na}/{nm}".encode())
        return h.digest()

    def _state(self, n: int, fed: int, chain: Any, states: list[bytes], cache: str) -> bytes:
        """State of a chain after its first ``n`` records (``fed`` so far)."""
        if n < 0 or n > fed:
            raise IndexError(f"{n} records asked, {fed} fed")
        if n == fed:
            now = getattr(self, cache)
            if now is None or now[0] != n:
                now = (n, chain.digest())
                setattr(self, cache, now)
            return now[1]
        return states[n]  # IndexError without keep_prefixes

    def hexdigest(self) -> str:
        """Digest of everything fed so far (hex)."""
        h = hashlib.sha256(ALGORITHM.encode())
        h.update(self._messages.digest())
        h.update(self._attachments.digest())
        meta = hashlib.sha256()
        for m in sorted(self._metadata):
            _field(meta, m)
        h.update(meta.digest())
        h.update(f"{self.n_messages}/{self.n_attachments}/{len(self._metadata)}".encode())
        return h.hexdigest()

    def seal(self) -> dict[str, str]:
        """The seal record's values (strings, as MCAP metadata requires)."""
        return {"algorithm": ALGORITHM, "digest": self.hexdigest(), "messages": str(self.n_messages),
                "attachments": str(self.n_attachments), "metadata": str(len(self._metadata))}


def check_seal(seal: dict[str, str] | None, digest: Digest) -> tuple[str, str]:
    """Compare a log's seal with the digest of what was read.

    Returns:
        (status, detail): status ``"sealed"`` (match), ``"mismatch"`` (the log changed
        after it was sealed) or ``"unsealed"`` (no seal record: a writer without the
        hook, a killed writer, or a stripped seal).
    """
    if not seal:
        return "unsealed", "no digest seal (older writer, killed writer, or seal removed)"
    if seal.get("algorithm") != ALGORITHM:
        return "mismatch", f"seal algorithm {str(seal.get('algorithm'))[:40]!r} is not {ALGORITHM}"
    got = digest.seal()
    if seal.get("digest") == got["digest"]:
        return "sealed", f"digest matches ({got['messages']} messages, {got['attachments']} attachments)"
    counts = ", ".join(f"{k} {seal.get(k)} sealed vs {got[k]} read"
                       for k in ("messages", "attachments", "metadata") if seal.get(k) != got[k])
    return "mismatch", ("the log changed after its writer sealed it: digest differs"
                        + (f" ({counts})" if counts else " (same record counts: edited or reordered)"))


__all__ = ["Digest", "check_seal", "METADATA_DIGEST", "ALGORITHM", "CHECKPOINT_ALGORITHM"]
