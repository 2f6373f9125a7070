import mujoco, numpy as np, math
from monitor import Plan
from monitor.motion.pack import pack_trajectory
from monitor.errors import MonitorError
XML = """
<mujoco>
  <worldbody>
    <body name="f" pos="0 0 0"><freejoint/><geom type="box" size="0.1 0.05 0.02"/>
      <body name="c" pos="0.2 0 0"><joint type="hinge" axis="0 0 1"/><geom type="capsule" size="0.02 0.1"/>
        <body name="d" pos="0.2 0 0"><joint type="slide" axis="1 0 0"/><geom type="sphere" size="0.03"/></body>
      </body>
    </body>
    <body name="b" pos="1 0 0"><joint type="ball"/><geom type="box" size="0.1 0.1 0.1" pos="0.1 0 0"/></body>
    <body name="mc" mocap="true" pos="0 1 0"><geom type="sphere" size="0.1"/></body>
  </worldbody>
</mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
rng = np.random.default_rng(0)
def rq(n): u = rng.normal(size=(n, 4)); return u / np.linalg.norm(u, axis=1, keepdims=True)
def mk(K, off, amp, tscale, angamp, negq=False, denorm=False):
    q = np.zeros((K, m.nq))
    q[:, 0:3] = off + amp * rng.normal(size=(K, 3))
    base = rq(1)[0]
    for k in range(K):
        ax = rng.normal(size=3); ax /= np.linalg.norm(ax)
        ang = angamp * rng.normal()
        dq = np.r_[math.cos(ang/2), math.sin(ang/2) * ax]
        w1, v1 = base[0], base[1:]; w2, v2 = dq[0], dq[1:]
        qq = np.r_[w1*w2 - v1@v2, w1*v2 + w2*v1 + np.cross(v1, v2)]
        if negq and k % 2: qq = -qq
        q[k, 3:7] = qq
    q[:, 7] = off * 0 + amp * rng.normal(size=K) * 10
    q[:, 8] = amp * rng.normal(size=K)
    q[:, 9:13] = rq(K)
    if denorm:
        q[:, 8] = 5e-324 * rng.integers(0, 3, K)
    t = np.sort(rng.uniform(0, tscale, K)); t[0] = 0.0
    t = np.unique(t)
    return t, q[:len(t)]
worst = 0; n = 0; below = 0; flagbad = 0; errs = 0
for case in range(400):
    K = int(rng.integers(2, 12))
    off = [0, 1e4, -1e4, 1e3][case % 4]
    amp = [1e-12, 1e-6, 1e-2, 1.0, 0.0][case // 4 % 5]
    tscale = [1e-6, 1.0, 1e6][case // 20 % 3]
    angamp = [0.0, 1e-9, 1.0, 3.1, 100.0][case // 60 % 5]
    t, q = mk(K, off, amp, tscale, angamp, negq=(case % 7 == 0), denorm=(case % 11 == 0))
    try:
        p = Plan(t, q, m)
    except MonitorError as e:
        errs += 1; continue
    mp = pack_trajectory(p)
    s_pack = float(mp.tol[3]); s_plan = p._scale if p._moving.any() else 0.0
    n += 1
    if (mp.body_moving != 0).tolist() != p._moving.tolist() or (mp.body_rotating != 0).tolist() != p._rotating.tolist():
        flagbad += 1; print("flags", case)
    if s_plan > 0:
        r = (s_plan - s_pack) / s_plan
        worst = max(worst, abs(r))
        if s_pack < s_plan * (1 - 1e-12):
            below += 1
            print("pack scale below plan", case, s_pack, s_plan, r)
    qm = p._magnitude["q"]
    if mp.tol[4] != qm: print("qmag", case, mp.tol[4], qm)
    if mp.tol[5] != p._magnitude["path"]: print("path", case, mp.tol[5], p._magnitude["path"])
print("plans", n, "errors", errs, "worst rel", worst, "below", below, "flagbad", flagbad)
# NaN / inf rows
for bad in (np.nan, np.inf, -np.inf):
    t, q = mk(4, 0, 0.1, 1, 0.5); q[2, 8] = bad
    try: Plan(t, q, m); print("accepted", bad)
    except MonitorError as e: print("typed", type(e).__name__, str(e)[:80])
    t, q = mk(4, 0, 0.1, 1, 0.5); t = t.copy(); t[1] = bad
    try: Plan(t, q, m); print("accepted t", bad)
    except MonitorError as e: print("typed", type(e).__name__, str(e)[:80])
