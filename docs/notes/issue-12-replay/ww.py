"""Isolated cost of one window's logging with and without its rollout: MonitorLog.write_window of the same
plan and certificate (+ note_model), alternating, tunnel and arm gate windows."""
import time, sys
import numpy as np, mujoco
from monitor.gate import Gate, _logged_rollout, _WindowRows
from monitor._paths import scene_path
from monitor.log.writer import MonitorLog
for name in ("tunnel", "arm"):
    m = mujoco.MjModel.from_xml_path(str(scene_path(name)))
    d = mujoco.MjData(m)
    g = Gate(m, log=f"/tmp/replay/ww_{name}.mcap", frame_skip=5 if name == "tunnel" else 20, allowed=None)
    r = g.step(d, np.zeros(m.nu))
    log = g._log
    win = _WindowRows(g._rollout._window(d, np.zeros(m.nu), g.frame_skip), m, d, g._rollout.window_key)
    ro = _logged_rollout(win)
    plan, cert = win.plan, r.certificate
    t = {True: [], False: []}
    for k in range(4000):
        on = k % 2 == 0
        t0 = time.perf_counter()
        if on:
            log.note_model(m)
            log.write_window(r.time + k, plan, cert, r.proposed_ctrl, r.applied_ctrl, False, rollout=ro)
        else:
            log.write_window(r.time + k, plan, cert, r.proposed_ctrl, r.applied_ctrl, False)
        t[on].append(time.perf_counter() - t0)
    g.close()
    on, off = np.median(t[True]) * 1e6, np.median(t[False]) * 1e6
    print(f"{name}: window logged with rollout + note_model {on:.1f} us, without {off:.1f} us: {on - off:+.1f} us")
