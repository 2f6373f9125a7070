"""Red team 12: motion bounds relative to a pair's moving common ancestor (issue 12, hand30k).

``pair_bound(relative=1)`` / ``_bounds_core`` with ``need == 2`` freeze the pair's deepest moving
common ancestor C at its pose at the sub-interval's midpoint; stage 0 of ``window_kernel`` culls
by swept spheres relative to C; stage 1 stops after ``CALL_TESTS`` whole-shape tests and the
engine resumes from ``WI_DONE``. A wrong relative bound is a false certificate or a culled /
certified clearance above the true minimum distance.

Oracles (independent of monitor's kinematics): closed forms for spheres on a rotating arm (the
distance depends only on the relative angle), MuJoCo's ``mj_kinematics`` on dense samples with
closed-form sphere / capsule distances (a sample is a real time of the motion: a sampled distance
below the margin proves a violation, and a certified clearance must not exceed any sampled
distance), and the general tail of the engine for the kernel-decided shortcut.

Attacks: C = one of the two bodies (parent-child), siblings and cousins under C, C with a hinge
(3 rad yaw in one window), slide, ball or free joint, C welded under a moving root, offsets of
1e4 m with tiny relative motion, non-unit joint axes, long windows (many waypoints), a world geom
(its common ancestor with any body is the world; MuJoCo allows no plane on a moving body), the
sweep (``engine.SWEEP_MIN_GEOMS = 0``), and windows with more than ``CALL_TESTS`` whole-shape tests.
The random fuzz (``_fuzz_case``) is behind ``slow``.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from redteam_oracle import interp_qpos  # independent of monitor.Plan's interpolation

import monitor
from monitor.certify import engine

# ----------------------------------------------------------------------------- closed-form arm
_ROOT_JOINT = {
    "hinge": '<joint name="r0" type="hinge" axis="0 0 2"/>',          # non-unit axis on purpose
    "slide": '<joint name="r0" type="slide" axis="0.3 0.4 0"/>',
    "ball": '<joint name="r0" type="ball"/>',
    "free": '<joint name="r0" type="free"/>',
}

_PHI = 0.25
"""Angle (rad) of the welded frame w about C's z: sb's arm starts _PHI ahead of its hinge's zero."""

_ARM_XML = """<mujoco><worldbody>
  <body name="C" pos="{off} 0.5 0.25" quat="0.9 0.1 0.3 0.2">{root}
    <geom name="sc" type="sphere" size="{rc}" pos="{pc}"/>
    <body name="a" pos="0 0 0"><joint name="ja" type="hinge" axis="0 0 -3"/>
      <geom name="sa" type="sphere" size="{r}" pos="{L} 0 0"/></body>
    <body name="w" pos="0 0 0" quat="{wq0} 0 0 {wq3}">
      <body name="b" pos="0 0 0"><joint name="jb" type="hinge" axis="0 0 0.5"/>
        <geom name="sb" type="sphere" size="{r}" pos="{Lb} 0 0"/></body></body>
  </body>
</worldbody></mujoco>"""


