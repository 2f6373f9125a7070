"""Drop numba's on-disk machine code of every kernel file when any kernel file changed.

numba's cache (``cache=True``) keys each function's machine code on *its own* source file
(modification time and size). A compiled caller links its callees' code into its own, so
after an edit of a callee's file (another branch checked out, a merge, a partial upgrade)
the caller's cached code in an unchanged file still runs the old callee: numba does not
track dependencies across files. On 2026-11-28 a merge changed ``monitor/motion/kernel.py``
and not ``monitor/motion/pack.py``; ``pack._derive_and_scale`` loaded from the cache kept
the old kernel code and a certificate changed (a pair the new stage 0 culls went through the
whole-shape stage instead; ``docs/notes/session-2026-11-28-night.md``). Nothing guarantees a
stale kernel errs on the safe side, so the package does not rely on it.

:func:`purge_if_changed` (called once per process, by the first kernel module imported) computes one stamp
over every kernel file (:data:`KERNEL_FILES`: path, modification time in ns, size, content hash) and
compares it with the stamp stored beside each file's numba cache; where they differ, that
file's ``.nbi`` / ``.nbc`` files are deleted and the stamp is written. Editing any kernel file
thus recompiles every kernel once (~50 s of CPU on this project's machine): the price of never
running a mixture. Cost when nothing changed: a few stats and small reads (well under a
millisecond). The cache directories are numba's own (its locators: ``NUMBA_CACHE_DIR``, the
source tree's ``__pycache__``, the user-wide cache); with a numba that lacks them nothing is
purged. Each kernel file calls :func:`purge_if_changed` right after importing numba, so the
check runs before any cached kernel is loaded (numba loads at a function's first call).
Standard library and numba only.
"""

from __future__ import annotations

import hashlib
import os
import warnings
from pathlib import Path

KERNEL_FILES: tuple[str, ...] = (
    "certify/extrusion_kernels.py",
    "certify/extrusion_null.py",
    "certify/extrusion_swept.py",
    "certify/fat_kernels.py",
    "certify/kernels.py",
    "geometry/_gjk.py",
    "motion/kernel.py",
    "motion/pack.py",
)
"""Every file of the package with ``cache=True`` numba functions, relative to the package root
(``tests/test_jit_cache.py`` checks the list against the sources)."""

STAMP_SUFFIX = ".monitor-kernels.stamp"
"""Name of the stamp file beside a kernel file's numba cache: ``<file stem>`` + this."""

_done = False
_stamp: str | None = None
"""This process's stamp of the kernel files (taken by :func:`purge_if_changed`), or None before it."""


def sources_stamp(root: Path, files: tuple[str, ...] = KERNEL_FILES) -> str:
    """One hex digest over (relative path, mtime ns, size, content) of ``files`` under ``root``.

    The content's SHA-256 is in it because numba's own check (modification time and size) misses
    an edit that keeps both: a one-digit constant changed in a file copied with its old time
    (``cp -p``, ``rsync -t``, an archive or a wheel with fixed timestamps). Reading and hashing the
    ~350 kB of kernel sources costs well under a millisecond, once per process.
    """
    h = hashlib.sha256()
    for rel in files:
        try:
            with open(root / rel, "rb") as f:
                st = os.fstat(f.fileno())
                content = hashlib.sha256(f.read()).hexdigest()
            h.update(f"{rel}\0{st.st_mtime_ns}\0{st.st_size}\0{content}\n".encode())
        except OSError:
            h.update(f"{rel}\0missing\n".encode())
    return h.hexdigest()


def _numba_cache_dir(py_file: Path) -> Path | None:
    """The directory numba caches ``py_file``'s functions in (its first locator that applies), or None."""
    try:
        from numba.core import caching
    except ImportError:  # pragma: no cover - numba is a dependency
        return None
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
    classes = getattr(impl, "_locator_classes", None)
    if not classes:
        return None

    def probe() -> None:  # a function object for the locators (they read its line number)
        return None

    for cls in classes:
        try:
            loc = cls.from_function(probe, str(py_file))
        except Exception:  # noqa: BLE001 - a locator that does not apply here
            loc = None
        if loc is not None:
            return Path(loc.get_cache_path())
    return None


