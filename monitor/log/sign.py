"""Signed monitor logs: HMAC-SHA256 checkpoints over the digest chain (authenticity).

The digest seal (:mod:`monitor.log.digest`) is unkeyed: anyone can rewrite a log consistently
and seal it again. A log written with a key (``MonitorLog(..., key=...)``, or the file named by
the environment variable :data:`KEY_FILE_ENV`) also holds **signed checkpoints**, messages on
:data:`monitor.log.topics.SIGNATURE`:

* checkpoint 0 when the log opens (run metadata, model attachments), one after every window
  (written before the per-window flush) and a final one (``"final": true``) at close;
* each is ``{"algorithm", "key_id", "checkpoint", "windows", "messages", "attachments",
  "metadata", "final", "mac"}`` with ``mac = HMAC-SHA256(key, DOMAIN + canonical JSON of the
  other fields + Digest.checkpoint(attachments, metadata))``: every message before it (earlier
  checkpoints included, so none can be dropped or reordered), the first ``attachments``
  attachments and ``metadata`` metadata records (each in its own order: a chunked file keeps
  those orders but not their position among messages);
* the ``monitor.run`` metadata says ``"signature": {"algorithm", "key_id", "topic"}``, inside
  what checkpoint 0 signs. The key id is the first 8 bytes of SHA-256 of the key, never the key.

A writer killed mid-run leaves every window before its last flush signed; review
(:func:`check_signatures`) reports exactly which windows are covered by a valid checkpoint and
which trail after the last one.

What a valid signature proves: the covered records were written by a process holding the key,
unchanged since. What it does not prove: that the process told the truth (review still
re-derives every window), that the key was not stolen (anyone with the key can sign anything),
or that a log without a signed close is whole (a copy cut after a checkpoint reads like a
killed writer's log: only a signed close rules that out).
"""

from __future__ import annotations

import hashlib
import hmac
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from monitor.errors import LogKeyError
from monitor.log import topics
from monitor.log.digest import Digest

SIGN_ALGORITHM = "hmac-sha256/monitor-checkpoint-1"
"""Stored in every checkpoint and in the run metadata's ``signature`` claim."""
KEY_FILE_ENV = "MONITOR_LOG_KEY_FILE"
"""Environment variable naming a key FILE, read by :class:`~monitor.log.writer.MonitorLog` when no
``key`` is given and by ``review`` when no ``--key-file`` is given."""
MIN_KEY_BYTES = 16
"""Shortest key accepted (bytes). Use random bytes, e.g. ``head -c 32 /dev/urandom > log.key``."""
RUN_KEY = "signature"
"""``monitor.run`` key of the signature claim (algorithm, key id, topic)."""
_TRAILING = b" \t\r\n"
"""Trailing bytes removed from every key (a key file's final newline; see :func:`as_key`)."""
_DOMAIN = b"monitor-log-signature/1\0"
_FIELDS = ("algorithm", "key_id", "checkpoint", "windows", "messages", "attachments", "metadata", "final")
_PAYLOAD = ('{"algorithm":"%s","key_id":"%s","checkpoint":%d,"windows":%d,"messages":%d,"attachments":%d,'
            '"metadata":%d,"final":%s,"mac":"%s"}')
"""The checkpoint payload (compact JSON; the fields are a fixed ASCII string, a hex id and ints)."""


def key_id(key: bytes) -> str:
    """Public id of a key: the first 8 bytes of its SHA-256, hex (16 characters)."""
    return hashlib.sha256(key).hexdigest()[:16]


def as_key(key: Any, what: str = "key") -> bytes:
    """Validate a key: bytes (or bytearray / memoryview) of at least :data:`MIN_KEY_BYTES`.

    Trailing ASCII whitespace (space, tab, CR, LF) is removed, as :func:`load_key` removes it from a
    key file: a key given in code and the same bytes written to a key file are one key (a random
    key ending in such a byte signed with one id and reviewed with another).

    Raises:
        LogKeyError: another type (a ``str`` is refused: a path or a passphrase? use
            :func:`load_key` for a file) or a key that is too short.
    """
    if not isinstance(key, (bytes, bytearray, memoryview)):
        raise LogKeyError(f"{what} must be bytes (for a key file use monitor.log.sign.load_key(path) or "
                          f"${KEY_FILE_ENV}), got {type(key).__name__}")
    key = bytes(key).rstrip(_TRAILING)
    if len(key) < MIN_KEY_BYTES:
        raise LogKeyError(f"{what} has {len(key)} byte(s); at least {MIN_KEY_BYTES} are needed")
    return key


