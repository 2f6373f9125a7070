import time, statistics, mujoco, numpy as np, operator
from monitor import Plan, Scene, certify
import monitor.motion.plan as PP
from monitor.errors import InvalidInputError
def base_ts(self, body):
    b = int(body)
    if not 0 <= b < self.nbody:
        raise InvalidInputError("x")
    if not self._moving[b]:
        p = self._wp_pos[0, b]
        return self._times[[0, -1]], p[None].repeat(2, 0)
    if self._rotating[b]:
        return None
    return self._times.copy(), self._wp_pos[:, b].copy()
def py_ts(self, body):
    b = int(body)
    if not 0 <= b < self.nbody:
        raise InvalidInputError("x")
    if not self._moving[b]:
        p = self._wp_pos[0, b]
        return self._times[[0, -1]], p[None].repeat(2, 0)
    if self._rotating[b]:
        return None
    o = self._wp_pos[:, b].copy()
    tl = self._tlist
    dt_min = min(map(operator.sub, tl[1:], tl[:-1]))
    if not max(o.max(), -o.min()) <= dt_min * 1e307:
        return None
    return self._times.copy(), o
def py2_ts(self, body):
    b = int(body)
    if not 0 <= b < self.nbody:
        raise InvalidInputError("x")
    if not self._moving[b]:
        p = self._wp_pos[0, b]
        return self._times[[0, -1]], p[None].repeat(2, 0)
    if self._rotating[b]:
        return None
    o = self._wp_pos[:, b].copy()
    tl = self._tlist
    dt_min = min(map(operator.sub, tl[1:], tl[:-1]))
    if not max(map(abs, o.ravel().tolist())) <= dt_min * 1e307:
        return None
    return self._times.copy(), o
V = {"new": PP.Plan.translation_segments, "base": base_ts, "py": py_ts, "py2": py2_ts}
XML = """<mujoco><option timestep="0.01"/><worldbody><body name="wall" pos="0.1 0 0"><geom name="wall" type="box" size="0.005 0.2 0.2"/></body>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.01"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
T = np.linspace(0, 0.05, 6); Q = np.linspace(-0.05, -0.03, 6)[:, None]
plans = [Plan(T, Q + 1e-6 * k, m) for k in range(12000)]
for p in plans[:200]: certify(sc, p, 0.001)
res = {k: [] for k in V}
i = 200; names = list(V)
for blk in range(40):
    mode = names[blk % 4]
    PP.Plan.translation_segments = V[mode]
    t0 = time.process_time()
    for p in plans[i:i + 280]:
        certify(sc, p, 0.001)
    i += 280
    res[mode].append((time.process_time() - t0) / 280 * 1e6)
print(" ".join("%s %.1f" % (k, statistics.median(v)) for k, v in res.items()))
