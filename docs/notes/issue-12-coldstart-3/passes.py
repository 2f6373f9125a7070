"""After the cold first certify: numba pass times of the biggest compiles (pipeline_times metadata)."""
import runpy, sys, os
os.environ.setdefault("TOPN", "12")
sys.argv = ["trace"]
g = runpy.run_path(os.path.join(os.path.dirname(os.path.abspath(__file__)), "trace.py"))
from collections import defaultdict
import numba
from monitor.certify import kernels as KC
from monitor.motion import kernel as KM
from monitor.geometry import _gjk as G
for name, d in [("window_kernel", KC.window_kernel), ("core_distance", G.core_distance), ("_bounds_core", KM._bounds_core), ("batch", KM.batch), ("separated_beyond", KC.separated_beyond), ("posed_distance", KC.posed_distance)]:
    for sig, md in d.get_metadata().items() if hasattr(d, "get_metadata") else []:
        pt = md.get("pipeline_times", {})
        tot = defaultdict(float)
        for pipe, passes in pt.items():
            for pname, t in passes.items():
                tot[pname.split("_", 1)[-1] if False else pname] += t.init + t.run + t.finalize
        top = sorted(tot.items(), key=lambda kv: -kv[1])[:6]
        print(name, " | ".join(f"{k}: {v:.2f}" for k, v in top))
