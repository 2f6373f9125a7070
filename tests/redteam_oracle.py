"""Independent red-team oracle: true geom poses and verified distance witnesses.

Written from scratch for the red-team audit; it shares no code with ``monitor`` (only
MuJoCo's own forward kinematics and scipy). Geometry comes straight from the MjModel
(``geom_type``, ``geom_size``, ``mesh_vert``) and world poses from ``mj_kinematics`` on
an oracle-owned ``MjData`` with joint interpolation re-implemented here (lerp for
hinge/slide, lerp + shortest-arc slerp for free, shortest-arc slerp for ball).

Every "collides" / "closer than margin" label is backed by a *verified witness*:

* penetration: a point ``z`` whose inside depth in both geoms (a certified lower bound on
  the radius of a ball around ``z`` inside the geom, evaluated in closed form) is > 0;
* separation below margin: two points ``x in A`` and ``y in B`` (membership checked in
  closed form after projection onto the set) with ``|x - y|`` below the margin.

So ``upper_distance`` is a rigorous upper bound on the signed distance up to float64
rounding of a handful of flops (reported witnesses are re-checked with slack 1e-12 m).
It is not a lower bound: the oracle can only *prove* violations, which is exactly what a
false-negative hunt needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.optimize import linprog, minimize, minimize_scalar, nnls
from scipy.spatial import ConvexHull

PLANE, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = (
    int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_SPHERE),
    int(mujoco.mjtGeom.mjGEOM_CAPSULE), int(mujoco.mjtGeom.mjGEOM_ELLIPSOID),
    int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_BOX),
    int(mujoco.mjtGeom.mjGEOM_MESH))


# ----------------------------------------------------------------------------- rotations
def quat_mat(q: np.ndarray) -> np.ndarray:
    """(3, 3) rotation of a (w, x, y, z) quaternion (normalised here)."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def slerp(q0: np.ndarray, q1: np.ndarray, s: float) -> np.ndarray:
    """Shortest-arc slerp of unit quaternions (w, x, y, z)."""
    q0 = np.asarray(q0, float) / np.linalg.norm(q0)
    q1 = np.asarray(q1, float) / np.linalg.norm(q1)
    d = float(q0 @ q1)
    if d < 0:
        q1, d = -q1, -d
    d = min(d, 1.0)
    th = np.arccos(d)
    if th < 1e-12:
        q = q0 + s * (q1 - q0)
    else:
        q = (np.sin((1 - s) * th) * q0 + np.sin(s * th) * q1) / np.sin(th)
    return q / np.linalg.norm(q)


def axis_quat(axis: np.ndarray, angle: float) -> np.ndarray:
    """Quaternion (w, x, y, z) of a rotation by ``angle`` about ``axis``."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * a])


# ----------------------------------------------------------------------------- motions
def interp_qpos(model: mujoco.MjModel, times: np.ndarray, qpos: np.ndarray, t: float) -> np.ndarray:
    """Joint-space interpolation of waypoints at time t (oracle's own implementation)."""
    times = np.asarray(times, float)
    k = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2))
    s = (t - times[k]) / (times[k + 1] - times[k])
    s = min(max(s, 0.0), 1.0)
    a, b = np.asarray(qpos[k], float), np.asarray(qpos[k + 1], float)
    q = a + s * (b - a)
    for j in range(model.njnt):
        adr = int(model.jnt_qposadr[j])
        typ = int(model.jnt_type[j])
        if typ == int(mujoco.mjtJoint.mjJNT_FREE):
            q[adr + 3:adr + 7] = slerp(a[adr + 3:adr + 7], b[adr + 3:adr + 7], s)
        elif typ == int(mujoco.mjtJoint.mjJNT_BALL):
            q[adr:adr + 4] = slerp(a[adr:adr + 4], b[adr:adr + 4], s)
    return q


@dataclass
class GeomPose:
    """One geom of the model at one time: type, size, world pose, mesh vertices (geom frame)."""

    type: int
    size: np.ndarray
    R: np.ndarray
    p: np.ndarray
    verts: np.ndarray | None = None