def _arm(root: str, off: float, K: int, rel: tuple[float, float], seed: int = 0):
    """Spheres on two arms hinged at C's origin (a: angle -qa about C's z; b: in a welded frame
    turned by _PHI, angle _PHI + qb about z, both in C's xy plane) and one on C itself (sc).

    C moves hugely (3 rad about its hinge / ball axis, 0.9 m slide, or a free 3 rad turn plus
    translation); the arms' angles move by ``rel`` (rad, start and end). Returns model, times,
    qpos, and the closed-form centre angles of the arms in C's frame as functions of qpos."""
    rng = np.random.default_rng(seed)
    L, Lb, r, rc = 0.3, 0.35, 0.02, 0.03
    pc = np.array([0.3, -0.04, 0.0])
    xml = _ARM_XML.format(off=off, root=_ROOT_JOINT[root], rc=rc, pc=" ".join(map(str, pc)), r=r, L=L, Lb=Lb,
                          wq0=math.cos(0.5 * _PHI), wq3=math.sin(0.5 * _PHI))
    m = mujoco.MjModel.from_xml_string(xml)
    times = np.linspace(0.0, 0.2, K)
    s = times / times[-1]
    q = np.tile(m.qpos0, (K, 1))
    adr = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j): int(m.jnt_qposadr[j]) for j in range(m.njnt)}
    if root in ("hinge", "slide"):
        q[:, adr["r0"]] = (3.0 if root == "hinge" else 0.9) * s
    else:
        ax = rng.normal(size=3)
        ax /= np.linalg.norm(ax)
        th = 3.0 * s
        a0 = adr["r0"] + (3 if root == "free" else 0)
        q[:, a0:a0 + 4] = np.stack([np.cos(th / 2), *(np.sin(th / 2)[None] * ax[:, None])], 1)
        if root == "free":
            q[:, adr["r0"]:adr["r0"] + 3] = np.array([off, 0.5, 0.25]) + np.outer(s, [0.4, -0.3, 0.2])
    q[:, adr["ja"]] = rel[0] + (rel[1] - rel[0]) * s
    q[:, adr["jb"]] = -0.5 * (rel[0] + (rel[1] - rel[0]) * s)
    return m, times, q, (L, Lb, r, rc, pc)


