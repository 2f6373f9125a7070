"""Capture the plans certify sees on the Arm gate, then time pack / kernel parts on them."""
import sys, time, statistics
import numpy as np, gymnasium as gym
import monitor, monitor.envs  # noqa
import monitor.certify.engine as E
import monitor.certify.kernels as K
import monitor.motion.pack as PK
import monitor.motion.kernel as KN
from monitor.gym_gate import SafetyGate
cap = []
_c = E.certify
def c(scene, plan, *a, **k):
    r = _c(scene, plan, *a, **k)
    cap.append((scene, plan, k.get("request"), r))
    return r
E.certify = c
env = SafetyGate(gym.make("monitor/Arm-v0"))
for ep in range(2):
    env.reset(seed=ep); env.action_space.seed(ep)
    for a in [env.action_space.sample() for _ in range(15)]:
        env.step(a)
E.certify = _c
pc = time.perf_counter
def tm(f, n=30):
    ts = []
    for _ in range(n):
        t = pc(); f(); ts.append(pc() - t)
    return statistics.median(ts) * 1e6
sel = {}
for scene, plan, req, r in cap:
    sel.setdefault(len(plan.times), (scene, plan, req, r))
from monitor.motion.plan import Plan
for K_, (scene, plan, req, r) in sorted(sel.items()):
    print(f"rows {K_}: verdict {r.verdict} tests {r.stats['tests']}")
    mp = PK.pack_trajectory(plan)
    print(f"  pack_trajectory  {tm(lambda: PK.pack_trajectory(plan)):8.1f} us")
    print(f"  _pack_plan w/o scale: ", end="")
    st = PK._plan_static(plan)
    print(f"  plan_data_agrees {tm(lambda: PK.plan_data_agrees(plan, mp)):8.1f} us")
    print(f"  _pack_agrees     {tm(lambda: K._pack_agrees(plan, mp)):8.1f} us")
    z = np.zeros(1); nb = mp.body_parent.shape[0]
    bufs = (np.empty((1, nb, 3)), np.empty((1, nb, 3, 3)), np.empty((1, nb)), np.empty((1, nb)))
    mp0 = mp._replace(tol=mp.tol.copy()); mp0.tol[3] = 0.0
    print(f"  BATCH_SCALE      {tm(lambda: KN.batch(mp0, KN.BATCH_SCALE, z, z, *bufs)):8.1f} us")
    moving = np.empty(nb, np.int64); rot = np.empty(nb, np.int64); tol = np.zeros(6)
    print(f"  derive           {tm(lambda: KN.derive(mp.qpos, st.body_parent, st.body_mocap, st.body_jntadr, st.body_jntnum, st.jnt_type, st.jnt_qposadr, moving, rot, tol)):8.1f} us")
    rows = np.column_stack([plan.times, plan.qpos])
    print(f"  Plan._trusted    {tm(lambda: Plan._trusted(rows[:,0].copy(), rows[:,1:].copy(), model=plan.model, mocap_pos=plan._mocap_pos.copy(), mocap_quat=plan._mocap_quat.copy())):8.1f} us")
    def full():
        p2 = Plan._trusted(rows[:,0].copy(), rows[:,1:].copy(), model=plan.model, mocap_pos=plan._mocap_pos.copy(), mocap_quat=plan._mocap_quat.copy())
        return _c(scene, p2, request=req)
    print(f"  certify(new plan) {tm(full, 15):8.1f} us")
    print(f"  certify(same plan) {tm(lambda: _c(scene, plan, request=req), 15):8.1f} us")
    # bounds over intervals of different spans
    t0, t1 = float(plan.times[0]), float(plan.times[-1])
    for span in (1, 4, 16, 64, K_ - 1):
        if span > K_ - 1: continue
        ta = np.array([plan.times[0]]); tb = np.array([plan.times[span]])
        pos = np.empty((1, nb, 3)); R = np.empty((1, nb, 3, 3)); tr = np.empty((1, nb)); an = np.empty((1, nb))
        ta100 = np.repeat(ta, 200); tb100 = np.repeat(tb, 200)
        pos = np.empty((200, nb, 3)); R = np.empty((200, nb, 3, 3)); tr = np.empty((200, nb)); an = np.empty((200, nb))
        us = tm(lambda: KN.batch(mp, KN.BATCH_BOUNDS, ta100, tb100, pos, R, tr, an), 10) / 200
        print(f"  tree_bounds span {span:3d} segs: {us:6.2f} us/interval  trans max {tr[0].max():.4f}")