class PlanOracle:
    """World geom poses of a joint-waypoint plan, computed independently of monitor.Plan."""

    def __init__(self, model: mujoco.MjModel, times: np.ndarray, qpos: np.ndarray):
        self.model = model
        self.times = np.asarray(times, float)
        self.qpos = np.asarray(qpos, float)
        self.data = mujoco.MjData(model)

    def geoms(self, t: float, ids: tuple[int, ...]) -> list[GeomPose]:
        """Poses of geoms ``ids`` at time ``t``."""
        self.data.qpos[:] = interp_qpos(self.model, self.times, self.qpos, t)
        mujoco.mj_kinematics(self.model, self.data)
        return [geom_pose(self.model, g, self.data.geom_xmat[g].reshape(3, 3).copy(),
                          self.data.geom_xpos[g].copy()) for g in ids]


class BodyMotionOracle:
    """World geom poses for explicit per-body waypoint poses (lerp + shortest-arc slerp)."""

    def __init__(self, model: mujoco.MjModel, times: np.ndarray, pos: np.ndarray, quat: np.ndarray):
        self.model = model
        self.times = np.asarray(times, float)
        self.pos = np.asarray(pos, float)
        self.quat = np.asarray(quat, float)

    def geoms(self, t: float, ids: tuple[int, ...]) -> list[GeomPose]:
        """Poses of geoms ``ids`` at time ``t``."""
        times = self.times
        k = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2))
        s = min(max((t - times[k]) / (times[k + 1] - times[k]), 0.0), 1.0)
        out = []
        for g in ids:
            b = int(self.model.geom_bodyid[g])
            x = self.pos[k, b] + s * (self.pos[k + 1, b] - self.pos[k, b])
            R = quat_mat(slerp(self.quat[k, b], self.quat[k + 1, b], s))
            Rg = quat_mat(self.model.geom_quat[g])
            out.append(geom_pose(self.model, g, R @ Rg, x + R @ self.model.geom_pos[g]))
        return out


class TrajectoryOracle:
    """World geom poses from a Trajectory's own ``body_poses`` (the motion the certificate is about).

    Used where the interpolation itself is ambiguous (slerp of antipodal-ish quaternions:
    a 180 degree rotation has two shortest arcs, and the branch depends on the rounding
    of a dot product), so the oracle must follow the branch the plan really takes.
    """

    def __init__(self, model: mujoco.MjModel, traj: object):
        self.model = model
        self.traj = traj

    def geoms(self, t: float, ids: tuple[int, ...]) -> list[GeomPose]:
        """Poses of geoms ``ids`` at time ``t``."""
        pos, rot = self.traj.body_poses(np.array([t]))
        out = []
        for g in ids:
            b = int(self.model.geom_bodyid[g])
            R, x = rot[0, b], pos[0, b]
            out.append(geom_pose(self.model, g, R @ quat_mat(self.model.geom_quat[g]),
                                 x + R @ self.model.geom_pos[g]))
        return out


def geom_pose(model: mujoco.MjModel, g: int, R: np.ndarray, p: np.ndarray) -> GeomPose:
    """GeomPose of geom g at world rotation R and position p."""
    typ = int(model.geom_type[g])
    verts = None
    if typ == MESH:
        m = int(model.geom_dataid[g])
        a, n = int(model.mesh_vertadr[m]), int(model.mesh_vertnum[m])
        verts = np.asarray(model.mesh_vert[a:a + n], float)
    return GeomPose(typ, np.asarray(model.geom_size[g], float).copy(), R, p, verts)


