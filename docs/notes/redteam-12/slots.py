import sys; sys.path.insert(0, "/tmp/rt12"); sys.path.insert(0, "/work/wt/rt12/tests")
import gen, numpy as np, monitor, mujoco
import test_redteam_12 as T
n_eq = n_diff = n_trees = 0
def check(m, times, qpos, pairs, margin):
    global n_eq, n_diff
    scene = monitor.Scene.from_model(m, pairs=pairs); plan = monitor.Plan(times, qpos, m)
    allc = monitor.certify(scene, plan, margin=margin, epsilon=1e-3, method="toleranced")
    got = {tuple(p.geoms): p for p in allc.pairs}
    order = list(range(len(pairs))); np.random.default_rng(0).shuffle(order)
    # a shuffled full selection too (another slot order)
    sh = monitor.certify(scene, plan, margin=margin, epsilon=1e-3, method="toleranced", pairs=[pairs[i] for i in order])
    for p in sh.pairs:
        q = got[tuple(p.geoms)]
        if p.method == "culled" and q.method == "culled":
            if p.clearance == q.clearance: n_eq += 1
            else: n_diff += 1; print("DIFF shuffled", p.geoms, p.clearance, q.clearance)
    for pr in pairs:
        c = monitor.certify(scene, plan, margin=margin, epsilon=1e-3, method="toleranced", pairs=[pr])
        p = c.pairs[0]; q = got[tuple(p.geoms)]
        if p.method == "culled" and q.method == "culled":
            if p.clearance == q.clearance: n_eq += 1
            else: n_diff += 1; print("DIFF single", p.geoms, p.clearance, q.clearance)
for seed in range(5000, 5060):
    m, times, qpos, meta = gen.make_case(seed)
    pairs = gen.candidate_pairs(m)
    check(m, times, qpos, pairs, 0.0); n_trees += 1
m, times, q, pairs = T._hand(8, 0.3, 0.002, False)
check(m, times, q, pairs, 0.001)
print("trees", n_trees, "culled clearances equal", n_eq, "diff", n_diff)
