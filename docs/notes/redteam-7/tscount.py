import sys, runpy, collections
import monitor.motion.plan as P
orig = P.Plan.translation_segments
stats = collections.Counter(); Ks = []
def ts(self, b):
    stats["calls"] += 1
    if self._moving[b] and not self._rotating[b]:
        stats["moving"] += 1; Ks.append(len(self._tlist))
    return orig(self, b)
P.Plan.translation_segments = ts
sys.argv = ["split.py", "tunnel", "200", "1"]
runpy.run_path("/work/wt/rt7/docs/notes/issue-12-gate-4/split.py", run_name="__main__")
import numpy as np
print(stats, "K median", np.median(Ks), "max", max(Ks))
