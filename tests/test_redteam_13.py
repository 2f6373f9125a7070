"""Red team 13: the stale-numba-cache guard (monitor._jit_cache), on the lead's fixes of 2026-11-28.

Oracles: a two-file numba package in a temporary directory whose caller's answer is known in
closed form from the callee's source (``g(1) = f(1) * 10``), run in fresh processes; the
package's own sources (which modules hold cached numba functions).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import monitor
from monitor import _jit_cache as J

PKG = Path(monitor.__file__).resolve().parent
WT = PKG.parent

_GUARD = textwrap.dedent('''
    from pathlib import Path
    from monitor import _jit_cache as J
    ROOT = Path(__file__).resolve().parent
    FILES = ("callee.py", "caller.py")
    STAMP = J.sources_stamp(ROOT, FILES)
    J.purge_stale(ROOT, FILES)
    from numba import njit
''')
# what every kernel file does after its functions (absent on 8f3998d: the guard was the purge alone)
_BIND = "J.bind_caches(globals(), STAMP)\n" if hasattr(J, "bind_caches") else ""


def _callee(offset: int) -> str:
    return _GUARD + f"@njit(cache=True)\ndef f(x):\n    return x + {offset}\n" + _BIND


@pytest.mark.slow
def test_a_process_holding_old_kernels_cannot_poison_the_cache_after_a_purge(tmp_path):
    """Old process P1 imported the kernels; the callee's file changes; P2 imports (purges, stamps the
    new sources); P1 then compiles the caller (old callee linked in) and caches it under the caller's
    unchanged file stamp; P3 must still run the new callee (g(1) = 230), not P1's code (20)."""
    root = tmp_path / "toy"
    root.mkdir()
    (root / "callee.py").write_text(_callee(1))
    (root / "caller.py").write_text(_GUARD + "from callee import f\n@njit(cache=True)\ndef g(x):\n"
                                    "    return f(x) * 10\n" + _BIND)
    env = dict(os.environ, PYTHONPATH=f"{WT}{os.pathsep}{root}")
    env.pop("NUMBA_CACHE_DIR", None)  # numba's in-tree cache (root/__pycache__)

    def run(code: str = "import caller; print(caller.g(1))") -> str:
        return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                              check=True, timeout=120).stdout.strip()

    assert run() == "20"  # caches of both files written
    old = subprocess.Popen([sys.executable, "-c", "import caller, sys; print('ready', flush=True); "
                            "sys.stdin.readline(); print(caller.g(1))"],
                           env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    assert old.stdout.readline().strip() == "ready"  # P1 holds the old callee in memory
    st = os.stat(root / "callee.py")
    (root / "callee.py").write_text(_callee(22))
    os.utime(root / "callee.py", ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))  # coarse-mtime file systems
    run("import caller")  # P2: the guard purges and stamps the new sources; compiles nothing
    out, _ = old.communicate("go\n", timeout=120)
    assert out.strip() == "20"  # P1 runs the code it loaded (and writes the caller's cache)
    time.sleep(0)
    assert run() == "230"  # P3: the new callee, never P1's cached caller


def test_every_cached_kernel_of_the_package_is_bound_to_the_kernel_files_stamp():
    """Each kernel module's cached functions carry the all-kernel stamp in numba's index stamp, so an
    index written by a process that saw other kernel sources is ignored (fails on 8f3998d: no binding)."""
    import importlib

    assert hasattr(J, "bind_caches"), "the guard has no defence against a process holding old kernels"
    n = 0
    for rel in J.KERNEL_FILES:
        mod = importlib.import_module("monitor." + rel[:-3].replace("/", "."))
        for obj in vars(mod).values():
            cache_file = getattr(getattr(obj, "_cache", None), "_cache_file", None)
            if cache_file is None or getattr(obj.py_func, "__module__", None) != mod.__name__:
                continue
            source = cache_file._source_stamp
            assert isinstance(source, tuple) and source[-1] == J._stamp == J.sources_stamp(PKG), (rel, obj)
            n += 1
    assert n >= 100  # the package's cached kernels (122 at 8f3998d + this fix)


