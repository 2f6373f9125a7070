"""cProfile of gated steps (shape only: cProfile inflates small calls).

usage: PYTHONPATH=<tree> python prof.py WORKLOAD STEPS [N_LINES]
WORKLOAD: tunnel | Pusher-v5 | monitor/Arm-v0 | Reacher-v5
"""
import cProfile
import pstats
import sys
import warnings

warnings.simplefilter("ignore")
work, steps = sys.argv[1], int(sys.argv[2])
nlines = int(sys.argv[3]) if len(sys.argv) > 3 else 40


sys.path.insert(0, __file__.rsplit("/", 1)[0])
from runners import runner  # noqa: E402

from monitor.warmup import ensure_warm  # noqa: E402

ensure_warm()
run = runner(work)
run(20)
pr = cProfile.Profile()
pr.enable()
run(steps)
pr.disable()
st = pstats.Stats(pr)
st.sort_stats("tottime").print_stats(nlines)
st.sort_stats("cumtime").print_stats(nlines)