def load_key(path: str | os.PathLike[str]) -> bytes:
    """The key in a key file: its bytes, trailing ASCII whitespace (a final newline) removed.

    Raises:
        LogKeyError: the file is missing, unreadable, not a regular file, empty or too short.
    """
    p = Path(path)
    if not p.is_file():
        raise LogKeyError(f"key file {str(p)!r}: no such file (or not a regular file)")
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise LogKeyError(f"key file {str(p)!r}: cannot read it ({exc.strerror or exc})") from exc
    data = data.rstrip(_TRAILING)
    if not data:
        raise LogKeyError(f"key file {str(p)!r} is empty")
    return as_key(data, f"key file {str(p)!r}")


def key_from_env() -> bytes | None:
    """The key of the file named by :data:`KEY_FILE_ENV`; None when the variable is unset or empty.

    Raises:
        LogKeyError: the variable names an unusable file.
    """
    path = os.environ.get(KEY_FILE_ENV)
    if not path:
        return None
    try:
        return load_key(path)
    except LogKeyError as exc:
        raise LogKeyError(f"${KEY_FILE_ENV}: {exc}") from exc


def _keyed(key: bytes) -> Any:
    """The key's HMAC-SHA256 object before any data (copied per checkpoint: ~1 µs instead of ~5)."""
    return hmac.new(key, digestmod=hashlib.sha256)


def _mac(keyed: Any, fields: dict[str, Any], chain: bytes) -> str:
    """HMAC-SHA256 (hex) of the domain, the fields (fixed order, ``|``-separated) and the chain digest.

    The encoding is unambiguous for what a verifier accepts: ``algorithm`` and ``key_id`` are
    compared with the expected constants before the HMAC is checked, the counts are ints.
    """
    text = "%s|%s|%d|%d|%d|%d|%d|%s" % (fields["algorithm"], fields["key_id"], fields["checkpoint"],  # noqa: UP031
                                        fields["windows"], fields["messages"], fields["attachments"],
                                        fields["metadata"], "1" if fields["final"] is True else "0")
    h = keyed.copy()
    h.update(_DOMAIN + text.encode() + b"\0" + chain)
    return h.hexdigest()


class Signer:
    """Makes a log's checkpoints (the writer's side).

    Example:
        >>> s = Signer(b"0123456789abcdef")
        >>> payload = s.checkpoint(digest, windows=0)  # bytes of the /monitor/signature message
    """

    def __init__(self, key: bytes) -> None:
        key = as_key(key)
        self._keyed = _keyed(key)
        self.key_id = key_id(key)
        self.n = 0

    def claim(self) -> dict[str, str]:
        """The run metadata's :data:`RUN_KEY` value."""
        return {"algorithm": SIGN_ALGORITHM, "key_id": self.key_id, "topic": topics.SIGNATURE}

    def checkpoint(self, digest: Digest, windows: int, final: bool = False) -> bytes:
        """JSON payload of the next checkpoint over everything ``digest`` was fed."""
        fields = {"algorithm": SIGN_ALGORITHM, "key_id": self.key_id, "checkpoint": self.n,
                  "windows": int(windows), "messages": digest.n_messages,
                  "attachments": digest.n_attachments, "metadata": digest.n_metadata, "final": bool(final)}
        mac = _mac(self._keyed, fields, digest.checkpoint())
        self.n += 1
        return (_PAYLOAD % (SIGN_ALGORITHM, self.key_id, fields["checkpoint"], fields["windows"],  # noqa: UP031
                            fields["messages"], fields["attachments"], fields["metadata"],
                            "true" if final else "false", mac)).encode()

    def __repr__(self) -> str:  # never the key
        return f"Signer(key_id={self.key_id!r}, checkpoints={self.n})"


@dataclass
class SignPoint:
    """One checkpoint message as a reader found it.

    Attributes:
        payload: the decoded fields (None when undecodable).
        chain: :meth:`Digest.checkpoint` at the message for its claimed attachment / metadata
            counts (None when they cannot be taken: ``problem`` says why).
        problem: why the checkpoint is malformed (None: well formed).
        messages_before: messages read before it (all topics).
        certificates_before: certificate payloads decoded before it.
    """

    payload: dict[str, Any] | None
    chain: bytes | None
    problem: str | None
    messages_before: int
    certificates_before: int


def _is_count(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool) and x >= 0


