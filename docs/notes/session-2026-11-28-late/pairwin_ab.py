"""The bench's pair-window target row alone (``monitor.bench.targets.pair_windows``), REPS repetitions.

PYTHONPATH=<tree> python pairwin_ab.py [REPS]   (one JSON line: ratio to python-fcl, both medians)
"""
import json
import os
import sys
from pathlib import Path

import monitor
from monitor.bench.suites import BenchConfig
from monitor.bench.targets import pair_windows

cfg = BenchConfig(quick=True, out=Path("/tmp"), reps=int(sys.argv[1]) if len(sys.argv) > 1 else 3)
r = pair_windows(cfg)
row = r["spec_row"]
print(json.dumps({"tree": os.path.dirname(os.path.dirname(monitor.__file__)), "ratio": row.get("value"), "ours": row.get("ours"), "ref": row.get("ref"),
                  "keys": sorted(k for k in r if k != "spec_row")[:12]}, default=str))
