"""The fixed, seeded pair-window case set of the accuracy and peer suites.

A case is two convex bodies ``A`` and ``B`` over one window ``[0, T]``. Each body
moves along ONE segment: its origin is linearly interpolated and its orientation
slerped (constant angular velocity about a fixed axis, angle < pi) between two
poses. This is exactly :class:`monitor.BodyMotion` with two waypoints and exactly
python-fcl's ``CCDM_LINEAR`` interpolated motion (rotation about the object
origin), so every peer that takes start and end poses sees the true motion.

Each geom sits at its body origin with identity orientation, so body-frame and
geom-frame coordinates coincide for all consumers (MJCF, python-fcl, ipctk,
``monitor.geometry``).

Cases come in four groups, ``"translating"`` (no rotation; the extrusion checker
and the exact LP oracle apply), ``"rotating"``, ``"screw"`` (the same two poses
joined by the SE(3) geodesic: ``BodyMotion(interpolation="screw")``, python-fcl
``CCDM_SCREW``) and ``"bezier"`` (a planar rational Bézier motion of A:
``BezierMotion``), and four intents:
``"collide"`` (paths cross), ``"graze"`` (shallow, brief penetration of depth
1e-3 / 1e-5 m: the case that time sampling misses), ``"near"`` (designed minimum
clearance ``c``, from 1e-1 down to 1e-5 m) and ``"clear"`` (about 0.2 m). The intent is only how the
case was built; the label used for scoring comes from :mod:`monitor.bench.oracle`.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

NEAR_CLEARANCES_FULL = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5)
NEAR_CLEARANCES_QUICK = (1e-2, 1e-4)
GRAZE_DEPTHS_FULL = (1e-3, 1e-5)
GRAZE_DEPTHS_QUICK = (1e-3,)
CLEAR_DISTANCE = 0.2
INTERPOLATIONS = ("lerp_slerp", "screw", "bezier")
"""Designed minimum clearance (m) of the ``"clear"`` cases."""


@dataclass(frozen=True, eq=False)
class ShapeSpec:
    """One convex geom at its body origin.

    Attributes:
        kind: ``"box" | "hull" | "sphere" | "capsule" | "cylinder" | "ellipsoid"``.
        vertices: (n, 3) body-frame vertices (m) for box/hull; (0, 3) otherwise.
        half_extents: (3,) box / ellipsoid half sizes (m), or zeros.
        radius: sphere/capsule/cylinder radius (m).
        half_length: capsule/cylinder half length along body z (m).
    """

    kind: str
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    half_extents: np.ndarray = field(default_factory=lambda: np.zeros(3))
    radius: float = 0.0
    half_length: float = 0.0

    @staticmethod
    def box(half_extents: np.ndarray) -> ShapeSpec:
        """A box with half sizes ``half_extents`` (3,) m."""
        h = np.asarray(half_extents, float)
        v = np.array(
            [[sx * h[0], sy * h[1], sz * h[2]] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        )
        return ShapeSpec("box", v, h)

    @staticmethod
    def hull(points: np.ndarray) -> ShapeSpec:
        """The convex hull of ``points`` (n, 3) m (only hull vertices are kept)."""
        p = np.asarray(points, float)
        return ShapeSpec("hull", p[ConvexHull(p).vertices])

    @property
    def is_polytope(self) -> bool:
        """True for box and hull (triangle meshes exist)."""
        return self.kind in ("box", "hull")

    @functools.cached_property
    def triangles(self) -> np.ndarray:
        """(m, 3) int32 hull triangles (indices into ``vertices``); polytopes only."""
        hull = ConvexHull(self.vertices)
        tri = hull.simplices.astype(np.int32).copy()
        # Orient counter-clockwise seen from outside (outward normals).
        a, b, c = (self.vertices[tri[:, k]] for k in range(3))
        out = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - self.vertices.mean(axis=0)) < 0
        tri[out] = tri[out][:, ::-1]
        return tri

    @property
    def max_radius(self) -> float:
        """Largest distance (m) of a shape point from the body origin."""
        if self.is_polytope:
            return float(np.linalg.norm(self.vertices, axis=1).max())
        if self.kind == "ellipsoid":
            return float(self.half_extents.max())
        if self.kind == "cylinder":
            return float(np.hypot(self.radius, self.half_length))
        return self.half_length + self.radius

    @property
    def size(self) -> float:
        """A characteristic size (m): the smallest half extent / radius."""
        if self.kind == "box":
            return float(self.half_extents.min())
        if self.kind == "hull":
            return float(np.ptp(self.vertices, axis=0).min() / 2)
        return self.radius

    def mjcf(self, name: str) -> tuple[str, str]:
        """(asset XML, geom XML) for a geom named ``name`` at its body origin."""
        if self.kind == "box":
            h = " ".join(f"{x:.17g}" for x in self.half_extents)
            return "", f'<geom name="{name}" type="box" size="{h}"/>'
        if self.kind == "sphere":
            return "", f'<geom name="{name}" type="sphere" size="{self.radius:.17g}"/>'
        if self.kind in ("capsule", "cylinder"):
            return "", (
                f'<geom name="{name}" type="{self.kind}" size="{self.radius:.17g} {self.half_length:.17g}"/>'
            )
        if self.kind == "ellipsoid":
            h = " ".join(f"{x:.17g}" for x in self.half_extents)
            return "", f'<geom name="{name}" type="ellipsoid" size="{h}"/>'
        v = " ".join(f"{x:.17g}" for x in self.vertices.ravel())
        return (
            f'<mesh name="{name}_mesh" vertex="{v}"/>',
            f'<geom name="{name}" type="mesh" mesh="{name}_mesh"/>',
        )

    def convex_shape(self, facets: int = 16):
        """The :class:`monitor.geometry.shapes.ConvexShape` of this geom (body frame).

        Cylinders and ellipsoids are circumscribed polytopes with ``facets``.
        """
        from monitor.geometry import polytope

        if self.kind == "cylinder":
            return polytope.cylinder_polytope(self.radius, self.half_length, facets)
        if self.kind == "ellipsoid":
            return polytope.ellipsoid_polytope(self.half_extents, facets)
        if self.kind == "box":
            return polytope.box_polytope(self.half_extents)
        if self.kind == "hull":
            return polytope.polytope_from_points(self.vertices)
        if self.kind == "sphere":
            return polytope.sphere_shape(self.radius)
        return polytope.capsule_shape(self.radius, self.half_length)

    def to_dict(self) -> dict:
        """JSON form (for results.json)."""
        return {
            "kind": self.kind,
            "vertices": self.vertices.tolist(),
            "half_extents": self.half_extents.tolist(),
            "radius": self.radius,
            "half_length": self.half_length,
        }


def slerp_matrices(q0: np.ndarray, q1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) of the slerp from q0 to q1 (w, x, y, z; q0.q1 >= 0) at s (N,)."""
    q0 = q0 / np.linalg.norm(q0)
    q1 = q1 / np.linalg.norm(q1)
    c = float(np.clip(q0 @ q1, -1.0, 1.0))
    th = np.arccos(c)
    if th < 1e-9:
        q = q0[None] + s[:, None] * (q1 - q0)[None]
    else:
        q = (np.sin((1 - s) * th)[:, None] * q0 + np.sin(s * th)[:, None] * q1) / np.sin(th)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    return Rotation.from_quat(q, scalar_first=True).as_matrix().reshape(-1, 3, 3)


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _screw_poses(p0: np.ndarray, q0: np.ndarray, twist: np.ndarray, s: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Poses exp(s xi) X0 of a world twist xi = (omega, v): origins (N, 3), rotations (N, 3, 3).

    Closed form (Murray, Li & Sastry, Prop. 2.8) with k = omega / |omega|, v' = v / |omega|,
    theta = s |omega|: R_s = exp(theta [k]), t_s = (I - R_s)(k x v') + k (k . v') theta.
    """
    w, v = twist[:3], twist[3:]
    R0 = Rotation.from_quat(q0, scalar_first=True).as_matrix()
    nw = float(np.linalg.norm(w))
    if nw < 1e-15:
        return p0[None] + s[:, None] * v[None], np.broadcast_to(R0, (len(s), 3, 3)).copy()
    k, vp = w / nw, v / nw
    th = (s * nw)[:, None, None]
    Kx = _skew(k)
    Rs = np.eye(3)[None] + np.sin(th) * Kx[None] + (1.0 - np.cos(th)) * (Kx @ Kx)[None]  # Rodrigues
    t = (np.eye(3)[None] - Rs) @ np.cross(k, vp) + np.outer(s * nw, k * (k @ vp))
    return np.einsum("nij,j->ni", Rs, p0) + t, Rs @ R0


def _screw_speed(p0: np.ndarray, twist: np.ndarray, max_radius: float) -> float:
    """Bound (m per unit parameter) on the speed of any shape point under the screw."""
    w, v = twist[:3], twist[3:]
    nw = float(np.linalg.norm(w))
    if nw < 1e-15:
        return float(np.linalg.norm(v))
    k = w / nw
    c = np.cross(k, v / nw)  # the axis point nearest the world origin
    d = p0 - c
    dist = float(np.linalg.norm(d - (d @ k) * k))
    return nw * (dist + max_radius) + abs(float(k @ v))


def _casteljau(P: np.ndarray, x: float) -> np.ndarray:
    """Point at parameter x of the polynomial Bézier curve with control points P (n+1, d)."""
    cur = np.asarray(P, float)
    while len(cur) > 1:
        cur = (1.0 - x) * cur[:-1] + x * cur[1:]
    return cur[0]


def _bezier_poses(Q: np.ndarray, T: np.ndarray, W: np.ndarray, s: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Origins (N, 3) and rotations (N, 3, 3) of the rational motion (Q, T) at parameters s (N,).

    R(s) is the rotation of the unit quaternion Q(s) / |Q(s)|; the origin is the rational
    curve with homogeneous control points (W_k, W_k T_k) (W: Bernstein coefficients of |Q|^2).
    """
    q = np.array([_casteljau(Q, x) for x in s])
    H = np.concatenate([W[:, None], W[:, None] * T], axis=1)
    h = np.array([_casteljau(H, x) for x in s])
    return h[:, 1:] / h[:, :1], Rotation.from_quat(q, scalar_first=True).as_matrix()


def _bezier_speed(Q: np.ndarray, T: np.ndarray, W: np.ndarray, max_radius: float) -> float:
    """Bound (m per unit parameter) on the speed of any shape point of the rational motion.

    Angular speed of q = Q/|Q|: 2 |q'| <= 2 |Q'| / |Q| <= 2 m max|Q_{k+1} - Q_k| / sqrt(min W)
    (|Q|^2 = sum B_k W_k >= min W). Origin x = N~ / W + T_0 with N~ the curve of control
    points W_k (T_k - T_0): |x'| <= (|N~'| W + |N~| |W'|) / W^2
    <= n max|dN~_k| / min W + max|N~_k| n max|dW_k| / min W^2 (n = 2m; hodograph and
    convex-hull bounds of Bernstein polynomials).
    """
    m = len(Q) - 1
    n = 2 * m
    wmin = float(W.min())
    omega = 2.0 * m * float(np.linalg.norm(np.diff(Q, axis=0), axis=1).max()) / math.sqrt(wmin)
    Nt = W[:, None] * (T - T[0])
    dx = (n * float(np.linalg.norm(np.diff(Nt, axis=0), axis=1).max()) / wmin
          + float(np.linalg.norm(Nt, axis=1).max()) * n * float(np.abs(np.diff(W)).max()) / wmin**2)
    return omega * max_radius + dx


@dataclass(eq=False)
class PairCase:
    """Two bodies, one lerp/slerp segment each, window ``[0, duration]`` s.

    Attributes:
        name: unique case name.
        group: ``"translating" | "rotating"``.
        intent: ``"collide" | "near" | "clear"`` (how it was built, not the label).
        nominal: designed minimum distance (m), approximate; negative for collide.
        shapes: (A, B) :class:`ShapeSpec`.
        pos: (2, 2, 3) body origin positions [body, waypoint] (m, world).
        quat: (2, 2, 4) body orientations (w, x, y, z) [body, waypoint].
        moving: (2,) bool; a non-moving body is welded to the world in the MJCF.
        duration: window length T (s).
        interpolation: ``"lerp_slerp"`` (default; ``"lerp-slerp"`` accepted), ``"screw"``
            (constant world twist between the two poses: the SE(3) geodesic, as
            ``BodyMotion(interpolation="screw")`` and python-fcl's ``CCDM_SCREW``) or
            ``"bezier"`` (body A follows the rational Bézier motion :attr:`bezier`; B is
            fixed at its first pose; ``pos``/``quat`` hold A's start and end poses).
        bezier: for ``"bezier"``: (quat_ctrl (m+1, 4), trans_ctrl (2m+1, 3)) of A, the
            control points of :class:`monitor.motion.bezier.RigidBezier`; else None.
    """

    name: str
    group: str
    intent: str
    nominal: float
    shapes: tuple[ShapeSpec, ShapeSpec]
    pos: np.ndarray
    quat: np.ndarray
    moving: tuple[bool, bool]
    duration: float = 1.0
    interpolation: str = "lerp_slerp"
    bezier: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self) -> None:
        if self.interpolation == "lerp-slerp":
            self.interpolation = "lerp_slerp"
        if self.interpolation not in INTERPOLATIONS:
            raise ValueError(f"interpolation must be one of {INTERPOLATIONS}, got {self.interpolation!r}")
        if (self.interpolation == "bezier") != (self.bezier is not None):
            raise ValueError("bezier control points are given iff interpolation == 'bezier'")

    # ----------------------------------------------------------------- motion
    def poses(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Exact world poses at ``times`` (N,) s: positions (N, 2, 3), rotations (N, 2, 3, 3).

        Computed independently of :mod:`monitor.motion` (oracle use): slerp for
        ``lerp_slerp``; the closed-form exponential of the twist from ``scipy.linalg.logm``
        for ``screw``; hand-written de Casteljau for ``bezier``.
        """
        s = np.clip(np.asarray(times, float).reshape(-1) / self.duration, 0.0, 1.0)
        if self.interpolation == "screw":
            out = [_screw_poses(self.pos[b, 0], self.quat[b, 0], self._twists[b], s) for b in range(2)]
            return np.stack([o[0] for o in out], axis=1), np.stack([o[1] for o in out], axis=1)
        P = self.pos[None, :, 0, :] + s[:, None, None] * (self.pos[None, :, 1, :] - self.pos[None, :, 0, :])
        R = np.stack([slerp_matrices(self.quat[b, 0], self.quat[b, 1], s) for b in range(2)], axis=1)
        if self.interpolation == "bezier":
            P[:, 0], R[:, 0] = _bezier_poses(self.bezier[0], self.bezier[1], self._bezier_weights, s)
            P[:, 1], R[:, 1] = P[:1, 1], R[:1, 1]
        return P, R

    @functools.cached_property
    def _twists(self) -> np.ndarray:
        """(2, 6) world twists (omega, v) per unit parameter of the two screw segments."""
        from scipy.linalg import logm

        out = np.zeros((2, 6))
        for b in range(2):
            X = [np.eye(4), np.eye(4)]
            for k in range(2):
                X[k][:3, :3] = Rotation.from_quat(self.quat[b, k], scalar_first=True).as_matrix()
                X[k][:3, 3] = self.pos[b, k]
            if np.array_equal(X[0], X[1]):
                continue
            L = np.real(logm(X[1] @ np.linalg.inv(X[0])))
            out[b] = [L[2, 1], L[0, 2], L[1, 0], *L[:3, 3]]
        return out

    @functools.cached_property
    def _bezier_weights(self) -> np.ndarray:
        """(2m+1,) Bernstein coefficients of |Q(s)|^2, by interpolation at 2m+1 parameters."""
        Q = self.bezier[0]
        n = 2 * (len(Q) - 1)
        s = np.linspace(0.0, 1.0, n + 1)
        q = np.array([_casteljau(Q, x) for x in s])
        B = np.array([[math.comb(n, k) * x**k * (1 - x) ** (n - k) for k in range(n + 1)] for x in s])
        return np.linalg.solve(B, (q * q).sum(axis=1))

    def angles(self) -> np.ndarray:
        """(2,) rotation angle (rad) of each body over the window."""
        out = np.zeros(2)
        for b in range(2):
            r = Rotation.from_quat(self.quat[b], scalar_first=True)
            out[b] = (r[1] * r[0].inv()).magnitude()
        return out

    def speed_bounds(self) -> np.ndarray:
        """(2,) bound (m/s) on the speed of any point of each body's shape.

        lerp_slerp: a point p (body frame) moves with velocity v + omega x R p, so its
        speed is at most |v| + |omega| max|p|, with v and omega constant over the segment.
        screw: a point y moves with omega x y + v = omega x (y - c) + (k.v) k (c on the
        axis, k its direction), so its speed is |omega| dist(y, axis) + |k.v|, and
        dist(y, axis) <= dist(origin_0, axis) + max|p| is constant along the helix.
        bezier: see :func:`_bezier_speed` (hodograph bounds of Q and of the origin curve).
        Padded by 1e-12 relative for rounding (1e-9 for bezier).
        """
        r = np.array([s.max_radius for s in self.shapes])
        if self.interpolation == "screw":
            return np.array([_screw_speed(self.pos[b, 0], self._twists[b], r[b]) for b in range(2)]) / (
                self.duration) * (1 + 1e-12) + 1e-15
        if self.interpolation == "bezier":
            a = _bezier_speed(self.bezier[0], self.bezier[1], self._bezier_weights, r[0]) / self.duration
            return np.array([a * (1 + 1e-9) + 1e-15, 0.0])
        v = np.linalg.norm(self.pos[:, 1] - self.pos[:, 0], axis=1) / self.duration
        w = self.angles() / self.duration
        return (v + w * r) * (1 + 1e-12) + 1e-15

    def velocities(self) -> np.ndarray:
        """(2, 3) constant origin velocities (m/s)."""
        return (self.pos[:, 1] - self.pos[:, 0]) / self.duration

    # ----------------------------------------------------------------- MuJoCo
    def mjcf(self) -> str:
        """An MJCF scene: bodies ``A`` and ``B`` (free joint if moving), geoms ``gA``, ``gB``."""
        assets, bodies = [], []
        for b, nm in enumerate("AB"):
            asset, geom = self.shapes[b].mjcf(f"g{nm}")
            if asset:
                assets.append(asset)
            p = " ".join(f"{x:.17g}" for x in self.pos[b, 0])
            q = " ".join(f"{x:.17g}" for x in self.quat[b, 0])
            joint = f'<freejoint name="j{nm}"/>' if self.moving[b] else ""
            bodies.append(f'<body name="{nm}" pos="{p}" quat="{q}">{joint}{geom}</body>')
        return (
            '<mujoco model="bench_case"><option gravity="0 0 0"/>'
            f"<asset>{''.join(assets)}</asset>"
            f"<worldbody>{''.join(bodies)}</worldbody></mujoco>"
        )

    @functools.cached_property
    def model(self):
        """The compiled ``mujoco.MjModel`` of :meth:`mjcf` (cached)."""
        import mujoco

        return mujoco.MjModel.from_xml_string(self.mjcf())

    def qpos(self, times: np.ndarray) -> np.ndarray:
        """(N, nq) free-joint coordinates of the moving bodies at ``times``."""
        P, R = self.poses(times)
        Q = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat(scalar_first=True).reshape(len(P), 2, 4)
        cols = [np.concatenate([P[:, b], Q[:, b]], axis=1) for b in range(2) if self.moving[b]]
        return np.concatenate(cols, axis=1)

    def body_motion(self):
        """The exact motion over (world, A, B).

        A :class:`monitor.BodyMotion` (lerp_slerp or screw) or a
        :class:`monitor.motion.bezier.BezierMotion` (bezier).
        """
        from monitor import BodyMotion

        pos = np.zeros((2, 3, 3))
        quat = np.zeros((2, 3, 4))
        quat[:, 0, 0] = 1.0
        for b in range(2):
            pos[:, b + 1] = self.pos[b]
            quat[:, b + 1] = self.quat[b]
        if self.interpolation == "bezier":
            from monitor.motion.bezier import BezierMotion, RigidBezier

            return BezierMotion((0.0, self.duration), pos[0], quat[0],
                                {1: RigidBezier(self.bezier[0], self.bezier[1])})
        return BodyMotion(np.array([0.0, self.duration]), pos, quat, interpolation=self.interpolation)

    def scene(self, facets: int = 16):
        """``monitor.Scene`` of :attr:`model` with all pairs (one candidate pair)."""
        return _scene(self, facets)

    def to_dict(self) -> dict:
        """JSON form (for results.json)."""
        return {
            "name": self.name,
            "group": self.group,
            "intent": self.intent,
            "nominal": self.nominal,
            "shapes": [s.kind for s in self.shapes],
            "pos": self.pos.tolist(),
            "quat": self.quat.tolist(),
            "moving": list(self.moving),
            "duration": self.duration,
            "interpolation": self.interpolation,
            "bezier": None if self.bezier is None else [np.asarray(x).tolist() for x in self.bezier],
        }


@functools.lru_cache(maxsize=512)
def _scene(case: PairCase, facets: int):
    from monitor import Scene

    return Scene.from_model(case.model, pairs="all", facets=facets)


# --------------------------------------------------------------------------- building
def _random_shape(rng: np.random.Generator, kind: str) -> ShapeSpec:
    if kind == "box":
        return ShapeSpec.box(rng.uniform(0.05, 0.25, 3))
    if kind == "hull":
        d = rng.normal(size=(14, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return ShapeSpec.hull(d * rng.uniform(0.08, 0.22, (14, 1)) * rng.uniform(0.6, 1.0, 3))
    if kind == "sphere":
        return ShapeSpec("sphere", radius=float(rng.uniform(0.05, 0.2)))
    return ShapeSpec(
        "capsule", radius=float(rng.uniform(0.04, 0.1)), half_length=float(rng.uniform(0.05, 0.2))
    )


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _random_quat(rng: np.random.Generator) -> np.ndarray:
    return Rotation.random(random_state=rng).as_quat(scalar_first=True)


def _random_start(rng: np.random.Generator, ka: str, kb: str) -> tuple:
    """A case's random start, drawn from ``rng`` in this order (seeded case sets depend on it).

    Returns shapes of kinds ka, kb, a travel direction u (3,), a unit w (3,) normal to it, a
    travel length (m) and two start orientations qa, qb (wxyz quaternions).
    """
    shapes = (_random_shape(rng, ka), _random_shape(rng, kb))
    u = _unit(rng)
    w = np.cross(u, _unit(rng))
    w /= np.linalg.norm(w)
    travel = rng.uniform(0.5, 0.9)
    qa, qb = _random_quat(rng), _random_quat(rng)
    return shapes, u, w, travel, qa, qb


def min_distance(case: PairCase, dist: Callable[[PairCase, float], float], samples: int = 40) -> float:
    """Approximate minimum over the window of ``dist(case, t)`` (m): sampling + local refinement."""
    ts = np.linspace(0.0, case.duration, samples)
    d = np.array([dist(case, t) for t in ts])
    best = float(d.min())
    h = ts[1] - ts[0]
    for i in np.argsort(d)[:2]:
        lo, hi = max(0.0, ts[i] - h), min(case.duration, ts[i] + h)
        r = minimize_scalar(
            lambda t: dist(case, t),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-12 * case.duration},
        )
        best = min(best, float(r.fun))
    return best


def _shifted(case: PairCase, w: np.ndarray, s: float) -> PairCase:
    pos = case.pos.copy()
    pos[0] += s * w  # a constant shift of both poses shifts the lerp, the screw and the Bézier
    bez = None if case.bezier is None else (case.bezier[0], case.bezier[1] + s * w)
    out = dataclasses.replace(case, pos=pos, bezier=bez)
    if "model" in case.__dict__:  # A always moves (free joint), so the compiled model is shared
        out.__dict__["model"] = case.__dict__["model"]
    return out


def _place(case: PairCase, w: np.ndarray, target: float, dist) -> PairCase:
    """Shift A's path along ``w`` so that its minimum distance is ``target`` (bisection)."""
    if target == 0:
        return case
    case.model  # noqa: B018  compile once; shifted copies share it
    lo, hi = 0.0, case.shapes[0].max_radius + case.shapes[1].max_radius + target + 0.05
    f_lo = min_distance(_shifted(case, w, lo), dist) - target
    f_hi = min_distance(_shifted(case, w, hi), dist) - target
    while f_hi < 0 and hi < 20.0:  # a curved path (screw, Bézier) can sweep wider than the bracket
        lo, f_lo = hi, f_hi
        hi *= 2.0
        f_hi = min_distance(_shifted(case, w, hi), dist) - target
    side = 0
    s = hi
    for _ in range(60):  # regula falsi (Illinois) on the bracket [lo, hi]
        s = hi - f_hi * (hi - lo) / (f_hi - f_lo) if f_hi != f_lo else 0.5 * (lo + hi)
        if not lo < s < hi:
            s = 0.5 * (lo + hi)
        f = min_distance(_shifted(case, w, s), dist) - target
        if abs(f) <= 0.02 * abs(target):
            break
        if f < 0:
            lo, f_lo = s, f
            if side == -1:
                f_hi *= 0.5
            side = -1
        else:
            hi, f_hi = s, f
            if side == 1:
                f_lo *= 0.5
            side = 1
    out = _shifted(case, w, s)
    out.nominal = min_distance(out, dist)
    return out


def make_cases(seed: int = 7, quick: bool = False, dist=None) -> list[PairCase]:
    """Build the seeded case set.

    Args:
        seed: RNG seed (the case set is a pure function of seed and quick).
        quick: fewer shape combinations and clearances.
        dist: static distance ``dist(case, t) -> float`` used to place near-misses
            (default: MuJoCo's ``mj_geomDistance``, fast; placement only needs to be
            approximate, the oracle labels every case rigorously afterwards).

    Returns:
        list of :class:`PairCase`, names unique.
    """
    if dist is None:
        from monitor.bench.oracle import mujoco_distance as dist
    rng = np.random.default_rng(seed)
    combos = [("box", "box"), ("hull", "box"), ("hull", "hull"), ("capsule", "box"), ("sphere", "hull")]
    clearances = NEAR_CLEARANCES_QUICK if quick else NEAR_CLEARANCES_FULL
    graze = GRAZE_DEPTHS_QUICK if quick else GRAZE_DEPTHS_FULL
    if quick:
        combos = [("box", "box"), ("hull", "box"), ("capsule", "box")]
    cases: list[PairCase] = []
    for group in ("translating", "rotating"):
        for ka, kb in combos:
            intents = (
                [("collide", -1.0)]
                + [("graze", -d) for d in graze]
                + [("near", c) for c in clearances]
                + [("clear", CLEAR_DISTANCE)]
            )
            for k, (intent, c) in enumerate(intents):
                both = bool(k % 2)
                shapes, u, w, travel, qa, qb = _random_start(rng, ka, kb)
                pos = np.zeros((2, 2, 3))
                pos[0, 0], pos[0, 1] = -travel * u, travel * u
                quat = np.zeros((2, 2, 4))
                quat[0, :] = qa
                quat[1, :] = qb
                if group == "rotating":
                    ang = rng.uniform(0.5, 2.5)
                    ra = Rotation.from_rotvec(ang * _unit(rng)) * Rotation.from_quat(qa, scalar_first=True)
                    quat[0, 1] = ra.as_quat(scalar_first=True)
                if both:
                    pos[1, 1] = 0.15 * _unit(rng)
                    if group == "rotating":
                        rb = Rotation.from_rotvec(0.6 * _unit(rng)) * Rotation.from_quat(
                            qb, scalar_first=True
                        )
                        quat[1, 1] = rb.as_quat(scalar_first=True)
                for b in range(2):  # shortest arc so that slerp angle < pi
                    if quat[b, 0] @ quat[b, 1] < 0:
                        quat[b, 1] *= -1
                name = f"{group[:3]}-{ka}-{kb}-{intent}" + (
                    f"-{abs(c):.0e}" if intent in ("near", "graze") else ""
                )
                case = PairCase(name, group, intent, c, shapes, pos, quat, (True, both))
                if intent != "collide":
                    case = _place(case, w, c, dist)
                else:
                    case.nominal = min_distance(case, dist)
                cases.append(case)
    cases += _motion_cases(rng, quick, dist)
    return cases


MOTION_INTENTS_FULL = (
    ("collide", -1.0), ("graze", -1e-3), ("near", 1e-2), ("near", 1e-4), ("clear", CLEAR_DISTANCE))
MOTION_INTENTS_QUICK = (("collide", -1.0), ("graze", -1e-3), ("near", 1e-2))


def planar_bezier(rng: np.random.Generator, travel: float, u: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """A smooth planar rational Bézier motion of degree 4: (quat_ctrl (3, 4), trans_ctrl (5, 3)).

    The rotation turns about the plane normal n by 0 .. a (a in [0.5, 2] rad) through a
    quadratic quaternion polynomial with control points q_n(0), q_n(a/2), q_n(a) (times a
    random base orientation); the origin's control polygon is a cubic S-curve from
    -travel u to +travel u in the plane (through lateral offsets), degree-elevated to 4.
    The weights (Bernstein coefficients of |Q|^2) are positive for a <= 2.
    """
    n = np.cross(u, _unit(rng))
    n /= np.linalg.norm(n)
    e = np.cross(n, u)
    a = rng.uniform(0.5, 2.0)
    base = Rotation.random(random_state=rng)
    Q = np.array([(Rotation.from_rotvec(phi * n) * base).as_quat(scalar_first=True) for phi in (0, a / 2, a)])
    for k in range(1, 3):  # one sign branch: consecutive control quaternions within 90 degrees
        if Q[k] @ Q[k - 1] < 0:
            Q[k] *= -1
    b1, b2 = rng.uniform(-0.3, 0.3, 2)
    C = np.array([-travel * u, -travel / 3 * u + b1 * e, travel / 3 * u + b2 * e, travel * u])
    E = np.array([C[0]] + [(k / 4) * C[k - 1] + (1 - k / 4) * C[k] for k in (1, 2, 3)] + [C[3]])
    return Q, E


def _motion_cases(rng: np.random.Generator, quick: bool, dist,
                  groups: tuple[str, ...] = ("screw", "bezier")) -> list[PairCase]:
    """Screw cases (constant twist between two poses) and planar Bézier cases (issue 14).

    Screw: A turns by 0.5..2.5 rad about a random axis while its origin goes from
    -travel u to +travel u, interpolated as the SE(3) geodesic (a helix, not the lerp
    line); every other case B screws too (0.6 rad, 15 cm). Bézier: A follows
    :func:`planar_bezier`, B is fixed. Quick: 3 + 3 cases (box-box screw, hull-box Bézier).
    ``groups`` selects the interpolations (the RNG stream then differs from the default).
    """
    combos = [("box", "box"), ("hull", "box"), ("hull", "hull"), ("capsule", "box"), ("sphere", "hull")]
    intents = MOTION_INTENTS_QUICK if quick else MOTION_INTENTS_FULL
    out: list[PairCase] = []
    for interp in groups:
        for ka, kb in ([combos[0]] if interp == "screw" else [combos[1]]) if quick else combos:
            for k, (intent, c) in enumerate(intents):
                both = interp == "screw" and bool(k % 2)
                shapes, u, w, travel, qa, qb = _random_start(rng, ka, kb)
                pos = np.zeros((2, 2, 3))
                quat = np.zeros((2, 2, 4))
                quat[0, :], quat[1, :] = qa, qb
                bez = None
                if interp == "screw":
                    pos[0, 0], pos[0, 1] = -travel * u, travel * u
                    ra = Rotation.from_rotvec(rng.uniform(0.5, 2.5) * _unit(rng)) * Rotation.from_quat(
                        qa, scalar_first=True)
                    quat[0, 1] = ra.as_quat(scalar_first=True)
                    if both:
                        pos[1, 1] = 0.15 * _unit(rng)
                        rb = Rotation.from_rotvec(0.6 * _unit(rng)) * Rotation.from_quat(
                            qb, scalar_first=True)
                        quat[1, 1] = rb.as_quat(scalar_first=True)
                    for b in range(2):
                        if quat[b, 0] @ quat[b, 1] < 0:
                            quat[b, 1] *= -1
                else:
                    bez = planar_bezier(rng, travel, u)
                    pos[0, 0], pos[0, 1] = bez[1][0], bez[1][-1]
                    quat[0, 0] = bez[0][0] / np.linalg.norm(bez[0][0])
                    quat[0, 1] = bez[0][-1] / np.linalg.norm(bez[0][-1])
                name = f"{interp[:3]}-{ka}-{kb}-{intent}" + (
                    f"-{abs(c):.0e}" if intent in ("near", "graze") else "")
                case = PairCase(name, interp, intent, c, shapes, pos, quat, (True, both),
                                interpolation=interp, bezier=bez)
                if intent != "collide":
                    case = _place(case, w, c, dist)
                else:
                    case.nominal = min_distance(case, dist)
                out.append(case)
    return out


# --------------------------------------------------------------------------- translating cross-check cases
XCHECK_KINDS_A = ("box", "hull", "sphere", "capsule")
XCHECK_KINDS_B = ("box", "hull", "sphere", "capsule", "plane")
XCHECK_INTENTS = ("clear", "graze", "collide", "tunnel", "start-inside")
_XCHECK_INTENT_P = (0.28, 0.32, 0.14, 0.14, 0.12)


@dataclass(eq=False)
class TranslatingCase:
    """Two convex geoms on bodies that translate with piecewise-constant velocity.

    The cross-check of the two certifiers (issue 14) runs both ``method="toleranced"``
    and ``method="extrusion"`` of :func:`monitor.certify` on such cases. Every body keeps
    a constant (random) orientation; origins are linear between the waypoints.

    Attributes:
        name: unique case name (``xc-<seed>-<kind A>-<kind B>-<intent>``).
        intent: one of :data:`XCHECK_INTENTS` (how it was built, not a label).
        kinds: (kind A, kind B), from :data:`XCHECK_KINDS_A` / :data:`XCHECK_KINDS_B`.
        margin: clearance (m) the certificate must prove.
        shapes: (A, B) :class:`monitor.geometry.shapes.ConvexShape` in their body frames.
        rotations: (2, 3, 3) constant world rotations R_WB of A and B.
        times: (K,) waypoint times (s), K >= 2.
        origins: (K, 2, 3) body origins (m, world) of A and B at the waypoints.
        b_static: B is welded to the world (its geom is placed on the world body).
    """

    name: str
    intent: str
    kinds: tuple[str, str]
    margin: float
    shapes: tuple
    rotations: np.ndarray
    times: np.ndarray
    origins: np.ndarray
    b_static: bool

    def velocities(self) -> np.ndarray:
        """(K-1, 2, 3) constant origin velocities (m/s) per segment."""
        return np.diff(self.origins, axis=0) / np.diff(self.times)[:, None, None]

    def relative_speeds(self) -> np.ndarray:
        """(K-1,) |v_A - v_B| (m/s) per segment: the Lipschitz constant of the pair's distance.

        For translations the signed distance of A and B is 1-Lipschitz in the relative
        offset, so on segment k it changes at most at this rate. Padded by 1e-12 relative.
        """
        v = self.velocities()
        return np.linalg.norm(v[:, 0] - v[:, 1], axis=1) * (1 + 1e-12) + 1e-15

    def origins_at(self, times: np.ndarray) -> np.ndarray:
        """(N, 2, 3) body origins (m, world) at ``times`` (N,) s (linear between waypoints)."""
        t = np.clip(np.asarray(times, float).reshape(-1), self.times[0], self.times[-1])
        out = np.empty((len(t), 2, 3))
        for b in range(2):
            for c in range(3):
                out[:, b, c] = np.interp(t, self.times, self.origins[:, b, c])
        return out

    def distance_bounds(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rigorous (lower (N,), upper (N,)) bounds (m) on the signed distance at ``times`` (N,)."""
        from monitor.geometry.distance import shape_distance_batch

        P = self.origins_at(times)
        R = self.rotations
        return shape_distance_batch(self.shapes[0], (np.broadcast_to(R[0], (len(P), 3, 3)), P[:, 0]),
                                    self.shapes[1], (np.broadcast_to(R[1], (len(P), 3, 3)), P[:, 1]))

    def scene(self):
        """Hand-built :class:`monitor.Scene` (no MuJoCo model): bodies (world, A, B), geoms A, B.

        A static B is placed on the world body with its pose baked into the shape.
        """
        from monitor.scene import GeomInfo, Scene
        from monitor.tolerances import DEFAULT

        sa, sb = self.shapes
        if self.b_static:
            sb = sb.transformed(self.rotations[1], self.origins[0, 1])
        geoms = (
            GeomInfo("A", 0, "A", 1, sa.kind, sa, 0.0, False, False),
            GeomInfo("B", 1, "world" if self.b_static else "B", 0 if self.b_static else 2, sb.kind, sb,
                     0.0, self.b_static, False),
        )
        return Scene(None, geoms, np.array([[0, 1]], np.int64), ("world", "A", "B"),
                     np.array([True, False, self.b_static]), 16, DEFAULT)

    def body_motion(self):
        """The exact motion as a :class:`monitor.BodyMotion` over (world, A, B)."""
        from monitor.motion.bodymotion import BodyMotion

        K = len(self.times)
        pos = np.zeros((K, 3, 3))
        quat = np.zeros((K, 3, 4))
        quat[:, :, 0] = 1.0
        for b in range(2):
            if b == 1 and self.b_static:
                continue
            pos[:, b + 1] = self.origins[:, b]
            quat[:, b + 1] = Rotation.from_matrix(self.rotations[b]).as_quat(scalar_first=True)
        return BodyMotion(self.times.copy(), pos, quat)

    def to_dict(self) -> dict:
        """JSON form (for results.json)."""
        return {"name": self.name, "intent": self.intent, "kinds": list(self.kinds), "margin": self.margin,
                "times": self.times.tolist(), "origins": self.origins.tolist(), "b_static": self.b_static}


def _xc_shape(rng: np.random.Generator, kind: str, thin: bool = False):
    from monitor.geometry import polytope

    if kind == "box":
        h = rng.uniform(0.04, 0.2, 3)
        if thin:
            h[rng.integers(3)] = rng.uniform(0.002, 0.01)
        return polytope.box_polytope(h)
    if kind == "hull":
        pts = rng.normal(size=(int(rng.integers(6, 12)), 3)) * rng.uniform(0.05, 0.15)
        if thin:
            pts[:, rng.integers(3)] *= 0.05
        return polytope.polytope_from_points(pts)
    if kind == "sphere":
        return polytope.sphere_shape(float(rng.uniform(0.01 if thin else 0.03, 0.15)))
    if kind == "capsule":
        return polytope.capsule_shape(float(rng.uniform(0.01 if thin else 0.02, 0.08)),
                                      float(rng.uniform(0.03, 0.15)))
    return polytope.halfspace_shape()


def _closest_translating(case: TranslatingCase, samples: int = 17, levels: int = 3
                         ) -> tuple[float, float]:
    """(approximate minimum signed distance (m), its time (s)) over the window.

    For translations the signed distance is convex in time on every segment (it is the
    signed distance of the origin to the Minkowski difference, which moves linearly), so
    zooming on the best sample's neighbours keeps the minimiser in the bracket.
    """
    best, t_best = np.inf, float(case.times[0])
    for a0, b0 in zip(case.times[:-1], case.times[1:]):
        a, b = float(a0), float(b0)
        for _ in range(levels):
            ts = np.linspace(a, b, samples)
            _, up = case.distance_bounds(ts)
            k = int(np.argmin(up))
            a, b = float(ts[max(k - 1, 0)]), float(ts[min(k + 1, samples - 1)])
        if up[k] < best:
            best, t_best = float(up[k]), float(ts[k])
    return best, t_best


def _normal_at(case: TranslatingCase, t: float) -> np.ndarray:
    """Unit world direction from B towards A at time ``t`` (the plane normal for a plane B)."""
    from monitor.geometry.distance import shape_distance

    if case.kinds[1] == "plane":
        return case.rotations[1] @ np.array([0.0, 0.0, 1.0])
    P = case.origins_at(np.array([t]))[0]
    r = shape_distance(case.shapes[0], (case.rotations[0], P[0]), case.shapes[1], (case.rotations[1], P[1]))
    n = r.p_a - r.p_b
    nn = float(np.linalg.norm(n))
    if nn < 1e-12:
        return _unit(np.random.default_rng(int(1e6 * t) % 2**32))
    return n / nn


def _shift_b(case: TranslatingCase, d: np.ndarray) -> TranslatingCase:
    origins = case.origins.copy()
    origins[:, 1] += d
    return TranslatingCase(case.name, case.intent, case.kinds, case.margin, case.shapes, case.rotations,
                           case.times, origins, case.b_static)


def make_translating_case(seed: int) -> TranslatingCase:
    """One seeded translating case (a pure function of ``seed``).

    Kinds: A in :data:`XCHECK_KINDS_A`, B in :data:`XCHECK_KINDS_B` (a plane is a
    static half-space). Margin 0 (70 %) or 1 cm. 2-4 waypoints over a 1 s window; B is
    static or moves slowly. Intents (the oracle labels the case afterwards):

    * ``clear``: minimum distance margin + 2..30 cm;
    * ``graze``: margin + 1e-6..1e-2 m (60 %), exactly the margin (10 %), or a shallow
      penetration of the margin band by 1e-5..1e-3 m (30 %);
    * ``collide``: penetration of the band by 1 mm..5 cm;
    * ``tunnel``: one fast straight segment whose start and end poses are clear but
      which takes A's inner point (vertex mean) through B's (thin plates and small
      shapes: what endpoint or coarse time sampling misses); always a collision;
    * ``start-inside``: A's inner point starts at B's (or below the plane) and moves
      away; always a violation at t0.
    """
    rng = np.random.default_rng(seed)
    ka = XCHECK_KINDS_A[int(rng.integers(len(XCHECK_KINDS_A)))]
    kb = XCHECK_KINDS_B[int(rng.integers(len(XCHECK_KINDS_B)))]
    intent = XCHECK_INTENTS[int(rng.choice(len(XCHECK_INTENTS), p=_XCHECK_INTENT_P))]
    margin = 0.0 if rng.uniform() < 0.7 else 0.01
    thin = intent == "tunnel"
    sa, sb = _xc_shape(rng, ka, thin), _xc_shape(rng, kb, thin)
    rot = np.stack([Rotation.random(random_state=rng).as_matrix() for _ in range(2)])
    b_static = kb == "plane" or rng.uniform() < 0.5
    K = 2 if intent == "tunnel" else int(rng.integers(2, 5))
    times = np.linspace(0.0, 1.0, K)
    origins = np.zeros((K, 2, 3))
    u = _unit(rng)
    n_plane = rot[1] @ np.array([0.0, 0.0, 1.0])
    if not b_static:  # B first: the tunnel aims at where B is when A passes
        vb = 0.15 * rng.normal(size=(K - 1, 3)) * rng.uniform(0, 1)
        origins[1:, 1] = np.cumsum(vb * np.diff(times)[:, None], axis=0)
    # inner points (the vertex mean lies in the convex core), world offsets from the origins
    ca = rot[0] @ sa.points.mean(axis=0)
    cb = rot[1] @ sb.points.mean(axis=0)
    ra = sa.bounding_radius
    rb = 0.0 if kb == "plane" else sb.bounding_radius
    if intent == "tunnel":
        # straight (one segment) through B's inner point at time tm, so the cores meet at tm;
        # both ends clear of B unless B's own motion brings it back
        reach = ra + rb + margin + rng.uniform(0.05, 0.3)
        if kb == "plane":
            u = -n_plane  # from above through the plane (ends inside the half-space)
        tm = float(rng.uniform(0.3, 0.7))
        b_tm = origins[0, 1] + tm * (origins[1, 1] - origins[0, 1])
        origins[:, 0] = b_tm + cb - ca + (times[:, None] - tm) * (reach / max(tm, 1 - tm)) * u
    elif intent == "start-inside":
        # A's inner point starts at B's inner point (or below the plane) and moves away
        away = n_plane if kb == "plane" else u
        start = cb - ca - rng.uniform(0.0, 0.03) * n_plane if kb == "plane" else cb - ca
        step = rng.uniform(0.1, 0.4) * (times[:, None] / times[-1])
        origins[:, 0] = start + step * (away + 0.3 * _unit(rng))
    else:
        seg = rng.uniform(0.15, 0.5, K - 1)
        dirs = [u]
        for _ in range(K - 2):
            d = dirs[-1] + 0.8 * _unit(rng)
            dirs.append(d / np.linalg.norm(d))
        pts = [np.zeros(3)]
        for L, d in zip(seg, dirs):
            pts.append(pts[-1] + L * d)
        pts = np.array(pts)
        origins[:, 0] = pts - pts.mean(axis=0)
        if kb == "plane":
            origins[:, 0] += (0.3 + ra) * n_plane
    name = f"xc-{seed}-{ka}-{kb}-{intent}"
    case = TranslatingCase(name, intent, (ka, kb), margin, (sa, sb), rot, times, origins, b_static)
    if intent in ("tunnel", "start-inside"):
        return case
    u_t = rng.uniform()
    if intent == "clear":
        target = margin + rng.uniform(0.02, 0.3)
    elif intent == "collide":
        target = margin - rng.uniform(1e-3, 0.05)
    elif u_t < 0.6:
        target = margin + 10 ** rng.uniform(-6, -2)
    elif u_t < 0.7:
        target = margin
    else:
        target = margin - 10 ** rng.uniform(-5, -3)
    # push B away from A's path until clearly apart, then move it along the closest-point
    # normal so that the minimum over the window is (about) the target
    away = -n_plane if kb == "plane" else _unit(rng)
    for _ in range(30):
        d, t = _closest_translating(case)
        if d > 0.02:
            break
        case = _shift_b(case, (0.1 - min(d, 0.0)) * away)
    d, t = _closest_translating(case)
    return _shift_b(case, (d - target) * _normal_at(case, t))


def make_translating_cases(n: int, seed0: int = 0) -> list[TranslatingCase]:
    """``n`` seeded translating cases, seeds ``seed0 .. seed0 + n - 1``."""
    return [make_translating_case(seed0 + i) for i in range(n)]


__all__ = [
    "ShapeSpec",
    "PairCase",
    "make_cases",
    "min_distance",
    "NEAR_CLEARANCES_FULL",
    "NEAR_CLEARANCES_QUICK",
    "CLEAR_DISTANCE",
    "INTERPOLATIONS",
    "planar_bezier",
    "TranslatingCase",
    "make_translating_case",
    "make_translating_cases",
    "XCHECK_KINDS_A",
    "XCHECK_KINDS_B",
    "XCHECK_INTENTS",
]
