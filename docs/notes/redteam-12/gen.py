"""rt12 case generator + oracle (sphere/capsule closed forms on MuJoCo FK). Shared by branch/base runs."""
from __future__ import annotations

import math

import mujoco
import numpy as np


def _q(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def _ax(rng):
    a = rng.normal(size=3)
    return a * rng.uniform(0.3, 3.0) / np.linalg.norm(a)   # non-unit on purpose


def _f(v):
    return " ".join(f"{x:.17g}" for x in v)


def _geom(rng, name, big):
    if rng.random() < 0.5:
        return f'<geom name="{name}" type="sphere" size="{rng.uniform(0.01, 0.05):.6g}" pos="{_f(rng.uniform(-0.03, 0.03, 3))}"/>'
    a = rng.uniform(-0.05, 0.05, 3)
    b = a + rng.uniform(-0.08, 0.08, 3)
    return f'<geom name="{name}" type="capsule" fromto="{_f(a)} {_f(b)}" size="{rng.uniform(0.005, 0.03):.6g}"/>'


ROOTS = ("hinge", "slide", "ball", "free", "slide+hinge", "hinge+hinge", "mocap")


def make_case(seed: int):
    rng = np.random.default_rng(seed)
    root = ROOTS[seed % len(ROOTS)]
    big = rng.random() < 0.25
    off = rng.uniform(-1e4, 1e4, 3) if big else rng.uniform(-0.5, 0.5, 3)
    welded = rng.random() < 0.4       # C a welded (jointless) child of the moving root
    kinds = ["hinge", "slide", "ball"]

    def joint(name, typ):
        if typ == "hinge":
            return f'<joint name="{name}" type="hinge" axis="{_f(_ax(rng))}" pos="{_f(rng.uniform(-0.05, 0.05, 3))}"/>'
        if typ == "slide":
            return f'<joint name="{name}" type="slide" axis="{_f(_ax(rng))}"/>'
        return f'<joint name="{name}" type="ball" pos="{_f(rng.uniform(-0.05, 0.05, 3))}"/>'

    rj = ""
    if root == "hinge":
        rj = f'<joint name="r0" type="hinge" axis="{_f(_ax(rng))}"/>'
    elif root == "slide":
        rj = f'<joint name="r0" type="slide" axis="{_f(_ax(rng))}"/>'
    elif root == "ball":
        rj = '<joint name="r0" type="ball"/>'
    elif root == "free":
        rj = '<joint name="r0" type="free"/>'
    elif root == "slide+hinge":
        rj = f'<joint name="r0" type="slide" axis="{_f(_ax(rng))}"/><joint name="r1" type="hinge" axis="0 0 1"/>'
    elif root == "hinge+hinge":
        rj = f'<joint name="r0" type="hinge" axis="0 0 1"/><joint name="r1" type="hinge" axis="{_f(_ax(rng))}"/>'
    mocap = ' mocap="true"' if root == "mocap" else ""
    if mocap:
        rj = ""
    sub = []
    jk = []
    for side in ("a", "b"):
        depth = int(rng.integers(1, 4))
        xml = ""
        for d in range(depth):
            typ = kinds[int(rng.integers(0, 3))]
            jk.append(typ)
            inner = joint(f"j{side}{d}", typ) if rng.random() < 0.85 else ""   # sometimes welded
            p = rng.uniform(-0.08, 0.08, 3)
            xml += (f'<body name="{side}{d}" pos="{_f(p)}" quat="{_f(_q(rng))}">{inner}'
                    + _geom(rng, f"g{side}{d}", big))
        xml += "</body>" * depth
        sub.append(xml)
    cbody = (f'<body name="C" pos="{_f(rng.uniform(-0.1, 0.1, 3))}" quat="{_f(_q(rng))}">' + _geom(rng, "gC", big)
             + sub[0] + sub[1] + "</body>")
    inner = (_geom(rng, "gR", big) + cbody) if welded else (_geom(rng, "gR", big) + sub[0] + sub[1])
    world = f'<geom name="wball" type="sphere" size="0.05" pos="{_f(off + rng.uniform(-0.3, 0.3, 3))}"/>'
    xml = (f'<mujoco><option><flag contact="disable"/></option><worldbody>{world}'
           f'<body name="R" pos="{_f(off)}" quat="{_f(_q(rng))}"{mocap}>{rj}{inner}</body></worldbody></mujoco>')
    m = mujoco.MjModel.from_xml_string(xml)
    # plan: the root sweeps big, the relative joints move a little
    K = int(rng.choice([2, 3, 5, 12, 30]))
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.1, K - 1))])
    s = (times - times[0]) / (times[-1] - times[0])
    qpos = np.tile(m.qpos0, (K, 1)).astype(float)
    rel_amp = rng.choice([1e-4, 1e-2, 0.3])
    for j in range(m.njnt):
        adr = m.jnt_qposadr[j]
        typ = m.jnt_type[j]
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
        is_root = name.startswith("r")
        amp = 3.0 if is_root else rel_amp
        if typ == 3 or typ == 2:   # hinge/slide
            lin = rng.uniform(-1, 1) * amp
            noise = rng.normal(scale=0.05 * amp, size=K) if K > 2 else 0.0
            qpos[:, adr] = rng.uniform(-0.3, 0.3) * (amp if not is_root else 1) + lin * s + noise
            if typ == 2 and is_root:
                qpos[:, adr] *= 0.3
        elif typ == 1:  # ball
            ax = rng.normal(size=3)
            ax /= np.linalg.norm(ax)
            th0 = rng.uniform(-0.3, 0.3) * min(amp, 1)
            th = th0 + rng.uniform(-1, 1) * amp * s + (rng.normal(scale=0.05 * amp, size=K) if K > 2 else 0)
            qpos[:, adr:adr + 4] = np.stack([np.cos(th / 2), *(np.sin(th / 2)[None] * ax[:, None])], 1)
        elif typ == 0:  # free
            qpos[:, adr:adr + 3] = off + np.outer(s, rng.uniform(-0.5, 0.5, 3))
            ax = rng.normal(size=3)
            ax /= np.linalg.norm(ax)
            th = 3.0 * s * rng.uniform(-1, 1)
            qpos[:, adr + 3:adr + 7] = np.stack([np.cos(th / 2), *(np.sin(th / 2)[None] * ax[:, None])], 1)
    return m, times, qpos, dict(root=root, big=bool(big), welded=bool(welded), K=K, rel_amp=float(rel_amp))