def _arm_distances(q_a: np.ndarray, q_b: np.ndarray, dims) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closed forms in C's frame: (sa-sb, sa-sc, sb-sc) sphere distances for arm angles q_a, q_b.

    sa's centre is L (cos, sin)(-qa) (hinge axis -z); sb's frame is turned by _PHI
    about z and its hinge axis is +z: centre Lb (cos, sin)(phi + qb)."""
    L, Lb, r, rc, pc = dims
    phi = _PHI
    ca = L * np.stack([np.cos(-q_a), np.sin(-q_a)], -1)
    cb = Lb * np.stack([np.cos(phi + q_b), np.sin(phi + q_b)], -1)
    d_ab = np.linalg.norm(ca - cb, axis=-1) - 2 * r
    d_ac = np.linalg.norm(ca - pc[:2], axis=-1) - r - rc
    d_bc = np.linalg.norm(cb - pc[:2], axis=-1) - r - rc
    return d_ab, d_ac, d_bc


def _closed_min(m, times, q, dims) -> dict[tuple[str, str], float]:
    """Minimum over the window of each pair's closed-form distance (dense in the arm angles, which
    are linear in t, plus the analytic stationary point of the sa-sb distance when inside)."""
    ja = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "ja")])
    jb = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "jb")])
    s = np.linspace(0.0, 1.0, 20001)
    qa = q[0, ja] + s * (q[-1, ja] - q[0, ja])
    qb = q[0, jb] + s * (q[-1, jb] - q[0, jb])
    d_ab, d_ac, d_bc = _arm_distances(qa, qb, dims)
    return {("sa", "sb"): float(d_ab.min()), ("sa", "sc"): float(d_ac.min()), ("sb", "sc"): float(d_bc.min())}


def _mujoco_agrees(m, times, q, dims) -> None:
    """The closed forms equal MuJoCo's FK distances at a few times (the model is what we think)."""
    d = mujoco.MjData(m)
    ja = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "ja")])
    jb = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "jb")])
    gid = {n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in ("sa", "sb", "sc")}
    for k in range(0, len(times), max(1, len(times) // 4)):
        d.qpos[:] = q[k]
        mujoco.mj_kinematics(m, d)
        want = _arm_distances(np.array(q[k, ja]), np.array(q[k, jb]), dims)
        got = []
        for a, b in (("sa", "sb"), ("sa", "sc"), ("sb", "sc")):
            ra, rb = m.geom_size[gid[a], 0], m.geom_size[gid[b], 0]
            got.append(np.linalg.norm(d.geom_xpos[gid[a]] - d.geom_xpos[gid[b]]) - ra - rb)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)


def _check(cert, truth: dict, margin: float) -> str:
    """Soundness against the closed forms: returns the verdict (asserts every claim holds)."""
    for p in cert.pairs:
        key = tuple(sorted(p.geoms))
        if p.verdict == "certified":
            assert truth[key] > margin, (p, truth[key], margin)
            assert p.clearance <= truth[key] + 1e-12, (p, truth[key])
    low = min(truth[tuple(sorted(p.geoms))] for p in cert.pairs)     # of the certified pairs
    if cert.verdict == "certified":
        assert low > margin and cert.clearance <= low + 1e-12, (cert.clearance, low, margin)
    if low < margin:
        assert cert.verdict != "certified", (cert.verdict, truth, margin)
    return str(cert.verdict)


@pytest.mark.parametrize("root", ["hinge", "slide", "ball", "free"])
@pytest.mark.parametrize("off", [0.0, 1e4])
def test_spheres_on_a_moving_base_against_closed_forms(root, off):
    """Siblings (sa-sb) and parent-child pairs (sa-sc, sb-sc: C is one of the two bodies) on a base
    that moves by 3 rad / 0.9 m in the window while the arms move 0.25 rad: the relative bounds are
    tight, the absolute ones are not. Margins just below and just above each pair's closed-form
    minimum (+-2e-4 m): below may not be a violation, above must not be certified; clearances never
    exceed the closed-form minimum. Two and 21 waypoints (single segment: the velocity bound;
    many: the chain bound and the long-window rule)."""
    verdicts = []
    for K in (2, 21):
        m, times, q, dims = _arm(root, off, K, (-0.35, -0.1))
        _mujoco_agrees(m, times, q, dims)
        truth = _closed_min(m, times, q, dims)
        assert 0.005 < truth[("sa", "sb")] < 0.03, truth       # a near pair (designed)
        scene = monitor.Scene.from_model(m, pairs=[("sa", "sb"), ("sa", "sc"), ("sb", "sc")])
        plan = monitor.Plan(times, q, m)
        for pair in (("sa", "sb"), ("sa", "sc"), ("sb", "sc")):
            for dm in (-2e-4, 2e-4):
                margin = truth[pair] + dm
                cert = monitor.certify(scene, plan, margin=margin, epsilon=2e-5, method="toleranced",
                                       pairs=[pair], budget={"seconds": 60})
                v = _check(cert, truth, margin)
                assert (v == "violation") or dm < 0 or v == "uncertain"
                verdicts.append(v)
        margin = min(truth.values()) - 1e-3
        cert = monitor.certify(scene, plan, margin=margin, epsilon=1e-4, method="toleranced",
                               budget={"seconds": 60})
        verdicts.append(_check(cert, truth, margin))
    # the relative bounds must decide most of these (teeth: a broken bound would certify above)
    assert verdicts.count("certified") >= 4 and verdicts.count("violation") >= 4, verdicts


# ----------------------------------------------------------------------------- dense-sample fuzz
def _seg_dist(p, q, r, s) -> float:
    """Distance of segments pq and rs (clamped closest points; exact up to rounding)."""
    d1, d2, w = q - p, s - r, p - r
    a, e, f = d1 @ d1, d2 @ d2, d2 @ w
    if a <= 1e-30 and e <= 1e-30:
        return float(np.linalg.norm(w))
    if a <= 1e-30:
        u, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = d1 @ w
        if e <= 1e-30:
            t, u = 0.0, min(max(-c / a, 0.0), 1.0)
        else:
            b = d1 @ d2
            den = a * e - b * b
            u = min(max((b * f - c * e) / den, 0.0), 1.0) if den > 0 else 0.0
            t = (b * u + f) / e
            if t < 0:
                t, u = 0.0, min(max(-c / a, 0.0), 1.0)
            elif t > 1:
                t, u = 1.0, min(max((b - c) / a, 0.0), 1.0)
    return float(np.linalg.norm(p + d1 * u - r - d2 * t))


def _geom_dist(m, d, ga: int, gb: int) -> float:
    """Closed-form distance of two sphere / capsule geoms at MuJoCo's poses in ``d``."""
    segs = []
    for g in (ga, gb):
        c = d.geom_xpos[g].copy()
        h = d.geom_xmat[g].reshape(3, 3)[:, 2] * (m.geom_size[g, 1] if m.geom_type[g] == 3 else 0.0)
        segs.append((c - h, c + h, m.geom_size[g, 0]))
    return _seg_dist(segs[0][0], segs[0][1], segs[1][0], segs[1][1]) - segs[0][2] - segs[1][2]


def _oracle_qpos(m, times, qpos, t) -> np.ndarray:
    """The red-team oracle's own joint interpolation (lerp; shortest-arc slerp for ball / free)."""
    return interp_qpos(m, np.asarray(times, float), qpos, float(t))


def _sampled(m, times, qpos, pairs_ids, t0, t1, n) -> np.ndarray:
    """(n, P) closed-form distances of the pairs at n times of [t0, t1] (MuJoCo FK)."""
    d = mujoco.MjData(m)
    out = np.empty((n, len(pairs_ids)))
    for i, t in enumerate(np.linspace(t0, t1, n)):
        d.qpos[:] = _oracle_qpos(m, times, qpos, t)
        mujoco.mj_kinematics(m, d)
        out[i] = [_geom_dist(m, d, a, b) for a, b in pairs_ids]
    return out


_ROOTS = ("hinge", "slide", "ball", "free", "slide+hinge", "mocap")


def _fuzz_case(seed: int):
    """A random tree: root R (moving by its joint(s), or mocap), optionally a welded C under it, two
    branches of 1-3 bodies (hinge / slide / ball with non-unit axes, random offsets and quats, some
    welded), sphere / capsule geoms; the root moves by up to 3 rad / 0.9 m, the branches by 1e-4 to
    0.3. Offsets of 1e4 m in a quarter of the cases. Returns (model, times, qpos)."""
    rng = np.random.default_rng(seed)
    root = _ROOTS[seed % len(_ROOTS)]
    off = rng.uniform(-1e4, 1e4, 3) if rng.random() < 0.25 else rng.uniform(-0.5, 0.5, 3)

    def f(v):
        return " ".join(f"{x:.17g}" for x in v)

    def ax():
        a = rng.normal(size=3)
        return a * rng.uniform(0.3, 3.0) / np.linalg.norm(a)

    def quat():
        x = rng.normal(size=4)
        return x / np.linalg.norm(x)

    def geom(name):
        if rng.random() < 0.5:
            return (f'<geom name="{name}" type="sphere" size="{rng.uniform(0.01, 0.05):.6g}" '
                    f'pos="{f(rng.uniform(-0.03, 0.03, 3))}"/>')
        a = rng.uniform(-0.05, 0.05, 3)
        return (f'<geom name="{name}" type="capsule" fromto="{f(a)} {f(a + rng.uniform(-0.08, 0.08, 3))}" '
                f'size="{rng.uniform(0.005, 0.03):.6g}"/>')

    rj = {"hinge": f'<joint name="r0" type="hinge" axis="{f(ax())}"/>',
          "slide": f'<joint name="r0" type="slide" axis="{f(ax())}"/>',
          "ball": '<joint name="r0" type="ball"/>', "free": '<joint name="r0" type="free"/>',
          "slide+hinge": f'<joint name="r0" type="slide" axis="{f(ax())}"/><joint name="r1" type="hinge"/>',
          "mocap": ""}[root]
    branches = []
    for side in "ab":
        depth = int(rng.integers(1, 4))
        xml = ""
        for k in range(depth):
            typ = ("hinge", "slide", "ball")[int(rng.integers(0, 3))]
            j = ""
            if rng.random() < 0.85:
                j = (f'<joint name="j{side}{k}" type="{typ}" '
                     + (f'axis="{f(ax())}" ' if typ != "ball" else "")
                     + (f'pos="{f(rng.uniform(-0.05, 0.05, 3))}"' if typ != "slide" else "") + "/>")
            xml += (f'<body name="{side}{k}" pos="{f(rng.uniform(-0.08, 0.08, 3))}" quat="{f(quat())}">{j}'
                    + geom(f"g{side}{k}"))
        branches.append(xml + "</body>" * depth)
    inner = geom("gR") + branches[0] + branches[1]
    if rng.random() < 0.4:     # C welded under the moving root
        inner = (geom("gR") + f'<body name="C" pos="{f(rng.uniform(-0.1, 0.1, 3))}" quat="{f(quat())}">'
                 + geom("gC") + branches[0] + branches[1] + "</body>")
    mocap = ' mocap="true"' if root == "mocap" else ""
    xml = ('<mujoco><worldbody><geom name="wball" type="sphere" size="0.05" '
           f'pos="{f(off + rng.uniform(-0.3, 0.3, 3))}"/>'
           f'<body name="R" pos="{f(off)}" quat="{f(quat())}"{mocap}>{rj}{inner}</body></worldbody></mujoco>')
    m = mujoco.MjModel.from_xml_string(xml)
    K = int(rng.choice([2, 3, 5, 12, 30]))
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.1, K - 1))])
    s = times / times[-1]
    qpos = np.tile(m.qpos0, (K, 1)).astype(float)
    rel = float(rng.choice([1e-4, 1e-2, 0.3]))
    for j in range(m.njnt):
        adr, typ = int(m.jnt_qposadr[j]), int(m.jnt_type[j])
        is_root = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j).startswith("r")
        amp = 3.0 if is_root else rel
        if typ >= 2:
            noise = rng.normal(scale=0.05 * amp, size=K) if K > 2 else 0.0
            qpos[:, adr] = (rng.uniform(-0.3, 0.3) * (1 if is_root else amp) + rng.uniform(-1, 1) * amp * s
                            + noise) * (0.3 if typ == 2 and is_root else 1)
        else:
            a = rng.normal(size=3)
            a /= np.linalg.norm(a)
            th = rng.uniform(-0.3, 0.3) * min(amp, 1) + rng.uniform(-1, 1) * amp * s
            w = adr + (3 if typ == 0 else 0)
            qpos[:, w:w + 4] = np.stack([np.cos(th / 2), *(np.sin(th / 2)[None] * a[:, None])], 1)
            if typ == 0:
                qpos[:, adr:adr + 3] = off + np.outer(s, rng.uniform(-0.5, 0.5, 3))
    return m, times, qpos


