"""A/B of Scene.from_model and the first certify on fresh sparse scaling scenes, two trees alternated.

Usage: python docs/notes/issue-12-scenepack/ab_scene.py BASE_TREE NEW_TREE ROUNDS [N ...]
Each round runs one fresh process per tree (order alternated). In a process, after a warm-up scene
(3 bodies, then a 1000-body one, so the sweep specialisation of the window kernel is loaded as in
the bench), for each N (default 100 1000 3000): ``Scene.from_model(model, pairs="all")`` with
pairs "all" and "mujoco" (medians of 3 fresh scenes; 1 at N >= 3000), and the FIRST certify of a
fresh BodyMotion on a fresh "all" scene (as the bench's scaling row), translating, and that scene's
from_model plus the certify (page faults of large fresh arrays move between the two: the sum is the
fair figure).
Prints per tree and N the medians over rounds and the ratio new / base.
"""
import json
import statistics
import subprocess
import sys

CHILD = r'''
import json, sys, time
import monitor
assert monitor.__file__.startswith(sys.argv[1]), monitor.__file__   # the tree under test (cwd = tree)
from monitor.bench.suites import scaling_scene
from monitor.certify.common import Budget
m3, b3 = scaling_scene(3, "sparse", "translating")
monitor.certify(monitor.Scene.from_model(m3, pairs="all"), b3, epsilon=1e-3)
m1, b1 = scaling_scene(1000, "sparse", "translating", seed=1)
monitor.certify(monitor.Scene.from_model(m1, pairs="all"), b1, epsilon=1e-3)
out = {}
for n in [int(x) for x in sys.argv[2:]]:
    model, bm = scaling_scene(n, "sparse", "translating")
    reps = 1 if n >= 3000 else 3
    for pairs in ("all", "mujoco"):
        ts = []
        for _ in range(reps):
            t = time.perf_counter()
            monitor.Scene.from_model(model, pairs=pairs)
            ts.append(time.perf_counter() - t)
        out[f"from_model {pairs} {n}"] = sorted(ts)[len(ts) // 2]
    ts, both = [], []
    for _ in range(reps):
        _, bm = scaling_scene(n, "sparse", "translating")
        t0 = time.perf_counter()
        scene = monitor.Scene.from_model(model, pairs="all")
        t = time.perf_counter()
        monitor.certify(scene, bm, epsilon=1e-3, budget=Budget(seconds=60.0))
        ts.append(time.perf_counter() - t)
        both.append(time.perf_counter() - t0)
    out[f"first certify {n}"] = sorted(ts)[len(ts) // 2]
    out[f"from_model + first certify {n}"] = sorted(both)[len(both) // 2]
print(json.dumps(out))
'''


def main():
    """Run the rounds and print the table."""
    base, new, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3])
    sizes = sys.argv[4:] or ["100", "1000", "3000"]
    res = {"base": [], "new": []}
    for r in range(rounds):
        order = [("base", base), ("new", new)] if r % 2 == 0 else [("new", new), ("base", base)]
        for label, tree in order:
            env = {"PYTHONPATH": tree, "PATH": ""}
            p = subprocess.run([sys.executable, "-c", CHILD, tree, *sizes], env=env, cwd=tree,
                               capture_output=True, text=True, check=True)
            res[label].append(json.loads(p.stdout.strip().splitlines()[-1]))
    print(f"{'row':34s} {'base ms':>24s} {'new ms':>24s} {'ratio':>6s}")
    for key in res["base"][0]:
        b = [x[key] * 1e3 for x in res["base"]]
        n = [x[key] * 1e3 for x in res["new"]]
        mb, mn = statistics.median(b), statistics.median(n)
        runs_b, runs_n = " ".join(f"{x:.1f}" for x in b), " ".join(f"{x:.1f}" for x in n)
        print(f"{key:34s} {mb:9.2f} ({runs_b}) {mn:9.2f} ({runs_n}) {mn / mb:6.3f}")


if __name__ == "__main__":
    main()
