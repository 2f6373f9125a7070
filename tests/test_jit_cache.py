"""monitor._jit_cache: numba caches of every kernel file are dropped when any kernel file changed.

Oracles: the package's own sources (which files hold ``cache=True`` functions, which call the
guard), and a fake kernel tree in a temporary directory (stamps, purges, untouched neighbours).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import monitor
from monitor import _jit_cache as J

PKG = Path(monitor.__file__).resolve().parent


def test_the_kernel_file_list_is_every_file_with_cached_numba_functions():
    found = sorted(str(p.relative_to(PKG)) for p in PKG.rglob("*.py")
                   if re.search(r"@njit\([^)]*cache=True", p.read_text()))
    assert found == sorted(J.KERNEL_FILES)


def test_every_kernel_file_runs_the_guard_at_import():
    for rel in J.KERNEL_FILES:
        text = (PKG / rel).read_text()
        assert re.search(r"^purge_if_changed\(\)", text, re.M), rel


def _tree(tmp_path: Path) -> tuple[Path, Path, tuple[str, ...]]:
    root, cache = tmp_path / "pkg", tmp_path / "cache"
    files = ("a/k1.py", "b/k2.py")
    for rel in files:
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text("x = 1\n")
    cache.mkdir()
    return root, cache, files


def _fill(cache: Path) -> list[Path]:
    made = [cache / n for n in ("k1.f-10.py311.nbi", "k1.f-10.py311.1.nbc", "k2.g-3.py311.nbi",
                                "k10.h-1.py311.nbi", "other.txt")]
    for f in made:
        f.write_text("cached")
    return made


def test_a_changed_kernel_file_drops_every_kernel_files_cache_once(tmp_path):
    root, cache, files = _tree(tmp_path)
    made = _fill(cache)
    find = lambda py_file: cache  # noqa: E731 - one cache dir for both files
    # no stamp yet (an older tree's cache): dropped, stamps written
    assert J.purge_stale(root, files, find) == list(files)
    left = sorted(p.name for p in cache.iterdir() if not p.name.endswith(J.STAMP_SUFFIX))
    assert left == ["k10.h-1.py311.nbi", "other.txt"]  # another module's files and non-cache files stay
    # nothing changed: nothing dropped
    made = _fill(cache)
    assert J.purge_stale(root, files, find) == []
    assert all(p.exists() for p in made)
    # one file edited (its mtime moves): the caches of BOTH files go (a caller's cached code links callees)
    st = os.stat(root / files[1])
    os.utime(root / files[1], ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))
    assert J.purge_stale(root, files, find) == list(files)
    assert not (cache / "k1.f-10.py311.1.nbc").exists() and not (cache / "k2.g-3.py311.nbi").exists()


def test_an_edit_that_keeps_mtime_and_size_still_drops_the_caches(tmp_path):
    """numba's own check (mtime, size) misses this edit; the stamp's content hash does not."""
    root, cache, files = _tree(tmp_path)
    find = lambda py_file: cache  # noqa: E731
    J.purge_stale(root, files, find)
    made = _fill(cache)
    assert J.purge_stale(root, files, find) == []
    f = root / files[0]
    st = os.stat(f)
    f.write_text("x = 2\n")                       # one digit: same size
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns))  # the old time, as ``cp -p`` would leave it
    assert os.stat(f).st_size == st.st_size and os.stat(f).st_mtime_ns == st.st_mtime_ns
    assert J.purge_stale(root, files, find) == list(files)
    assert not any(p.exists() for p in made[:3])


def test_no_cache_directory_is_not_an_error(tmp_path):
    root, _, files = _tree(tmp_path)
    assert J.purge_stale(root, files, lambda py_file: None) == []
    assert J.purge_stale(root, files, lambda py_file: tmp_path / "absent") == []


def test_numba_locates_the_package_cache():
    # the real locator answers for a kernel file (the in-tree __pycache__ or NUMBA_CACHE_DIR's mirror)
    d = J._numba_cache_dir(PKG / "geometry" / "_gjk.py")
    assert d is not None and d.is_dir()
