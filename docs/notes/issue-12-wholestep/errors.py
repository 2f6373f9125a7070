"""What a MuJoCo error (``mju_error``) inside ``mj_step`` does when the call comes from numba through ctypes.

Usage: PYTHONPATH=$PWD:$PWD/docs/notes/issue-12-wholestep python docs/notes/issue-12-wholestep/errors.py

The model: 12 free boxes falling on a plane with ``<size memory="16K"/>``; the arena is exhausted a
few hundred steps in (the stack overflows in the constraint code: ``mj_stackAlloc: out of memory``).
Each case runs in a child process, in a temporary working directory (MuJoCo's default handler
appends to ``MUJOCO_LOG.TXT`` there); the parent reports its exit code and last output lines:

* ``bindings``: ``mujoco.mj_step`` through the Python bindings, 400 times;
* ``ctypes``: the same steps from a numba nopython loop calling ``mj_step`` through ctypes;
* ``ctypes_returning``: the same, with a legacy ``mju_user_error`` handler that records the message
  and RETURNS (what a numba ``cfunc`` / ctypes callback handler would do: neither can ``longjmp``);
* ``callback_bindings`` / ``callback_ctypes``: a healthy model (the tunnel) with a Python
  ``mjcb_control`` that raises, stepped through the bindings / from numba;
* ``callback_ok_ctypes``: the same with a Python ``mjcb_control`` that returns (sets ``ctrl`` = 1 and
  counts its calls), stepped from numba (the GIL is held by the numba caller; no deadlock expected).
"""
from __future__ import annotations

import ctypes
import subprocess
import sys
import tempfile
from pathlib import Path

TUNNEL = str(Path(__file__).resolve().parents[3] / "models" / "tunnel" / "scene.xml")

XML = ('<mujoco><size memory="16K"/><worldbody><geom type="plane" size="1 1 .1"/>{}</worldbody></mujoco>')
BOX = ('<body pos="{x} {y} {z}"><freejoint/><geom type="box" size="0.03 0.03 0.03"/></body>')


def model():
    import mujoco
    bodies = "".join(BOX.format(x=0.05 * (i % 4), y=0.05 * (i // 4), z=0.1 + 0.06 * i) for i in range(12))
    return mujoco.MjModel.from_xml_string(XML.format(bodies))


def child(mode):
    seen = []
    import mujoco
    import numba as nb
    from cmj import LIB, c_mj_step

    @nb.njit
    def run(ma, da, n):
        for _ in range(n):
            c_mj_step(ma, da)
        return n

    if mode.startswith("callback"):
        m = mujoco.MjModel.from_xml_path(TUNNEL)

        def bad(m_, d_):
            if mode == "callback_ok_ctypes":
                d_.ctrl[0] = 1.0
                seen.append(b"callback")
                return
            raise RuntimeError("callback raised")
        mujoco.set_mjcb_control(bad)
    else:
        m = model()
    d = mujoco.MjData(m)
    if mode == "ctypes_returning":
        handler = ctypes.CFUNCTYPE(None, ctypes.c_char_p)(lambda msg: seen.append(msg))
        ctypes.c_void_p.in_dll(LIB, "mju_user_error").value = ctypes.cast(handler, ctypes.c_void_p).value
    print("start", flush=True)
    try:
        if mode in ("bindings", "callback_bindings"):
            for _ in range(400):
                mujoco.mj_step(m, d)
        else:
            run(m._address, d._address, 400)
        print(f"returned normally: time {d.time:.2f} s, {len(seen)} calls of the handler / callback, "
              f"nefc {d.nefc}, ncon {d.ncon}, qvel[0] {d.qvel[0]:.3f}", flush=True)
        if seen and mode == "ctypes_returning":
            print("first error:", seen[0].decode().splitlines()[0], flush=True)
    except BaseException as e:  # noqa: BLE001 - report whatever comes back
        print(f"raised {type(e).__module__}.{type(e).__name__}: {str(e).splitlines()[0]}", flush=True)


def main():
    if len(sys.argv) > 1:
        child(sys.argv[1])
        return
    for mode in ("bindings", "ctypes", "ctypes_returning", "callback_bindings", "callback_ctypes",
                 "callback_ok_ctypes"):
        with tempfile.TemporaryDirectory() as cwd:  # MuJoCo's MUJOCO_LOG.TXT goes there
            p = subprocess.run([sys.executable, "-W", "ignore", str(Path(__file__).resolve()), mode],
                               capture_output=True, text=True, cwd=cwd)
        out = [x for x in (p.stdout + p.stderr).splitlines() if x.strip() and "WARNING" not in x]
        print(f"== {mode}: exit code {p.returncode}")
        for line in out[-3:]:
            print("   ", line[:150])


if __name__ == "__main__":
    main()
