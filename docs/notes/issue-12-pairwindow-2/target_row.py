"""The bench's pair-window target row alone (monitor.bench.targets.pair_windows, quick, seed 7)."""
import tempfile
from pathlib import Path

from monitor.bench.suites import BenchConfig
from monitor.bench.targets import pair_windows

cfg = BenchConfig(quick=True, out=Path(tempfile.mkdtemp()), log=lambda s: None)
a = pair_windows(cfg)["rows"][-1]
print(f"ours {a['ours_us_median']:.1f} us  fcl {a['fcl_us_median']:.2f} us  ratio {a['ratio']:.2f}  "
      f"misses {a['ours_misses']}  late {a['ours_late']}  n {a['n']}")
