"""Write an N-window log (default 10 000), then time close/finalise, read_log, analyze+text, --report, CLI review.

Usage: PYTHONPATH=. python scripts/measure_review.py [N]
"""
import sys, time, types, statistics, subprocess
import numpy as np, mujoco
from monitor.certify.certificate import Certificate, PairResult, Witness
from monitor.log import MonitorLog, read_log
from monitor.review import analyze, render_text, write_report

N = int(sys.argv[1]) if len(sys.argv) > 1 else 10000
XML = """<mujoco><worldbody><body name="table" pos=".6 0 .2"><geom name="top" type="box" size=".2 .3 .02"/></body>
<body name="arm" pos="0 0 .3"><joint type="hinge" axis="0 0 1"/><geom name="link" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
</body></worldbody></mujoco>"""
model = mujoco.MjModel.from_xml_string(XML)
import tempfile
OUT = tempfile.mkdtemp(prefix="measure_review_")
path = f"{OUT}/review{N}.mcap"
rng = np.random.default_rng(0)
t = time.perf_counter()
log = MonitorLog(path, model=model)
for k in range(N):
    t0 = 0.01 * (k % 500)
    v = "violation" if k % 97 == 5 else "uncertain" if k % 89 == 3 else "certified"
    w = Witness(t0, ("link", "top"), np.array([.5, 0, .2]), -1e-3) if v == "violation" else None
    pr = PairResult(("link", "top"), ("arm", "table"), v, "toleranced", 5, 2, (), 0.01 if v == "certified" else float("-inf"), w)
    c = Certificate(v, (t0, t0 + 0.01), 0.001, 1e-3, "auto", w, None if v == "certified" else t0,
                    0.01 if v == "certified" else float("-inf"), (pr,), {"wall_seconds": float(rng.uniform(1e-4, 1e-2))})
    plan = types.SimpleNamespace(times=np.array([t0, t0 + 0.01]), qpos=np.array([[0.001 * k], [0.001 * k + 0.01]]), model=model)
    log.write_window(t0, plan, c, np.array([0.1]), np.array([0.1]), replaced=v != "certified")
t_write = time.perf_counter() - t
t = time.perf_counter(); log.close(); t_close = time.perf_counter() - t
import os
size = os.path.getsize(path)
t = time.perf_counter(); cts = read_log(path, progress=False); t_read = time.perf_counter() - t
t = time.perf_counter(); e = analyze(cts); txt = render_text({"logs": [e], "total": None}); t_an = time.perf_counter() - t
t = time.perf_counter(); write_report({"logs": [e], "total": None}, f"{OUT}/r{N}.html"); t_rep = time.perf_counter() - t
t = time.perf_counter()
r = subprocess.run([sys.executable, "-m", "monitor", "review", path], capture_output=True, text=True)
t_cli = time.perf_counter() - t
print(f"N={N} size={size/1e6:.1f} MB  write {t_write:.2f}s ({t_write/N*1e3:.3f} ms/win)  close+finalise {t_close:.2f}s "
      f"({t_close/N*1e6:.0f} us/win)  read_log {t_read:.2f}s ({t_read/N*1e6:.0f} us/win)  analyze+text {t_an:.2f}s "
      f"({t_an/N*1e6:.0f} us/win)  report {t_rep:.2f}s  CLI review (fresh process) {t_cli:.2f}s rc={r.returncode}")