def geom_names(m):
    return [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(m.ngeom)]


def candidate_pairs(m):
    names = geom_names(m)
    out = []
    for a in range(m.ngeom):
        for b in range(a + 1, m.ngeom):
            if m.geom_bodyid[a] == m.geom_bodyid[b]:
                continue
            out.append((names[a], names[b]))
    return out


# ---------------------------------------------------------------- oracle
def interp(m, times, qpos, t):
    k = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2))
    s = min(max((t - times[k]) / (times[k + 1] - times[k]), 0.0), 1.0)
    a, b = qpos[k], qpos[k + 1]
    q = a + s * (b - a)
    for j in range(m.njnt):
        adr = int(m.jnt_qposadr[j])
        typ = int(m.jnt_type[j])
        sl = slice(adr + 3, adr + 7) if typ == 0 else (slice(adr, adr + 4) if typ == 1 else None)
        if sl is None:
            continue
        q0, q1 = a[sl] / np.linalg.norm(a[sl]), b[sl] / np.linalg.norm(b[sl])
        d = float(q0 @ q1)
        if d < 0:
            q1, d = -q1, -d
        th = math.acos(min(d, 1.0))
        qq = q0 + s * (q1 - q0) if th < 1e-12 else (math.sin((1 - s) * th) * q0 + math.sin(s * th) * q1) / math.sin(th)
        q[sl] = qq / np.linalg.norm(qq)
    return q


def _seg(p, q, r, s):
    """min distance of segments pq and rs (the test file's closed form)."""
    import sys
    sys.path.insert(0, "/work/wt/rt12/tests")
    from test_redteam_12 import _seg_dist
    return _seg_dist(p, q, r, s)


def _segment(m, d, g):
    p = d.geom_xpos[g]
    if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
        return p, p, m.geom_size[g, 0]
    ax = d.geom_xmat[g].reshape(3, 3)[:, 2] * m.geom_size[g, 1]
    return p - ax, p + ax, m.geom_size[g, 0]


def dist(m, d, ga, gb):
    a0, a1, ra = _segment(m, d, ga)
    b0, b1, rb = _segment(m, d, gb)
    return _seg(a0.copy(), a1.copy(), b0.copy(), b1.copy()) - ra - rb


class Oracle:
    def __init__(self, m, times, qpos):
        self.m, self.times, self.qpos = m, times, qpos
        self.d = mujoco.MjData(m)
        if m.nmocap:
            pass

    def at(self, t, pairs_ids):
        self.d.qpos[:] = interp(self.m, self.times, self.qpos, t)
        mujoco.mj_kinematics(self.m, self.d)
        return [dist(self.m, self.d, a, b) for a, b in pairs_ids]

    def minimum(self, pairs_ids, t0, t1, n=600):
        ts = np.linspace(t0, t1, n)
        D = np.array([self.at(t, pairs_ids) for t in ts])      # (n, P)
        out = []
        for i in range(len(pairs_ids)):
            k = int(np.argmin(D[:, i]))
            lo, hi = ts[max(k - 1, 0)], ts[min(k + 1, n - 1)]
            best = D[k, i]
            f = lambda t: self.at(t, [pairs_ids[i]])[0]  # noqa: E731
            g = (math.sqrt(5) - 1) / 2
            a, b = lo, hi
            c, dd = b - g * (b - a), a + g * (b - a)
            fc, fd = f(c), f(dd)
            for _ in range(40):
                if fc < fd:
                    b, dd, fd = dd, c, fc
                    c = b - g * (b - a)
                    fc = f(c)
                else:
                    a, c, fc = c, dd, fd
                    dd = a + g * (b - a)
                    fd = f(dd)
                best = min(best, fc, fd)
            out.append(best)
        return np.array(out), D.min(axis=0)