# ----------------------------------------------------------------------------- geometry
_HULLS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _hrep(verts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    key = hash(verts.tobytes())
    if key not in _HULLS:
        h = ConvexHull(verts)
        _HULLS[key] = (h.equations[:, :3], -h.equations[:, 3])
    return _HULLS[key]


def depth(g: GeomPose, z: np.ndarray) -> float:
    """Certified lower bound on the radius of a ball around world point z inside g (negative: outside-ish)."""
    u = g.R.T @ (np.asarray(z, float) - g.p)
    s = g.size
    if g.type == PLANE:
        return -u[2]
    if g.type == SPHERE:
        return s[0] - np.linalg.norm(u)
    if g.type == CAPSULE:
        c = np.array([0.0, 0.0, np.clip(u[2], -s[1], s[1])])
        return s[0] - np.linalg.norm(u - c)
    if g.type == BOX:
        return float(np.min(s - np.abs(u)))
    if g.type == CYLINDER:
        return float(min(s[0] - np.hypot(u[0], u[1]), s[1] - abs(u[2])))
    if g.type == ELLIPSOID:
        f = np.linalg.norm(u / s[:3])
        return float((1.0 - f) * np.min(s[:3]))
    if g.type == MESH:
        n, o = _hrep(g.verts)
        return float(np.min(o - n @ u))
    raise ValueError(f"unsupported geom type {g.type}")


def project(g: GeomPose, z: np.ndarray) -> np.ndarray:
    """A point of g near world point z (exact projection for all but ellipsoid/mesh: a point of g)."""
    u = g.R.T @ (np.asarray(z, float) - g.p)
    s = g.size
    if g.type == PLANE:
        v = u.copy()
        v[2] = min(v[2], 0.0)
    elif g.type == SPHERE:
        n = np.linalg.norm(u)
        v = u if n <= s[0] else u * (s[0] / n)
    elif g.type == CAPSULE:
        c = np.array([0.0, 0.0, np.clip(u[2], -s[1], s[1])])
        d = u - c
        n = np.linalg.norm(d)
        v = u if n <= s[0] else c + d * (s[0] / n)
    elif g.type == BOX:
        v = np.clip(u, -s, s)
    elif g.type == CYLINDER:
        v = u.copy()
        r = np.hypot(u[0], u[1])
        if r > s[0]:
            v[:2] *= s[0] / r
        v[2] = np.clip(u[2], -s[1], s[1])
    elif g.type == ELLIPSOID:
        a = s[:3]
        # sum((a u / (a^2 + lam))^2) - 1 on Python floats, in numpy's order for 3 terms
        # ((q0^2 + q1^2) + q2^2): the same value bit for bit, ~10x cheaper per call (the
        # 80-step bisection below was most of the ellipsoid red-team tests' time)
        (au0, au1, au2), (aa0, aa1, aa2) = (a * u).tolist(), (a * a).tolist()

        def obj(lam: float) -> float:
            q0, q1, q2 = au0 / (aa0 + lam), au1 / (aa1 + lam), au2 / (aa2 + lam)
            return (q0 * q0 + q1 * q1) + q2 * q2 - 1.0

        if np.sum((u / a) ** 2) <= 1.0:
            v = u
        else:
            lo, hi = 0.0, float(np.linalg.norm(u) * np.max(a)) + 1.0
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if obj(mid) > 0:
                    lo = mid
                else:
                    hi = mid
            v = a * a * u / (a * a + hi)
            f = np.linalg.norm(v / a)
            if f > 1.0:
                v = v / f
    elif g.type == MESH:
        V = g.verts
        # min |V^T lam - u|^2 + (w (sum lam - 1))^2, lam >= 0 (Lawson-Hanson), then renormalise:
        # the result is an exact convex combination, i.e. a point of the hull.
        w = 1e4 * (1.0 + float(np.abs(V).max()))
        A = np.vstack([V.T, w * np.ones((1, V.shape[0]))])
        lam, _ = nnls(A, np.concatenate([u, [w]]), maxiter=2000)
        lam = np.clip(lam, 0, None)
        lam /= lam.sum()
        v = lam @ V
    else:
        raise ValueError(f"unsupported geom type {g.type}")
    return g.R @ v + g.p


def centre(g: GeomPose) -> np.ndarray:
    """A point inside g (world)."""
    if g.type == MESH:
        return g.R @ g.verts.mean(axis=0) + g.p
    return g.p.copy()


@dataclass
class Witness:
    """Verified witness: ``upper`` >= true signed distance; points are world coordinates."""

    upper: float
    x: np.ndarray
    y: np.ndarray


def _pen_witness(a: GeomPose, b: GeomPose, z0: np.ndarray) -> Witness:
    def f(z: np.ndarray) -> float:
        return -min(depth(a, z), depth(b, z))

    best = np.asarray(z0, float)
    fb = f(best)
    scale = 1e-3 + 0.1 * float(min(np.max(np.abs(a.size)), np.max(np.abs(b.size)), 10.0))
    for step in (scale, scale * 1e-2, scale * 1e-4):
        r = minimize(f, best, method="Nelder-Mead",
                     options={"xatol": step * 1e-6, "fatol": 1e-16, "maxiter": 4000,
                              "initial_simplex": best + np.vstack([np.zeros(3), step * np.eye(3)])})
        if r.fun < fb:
            best, fb = r.x, float(r.fun)
    return Witness(fb, best, best)


def _lp_overlap(a: GeomPose, b: GeomPose) -> Witness | None:
    """Polytope-polytope (box/mesh/plane): max t with z t-deep in both, by LP."""
    rows, offs = [], []
    for g in (a, b):
        if g.type == BOX:
            n = np.vstack([np.eye(3), -np.eye(3)])
            o = np.concatenate([g.size, g.size])
        elif g.type == MESH:
            n, o = _hrep(g.verts)
        elif g.type == PLANE:
            n, o = np.array([[0.0, 0.0, 1.0]]), np.array([0.0])
        else:
            return None
        nw = n @ g.R.T  # world normals (rows), unit
        rows.append(nw)
        offs.append(o + nw @ g.p)
    A = np.vstack(rows)
    h = np.concatenate(offs)
    A_ub = np.hstack([A, np.ones((A.shape[0], 1))])
    res = linprog(np.array([0, 0, 0, -1.0]), A_ub=A_ub, b_ub=h, bounds=[(None, None)] * 3 + [(None, 1e3)],
                  method="highs")
    if res.status != 0:
        return None
    z = res.x[:3]
    d = min(depth(a, z), depth(b, z))
    return Witness(-d, z, z)


def core(g: GeomPose) -> tuple[np.ndarray, float] | None:
    """World vertices of the convex core and the radius, for sphere/capsule/box/mesh."""
    s = g.size
    if g.type == SPHERE:
        V, r = np.zeros((1, 3)), s[0]
    elif g.type == CAPSULE:
        V, r = np.array([[0.0, 0.0, -s[1]], [0.0, 0.0, s[1]]]), s[0]
    elif g.type == BOX:
        V = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float) * s
        r = 0.0
    elif g.type == MESH:
        V, r = g.verts, 0.0
    else:
        return None
    return V @ g.R.T + g.p, float(r)


