"""Red team 18's clearance oracle for the motion MuJoCo applied (independent of ``monitor``).

Shares no code with ``monitor``: MuJoCo only for forward kinematics (``mj_kinematics`` on an
oracle-owned ``MjData``) and, as a cross-check only, ``mj_geomDistance``; geometry straight from the
MjModel (``geom_type``, ``geom_size``, ``mesh_vert``); distances written here (numpy / scipy).

What it checks: for joint-space waypoints ``rows`` (K, nq) (the qpos of every substep a gate
certified and MuJoCo applied), the CONTINUOUS motion the certificate is about: lerp of hinge / slide
coordinates, lerp of position + shortest-arc slerp of the quaternion for free joints, slerp for ball
joints, between consecutive rows (``docs/design.md``: ``Plan``, interpolated in joint space).

Per pair and per row interval the oracle either
* proves the pair clear of its threshold on the whole interval: signed-distance lower bounds at
  sampled parameters and a Lipschitz bound (below) between them, bisecting where needed; or
* proves a FINDING: a sampled instant whose signed-distance UPPER bound (a verified witness: points
  of both geoms, or a closed form) is below the threshold by more than ``ERR``; or
* gives up at ``MAX_DEPTH`` bisections: "unresolved" (reported, never counted as either).

Signed distance (negative = penetration depth) per geom class:
* plane (half-space z <= 0 in its frame) vs anything: closed form (support function), exact;
* sphere / capsule vs sphere / capsule: segment-segment distance in closed form minus the radii, exact;
* anything else (box, mesh hull, cylinder): min-norm point of the core hulls by non-negative least
  squares (a convex combination of each core's points, so ``upper`` is a point pair of the geoms),
  ``lower`` from the support functions along that direction (any direction gives a lower bound).
  Cylinders use an inscribed 2n-gon prism for ``upper`` (its points are in the cylinder) and the
  circumscribed one (``1 / cos(pi / n)``) for ``lower``. Overlapping cores: ``upper = -(r_a + r_b)``
  (a common point with both radii around it), ``lower = -inf``; two polytopes overlapping: an LP
  finds the deepest common point (a ball of that radius in both, so ``upper = -radius``).

Lipschitz bound between samples (per geom, per row interval with joint increments dq): every point
p of the geom moves at parameter speed <= sum_j |dq_j| * |p - a_j| over the rotational joints j of its
chain (hinge anchor a_j, ball anchor, free joint: the body origin) plus the translational increments
(slide |dq|, free |dpos|). With r0_j = max over the interval's two ends of |centre - a_j| + the geom's
bounding radius, Q = sum of the rotation increments and D0 = sum_j |dq_j| r0_j + translations,
|p - a_j| <= r0_j + 2 D on the interval, so the speed is at most D = D0 / (1 - 2 Q) when Q < 1/2
(else points of the same path are inserted first: ``_refine_rows``). Signed distance changes at most
by the two geoms' speeds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np
from scipy.optimize import linprog, nnls
from scipy.spatial import ConvexHull

PLANE, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = (
    int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_SPHERE),
    int(mujoco.mjtGeom.mjGEOM_CAPSULE), int(mujoco.mjtGeom.mjGEOM_ELLIPSOID),
    int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_BOX),
    int(mujoco.mjtGeom.mjGEOM_MESH))
FREE, BALL, SLIDE, HINGE = (int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL),
                            int(mujoco.mjtJoint.mjJNT_SLIDE), int(mujoco.mjtJoint.mjJNT_HINGE))
ERR = 1e-9          # m: a finding must be below its threshold by more than this (float64 rounding)
MAX_DEPTH = 12      # bisections of one row interval (1/4096 of a substep)
CYL_SIDES = 48      # polygon sides for cylinders (circumscribed gap r (1/cos(pi/48) - 1) ~ 2e-3 r)


# ----------------------------------------------------------------------------- joint-space interpolation
def _slerp(q0: np.ndarray, q1: np.ndarray, s: float) -> np.ndarray:
    q0 = q0 / np.linalg.norm(q0)
    q1 = q1 / np.linalg.norm(q1)
    d = float(q0 @ q1)
    if d < 0:
        q1, d = -q1, -d
    th = math.acos(min(d, 1.0))
    if th < 1e-12:
        q = q0 + s * (q1 - q0)
    else:
        q = (math.sin((1 - s) * th) * q0 + math.sin(s * th) * q1) / math.sin(th)
    return q / np.linalg.norm(q)


def _angle(q0: np.ndarray, q1: np.ndarray) -> float:
    """Rotation angle (rad) between two unit quaternions along the shortest arc."""
    d = abs(float(q0 @ q1) / (np.linalg.norm(q0) * np.linalg.norm(q1)))
    return 2.0 * math.acos(min(d, 1.0))


class Interp:
    """qpos at parameter s in [0, 1] between two rows, joint by joint (the oracle's own)."""

    def __init__(self, model: mujoco.MjModel) -> None:
        self.quat_slices = []
        for j in range(model.njnt):
            a, t = int(model.jnt_qposadr[j]), int(model.jnt_type[j])
            if t == FREE:
                self.quat_slices.append(slice(a + 3, a + 7))
            elif t == BALL:
                self.quat_slices.append(slice(a, a + 4))

    def __call__(self, qa: np.ndarray, qb: np.ndarray, s: float) -> np.ndarray:
        """Qpos at parameter s (lerp, slerp for quaternions)."""
        q = qa + s * (qb - qa)
        for sl in self.quat_slices:
            q[sl] = _slerp(qa[sl], qb[sl], s)
        return q


# ----------------------------------------------------------------------------- geoms
@dataclass
class GeomModel:
    """One geom: class, radius, core points (geom frame) inscribed / circumscribed, bounding radius."""

    gid: int
    type: int
    radius: float
    core_in: np.ndarray        # (n, 3) points whose hull lies in the core
    core_out: np.ndarray       # (m, 3) points whose hull contains the core
    rbound: float              # every point of the geom within this of the geom's origin
    size: np.ndarray
    chain: list = field(default_factory=list)   # [(joint id, type, qposadr)] root..leaf


def _cyl_points(r: float, h: float, scale: float) -> np.ndarray:
    a = 2 * np.pi * np.arange(CYL_SIDES) / CYL_SIDES
    ring = np.stack([r * scale * np.cos(a), r * scale * np.sin(a)], axis=1)
    return np.vstack([np.column_stack([ring, np.full(CYL_SIDES, -h)]),
                      np.column_stack([ring, np.full(CYL_SIDES, h)])])


def geom_model(model: mujoco.MjModel, g: int) -> GeomModel:
    """The oracle's description of geom ``g`` (raises ValueError for types it does not handle)."""
    t, s = int(model.geom_type[g]), np.array(model.geom_size[g], float)
    if t == PLANE:
        core = np.zeros((1, 3))
        gm = GeomModel(g, t, 0.0, core, core, math.inf, s)
    elif t == SPHERE:
        gm = GeomModel(g, t, s[0], np.zeros((1, 3)), np.zeros((1, 3)), s[0], s)
    elif t == CAPSULE:
        seg = np.array([[0, 0, -s[1]], [0, 0, s[1]]])
        gm = GeomModel(g, t, s[0], seg, seg, s[0] + s[1], s)
    elif t == BOX:
        V = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float) * s
        gm = GeomModel(g, t, 0.0, V, V, float(np.linalg.norm(s)), s)
    elif t == MESH:
        m = int(model.geom_dataid[g])
        a, n = int(model.mesh_vertadr[m]), int(model.mesh_vertnum[m])
        V = np.array(model.mesh_vert[a:a + n], float)
        V = V[ConvexHull(V).vertices]
        gm = GeomModel(g, t, 0.0, V, V, float(np.linalg.norm(V, axis=1).max()), s)
    elif t == CYLINDER:
        scale = 1.0 / math.cos(math.pi / CYL_SIDES)
        gm = GeomModel(g, t, 0.0, _cyl_points(s[0], s[1], 1.0), _cyl_points(s[0], s[1], scale),
                       math.hypot(s[0] * scale, s[1]), s)
    else:
        raise ValueError(f"oracle: geom type {t} not handled")
    b = int(model.geom_bodyid[g])
    chain = []
    while b > 0:
        for j in range(int(model.body_jntadr[b]), int(model.body_jntadr[b]) + int(model.body_jntnum[b])):
            chain.append((j, int(model.jnt_type[j]), int(model.jnt_qposadr[j])))
        b = int(model.body_parentid[b])
    gm.chain = chain[::-1]
    return gm


