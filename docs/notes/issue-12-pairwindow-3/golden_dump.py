import json, sys, os
sys.path.insert(0, os.path.join(os.environ["PYTHONPATH"], "tests"))
from _engine_entry_cases import _summary, box_calls, pusher_calls, bench_calls
from monitor.certify import engine
engine._SWEPT_FIRST = False
which = sys.argv[2]
gen = {"box": box_calls, "pusher": pusher_calls, "bench": bench_calls}[which]()
out = {name: json.loads(json.dumps(_summary(run()))) for name, run in gen}
json.dump(out, open(sys.argv[1], "w"), sort_keys=True)
print(len(out))
