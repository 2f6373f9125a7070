import os
import sys
import types

import monitor
from monitor.bench.targets import tunnel_gate

cfg = types.SimpleNamespace(quick=False, smoke=False, reps=int(sys.argv[1]) if len(sys.argv) > 1 else 5, log=print)
r = tunnel_gate(cfg)
print(f"TUN {os.path.basename(os.path.dirname(os.path.dirname(monitor.__file__)))} gated_us {r['gated_s']*1e6:.1f} ungated_us {r['ungated_s']*1e6:.2f} ratio {r['ratio']:.1f} verdicts {r['verdicts']}")
