"""Convex shapes in a body frame: a convex *core* swept by a ball of ``radius``.

Every MuJoCo geom becomes one :class:`ConvexShape`, expressed in the frame of
the body that carries it (``p_B = X_BG * p_G`` already applied):

=========  ======================  =========================================
kind       core                    radius
=========  ======================  =========================================
sphere     one point (1, 3)        sphere radius (exact)
capsule    segment (2, 3)          capsule radius (exact)
polytope   convex polytope (n, 3)  0 (boxes, mesh hulls: exact; cylinders and
                                   ellipsoids: circumscribed, see approx_error)
halfspace  plane point (1, 3)      0; solid is {x : normals[0] . x <= offsets[0]}
=========  ======================  =========================================

The distance between two shapes is ``dist(core_A, core_B) - radius_A - radius_B``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

ShapeKind = Literal["sphere", "capsule", "polytope", "halfspace"]


@dataclass(frozen=True, eq=False)
class ConvexShape:
    """A convex core (point, segment, polytope or half-space) plus a radius.

    Attributes:
        kind: one of ``"sphere" | "capsule" | "polytope" | "halfspace"``.
        points: (n, 3) float64 core vertices in the body frame, metres.
            sphere n=1, capsule n=2, polytope n>=4, halfspace n=1 (a point on the plane).
        radius: metres; 0 for polytopes and half-spaces.
        edges: (m, 2) int64 vertex-index pairs (capsule: [[0, 1]]; sphere/halfspace: (0, 2)).
        faces: tuple of int64 arrays, each a convex face loop ordered counter-clockwise
            seen from outside (polytope only; empty otherwise).
        normals: (f, 3) outward unit normals of the H-representation, body frame.
        offsets: (f,) so that the solid core is ``{x : normals @ x <= offsets}``
            (polytope and halfspace; empty for sphere/capsule).
        approx_error: metres by which the shape over-approximates the true geom
            (0 for exact shapes; circumscribed cylinders/ellipsoids > 0).
    """

    kind: ShapeKind
    points: np.ndarray
    radius: float = 0.0
    edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    faces: tuple[np.ndarray, ...] = ()
    normals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    offsets: np.ndarray = field(default_factory=lambda: np.zeros(0))
    approx_error: float = 0.0

    @property
    def bounding_center(self) -> np.ndarray:
        """(3,) centre of the core's bounding sphere, body frame (AABB midpoint)."""
        return 0.5 * (self.points.min(axis=0) + self.points.max(axis=0))

    @property
    def bounding_radius(self) -> float:
        """Radius (m) of a sphere about :attr:`bounding_center` containing the shape.

        Infinite for half-spaces.
        """
        if self.kind == "halfspace":
            return float("inf")
        c = self.bounding_center
        return float(np.sqrt(((self.points - c) ** 2).sum(axis=1).max()) + self.radius)

    def transformed(self, R: np.ndarray, p: np.ndarray) -> ConvexShape:
        """Return the shape mapped by x -> R @ x + p (R (3,3) rotation, p (3,))."""
        pts = self.points @ R.T + p
        nrm = self.normals @ R.T
        off = self.offsets + nrm @ p if len(self.offsets) else self.offsets
        return ConvexShape(self.kind, pts, self.radius, self.edges, self.faces, nrm, off,
                           self.approx_error)


__all__ = ["ConvexShape", "ShapeKind"]