# ----------------------------------------------------------------------------- distances
def _seg_seg(p1, q1, p2, q2) -> tuple[float, np.ndarray, np.ndarray]:
    """Closest points of segments [p1, q1], [p2, q2] (Ericson, Real-Time Collision Detection 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    eps = 1e-30
    if a <= eps and e <= eps:
        return float(np.linalg.norm(p1 - p2)), p1, p2
    if a <= eps:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = d1 @ r
        if e <= eps:
            t, s = 0.0, min(max(-c / a, 0.0), 1.0)
        else:
            b = d1 @ d2
            den = a * e - b * b
            s = min(max((b * f - c * e) / den, 0.0), 1.0) if den > eps else 0.0
            t = (b * s + f) / e
            if t < 0:
                t, s = 0.0, min(max(-c / a, 0.0), 1.0)
            elif t > 1:
                t, s = 1.0, min(max((b - c) / a, 0.0), 1.0)
    c1, c2 = p1 + s * d1, p2 + t * d2
    return float(np.linalg.norm(c1 - c2)), c1, c2


def _plane_height(pl_R, pl_p, gm: GeomModel, R, p) -> float:
    """Exact signed distance of geom (R, p) to the half-space below the plane (R_pl, p_pl)."""
    n = pl_R[:, 2]
    if gm.type == CYLINDER:
        nl = R.T @ n
        low = (n @ (p - pl_p)) - gm.size[1] * abs(nl[2]) - gm.size[0] * math.hypot(nl[0], nl[1])
        return float(low)
    V = gm.core_in @ R.T + p
    return float(np.min((V - pl_p) @ n) - gm.radius)


_HREP: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _lp_depth(ga: GeomModel, Ra, pa, gb: GeomModel, Rb, pb) -> float:
    """Radius of the largest ball in both (polytope) inscribed cores, by LP (0 if none)."""
    rows, offs = [], []
    for gm, R, p in ((ga, Ra, pa), (gb, Rb, pb)):
        if gm.gid not in _HREP:
            h = ConvexHull(gm.core_in)
            _HREP[gm.gid] = (h.equations[:, :3], -h.equations[:, 3])
        n, o = _HREP[gm.gid]
        nw = n @ R.T
        rows.append(nw)
        offs.append(o + nw @ p)
    A = np.vstack(rows)
    res = linprog(np.array([0, 0, 0, -1.0]), A_ub=np.hstack([A, np.ones((len(A), 1))]),
                  b_ub=np.concatenate(offs), bounds=[(None, None)] * 3 + [(0, 1e3)], method="highs")
    return float(res.x[3]) if res.status == 0 else 0.0


_NORMALS: dict[int, np.ndarray] = {}


def _normals(gm: GeomModel) -> np.ndarray:
    """(n, 3) outward face normals of the geom's core hull (geom frame); capsule / sphere: none."""
    if gm.gid not in _NORMALS:
        pts = gm.core_in
        _NORMALS[gm.gid] = (ConvexHull(pts).equations[:, :3] if len(pts) >= 4 else np.zeros((0, 3)))
    return _NORMALS[gm.gid]


