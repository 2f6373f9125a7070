"""Exclusive claim of a log path, so that two writers never share (and corrupt) one file.

A gate that logs to ``x.mcap`` takes an exclusive, non-blocking ``fcntl.flock`` on
the file for as long as it writes. ``flock`` locks belong to an open file
description, so they conflict between processes *and* between two opens in one
process (two gates of a ``SyncVectorEnv``), and the OS drops them when the holder
exits or crashes. A path that is already claimed is never truncated: the claim
moves on to ``x.1.mcap``, ``x.2.mcap``, ... (the first one free). Where ``fcntl``
is unavailable (Windows) the path is returned unclaimed.
"""

from __future__ import annotations

from pathlib import Path
from typing import IO

from monitor.errors import InvalidInputError

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None  # type: ignore[assignment]

MAX_SIBLINGS = 10_000
"""Most numbered siblings tried before giving up (a bound, never reached in practice)."""


def sibling(path: Path, n: int) -> Path:
    """``path`` itself for n = 0, else ``<stem>.<n><suffix>`` (``x.mcap`` -> ``x.3.mcap``)."""
    if n == 0:
        return path
    return path.with_name(f"{path.stem}.{n}{path.suffix}")


def claim_log_path(path: Path) -> tuple[Path, IO[bytes] | None]:
    """Claim ``path`` (or its first free numbered sibling) for exclusive writing.

    Args:
        path: the requested log file.

    Returns:
        (the claimed path, the open lock handle: keep it open while writing, close it to release;
        None without ``fcntl``).

    Raises:
        InvalidInputError: the path cannot be opened (missing directory, permissions), or
            every sibling up to :data:`MAX_SIBLINGS` is claimed.
    """
    if fcntl is None:  # pragma: no cover
        return path, None
    for n in range(MAX_SIBLINGS):
        candidate = sibling(path, n)
        try:
            handle = open(candidate, "ab")  # noqa: SIM115 - creates, never truncates; the caller closes it
        except OSError as e:
            raise InvalidInputError(f"log: cannot open {str(candidate)!r} for writing: {e}") from e
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:  # held by another writer
            handle.close()
            continue
        return candidate, handle
    raise InvalidInputError(
        f"log: {str(path)!r} and its {MAX_SIBLINGS} numbered siblings are all being written")


__all__ = ["claim_log_path", "sibling", "MAX_SIBLINGS"]