def _core_distance(a: GeomPose, b: GeomPose) -> Witness | None:
    """Core-core distance by a convex-combination least squares (nnls), minus the radii."""
    ca, cb = core(a), core(b)
    if ca is None or cb is None:
        return None
    (Va, ra), (Vb, rb) = ca, cb
    na, nb = len(Va), len(Vb)
    w = 1e4 * (1.0 + float(max(np.abs(Va).max(), np.abs(Vb).max())))
    A = np.zeros((5, na + nb))
    A[:3, :na], A[:3, na:] = Va.T, -Vb.T
    A[3, :na], A[4, na:] = w, w
    lam, _ = nnls(A, np.array([0, 0, 0, w, w]), maxiter=5000)
    la, lb = np.clip(lam[:na], 0, None), np.clip(lam[na:], 0, None)
    if la.sum() <= 0 or lb.sum() <= 0:
        return None
    pa, pb = (la / la.sum()) @ Va, (lb / lb.sum()) @ Vb
    d = float(np.linalg.norm(pb - pa))
    if d <= 1e-300:
        return None
    u = (pb - pa) / d
    if d >= ra + rb:
        return Witness(d - ra - rb, pa + ra * u, pb - rb * u)
    z = pa + (ra - 0.5 * (ra + rb - d)) * u
    return Witness(-min(depth(a, z), depth(b, z)), z, z)


