"""Fuzz: engine._LAZY_SEGMENTS / _CONFIRM_COMPILED on vs off (same certificate), and an independent
oracle: closed-form sphere distances at mj_kinematics poses, minimised per segment (convex in time:
every geom translates linearly within a segment)."""
import sys
import numpy as np, mujoco
from monitor import Plan, Scene, certify
from monitor.certify import engine
from monitor.certify.types import Verdict
from monitor.errors import MonitorError

def xml(rng, S):
    e = rng.uniform(-40, 40, 3)
    return f"""
<mujoco><option timestep="0.01"/><worldbody>
<geom name="wall" type="box" size="{0.05*S} {0.4*S} {0.4*S}" pos="{0.5*S} 0 {0.3*S}" euler="{e[0]} {e[1]} {e[2]}"/>
<geom name="floor" type="plane" size="0 0 1" pos="0 0 {rng.uniform(-0.2,0)*S}"/>
<geom name="post" type="sphere" size="{0.05*S}" pos="{-0.4*S} {0.2*S} {0.3*S}"/>
<body name="carrier" pos="{rng.uniform(-.2,.2)*S} {rng.uniform(-.2,.2)*S} {0.3*S}">
  <joint name="c" type="slide" axis="{rng.normal()} {rng.normal()} {rng.normal()}"/>
  <geom name="cg" type="sphere" size="{0.03*S}" contype="0" conaffinity="0"/>
  <body name="ball" pos="{rng.uniform(-.1,.1)*S} {rng.uniform(-.1,.1)*S} {rng.uniform(-.1,.1)*S}">
    <joint name="b" type="slide" axis="{rng.normal()} {rng.normal()} {rng.normal()}"/>
    <joint name="h" type="hinge" axis="0 0 1"/>
    <geom name="ball" type="sphere" size="{0.04*S}" pos="{rng.uniform(-.05,.05)*S} 0 0"/>
  </body>
</body>
<body name="fb" pos="0 {-0.3*S} {0.3*S}"><freejoint/><geom name="fb" type="sphere" size="{0.05*S}"/></body>
<body name="mc" mocap="true" pos="{0.1*S} {0.1*S} {0.6*S}"><geom name="mc" type="sphere" size="{0.05*S}"/></body>
</worldbody></mujoco>"""

def gdist(m, d, a, b):
    ta, tb = m.geom_type[a], m.geom_type[b]
    if ta == 2 and tb == 2:
        return float(np.linalg.norm(d.geom_xpos[a] - d.geom_xpos[b]) - m.geom_size[a, 0] - m.geom_size[b, 0])
    if tb == 2:
        a, b, ta, tb = b, a, tb, ta
    c, r = d.geom_xpos[a], m.geom_size[a, 0]
    R = d.geom_xmat[b].reshape(3, 3)
    if tb == 0:
        return float(R[:, 2] @ (c - d.geom_xpos[b]) - r)
    assert tb == 6
    cl = R.T @ (c - d.geom_xpos[b]); h = m.geom_size[b]
    out = np.linalg.norm(cl - np.clip(cl, -h, h))
    return float((out if out > 0 else -np.min(h - np.abs(cl))) - r)

def pair_min(m, d, qs, times, a, b, w0, w1):
    best = (np.inf, None)
    def f(t):
        k = min(max(np.searchsorted(times, t, side="right") - 1, 0), len(times) - 2)
        s = (t - times[k]) / (times[k + 1] - times[k])
        q = qs[k] + s * (qs[k + 1] - qs[k]); q[-7:] = np.r_[qs[k][-7:-4] + s*(qs[k+1][-7:-4]-qs[k][-7:-4]), qs[0][-4:]]
        d.qpos[:] = q; mujoco.mj_kinematics(m, d)
        return gdist(m, d, a, b)
    for k in range(len(times) - 1):
        lo, hi = max(times[k], w0), min(times[k + 1], w1)
        if lo > hi: continue
        g = (5 ** .5 - 1) / 2
        x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
        f1, f2 = f(x1), f(x2)
        for _ in range(120):
            if f1 < f2: hi, x2, f2 = x2, x1, f1; x1 = hi - g * (hi - lo); f1 = f(x1)
            else: lo, x1, f1 = x1, x2, f2; x2 = lo + g * (hi - lo); f2 = f(x2)
        for t in (max(times[k], w0), min(times[k+1], w1), x1):
            v = f(t)
            if v < best[0]: best = (v, t)
    return best

def key(c):
    d = c.to_dict(); d.get("stats", {}).pop("wall_seconds", None); d.pop("wall_seconds", None)
    return repr(d)