def _fuzz_one(seed: int, method: str, n: int = 500) -> tuple[int, int]:
    """Certify the closest pairs of a random case with margins just above / below their sampled
    minima and all pairs together; returns (runs, certified runs). Asserts: no certificate with a
    sampled distance below the margin; no certified / culled clearance above a sampled distance."""
    m, times, qpos = _fuzz_case(seed)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(m.ngeom)]
    pairs = [(names[a], names[b]) for a in range(m.ngeom) for b in range(a + 1, m.ngeom)
             if m.geom_bodyid[a] != m.geom_bodyid[b]]
    ids = [(names.index(a), names.index(b)) for a, b in pairs]
    t0, t1 = float(times[0]), float(times[-1])
    D = _sampled(m, times, qpos, ids, t0, t1, n)
    dmin, dstart = D.min(axis=0), D[0]
    ok = np.flatnonzero(dstart > 0.002)
    if not ok.size:
        return 0, 0
    scene = monitor.Scene.from_model(m, pairs=pairs)
    plan = monitor.Plan(times, qpos, m)
    runs = certified = 0
    sels = [[int(i)] for i in ok[np.argsort(dmin[ok])][:3]] + [[int(i) for i in ok]]
    for sel in sels:
        for dm in (-1e-4, 1e-4):
            margin = max(float(dmin[sel].min()) + dm, 0.0)
            if margin >= dstart[sel].min():
                continue
            cert = monitor.certify(scene, plan, margin=margin, epsilon=1e-4, method=method,
                                   pairs=[pairs[i] for i in sel], budget={"seconds": 120})
            runs += 1
            certified += cert.verdict == "certified"
            if cert.verdict == "certified":
                assert dmin[sel].min() > margin, (seed, method, sel, margin, dmin[sel])
            for p in cert.pairs:
                i = pairs.index(tuple(p.geoms))
                if p.verdict == "certified":
                    assert p.clearance <= dmin[i] + 1e-9, (seed, method, p, dmin[i])
    return runs, certified