def read_point(data: bytes, digest: Digest, certificates_before: int) -> SignPoint:
    """A checkpoint message met by a reader, before ``digest`` is fed the message itself."""
    from monitor.log.reader import loads_strict

    n = digest.n_messages
    try:
        payload = loads_strict(bytes(data)) if len(data) < 4096 else None
    except (ValueError, UnicodeDecodeError):
        payload = None
    if not isinstance(payload, dict):
        return SignPoint(None, None, "undecodable checkpoint payload", n, certificates_before)
    bad = [k for k in _FIELDS if k not in payload]
    bad += [] if isinstance(payload.get("mac"), str) else ["mac"]
    bad += [k for k in ("checkpoint", "windows", "messages", "attachments", "metadata")
            if k in payload and not _is_count(payload[k])]
    bad += [] if isinstance(payload.get("final", False), bool) else ["final"]
    if bad:
        return SignPoint(payload, None, f"malformed checkpoint (fields {sorted(set(bad))})", n,
                         certificates_before)
    try:
        chain = digest.checkpoint(payload["attachments"], payload["metadata"])
    except IndexError:
        return SignPoint(payload, None, f"it covers {payload['attachments']} attachment(s) and "
                         f"{payload['metadata']} metadata record(s), but only {digest.n_attachments} and "
                         f"{digest.n_metadata} precede it", n, certificates_before)
    return SignPoint(payload, chain, None, n, certificates_before)


@dataclass
class SignatureCheck:
    """What :func:`check_signatures` found (``to_json`` for review's output).

    Attributes:
        status: ``"verified"`` (every record covered by a valid checkpoint, signed close),
            ``"partial"`` (valid checkpoints, then records no valid checkpoint covers, or no
            signed close), ``"mismatch"`` (a checkpoint does not verify), ``"wrong_key"``,
            ``"unsigned"`` (no checkpoint), ``"not_checked"`` (signed, no key given).
        key_id: the given key's id (None without a key); ``log_key_id``: the log's claim.
        checkpoints, valid: checkpoint messages read, leading ones that verify.
        signed_windows: windows (certificate payloads) before the last valid checkpoint;
            ``unsigned_windows``: the window indices after it.
        signed_close: the last valid checkpoint is the final one and nothing follows it.
        first_bad: ``{"checkpoint", "windows", "reason"}`` of the first checkpoint that fails.
        critical, unverifiable, notes: finding texts for review.
    """

    status: str
    key_id: str | None = None
    log_key_id: str | None = None
    checkpoints: int = 0
    valid: int = 0
    signed_windows: int = 0
    unsigned_windows: list[Any] = field(default_factory=list)
    signed_close: bool = False
    first_bad: dict[str, Any] | None = None
    critical: list[str] = field(default_factory=list)
    unverifiable: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        """Plain dict (JSON-serialisable)."""
        from dataclasses import asdict

        return asdict(self)


def _point_problem(sp: SignPoint, j: int, keyed: Any, kid: str) -> str | None:
    if sp.problem is not None:
        return sp.problem
    p = sp.payload
    if p["key_id"] != kid:
        return f"signed with key id {str(p['key_id'])[:20]!r}, not the given key's {kid}"
    if p["algorithm"] != SIGN_ALGORITHM:
        return f"algorithm {str(p['algorithm'])[:40]!r} is not {SIGN_ALGORITHM}"
    if p["checkpoint"] != j:
        return f"it is numbered {p['checkpoint']}, checkpoint {j} was expected (one dropped or repeated)"
    if p["messages"] != sp.messages_before:
        return (f"it covers {p['messages']} message(s), {sp.messages_before} precede it (messages added or "
                f"dropped)")
    if p["windows"] != sp.certificates_before:
        return (f"it covers {p['windows']} window(s), {sp.certificates_before} certificate(s) were read "
                f"before it (certificates hidden from the reader, e.g. on a channel that is not json)")
    if not hmac.compare_digest(_mac(keyed, p, sp.chain), p["mac"]):
        return "its HMAC does not match: a record it covers was changed after signing"
    return None


def _windows_text(idx: list[Any]) -> str:
    shown = ", ".join(str(k)[:12] for k in idx[:8])
    return f"{len(idx)} window(s) ({shown}{', ...' if len(idx) > 8 else ''})"