def run(seed):
    rng = np.random.default_rng(seed)
    S = float(rng.choice([1.0, 1e-5, 1e5, 1.0, 1.0]))
    m = mujoco.MjModel.from_xml_string(xml(rng, S))
    for j in range(2):  # non-unit slide axes (a hand edit: MuJoCo's FK uses them as they are)
        m.jnt_axis[j] *= rng.choice([1.0, 0.3, 3.0])
    d = mujoco.MjData(m)
    scene = Scene.from_model(m, pairs="all", allowed=None)
    K = int(rng.integers(2, 5))
    dur = float(rng.choice([1.0, 1e-6, 1e-12, 1e4]))
    times = np.cumsum(np.r_[0.0, rng.uniform(0.2, 1.0, K - 1)]) * dur
    qs = np.zeros((K, m.nq))
    mode = rng.integers(0, 4)
    for k in range(K):
        qs[k, 0] = rng.uniform(-0.6, 0.6) * S if rng.random() < .8 or k == 0 else qs[k-1, 0]
        qs[k, 1] = rng.uniform(-0.6, 0.6) * S if rng.random() < .8 or k == 0 else qs[k-1, 1]
        qs[k, 2] = 0.0 if mode != 3 else 0.7   # hinge constant (zero or not)
        qs[k, 3:6] = (np.r_[0, -0.3 * S, 0.3 * S] + rng.uniform(-.5, .5, 3) * S) if (rng.random() < .7 or k == 0) else qs[k-1, 3:6]
        q0 = np.array([.9, .1, -.3, .2]); q0 /= np.linalg.norm(q0)
        qs[k, 6:10] = q0 if (mode != 1 or k % 2 == 0) else -q0   # -q vs q: no real rotation
    w0, w1 = times[0], times[-1]
    if rng.random() < .3:
        w0, w1 = sorted(rng.uniform(times[0], times[-1], 2))
    plan = Plan(times, qs, m)
    geoms = [m.geom(i).name for i in range(m.ngeom)]
    gid = {n: i for i, n in enumerate(geoms)}
    pair_names = [(p.geom_a, p.geom_b) if hasattr(p, "geom_a") else None for p in []]
    res = []
    # true minimum over the window per scene pair
    trues = {}
    for pa in scene.pairs if hasattr(scene, "pairs") else []:
        pass
    margin_choice = rng.choice(["0", "tiny", "1cm", "huge", "graze"])
    out = []
    for method in ("auto", "extrusion"):
        certs = {}
        for lazy in (True, False):
            for comp in (True, False):
                engine._LAZY_SEGMENTS, engine._CONFIRM_COMPILED = lazy, comp
                try:
                    with np.errstate(all="ignore"):
                        c = certify(scene, plan, margin=MARG[0], method=method, window=(float(w0), float(w1)))
                    certs[(lazy, comp)] = c
                except MonitorError as e:
                    certs[(lazy, comp)] = "ERR " + type(e).__name__ + str(e)[:80]
        engine._LAZY_SEGMENTS = engine._CONFIRM_COMPILED = True
        out.append((method, certs))
    return m, d, scene, plan, qs, times, (w0, w1), out, gid

MARG = [0.0]
if __name__ == "__main__":
    n0, n1 = int(sys.argv[1]), int(sys.argv[2])
    stats = {}
    for seed in range(n0, n1):
        rng = np.random.default_rng(10**6 + seed)
        mc = rng.choice(["0", "tiny", "1cm", "huge"])
        MARG[0] = {"0": 0.0, "tiny": 1e-300, "1cm": 0.01, "huge": 1e3}[mc]
        try:
            m, d, scene, plan, qs, times, (w0, w1), out, gid = run(seed)
        except ValueError as e:
            stats["model"] = stats.get("model", 0) + 1; continue
        S = None
        for method, certs in out:
            ks = {k: (v if isinstance(v, str) else key(v)) for k, v in certs.items()}
            if len(set(ks.values())) != 1:
                print("DIFF", seed, method, {k: (v if isinstance(v, str) else v.verdict) for k, v in certs.items()}, flush=True)
            c = certs[(True, True)]
            if isinstance(c, str):
                stats["err"] = stats.get("err", 0) + 1; continue
            stats[str(c.verdict)] = stats.get(str(c.verdict), 0) + 1
            # oracle
            tmin = np.inf
            for pr in c.pairs:
                na, nb = pr.geoms
                v, t = pair_min(m, d, qs, times, gid[na], gid[nb], w0, w1)
                tmin = min(tmin, v)
            scale = 1e-9 * max(1.0, np.abs(qs).max())
            if c.verdict == Verdict.CERTIFIED and tmin < MARG[0] - scale:
                print("FALSE CERT", seed, method, tmin, MARG[0], flush=True)
            if c.clearance > tmin + scale:
                print("CLEARANCE ABOVE TRUE", seed, method, c.clearance, tmin, flush=True)
            if c.witness is not None:
                w = c.witness
                tw = w.time
                k = min(max(np.searchsorted(times, tw, side="right") - 1, 0), len(times) - 2)
                s = (tw - times[k]) / (times[k + 1] - times[k])
                q = qs[k] + s * (qs[k + 1] - qs[k]); q[-4:] = qs[0][-4:]
                d.qpos[:] = q; mujoco.mj_kinematics(m, d)
                na, nb = w.geoms
                ex = gdist(m, d, gid[na], gid[nb])
                if not ex < MARG[0] + scale:
                    print("WITNESS NOT REAL", seed, method, tw, (na, nb), ex, MARG[0], flush=True)
    print("stats", stats)