def purge_stale(root: Path, files: tuple[str, ...] = KERNEL_FILES,
                cache_dir_of: object = None) -> list[str]:
    """Delete the numba cache files of ``files`` whose stored stamp is not the current one.

    Args:
        root: the package directory.
        files: kernel files relative to ``root``.
        cache_dir_of: ``f(py_file: Path) -> Path | None`` (default: numba's locators).

    Returns:
        the relative paths whose caches were dropped (empty when every stamp matched).
    """
    find = cache_dir_of or _numba_cache_dir
    stamp = sources_stamp(root, files)
    purged = []
    for rel in files:
        py_file = root / rel
        cache = find(py_file)  # type: ignore[operator]
        if cache is None or not Path(cache).is_dir():
            continue
        cache = Path(cache)
        mark = cache / (py_file.stem + STAMP_SUFFIX)
        try:
            if mark.read_text() == stamp:
                continue
        except OSError:
            pass
        prefix = py_file.stem + "."
        for f in cache.iterdir():
            if f.name.startswith(prefix) and f.suffix in (".nbi", ".nbc"):
                try:
                    f.unlink()
                except OSError:
                    pass
        try:
            tmp = mark.with_name(mark.name + f".{os.getpid()}")
            tmp.write_text(stamp)
            os.replace(tmp, mark)
        except OSError:
            pass
        purged.append(rel)
    return purged


def purge_if_changed() -> list[str]:
    """:func:`purge_stale` for this package, once per process (later calls return [])."""
    global _done, _stamp
    if _done:
        return []
    _done = True
    try:
        root = Path(__file__).resolve().parent
        _stamp = sources_stamp(root)
        return purge_stale(root)
    except Exception as exc:  # noqa: BLE001 - never break the import over the cache
        warnings.warn(f"monitor could not check its numba cache for stale kernels: {exc}", stacklevel=2)
        return []


def bind_caches(namespace: dict, stamp: str | None = None) -> int:
    """Fold the kernel files' stamp into numba's source stamp of each cached function of a module.

    The purge alone misses one race: a process that imported the old sources (its callees' old
    code in memory) compiles a caller after another process purged and stamped the new sources,
    and writes the caller's cache under the caller's unchanged file stamp; every later process
    then loads that stale code (red team 13). With the stamp of *all* kernel files, as this
    process saw them at its first kernel import, inside each index's source stamp, numba itself
    ignores an index written by a process that saw other sources (its stamp check), and the
    data files carry the stamp in their names (no index of one source set pointing at a data file
    another process overwrote with code of other sources).

    Args:
        namespace: a kernel module's ``globals()`` (call at the end of the module, before any
            kernel runs); functions imported from other modules are left to their own module.
        stamp: the stamp to bind (default: this process's, from :func:`purge_if_changed`).

    Returns:
        how many functions were bound.
    """
    stamp = _stamp if stamp is None else stamp
    if stamp is None:
        return 0
    name = namespace.get("__name__")
    bound = 0
    for obj in list(namespace.values()):
        cache_file = getattr(getattr(obj, "_cache", None), "_cache_file", None)
        py_func = getattr(obj, "py_func", None)
        if cache_file is None or py_func is None or getattr(py_func, "__module__", None) != name:
            continue
        source = getattr(cache_file, "_source_stamp", None)
        if source is None:
            continue
        if not (isinstance(source, tuple) and len(source) == 3 and source[0] == STAMP_SUFFIX):
            cache_file._source_stamp = (STAMP_SUFFIX, source, stamp)
            # data files named per stamp too: two processes that saw different sources and compile the
            # same function at once cannot write the same data file under the other's index
            pattern = getattr(cache_file, "_data_name_pattern", None)
            if isinstance(pattern, str) and pattern.endswith(".{number:d}.nbc"):
                cache_file._data_name_pattern = pattern[:-len("nbc")] + stamp[:16] + ".nbc"
        bound += 1
    return bound