def check_signatures(contents: Any, key: bytes | None) -> SignatureCheck:
    """Check a read log's checkpoints with ``key`` (see the module docstring).

    Findings (texts; review makes them findings): *critical*: a checkpoint that does not verify
    (the first one is named), a key given and the log unsigned or signed with another key id,
    records after the signed close, a log whose seal claims a close that is not signed;
    *unverifiable*: records after the last valid checkpoint (a writer killed inside a window, or
    records appended), no signed close (the log may have been cut after a checkpoint); *notes*:
    no key given for a signed log ("signature not checked"), the checkpoints verified.

    Args:
        contents: a :class:`~monitor.log.reader.LogContents`.
        key: the key (None: not checked); normalised as the writer does (:func:`as_key`).

    Raises:
        LogKeyError: a key that :func:`as_key` refuses.
    """
    points: list[SignPoint] = list(getattr(contents, "signatures", []))
    claim = contents.run.get(RUN_KEY)
    claim = claim if isinstance(claim, dict) else None
    first = points[0].payload if points and points[0].payload else {}
    log_kid = str((claim or {}).get("key_id") or first.get("key_id") or "")[:40] or None
    out = SignatureCheck("unsigned", log_key_id=log_kid, checkpoints=len(points))
    if key is None:
        if claim is not None or points:
            out.status = "not_checked"
            out.notes.append(f"signature not checked: no key (the log says it is signed by key id {log_kid}, "
                             f"{len(points)} checkpoint(s); give --key-file or ${KEY_FILE_ENV})")
        return out
    key = as_key(key)  # the writer's normalisation (trailing whitespace), so both derive one key
    kid = out.key_id = key_id(key)
    out.unsigned_windows = [c.get("index") for c in contents.topic(topics.CERTIFICATE)]  # until verified
    if not points:
        out.critical.append("authenticity cannot be established: the log holds no signed checkpoint"
                            + (f" although its run metadata says it is signed by key id {log_kid} (stripped)"
                               if claim is not None else " (an unsigned log)")
                            + f"; the key given has id {kid}")
        return out
    if claim is not None and claim.get("key_id") != kid or first.get("key_id") not in (None, kid):
        out.status = "wrong_key"
        out.critical.append(f"authenticity cannot be established: the log is signed by key id {log_kid}, "
                            f"the key given has id {kid}")
        return out
    last: SignPoint | None = None
    keyed = _keyed(key)
    for j, sp in enumerate(points):
        why = _point_problem(sp, j, keyed, kid)
        if why is not None:
            w = last.payload["windows"] if last is not None else 0
            out.first_bad = {"checkpoint": j, "windows": w, "reason": why}
            at = "written at open" if j == 0 else f"written after window {j - 1}"
            out.critical.append(f"signature mismatch at checkpoint {j} ({at}): {why}; {w} window(s) before "
                                f"it stay signed, the log from there on is not what the key holder wrote")
            break
        last = sp
        out.valid += 1
    certs = contents.topic(topics.CERTIFICATE)
    covered = last.certificates_before if last is not None else 0
    out.signed_windows = covered
    out.unsigned_windows = [c.get("index") for c in certs[covered:]]
    counts = getattr(contents, "digest_counts", (contents.n_messages, 0, 0))
    if last is None:
        extra = [counts[0], counts[1], counts[2]]
        final = False
    else:
        p = last.payload
        extra = [counts[0] - last.messages_before - 1, counts[1] - p["attachments"],
                 counts[2] - p["metadata"]]
        final = bool(p["final"])
    kinds = ("message(s)", "attachment(s)", "metadata record(s)")
    tail = ", ".join(f"{n} {what}" for n, what in zip(extra, kinds) if n > 0)
    where = (f"checkpoint {out.valid - 1}, after window {last.payload['windows'] - 1}" if last is not None
             and last.payload["windows"] else f"checkpoint {out.valid - 1}" if last is not None else "none")
    if out.first_bad is None and tail:
        wins = _windows_text(out.unsigned_windows) if out.unsigned_windows else "no window"
        text = f"{wins} and {tail} after the last valid signature ({where})"
        if final:
            out.critical.append(f"records after the signed close: {text}")
        else:
            out.unverifiable.append(f"not covered by any signature: {text} (a writer killed inside a window, "
                                    f"or records added by someone without the key)")
    out.signed_close = final and not tail and out.first_bad is None
    if not out.signed_close and out.first_bad is None and not (final and tail):
        if getattr(contents, "seal", None) is not None:
            out.critical.append(f"the log claims a close (its digest seal) that is not signed: the signed "
                                f"part ends at {where}")
        else:
            # unverifiable, not a note: a copy cut right after a checkpoint hides every later window
            # (a violation among them) and reads exactly like a killed writer's log
            if not out.unverifiable:  # else the tail's finding already says the log ends unsigned
                out.unverifiable.append(f"no signed close: the signed part ends at {where} (a killed "
                                        f"writer, or a copy cut there: whether windows followed cannot be "
                                        f"known)")
    if out.critical:
        out.status = "mismatch"
    elif out.signed_close:
        out.status = "verified"
        out.notes.append(f"signature: {out.valid} checkpoint(s) verified with key id {kid}; signed close "
                         f"covers all {covered} window(s)")
    else:
        out.status = "partial"
        out.notes.append(f"signature: {out.valid} checkpoint(s) verified with key id {kid}, covering "
                         f"{covered} window(s)")
    return out


__all__ = ["Signer", "SignPoint", "SignatureCheck", "check_signatures", "read_point", "key_id", "as_key",
           "load_key", "key_from_env", "SIGN_ALGORITHM", "KEY_FILE_ENV", "MIN_KEY_BYTES", "RUN_KEY"]
