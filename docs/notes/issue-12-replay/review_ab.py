"""Review time per window with and without the re-simulation (in-process, alternating): review.verify on a
gate log, review._replay_findings swapped for a stub in alternate rounds. Usage: review_ab.py LOG ROUNDS"""
import sys, time
import numpy as np
from monitor import review
from monitor.log import read_log
path, rounds = sys.argv[1], int(sys.argv[2])
c = read_log(path)
real = review._replay_findings
t = {True: [], False: []}
for r in range(rounds):
    on = r % 2 == 0
    review._replay_findings = real if on else (lambda *a, **k: {})
    t0 = time.perf_counter(); v = review.verify(c, progress=False); t[on].append(time.perf_counter() - t0)
n = v["windows"]
on, off = np.median(t[True]) / n * 1e6, np.median(t[False]) / n * 1e6
print(f"{path}: {n} windows; verify {on:.0f} us/window with re-simulation, {off:.0f} without: "
      f"re-simulation {on - off:+.0f} us/window")
