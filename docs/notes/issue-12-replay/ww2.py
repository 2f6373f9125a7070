import time
import numpy as np, mujoco
from monitor.gate import Gate, _logged_rollout, _WindowRows
from monitor._paths import scene_path
for name in ("tunnel", "arm"):
    m = mujoco.MjModel.from_xml_path(str(scene_path(name)))
    d = mujoco.MjData(m)
    g = Gate(m, log=f"/tmp/replay/ww2_{name}.mcap", frame_skip=5 if name == "tunnel" else 20, allowed=None)
    r = g.step(d, np.zeros(m.nu))
    log = g._log
    win = _WindowRows(g._rollout._window(d, np.zeros(m.nu), g.frame_skip), m, d, g._rollout.window_key)
    ro = _logged_rollout(win)
    plan, cert = win.plan, r.certificate
    t = {k: [] for k in range(4)}
    for k in range(6000):
        mode = k % 4
        t0 = time.thread_time()
        if mode == 0:
            log.write_window(r.time + k, plan, cert, r.proposed_ctrl, r.applied_ctrl, False)
        elif mode == 1:
            log.write_window(r.time + k, plan, cert, r.proposed_ctrl, r.applied_ctrl, False, rollout=ro)
        elif mode == 2:
            log.note_model(m)
        else:
            _logged_rollout(win)
        t[mode].append(time.thread_time() - t0)
    g.close()
    med = {k: np.median(v) * 1e6 for k, v in t.items()}
    print(f"{name}: write_window {med[0]:.1f} us, with rollout {med[1]:.1f} us (+{med[1] - med[0]:.1f}); "
          f"note_model {med[2]:.1f} us; _logged_rollout {med[3]:.1f} us")