@pytest.mark.slow
@pytest.mark.parametrize("block", range(8))
def test_fuzz_relative_bounds_against_dense_samples(block):
    """40 random trees per block, both methods (the toleranced route and "auto")."""
    runs = certified = 0
    for seed in range(40 * block, 40 * block + 40):
        for method in ("toleranced", "auto"):
            r, c = _fuzz_one(seed, method)
            runs, certified = runs + r, certified + c
    assert runs > 200 and certified > 20, (runs, certified)


def test_fuzz_sample_of_relative_bounds():
    """The fast suite's sample of the fuzz above (three trees: a hinge root, C welded, a ball root)."""
    runs = 0
    for seed in (12, 20, 26):
        runs += _fuzz_one(seed, "toleranced", n=200)[0]
    assert runs >= 6, runs


# ------------------------------------------------------------ many fingers: stage 0, sweep, CALL_TESTS
def _hand(n_fingers: int, bend: float, gap: float, alternate: bool, K: int = 9):
    """A base sliding 0.6 m and yawing 3 rad (axis (0, 0, 2)), with ``n_fingers`` two-segment capsule
    fingers in a row ``2 * 0.008 + gap`` apart (hinges with non-unit axes), each joint bending by
    0.8-1 ``bend`` rad: about x (out of the row: neighbours stay about ``gap`` apart), or
    (``alternate``) about y, odd fingers one way and even ones the other, so that neighbours collide."""
    fingers = []
    ax_p, ax_d = ("0 3 0", "0 0.5 0") if alternate else ("3 0 0", "0.5 0 0")
    for i in range(n_fingers):
        x = (i - 0.5 * (n_fingers - 1)) * (0.016 + gap)
        fingers.append(
            f'<body name="p{i}" pos="{x:.6f} 0 -0.02"><joint name="jp{i}" type="hinge" axis="{ax_p}"/>'
            f'<geom name="cp{i}" type="capsule" fromto="0 0 0 0 0 -0.04" size="0.008"/>'
            f'<body name="d{i}" pos="0 0 -0.056"><joint name="jd{i}" type="hinge" axis="{ax_d}"/>'
            f'<geom name="cd{i}" type="capsule" fromto="0 0 0 0 0 -0.03" size="0.008"/></body></body>')
    xml = ('<mujoco><worldbody><body name="base" pos="3 1 0.5"><joint name="x" type="slide" axis="2 0 0"/>'
           '<joint name="yaw" type="hinge" axis="0 0 2"/><geom name="palm" type="box" size="0.2 0.02 0.01"/>'
           + "".join(fingers) + "</body></worldbody></mujoco>")
    m = mujoco.MjModel.from_xml_string(xml)
    times = np.linspace(0.0, 0.3, K)
    s = times / times[-1]
    q = np.zeros((K, m.nq))
    q[:, 0], q[:, 1] = 0.6 * s, 3.0 * s
    rng = np.random.default_rng(n_fingers)
    for i in range(n_fingers):
        sgn = -1.0 if alternate and i % 2 else 1.0
        q[:, 2 + 2 * i] = sgn * bend * s * rng.uniform(0.8, 1.0)
        q[:, 3 + 2 * i] = sgn * bend * s * rng.uniform(0.8, 1.0)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(m.ngeom)]
    pairs = [(a, b) for ia, a in enumerate(names) for b in names[ia + 1:]
             if a != "palm" and b != "palm" and a[2:] != b[2:]]          # segments of different fingers
    return m, times, q, pairs


