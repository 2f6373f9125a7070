"""Run the bench's own start-up script (monitor.bench.targets._START_SCRIPT) of the tree on sys.path, cold cache."""
import os, subprocess, sys, tempfile, time, json, resource
tree = sys.argv[1]
sys.path.insert(0, tree)
src = open(os.path.join(tree, "monitor/bench/targets.py")).read()
i = src.index('_START_SCRIPT = r"""') + len('_START_SCRIPT = r"""')
script = src[i:src.index('"""', i)]
with tempfile.TemporaryDirectory() as tmp:
    env = dict(os.environ, PYTHONPATH=tree, NUMBA_CACHE_DIR=tmp)
    t = time.time()
    p = subprocess.run([sys.executable, "-c", script, repr(t)], env=env, capture_output=True, text=True, cwd=tmp)
    wall = time.time() - t
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    line = [x for x in p.stdout.splitlines() if x.startswith("START ")]
    res = json.loads(line[-1][6:]) if line else {"error": p.stderr[-300:]}
    # warm: same cache, a second process
    t2 = time.time()
    p2 = subprocess.run([sys.executable, "-c", script, repr(t2)], env=env, capture_output=True, text=True, cwd=tmp)
    ru2 = resource.getrusage(resource.RUSAGE_CHILDREN)
    line2 = [x for x in p2.stdout.splitlines() if x.startswith("START ")]
    res2 = json.loads(line2[-1][6:]) if line2 else {"error": p2.stderr[-300:]}
print(json.dumps({"tree": tree, "cold_cpu_s": ru.ru_utime + ru.ru_stime, "cold_process_wall_s": wall,
                  "cold_first_call_s": res.get("first_call_s"), "cold_launch_to_answer_s": res.get("launch_to_answer_s"),
                  "verdict": res.get("verdict"), "warm_cpu_s": ru2.ru_utime + ru2.ru_stime - ru.ru_utime - ru.ru_stime,
                  "warm_first_call_s": res2.get("first_call_s"), "warm_launch_to_answer_s": res2.get("launch_to_answer_s"),
                  "later_median_s": res2.get("later_median_s"), "load": os.getloadavg()[0]}))
