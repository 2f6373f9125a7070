"""Red team 13, F1: a process holding old kernels poisons the purged numba cache (real package).

Usage: python race.py <a COPY of the source tree>
(it edits the copy's monitor/motion/kernel.py and restores it).
Prints tol[4] of one pack before the edit, from the old process P1, and from a later process P3.
The edit adds 1000 to tol[4] in motion.kernel.derive, reached only through pack._derive_and_scale.
"""

import os
import pathlib
import subprocess
import sys
import time

TREE = pathlib.Path(sys.argv[1]).resolve()
PY = sys.executable
ENV = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"} | {"PYTHONPATH": str(TREE)}
KERNEL = TREE / "monitor/motion/kernel.py"
PROBE = str(pathlib.Path(__file__).resolve().parent / "probe.py")
PLAIN = "    tol[TOL_QMAG] = qmag\n"
EDITED = "    tol[TOL_QMAG] = qmag + 1000.0  # red team 13 repro edit\n"


def edit(on: bool) -> None:
    """Apply (on) or undo the edit of motion.kernel.derive."""
    text = KERNEL.read_text()
    KERNEL.write_text(text.replace(PLAIN, EDITED) if on else text.replace(EDITED, PLAIN))


def run() -> str:
    """The probe's answer in a fresh process."""
    out = subprocess.run([PY, PROBE], env=ENV, capture_output=True, text=True, cwd=TREE, check=True).stdout
    return out.split(" from")[0]


edit(False)
print("before edit:", run())
p1 = subprocess.Popen([PY, "-c", "import monitor.motion.pack, sys; print('ready', flush=True); "
                       f"sys.stdin.readline(); exec(open({PROBE!r}).read())"],
                      env=ENV, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=TREE)
assert p1.stdout.readline().strip() == "ready"  # P1 holds the old kernels
time.sleep(1.1)  # a coarse-mtime file system still sees the edit
edit(True)
# P2: the guard purges and stamps the new sources
subprocess.run([PY, "-c", "import monitor.motion.pack"], env=ENV, check=True, cwd=TREE)
print("old process P1:", p1.communicate("go\n")[0].split(" from")[0])
print("later process P3 (source says 1000.3):", run())
edit(False)