def _spy_calls(monkeypatch) -> list:
    """Record (stage, k0, k1, WI_DONE, WI_SURV after the call) of every window_kernel call of the engine."""
    from monitor.certify import kernels as KS

    calls = []
    orig = engine._window_kernel

    def spy(*a):
        out = orig(*a)
        calls.append((a[7], a[8], a[9], int(a[-1][KS.WI_DONE]), int(a[-1][KS.WI_SURV])))
        return out

    monkeypatch.setattr(engine, "_window_kernel", spy)
    return calls


def _cert_key(cert) -> tuple:
    w = cert.witness
    return (str(cert.verdict), cert.clearance, cert.earliest_time,
            None if w is None else (w.time, w.geoms, w.distance),
            tuple((p.geoms, str(p.verdict), p.method, p.clearance, p.tests) for p in cert.pairs))


@pytest.mark.parametrize("gap, margin, alternate", [(0.002, 0.0015, False), (0.003, 0.001, True)])
def test_many_fingers_call_tests_resume_sweep_and_dense_samples(monkeypatch, gap, margin, alternate):
    """Eight fingers (112 cousin / sibling pairs under the moving base): stage 0's relative spheres,
    stage 1 over several capped calls (the engine resumes from WI_DONE), the kernel-decided
    shortcut versus the general tail, and the sweep versus the pair loop give one certificate, and
    it holds against closed-form capsule distances at 120 MuJoCo-FK samples (the second case bends
    neighbours into each other: a violation that must be found, not certified)."""
    m, times, q, pairs = _hand(8, 0.3, gap, alternate)
    scene = monitor.Scene.from_model(m, pairs=pairs)
    plan = monitor.Plan(times, q, m)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(m.ngeom)]
    ids = [(names.index(a), names.index(b)) for a, b in pairs]
    D = _sampled(m, times, q, ids, plan.t0, plan.t1, 120).min(axis=0)
    kw = dict(margin=margin, epsilon=1e-4, method="toleranced", budget={"seconds": 120})
    calls = _spy_calls(monkeypatch)
    cert = monitor.certify(scene, plan, **kw)
    stage1 = [c for c in calls if c[0] == 1]
    S = calls[0][4]
    assert calls[0][0] == 0 and calls[0][3] < S, calls       # the first call stopped at CALL_TESTS
    assert len(stage1) >= 3 and all(c[1] == p[3] for c, p in zip(stage1, calls)), calls   # resumed at WI_DONE
    assert stage1[-1][3] == S, calls
    # oracle: no certified pair with a sampled distance <= margin or below its clearance
    for p in cert.pairs:
        i = pairs.index(tuple(p.geoms))
        if p.verdict == "certified":
            assert D[i] > margin and p.clearance <= D[i] + 1e-12, (p, D[i])
    if D.min() < margin:
        assert cert.verdict == "violation", cert.verdict
        assert _geom_dist_at(m, times, q, cert.witness) < margin + 1e-9
    else:
        assert cert.verdict == "certified", cert.verdict
    want = _cert_key(cert)
    monkeypatch.setattr(engine, "_kernel_decided", lambda *a, **k: None)       # the general tail
    assert _cert_key(monitor.certify(monitor.Scene.from_model(m, pairs=pairs), plan, **kw)) == want
    monkeypatch.undo()
    monkeypatch.setattr(engine, "SWEEP_MIN_GEOMS", 0)                            # the sweep
    assert _cert_key(monitor.certify(monitor.Scene.from_model(m, pairs=pairs), plan, **kw)) == want


