"""cProfile (tottime) of the entry_bench.py cases: PYTHONPATH=<tree> python entry_prof.py CASE [reps]."""
import cProfile
import pstats
import sys

sys.argv = [sys.argv[0], "1"] + sys.argv[1:]
case = sys.argv[2]
nprof = int(sys.argv[3]) if len(sys.argv) > 3 else 1000
sys.argv = sys.argv[:2]
exec(open(__file__.replace("entry_prof.py", "entry_bench.py")).read())
E = sys.modules["monitor.certify.engine"]
cl = calls[case]  # noqa: F821
pr = cProfile.Profile()
pr.enable()
for _ in range(nprof):
    for sc, pl, kw in cl:
        E.certify(sc, pl, **kw)
pr.disable()
pstats.Stats(pr).sort_stats("tottime").print_stats(28)
