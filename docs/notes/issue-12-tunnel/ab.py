"""A/B of Gate(tunnel, margin=0.001).step: one worker process per code tree, alternating.

usage: python ab.py OLD_TREE NEW_TREE [rounds]
Each worker: 100 gated steps (the profile script's control), per-step median us over rounds,
plus a signature of every step (verdict, earliest time, witness time, clearance) to compare.
"""
import json
import os
import subprocess
import sys

WORKER = r'''
import collections, json, sys, time
import numpy as np, mujoco
from monitor.gate import Gate
import monitor
monitor_file = monitor.__file__
m = mujoco.MjModel.from_xml_path("/work/main/models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)
def run(n):
    mujoco.mj_resetDataKeyframe(m, d, 0); gate.reset()
    sig = []; t = time.perf_counter()
    for k in range(n):
        target = 0.3 if (k // 25) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
        c = r.certificate
        sig.append((str(r.verdict), c.earliest_time, None if c.witness is None else c.witness.time,
                    float(c.clearance)))
    return (time.perf_counter() - t) / n * 1e6, sig
run(5)
per = []
for _ in range(int(sys.argv[1])):
    us, sig = run(100); per.append(us)
print(json.dumps({"per": per, "sig": repr(sig), "qpos": repr(d.qpos.tolist())}))
'''


def main() -> None:
    """Alternate old/new workers; print medians, ratio and whether every step agreed."""
    old, new = sys.argv[1], sys.argv[2]
    rounds = sys.argv[3] if len(sys.argv) > 3 else "3"
    res = {}
    for tree in (old, new, old, new):
        # cwd "/": with -c, sys.path[0] is the cwd, which would shadow PYTHONPATH
        env = dict(os.environ, PYTHONPATH=tree)
        out = subprocess.run([sys.executable, "-c", WORKER + f"\nassert monitor_file.startswith({tree!r})",
                              rounds], env=env, cwd="/", capture_output=True, text=True, check=True).stdout
        r = json.loads(out.strip().splitlines()[-1])
        e = res.setdefault(tree, {"per": [], "sig": r["sig"], "qpos": r["qpos"]})
        e["per"] += r["per"]
        assert e["sig"] == r["sig"]
    import statistics
    mo, mn = (statistics.median(res[t]["per"]) for t in (old, new))
    print(f"old {mo:.0f} us/step  new {mn:.0f} us/step  ratio old/new {mo / mn:.2f}")
    print("identical signatures:", res[old]["sig"] == res[new]["sig"], " identical final qpos:",
          res[old]["qpos"] == res[new]["qpos"])
    verdicts = collections_count(res[new]["sig"])
    print("verdicts (new):", verdicts)


def collections_count(sig: str) -> dict:
    """{verdict: steps} of a signature repr."""
    import ast
    import collections
    return dict(collections.Counter(s[0] for s in ast.literal_eval(sig.replace("inf", "1e999"))))


if __name__ == "__main__":
    main()
