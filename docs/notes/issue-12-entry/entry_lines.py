"""Per-line wall time (perf_counter between line events, sys.settrace) of certify / _check_model /
_certify_fast on one entry_bench.py case: PYTHONPATH=<tree> python entry_lines.py CASE [reps].
Each line event costs the tracer ~0.3-1 us; read the figures as relative, the bench for absolutes."""
import sys
import time
from collections import defaultdict

case = sys.argv[1]
nrep = int(sys.argv[2]) if len(sys.argv) > 2 else 500
sys.argv = [sys.argv[0], "1"]
exec(open(__file__.replace("entry_lines.py", "entry_bench.py")).read())
E = sys.modules["monitor.certify.engine"]
targets = {E.certify.__code__, E._certify_fast.__code__, E._check_model.__code__}
for extra in ("_certify_entry", "_entry_fast"):
    if hasattr(E, extra):
        targets.add(getattr(E, extra).__code__)
tot = defaultdict(float)
last = {}


def local(frame, event, arg):
    now = time.perf_counter()
    key = frame.f_code
    if key in last:
        ln, t = last[key]
        tot[(key.co_name, ln)] += now - t
    if event == "return":
        last.pop(key, None)
    else:
        last[key] = (frame.f_lineno, time.perf_counter())
    return local


def glob(frame, event, arg):
    if frame.f_code in targets:
        return local
    return None


cl = calls[case]  # noqa: F821
sys.settrace(glob)
for _ in range(nrep):
    for sc, pl, kw in cl:
        E.certify(sc, pl, **kw)
sys.settrace(None)
n = nrep * len(cl)
src = {}
import inspect  # noqa: E402

for c in targets:
    lines, start = inspect.getsourcelines(c)
    for i, s in enumerate(lines):
        src[(c.co_name, start + i)] = s.strip()[:90]
for (fn, ln), t in sorted(tot.items(), key=lambda kv: -kv[1])[:30]:
    print(f"{t / n * 1e6:8.2f} us  {fn}:{ln}  {src.get((fn, ln), '')}")
print("sum", sum(tot.values()) / n * 1e6)
