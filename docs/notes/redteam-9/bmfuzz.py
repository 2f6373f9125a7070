"""BodyMotion / Plan with real rotation, boxes/capsules/cylinders/meshes: _CONFIRM_COMPILED and _LAZY_SEGMENTS on vs off."""
import sys, collections
import numpy as np, mujoco
from monitor import BodyMotion, Plan, Scene, certify
from monitor.certify import engine
from monitor.errors import MonitorError
XML = """<mujoco><worldbody>
<geom name="floor" type="plane" size="0 0 1" pos="0 0 -0.5"/>
<geom name="wall" type="box" size="0.05 0.4 0.4" pos="0.5 0 0" euler="10 20 30"/>
<body name="a"><freejoint/><geom name="ab" type="box" size="0.1 0.05 0.08"/><geom name="ac" type="capsule" size="0.03 0.1" pos="0 0 0.15"/></body>
<body name="b" pos="0.2 0.2 0"><freejoint/><geom name="bb" type="cylinder" size="0.05 0.1"/><geom name="bs" type="sphere" size="0.04" pos="0.1 0 0"/></body>
<body name="c" pos="-0.3 0 0"><joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 1 1"/><geom name="cb" type="box" size="0.07 0.07 0.07"/></body>
</worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
scene = Scene.from_model(m, pairs="all", allowed=None)
def key(c):
    d = c.to_dict(); d["stats"].pop("wall_seconds"); return repr(d)
rng = np.random.default_rng(int(sys.argv[1]))
cnt = collections.Counter()
for it in range(int(sys.argv[2])):
    K = int(rng.integers(2, 5))
    times = np.cumsum(np.r_[0, rng.uniform(0.1, 1, K - 1)]) * float(rng.choice([1.0, 1e-9, 1e3]))
    qs = np.zeros((K, m.nq))
    rotate = rng.random() < 0.5
    for k in range(K):
        for j, base in ((0, [0, 0, 0]), (7, [0.2, 0.2, 0])):
            qs[k, j:j + 3] = np.array(base) + rng.uniform(-0.3, 0.3, 3)
            q = rng.normal(size=4) if (rotate or k == 0) else qs[0, j + 3:j + 7]
            qs[k, j + 3:j + 7] = q / np.linalg.norm(q) * (rng.choice([1, -1]) if not rotate else 1)
        qs[k, 14:16] = rng.uniform(-0.3, 0.3, 2)
    margin = float(rng.choice([0.0, 1e-300, 0.01, 0.3]))
    win = None
    if rng.random() < 0.3:
        w = sorted(rng.uniform(times[0], times[-1], 2)); win = (float(w[0]), float(w[1]))
    traj = Plan(times, qs, m)
    if rng.random() < 0.5:
        pos, rot = traj.body_poses(times)
        quat = np.zeros((K, m.nbody, 4))
        for k in range(K):
            for b in range(m.nbody):
                mujoco.mju_mat2Quat(quat[k, b], rot[k, b].ravel())
        traj = BodyMotion(times, pos, quat)
    for meth in ("auto", "toleranced", "extrusion"):
        ks = set(); verd = None
        for lazy in (True, False):
            for comp in (True, False):
                engine._LAZY_SEGMENTS, engine._CONFIRM_COMPILED = lazy, comp
                try:
                    c = certify(scene, traj, margin=margin, method=meth, window=win); ks.add(key(c)); verd = verd or c.verdict.value
                except MonitorError as e:
                    ks.add(type(e).__name__ + str(e)); verd = verd or "error"
        engine._LAZY_SEGMENTS = engine._CONFIRM_COMPILED = True
        cnt[(type(traj).__name__, meth, verd)] += 1
        if len(ks) != 1:
            print("DIFF", it, meth, type(traj).__name__, flush=True)
print(cnt)