def _geom_dist_at(m, times, q, witness) -> float:
    """Closed-form distance of the witness's geoms at the witness's time (MuJoCo FK)."""
    d = mujoco.MjData(m)
    d.qpos[:] = _oracle_qpos(m, times, q, witness.time)
    mujoco.mj_kinematics(m, d)
    a, b = (mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in witness.geoms)
    return _geom_dist(m, d, a, b)



_SWING_XML = """<mujoco><worldbody>
  <body name="C" pos="{off} -1 0.4"><joint name="yaw" type="hinge" axis="0 0 1"/>
    <body name="a"><joint name="ja" type="hinge" axis="0 0 2"/>
      <geom name="sa" type="sphere" size="0.02" pos="0.3 0 0"/>
      <geom name="sa2" type="sphere" size="0.02" pos="-0.3 0 0"/></body>
    <body name="b"><geom name="sb" type="sphere" size="0.02" pos="{bx} {by} 0"/></body>
  </body>
</worldbody></mujoco>"""


@pytest.mark.parametrize("off", [0.0, 1e4])
@pytest.mark.parametrize("angle_b", [0.5, 0.8])
def test_stage0_relative_sphere_of_a_geom_swinging_about_its_reference_point(off, angle_b):
    """Stage 0's relative sphere must grow by chord(angle) * lever: body a's reference point is its
    hinge (two spheres at +-0.3 m), so its relative translation bound is ~0 and all of sa's motion
    (0.6 rad of swing on a 0.3 m arm while C yaws 3 rad) is rotation. sb sits on the arm's circle at
    ``angle_b``: 0.5 rad (inside the swing: sa passes through it, closed-form minimum -0.04 m, while
    at the window's middle the two are 0.0199 m apart) or 0.8 rad (outside: minimum 2 * 0.3 sin(0.1)
    - 0.04 m at the window's end). A relative sphere without the rotation term culls the colliding
    pair at the middle pose (a false certificate); the correct one keeps it."""
    m = mujoco.MjModel.from_xml_string(_SWING_XML.format(off=off, bx=0.3 * math.cos(angle_b),
                                                         by=0.3 * math.sin(angle_b)))
    times = np.linspace(0.0, 0.2, 5)
    s = times / times[-1]
    q = np.stack([3.0 * s, 0.6 * s], axis=1)
    truth = 2 * 0.3 * math.sin(0.5 * max(angle_b - 0.6, 0.0)) - 0.04
    d = mujoco.MjData(m)
    sa, sb = (mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in ("sa", "sb"))
    sampled = []
    for t in np.linspace(0.0, 0.2, 201):
        d.qpos[:] = _oracle_qpos(m, times, q, t)
        mujoco.mj_kinematics(m, d)
        sampled.append(float(np.linalg.norm(d.geom_xpos[sa] - d.geom_xpos[sb])) - 0.04)
    if angle_b < 0.6:
        assert min(sampled) < 0.0, min(sampled)       # a real collision (and the closed form's -0.04)
    else:
        assert abs(min(sampled) - truth) < 1e-9, (min(sampled), truth)   # at the window's end
    scene = monitor.Scene.from_model(m, pairs=[("sa", "sb")])
    plan = monitor.Plan(times, q, m)
    for margin in (max(truth - 1e-4, 0.0), max(truth + 1e-4, 0.0)):
        cert = monitor.certify(scene, plan, margin=margin, epsilon=1e-5, method="toleranced",
                               budget={"seconds": 60})
        (p,) = cert.pairs
        if truth < margin:
            assert cert.verdict != "certified" and p.method != "culled", p
        if cert.verdict == "certified":
            assert p.clearance <= truth + 1e-12, (p, truth)