def test_no_numba_function_escapes_the_kernel_file_list():
    """Held: every file that compiles numba code with a cache (any spelling: ``cache = True``,
    ``njit(...)(f)``, ``numba.jit``) is a kernel file that runs the guard first and binds after."""
    pattern = re.compile(r"cache\s*=\s*True|numba\.(n?jit|vectorize|guvectorize|cfunc)\b|\bn?jit\s*\(")
    for p in PKG.rglob("*.py"):
        rel = str(p.relative_to(PKG))
        code = "\n".join(line.split("#")[0] for line in p.read_text().splitlines()
                         if not line.lstrip().startswith(("``", "*", "-")))
        code = re.sub(r'"""[\s\S]*?"""', "", code)  # docstrings mention njit(cache=True)
        if pattern.search(code) and rel != "_jit_cache.py":
            assert rel in J.KERNEL_FILES, rel
            text = p.read_text()
            first_kernel = re.search(r"^@njit", text, re.M).start()
            assert re.search(r"^purge_if_changed\(\)", text, re.M).start() < first_kernel, rel
            assert re.search(r"^bind_caches\(globals\(\)\)", text, re.M), rel


def test_two_processes_compiling_under_different_sources_cannot_pair_index_and_data(tmp_path):
    """numba's save writes the index then the data file. A process holding old kernels (stamp A) and
    one holding new kernels (stamp B) compile the same function at once: B's index names data file 1,
    then A overwrites data file 1 after B wrote it. A reader with stamp B must not get A's code
    (fails on 8f3998d: both name their data ``<base>.1.nbc``)."""
    import types

    from numba.core.caching import IndexDataCacheFile

    def kernel():
        return None

    def bound(stamp: str) -> IndexDataCacheFile:
        cache_file = IndexDataCacheFile(str(tmp_path), "kernel.kernel-1.py3", ("src", 1.0, 10))
        fake = types.SimpleNamespace(_cache=types.SimpleNamespace(_cache_file=cache_file), py_func=kernel)
        if hasattr(J, "bind_caches"):
            assert J.bind_caches({"__name__": kernel.__module__, "kernel": fake}, stamp) == 1
        return cache_file

    old, new = bound("a" * 64), bound("b" * 64)
    key = ("sig", "target")
    old._save_index({key: old._data_name(1)})  # A: index (its load saw nothing fresh)
    new._save_index({key: new._data_name(1)})  # B: index, replaces A's
    new._save_data(new._data_name(1), "code of the new kernels")
    old._save_data(old._data_name(1), "code of the old kernels")  # A's data, last
    assert new.load(key) in ("code of the new kernels", None)  # never the old code under the new index


def test_gate_predict_checks_nstep_like_the_gated_step():
    """``Gate.predict`` is public and took ``int(nstep)``: 10**9 allocated (or ran) a 10**9-row rollout,
    2.5 silently became 2 substeps, -3 a numpy ValueError (fails on 8f3998d). Now the typed error of
    ``step`` / ``certify`` (MAX_WINDOW_STEPS)."""
    import mujoco

    from monitor.errors import InvalidInputError
    from monitor.gate import MAX_WINDOW_STEPS, Gate

    model = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><joint name='j' type='hinge'/><geom size='.1'/></body>"
        "<geom type='plane' size='1 1 .1' pos='0 0 -1'/></worldbody>"
        "<actuator><motor joint='j'/></actuator></mujoco>")
    data = mujoco.MjData(model)
    gate = Gate(model)
    for bad in (MAX_WINDOW_STEPS + 1, 10**9, 2.5, -3, 0, True, "3"):
        with pytest.raises(InvalidInputError):
            gate.predict(data, None, bad)
    plan = gate.predict(data, None, 3)
    assert len(plan.times) == 4 and data.time == 0.0  # 3 substeps, the live data untouched
