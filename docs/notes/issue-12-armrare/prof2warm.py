"""armtail's prof2.py (per-call classes) after ensure_warm() and gc.collect(): the steady-state classes."""
import sys, gc
from monitor.warmup import ensure_warm
ensure_warm(); gc.collect()
sys.argv = ["prof2.py"] + sys.argv[1:]
exec(open("/work/wt/armrare/docs/notes/issue-12-armtail/prof2.py").read())
