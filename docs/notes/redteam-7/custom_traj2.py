import mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
from monitor import Scene, certify, BodyMotion
shapes = {"sphere": 'type="sphere" size="0.02"', "box": 'type="box" size="0.02 0.03 0.01"', "capsule": 'type="capsule" size="0.02 0.05"',
          "cyl": 'type="cylinder" size="0.02 0.05"', "ell": 'type="ellipsoid" size="0.02 0.03 0.04"'}
obst = {"box": '<geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>',
        "plane": '<geom name="wall" type="plane" size="1 1 0.1" pos="0.3 0 0" zaxis="-1 0 0"/>',
        "sphere": '<geom name="wall" type="sphere" size="0.1" pos="0.3 0 0"/>',
        "capsule": '<geom name="wall" type="capsule" size="0.05 0.2" pos="0.3 0 0"/>'}
class Custom:
    def __init__(self, bm): self.bm = bm
    def __getattr__(self, k): return getattr(self.bm, k)
    def translation_segments(self, b):
        if not self.bm._moving[b]:
            p = self.bm._pos[0, b]; return np.array([self.bm.t0, self.bm.t1]), np.stack([p, p])
        if self.bm._rotating[b]: return None
        return self.bm._times.copy(), self.bm._pos[:, b].copy()
bad = n = 0
for on, ox in obst.items():
    for sn, sx in shapes.items():
        m = mujoco.MjModel.from_xml_string(f'<mujoco><worldbody>{ox}<body name="ball"><freejoint/><geom name="ball" {sx}/></body></worldbody></mujoco>')
        sc = Scene.from_model(m, pairs="all", allowed=None)
        for dt in (1e-308, 5e-324):
            for a in (1.0, 3.0):
                pos = np.zeros((2, 2, 3)); pos[0, 1, 0], pos[1, 1, 0] = -a, a
                quat = np.zeros((2, 2, 4)); quat[..., 0] = 1
                for traj in (Custom(BodyMotion([0, dt], pos, quat)), BodyMotion([0, dt], pos, quat)):
                    for meth in ("auto", "extrusion"):
                        n += 1
                        try:
                            r = certify(sc, traj, margin=0.0, method=meth)
                        except Exception as e:
                            continue
                        if r.verdict == "certified":
                            bad += 1; print("CERTIFIED", on, sn, dt, a, type(traj).__name__, meth)
print("calls", n, "certified", bad)