def _overlap_lower(ga: GeomModel, Ra, pa, gb: GeomModel, Rb, pb) -> float:
    """Lower bound on the signed distance of overlapping geoms: -(smallest separating translation).

    For any unit u, translating A by -delta u with delta = max_A(a.u) - min_B(b.u) separates the
    (outer) cores, so the penetration depth is at most delta + r_a + r_b for every u: directions
    tried are both cores' face normals, the world axes and the centre-to-centre direction.
    """
    A, B = ga.core_out @ Ra.T + pa, gb.core_out @ Rb.T + pb
    dirs = [Ra @ n for n in _normals(ga)] + [Rb @ n for n in _normals(gb)] + list(np.eye(3))
    c = B.mean(axis=0) - A.mean(axis=0)
    if np.linalg.norm(c) > 0:
        dirs.append(c / np.linalg.norm(c))
    U = np.array(dirs)
    U = np.vstack([U, -U])
    delta = np.max(A @ U.T, axis=0) - np.min(B @ U.T, axis=0)
    return -float(np.min(delta)) - ga.radius - gb.radius - 1e-12


def pair_bounds(ga: GeomModel, Ra, pa, gb: GeomModel, Rb, pb) -> tuple[float, float]:
    """(lower, upper) on the signed distance of two posed geoms (world (3, 3) rotations, (3,) origins)."""
    if ga.type == PLANE and gb.type == PLANE:
        return math.inf, math.inf
    if ga.type == PLANE or gb.type == PLANE:
        if gb.type == PLANE:
            ga, Ra, pa, gb, Rb, pb = gb, Rb, pb, ga, Ra, pa
        h = _plane_height(Ra, pa, gb, Rb, pb)
        return h - 1e-12 * (1 + abs(h)), h
    rounded = (SPHERE, CAPSULE)
    if ga.type in rounded and gb.type in rounded:
        A, B = ga.core_in @ Ra.T + pa, gb.core_in @ Rb.T + pb
        d, _, _ = _seg_seg(A[0], A[-1], B[0], B[-1])
        v = d - ga.radius - gb.radius
        return v - 1e-12 * (1 + abs(v)), v
    # general: min-norm point of conv(A_in) - conv(B_in) by nnls on convex weights
    A_in, B_in = ga.core_in @ Ra.T + pa, gb.core_in @ Rb.T + pb
    na, nb = len(A_in), len(B_in)
    w = 1e3 * (1.0 + float(max(np.abs(A_in).max(), np.abs(B_in).max())))
    M = np.zeros((5, na + nb))
    M[:3, :na], M[:3, na:] = A_in.T, -B_in.T
    M[3, :na], M[4, na:] = w, w
    lam, _ = nnls(M, np.array([0, 0, 0, w, w]), maxiter=20 * (na + nb))
    la, lb = np.clip(lam[:na], 0, None), np.clip(lam[na:], 0, None)
    ra_, rb_ = ga.radius + gb.radius, 0.0
    if la.sum() <= 0 or lb.sum() <= 0:
        return -math.inf, math.inf
    x, y = (la / la.sum()) @ A_in, (lb / lb.sum()) @ B_in
    d = float(np.linalg.norm(y - x))
    if d <= 1e-12 * (1 + float(np.abs(x).max())):
        up = -ra_
        if ra_ == 0.0:
            up = -_lp_depth(ga, Ra, pa, gb, Rb, pb)
        return _overlap_lower(ga, Ra, pa, gb, Rb, pb), up + 1e-12
    u = (y - x) / d
    A_out, B_out = ga.core_out @ Ra.T + pa, gb.core_out @ Rb.T + pb
    lower = float(np.min(B_out @ u) - np.max(A_out @ u)) - ra_ - rb_
    upper = d - ra_ - rb_
    return lower - 1e-12 * (1 + abs(lower)), upper + 1e-12 * (1 + abs(upper))


