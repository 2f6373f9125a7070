"""Red team 15: can a signing key leak from the writer side (log bytes, repr, pickle, deepcopy, env.spec,
exception messages), and does a bad key fail at construction?

Run: PYTHONPATH=$PWD /work/main/.venv/bin/python docs/notes/redteam-15/key_leaks.py
Prints one line per probe: LEAK / ok, and where the key's bytes (raw or hex) were found.
"""

from __future__ import annotations

import copy
import os
import pickle
import sys
import tempfile
import traceback
from pathlib import Path

import mujoco
import numpy as np

from monitor.gate import Gate
from monitor.log import MonitorLog
from monitor.log.sign import KEY_FILE_ENV

KEY = b"K3y-" + bytes(range(200, 228))  # 32 bytes, distinctive
XML = """<mujoco><worldbody><geom name="floor" type="plane" size="1 1 .1"/>
<body name="b" pos="0 0 .3"><joint name="z" type="slide" axis="0 0 1"/><geom name="g" type="sphere" size=".05"/></body>
</worldbody><actuator><motor joint="z"/></actuator></mujoco>"""


def forms(key: bytes) -> list[bytes]:
    return [key, key.hex().encode(), key.hex().upper().encode(), repr(key).encode()]


def leak(blob: bytes | str, key: bytes = KEY) -> bool:
    b = blob.encode("utf-8", "surrogateescape") if isinstance(blob, str) else blob
    return any(f in b for f in forms(key))


results: list[tuple[str, bool, str]] = []


def probe(name: str, fn) -> None:
    try:
        blob = fn()
        results.append((name, leak(blob), ""))
    except Exception as exc:  # noqa: BLE001 - the exception text is what we inspect
        text = f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"
        results.append((name + " (raised)", leak(text), f"{type(exc).__name__}: {str(exc)[:100]}"))


def main() -> int:
    tmp = Path(tempfile.mkdtemp(prefix="rt15-keys-"))
    model = mujoco.MjModel.from_xml_string(XML)
    data = mujoco.MjData(model)
    os.environ.pop(KEY_FILE_ENV, None)

    log = MonitorLog(tmp / "a.mcap", model=model, foxglove=False, key=KEY)
    probe("MonitorLog repr", lambda: repr(log))
    probe("MonitorLog vars repr", lambda: repr(vars(log)))
    probe("MonitorLog pickle", lambda: pickle.dumps(log))
    probe("MonitorLog deepcopy repr", lambda: repr(vars(copy.deepcopy(log))))
    probe("MonitorLog _signer pickle", lambda: pickle.dumps(log._signer))
    log.close()
    probe("log file bytes", lambda: (tmp / "a.mcap").read_bytes())

    g = Gate(model, log=tmp / "g.mcap", log_options={"key": KEY})
    probe("Gate repr (before open)", lambda: repr(g))
    probe("Gate pickle (before open)", lambda: pickle.dumps(g))
    probe("Gate deepcopy (before open)", lambda: pickle.dumps(copy.deepcopy(g).__dict__.get("_log_options")))
    probe("Gate describe()", lambda: g.describe())
    g.step(data, np.zeros(1))
    probe("Gate repr (open)", lambda: repr(g))
    probe("Gate pickle (open)", lambda: pickle.dumps(g))
    probe("Gate summary", lambda: repr(g.summary()))
    probe("Gate last_report", lambda: repr(g.last_report))
    g.close()
    probe("Gate pickle (closed)", lambda: pickle.dumps(g))
    probe("Gate log bytes", lambda: (tmp / "g.mcap").read_bytes())

    # bad keys: raised where, and does the message carry the key?
    short = KEY[:15]
    probe("MonitorLog short key message", lambda: MonitorLog(tmp / "s.mcap", key=short))
    kf = tmp / "short.key"
    kf.write_bytes(short)
    os.environ[KEY_FILE_ENV] = str(kf)
    probe("MonitorLog short env key file message", lambda: MonitorLog(tmp / "e.mcap"))
    os.environ.pop(KEY_FILE_ENV)
    ok_construct = True
    try:
        Gate(model, log=tmp / "bad.mcap", log_options={"key": short})
    except Exception:  # noqa: BLE001
        ok_construct = False
    results.append(
        (
            "Gate(log_options={'key': 15 bytes}) raises at construction",
            False,
            "raises at construction" if not ok_construct else "NOT at construction",
        )
    )
    os.environ[KEY_FILE_ENV] = str(tmp / "missing.key")
    try:
        Gate(model, log=tmp / "bad2.mcap")
        where = "NOT at construction"
    except Exception as exc:  # noqa: BLE001
        where = f"at construction: {type(exc).__name__}"
    results.append(("Gate(log=path) with $MONITOR_LOG_KEY_FILE missing", False, where))
    os.environ.pop(KEY_FILE_ENV)

    try:
        import gymnasium

        import envs  # noqa: F401 - registers monitor/* envs
        from monitor.gym_gate import SafetyGate

        env = SafetyGate(gymnasium.make("monitor/Arm-v0"), log=MonitorLog(tmp / "sg.mcap", key=KEY))
        probe("SafetyGate env.spec repr", lambda: repr(env.spec))
        probe("SafetyGate env.spec pickle", lambda: pickle.dumps(env.spec))
        probe("SafetyGate repr", lambda: repr(env))
        env.close()
    except ImportError as exc:
        results.append(("SafetyGate", False, f"skipped: {exc}"))

    for name, leaked, extra in results:
        print(f"{'LEAK' if leaked else 'ok  '}  {name}  {extra}")
    return int(any(r[1] for r in results))


if __name__ == "__main__":
    sys.exit(main())