def upper_distance(a: GeomPose, b: GeomPose, z0: np.ndarray | None = None) -> Witness:
    """Verified upper bound on the signed distance of two geoms (negative: penetration witness)."""
    if a.type == PLANE and b.type == PLANE:
        raise ValueError("plane-plane")
    if b.type == PLANE:
        w = upper_distance(b, a, z0)
        return Witness(w.upper, w.y, w.x)
    if a.type == PLANE:
        # exact: min over b of the height above the plane (support function), closed form per type
        n = a.R[:, 2]
        nb = b.R.T @ n  # normal in b's frame
        s = b.size
        if b.type == SPHERE:
            low = -s[0] * nb
        elif b.type == CAPSULE:
            low = np.array([0, 0, -s[1] * np.sign(nb[2])]) - s[0] * nb
        elif b.type == BOX:
            low = -s * np.sign(nb)
        elif b.type == CYLINDER:
            r = np.hypot(nb[0], nb[1])
            low = np.array([0.0, 0.0, -s[1] * np.sign(nb[2])])
            if r > 0:
                low[:2] = -s[0] * nb[:2] / r
        elif b.type == ELLIPSOID:
            A2 = s[:3] ** 2
            low = -A2 * nb / np.sqrt(np.sum(A2 * nb * nb))
        elif b.type == MESH:
            low = b.verts[np.argmin(b.verts @ nb)]
        else:
            raise ValueError(b.type)
        yw = b.R @ low + b.p
        h = float(n @ (yw - a.p))
        xw = yw - max(h, 0.0) * n
        if h < 0:  # the lowest point is in both (depth 0 in b): look for a point deep in both
            w = _pen_witness(a, b, yw + 0.5 * h * n)
            return w if w.upper < 0 else Witness(0.0, yw, yw)
        return Witness(h, xw, yw)
    lp = _lp_overlap(a, b)
    if lp is not None and lp.upper < 0:
        return lp
    cw = _core_distance(a, b)
    if cw is not None and check_witness(a, b, cw, slack=1e-12) and (cw.upper < 0 or lp is not None
                                                                     or cw.upper > 0):
        return cw
    # alternating projections warm start, then a local polish of |x - y| by Nelder-Mead on the
    # midpoint pair; both points are projected onto their sets, so the result is feasible.
    x = centre(a) if z0 is None else np.asarray(z0, float)
    y = project(b, x)
    for _ in range(400):
        x = project(a, y)
        y2 = project(b, x)
        if np.linalg.norm(y2 - y) < 1e-15:
            y = y2
            break
        y = y2
    d = float(np.linalg.norm(x - y))
    if d < 1e-9 or min(depth(a, y), depth(b, x)) > -1e-12:
        w = _pen_witness(a, b, 0.5 * (x + y))
        if w.upper < 0:
            return w
    return Witness(d, x, y)


def check_witness(a: GeomPose, b: GeomPose, w: Witness, slack: float = 1e-12) -> bool:
    """Re-verify a witness: both points inside their geoms (up to slack) and the claimed bound."""
    if w.upper < 0:
        return depth(a, w.x) >= -w.upper - slack and depth(b, w.x) >= -w.upper - slack
    return (depth(a, w.x) >= -slack and depth(b, w.y) >= -slack
            and np.linalg.norm(w.x - w.y) <= w.upper + slack)


# ----------------------------------------------------------------------------- time search
@dataclass
class MinResult:
    """Smallest verified upper bound over sampled times, and where."""

    upper: float
    time: float
    witness: Witness
    first_below: float | None  # earliest sampled time with upper < threshold (if asked)


def motion_min(oracle: PlanOracle | BodyMotionOracle, ga: int, gb: int, t0: float, t1: float,
               n: int = 400, refine: int = 3, threshold: float | None = None) -> MinResult:
    """Dense sampling of the true motion with local refinement around the best sample.

    Args:
        oracle: pose oracle.
        ga, gb: geom ids.
        t0, t1: window (s).
        n: samples per pass (uniform, endpoints included).
        refine: refinement passes (each resamples n points around the current best).
        threshold: if given, also report the earliest sampled time with upper < threshold.

    Returns:
        MinResult; every reported upper is a verified witness bound at that time.
    """
    def at(t: float) -> Witness:
        a, b = oracle.geoms(t, (ga, gb))
        w = upper_distance(a, b)
        if not check_witness(a, b, w, slack=1e-9):
            return Witness(np.inf, w.x, w.y)  # unverifiable: no claim
        return w

    ts = np.linspace(t0, t1, n)
    ws = [at(float(t)) for t in ts]
    ups = np.array([w.upper for w in ws])
    first = None
    if threshold is not None:
        hit = np.flatnonzero(ups < threshold)
        if hit.size:
            first = float(ts[hit[0]])
    k = int(np.argmin(ups))
    best_t, best_w = float(ts[k]), ws[k]
    width = (t1 - t0) / (n - 1)
    for _ in range(refine):
        lo, hi = max(t0, best_t - width), min(t1, best_t + width)
        for t in np.linspace(lo, hi, max(n // 4, 16)):
            w = at(float(t))
            if w.upper < best_w.upper:
                best_t, best_w = float(t), w
        width = (hi - lo) / max(n // 4, 16)
    if threshold is not None and first is None and best_w.upper < threshold:
        first = best_t
    return MinResult(best_w.upper, best_t, best_w, first)


def golden_min(f, lo: float, hi: float) -> tuple[float, float]:
    """Bounded scalar minimisation helper (scipy) returning (t, value)."""
    r = minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 1e-14})
    return float(r.x), float(r.fun)