# ----------------------------------------------------------------------------- the path audit
@dataclass
class PairVerdict:
    """Oracle result for one pair on one motion: 'clear' | 'finding' | 'unresolved'."""

    status: str
    min_upper: float          # smallest verified upper bound seen (m)
    time_param: float         # row index + s of that sample
    threshold: float
    mj_distance: float = math.nan   # MuJoCo's mj_geomDistance at that sample (cross-check only)


class PathOracle:
    """Audits joint-space waypoint paths of one model for a set of geom pairs."""

    def __init__(self, model: mujoco.MjModel) -> None:
        self.model = model
        self.data = mujoco.MjData(model)
        self.interp = Interp(model)
        self._geoms: dict[int, GeomModel] = {}
        self.samples = 0

    def geom(self, g: int) -> GeomModel:
        """The oracle's description of geom g (cached)."""
        if g not in self._geoms:
            self._geoms[g] = geom_model(self.model, g)
        return self._geoms[g]

    def _pose(self, qpos: np.ndarray) -> mujoco.MjData:
        d = self.data
        d.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, d)
        self.samples += 1
        return d

    def _bounds_at(self, d: mujoco.MjData, pairs: list[tuple[int, int]]) -> np.ndarray:
        out = np.empty((len(pairs), 2))
        for i, (a, b) in enumerate(pairs):
            ga, gb = self.geom(a), self.geom(b)
            Ra, pa = d.geom_xmat[a].reshape(3, 3), d.geom_xpos[a]
            Rb, pb = d.geom_xmat[b].reshape(3, 3), d.geom_xpos[b]
            if ga.type != PLANE and gb.type != PLANE:
                c = float(np.linalg.norm(pa - pb)) - ga.rbound - gb.rbound
                if c > 0.05:  # bounding spheres apart by 5 cm: a valid lower bound, no upper needed
                    out[i] = (c, math.inf)
                    continue
            out[i] = pair_bounds(ga, Ra, pa, gb, Rb, pb)
        return out

    def _speeds(self, qa: np.ndarray, qb: np.ndarray, da_xanchor: list, gids: list[int]) -> dict[int, float]:
        """Per geom: Lipschitz constant (m per unit parameter) of its points on [qa, qb] (None: Q >= 1/2)."""
        m = self.model
        out = {}
        (xa0, xp0, gx0), (xa1, xp1, gx1) = da_xanchor
        for g in gids:
            gm = self.geom(g)
            if gm.type == PLANE and not gm.chain:
                out[g] = 0.0
                continue
            rb = 0.0 if gm.type == PLANE else gm.rbound
            d0, Q = 0.0, 0.0
            for j, t, adr in gm.chain:
                if t == SLIDE:
                    d0 += abs(qb[adr] - qa[adr])
                    continue
                if t == HINGE:
                    ang = abs(qb[adr] - qa[adr])
                    anc0, anc1 = xa0[j], xa1[j]
                elif t == BALL:
                    ang = _angle(qa[adr:adr + 4], qb[adr:adr + 4])
                    anc0, anc1 = xa0[j], xa1[j]
                else:  # free: translation of the body origin, rotation about it
                    d0 += float(np.linalg.norm(qb[adr:adr + 3] - qa[adr:adr + 3]))
                    ang = _angle(qa[adr + 3:adr + 7], qb[adr + 3:adr + 7])
                    body = int(m.jnt_bodyid[j])
                    anc0, anc1 = xp0[body], xp1[body]
                if gm.type == PLANE:
                    return {g: math.inf for g in gids}  # a moving plane: not handled (never met)
                r0 = max(float(np.linalg.norm(gx0[g] - anc0)), float(np.linalg.norm(gx1[g] - anc1))) + rb
                d0 += ang * r0
                Q += ang
            out[g] = math.inf if Q >= 0.5 else d0 / (1.0 - 2.0 * Q)
        return out

    def audit(self, rows: np.ndarray, pairs: list[tuple[int, int]], thresholds: np.ndarray,
              cross_check: bool = True, max_samples: int = 20000) -> list[PairVerdict]:
        """Audit the lerp/slerp path through ``rows`` (K, nq) for ``pairs`` against ``thresholds`` (P,).

        ``max_samples`` caps the poses evaluated between rows: what is still open then is "unresolved".
        """
        rows = self._refine_rows(np.asarray(rows, float), sorted({g for p in pairs for g in p}))
        budget_end = self.samples + len(rows) + max_samples
        P = len(pairs)
        res = [PairVerdict("clear", math.inf, 0.0, float(thresholds[i])) for i in range(P)]
        if P == 0:
            return res
        gids = sorted({g for p in pairs for g in p})
        cache = []
        for k in range(len(rows)):
            d = self._pose(rows[k])
            cache.append((self._bounds_at(d, pairs), (d.xanchor.copy(), d.xpos.copy(), d.geom_xpos.copy())))
        for i in range(P):
            lo, up = cache[0][0][i]
            self._note(res[i], up, 0.0)
        for k in range(len(rows) - 1):
            qa, qb = np.asarray(rows[k], float), np.asarray(rows[k + 1], float)
            if np.array_equal(qa, qb):
                for i in range(P):
                    self._note(res[i], cache[k + 1][0][i][1], k + 1.0)
                continue
            sp = self._speeds(qa, qb, [cache[k][1], cache[k + 1][1]], gids)
            stack = [(0.0, 1.0, cache[k][0], cache[k + 1][0], np.arange(P), 0)]
            while stack:
                s0, s1, b0, b1, idx, depth = stack.pop()
                L = np.array([sp[pairs[i][0]] + sp[pairs[i][1]] for i in idx])
                lo_mid = 0.5 * (b0[idx, 0] + b1[idx, 0] - (s1 - s0) * L)
                for i in idx:
                    self._note(res[i], b1[i, 1], k + s1)
                # a pair already proven below its threshold needs no more samples
                done = np.array([res[i].min_upper < res[i].threshold - ERR for i in idx], dtype=bool)
                open_ = idx[~(lo_mid > thresholds[idx]) & ~done]
                if open_.size == 0:
                    continue
                stuck = depth >= 4 and np.all(np.isinf(b0[open_, 0])) and np.all(np.isinf(b1[open_, 0]))
                if depth >= MAX_DEPTH or self.samples >= budget_end or stuck:
                    for i in open_:
                        if res[i].status == "clear":
                            res[i].status = "unresolved"
                    continue
                sm = 0.5 * (s0 + s1)
                d = self._pose(self.interp(qa, qb, sm))
                bm = np.full((P, 2), np.nan)
                bm[open_] = self._bounds_at(d, [pairs[i] for i in open_])
                for i in open_:
                    self._note(res[i], bm[i, 1], k + sm)
                stack.append((s0, sm, b0, bm, open_, depth + 1))
                stack.append((sm, s1, bm, b1, open_, depth + 1))
        for i, r in enumerate(res):
            if r.min_upper < r.threshold - ERR:
                r.status = "finding"
                if cross_check:
                    r.mj_distance = self.mj_distance(rows, pairs[i], r.time_param)
        return res

    def _refine_rows(self, rows: np.ndarray, gids: list[int]) -> np.ndarray:
        """Insert points of the same path where a row interval rotates a chain by >= 1/4 rad in total.

        The Lipschitz bound needs Q < 1/2 per interval. A lerp of a lerp sub-interval, and a slerp of
        a slerp sub-interval (constant rate along one great arc), are the same path, so splitting an
        interval into m equal parameter pieces changes nothing but the bound.
        """
        out = [rows[0]]
        for k in range(len(rows) - 1):
            qa, qb = rows[k], rows[k + 1]
            Q = 0.0  # the largest total rotation increment of one geom's chain
            for g in gids:
                q = 0.0
                for _j, t, adr in self.geom(g).chain:
                    if t == HINGE:
                        q += abs(qb[adr] - qa[adr])
                    elif t == BALL:
                        q += _angle(qa[adr:adr + 4], qb[adr:adr + 4])
                    elif t == FREE:
                        q += _angle(qa[adr + 3:adr + 7], qb[adr + 3:adr + 7])
                Q = max(Q, q)
            pieces = int(math.ceil(Q / 0.25)) if Q >= 0.25 else 1
            for i in range(1, pieces):
                out.append(self.interp(qa, qb, i / pieces))
            out.append(qb)
        return np.array(out)

    @staticmethod
    def _note(r: PairVerdict, upper: float, tp: float) -> None:
        if upper < r.min_upper:
            r.min_upper, r.time_param = float(upper), float(tp)

    def mj_distance(self, rows: np.ndarray, pair: tuple[int, int], tp: float) -> float:
        """MuJoCo's own signed distance at parameter ``tp`` (cross-check only, never the verdict)."""
        k = min(int(tp), len(rows) - 2) if len(rows) > 1 else 0
        q = rows[k] if len(rows) == 1 else self.interp(np.asarray(rows[k], float),
                                                        np.asarray(rows[k + 1], float), tp - k)
        d = self._pose(q)
        return float(mujoco.mj_geomDistance(self.model, d, pair[0], pair[1], 10.0, None))

    def start_distance(self, qpos: np.ndarray, pairs: list[tuple[int, int]]) -> np.ndarray:
        """(P, 2) lower / upper signed distance at one configuration."""
        return self._bounds_at(self._pose(qpos), pairs)
