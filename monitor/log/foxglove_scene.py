"""Foxglove 3-D review messages for a monitor log (needs ``foxglove-sdk``).

Encoding: ``foxglove.messages`` classes, written by the plain ``mcap`` Writer with
their protobuf schemas (one file, one flush policy). Layout:

* ``/monitor/scene`` (``foxglove.SceneUpdate``): at the first window, one entity per
  geom in its **body frame** (``frame_id`` = body name; geometry is static in it).
* ``/monitor/markers`` (``foxglove.SceneUpdate``): at every violation/uncertain
  window, a red witness marker (sphere + label) in ``world`` that stays until the next
  certified window deletes it (entity id ``witness``).
* ``/monitor/tf`` (``foxglove.FrameTransforms``): at every window, world -> body
  transforms of every body at the plan's first waypoint.

Quaternions: MuJoCo is (w, x, y, z); Foxglove is (x, y, z, w): :func:`fox_quat`.
Importing this module raises ImportError when foxglove-sdk is missing; the writer
catches it and logs without the 3-D topics.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from foxglove.messages import (
    Color,
    CubePrimitive,
    CylinderPrimitive,
    FrameTransform,
    FrameTransforms,
    KeyValuePair,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneEntityDeletion,
    SceneEntityDeletionType,
    SceneUpdate,
    SpherePrimitive,
    TextPrimitive,
    Timestamp,
    TriangleListPrimitive,
    Vector3,
)

from monitor.certify.types import Verdict
from monitor.log import topics

WORLD_FRAME = "world"
PLANE_EXTENT = 20.0
"""Drawn size (m) of an infinite plane (MuJoCo plane size 0)."""

_COLORS = {
    "static": Color(r=0.55, g=0.55, b=0.6, a=0.6),
    "moving": Color(r=0.2, g=0.6, b=1.0, a=0.8),
    "witness": Color(r=1.0, g=0.1, b=0.1, a=1.0),
    "uncertain": Color(r=1.0, g=0.7, b=0.0, a=1.0),
}


def xyzw(q_wxyz: Any) -> np.ndarray:
    """Reorder a MuJoCo (w, x, y, z) quaternion (4,) to Foxglove/scipy (x, y, z, w) (4,)."""
    q = np.asarray(q_wxyz, np.float64).reshape(4)
    return np.array([q[1], q[2], q[3], q[0]])


def fox_quat(q_wxyz: Any) -> Quaternion:
    """MuJoCo (w, x, y, z) quaternion -> foxglove ``Quaternion(x, y, z, w)``."""
    x, y, z, w = (float(v) for v in xyzw(q_wxyz))
    return Quaternion(x=x, y=y, z=z, w=w)


def mj_quat(q: Any) -> np.ndarray:
    """Decoded Foxglove quaternion (protobuf with x, y, z, w) -> MuJoCo (4,) (w, x, y, z)."""
    return np.array([q.w, q.x, q.y, q.z], dtype=np.float64)


def _vec(p: Any) -> Vector3:
    p = np.asarray(p, np.float64).reshape(3)
    return Vector3(x=float(p[0]), y=float(p[1]), z=float(p[2]))


def _stamp(t_ns: int) -> Timestamp:
    return Timestamp(sec=int(t_ns // 1_000_000_000), nsec=int(t_ns % 1_000_000_000))


def body_frame(model: Any, b: int) -> str:
    """Frame id of body ``b``: its name, ``body<b>`` if unnamed, ``world`` for body 0."""
    if b == 0:
        return WORLD_FRAME
    import mujoco

    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}"


def geom_primitives(model: Any, g: int, color: Color) -> dict[str, list[Any]]:
    """Foxglove primitives of geom ``g`` in its body frame (sizes are full extents).

    The geom's pose in the body is :func:`monitor.scene.geom_frame`: a geom MuJoCo's compiler
    marked ``geom_sameframe`` sits at its body's (or inertial) frame whatever ``geom_pos`` /
    ``geom_quat`` say, and the drawing must show where the simulation (and the Scene) has it.
    """
    import mujoco

    from monitor.scene import geom_frame

    G = mujoco.mjtGeom
    t, s = int(model.geom_type[g]), model.geom_size[g]
    R_BG, p_BG = geom_frame(model, g)  # where MuJoCo's kinematics put it (geom_sameframe; red team 4)
    q_BG = np.empty(4)  # (w, x, y, z)
    mujoco.mju_mat2Quat(q_BG, np.ascontiguousarray(R_BG).ravel())
    pose = Pose(position=_vec(p_BG), orientation=fox_quat(q_BG))
    if t == G.mjGEOM_BOX:
        return {"cubes": [CubePrimitive(pose=pose, size=_vec(2 * s), color=color)]}
    if t == G.mjGEOM_SPHERE:
        return {"spheres": [SpherePrimitive(pose=pose, size=_vec([2 * s[0]] * 3), color=color)]}
    if t == G.mjGEOM_ELLIPSOID:
        return {"spheres": [SpherePrimitive(pose=pose, size=_vec(2 * s), color=color)]}
    if t == G.mjGEOM_CYLINDER:
        return {"cylinders": [CylinderPrimitive(pose=pose, size=_vec([2 * s[0], 2 * s[0], 2 * s[1]]),
                                                bottom_scale=1.0, top_scale=1.0, color=color)]}
    if t == G.mjGEOM_CAPSULE:
        axis = R_BG[:, 2]
        ends = [p_BG + sgn * s[1] * axis for sgn in (-1.0, 1.0)]
        return {"cylinders": [CylinderPrimitive(pose=pose, size=_vec([2 * s[0], 2 * s[0], 2 * s[1]]),
                                                bottom_scale=1.0, top_scale=1.0, color=color)],
                "spheres": [SpherePrimitive(pose=Pose(position=_vec(e), orientation=Quaternion(w=1.0)),
                                            size=_vec([2 * s[0]] * 3), color=color) for e in ends]}
    if t == G.mjGEOM_PLANE:
        sx = 2 * s[0] if s[0] > 0 else PLANE_EXTENT
        sy = 2 * s[1] if s[1] > 0 else PLANE_EXTENT
        size = Vector3(x=float(sx), y=float(sy), z=1e-3)
        return {"cubes": [CubePrimitive(pose=pose, size=size, color=color)]}
    if t == G.mjGEOM_MESH:
        i = model.geom_dataid[g]
        va, nv = model.mesh_vertadr[i], model.mesh_vertnum[i]
        fa, nf = model.mesh_faceadr[i], model.mesh_facenum[i]
        V = model.mesh_vert[va:va + nv]
        F = model.mesh_face[fa:fa + nf]
        return {"triangles": [TriangleListPrimitive(
            pose=pose, points=[Point3(x=float(v[0]), y=float(v[1]), z=float(v[2])) for v in V],
            indices=[int(k) for k in F.ravel()], color=color)]}
    return {}  # hfield / sdf / visual-only types: not drawn


class FoxgloveScene:
    """Builds the encoded foxglove messages of one model's log.

    Args:
        model: ``mujoco.MjModel``; geoms of ``geom_group`` > 2 (visual-only by
            convention) are skipped.
    """

    def __init__(self, model: Any) -> None:
        import mujoco

        self.model = model
        self._data = mujoco.MjData(model)
        self._geometry_sent = False
        self._marker_shown = False
        self._frames = [body_frame(model, b) for b in range(model.nbody)]

    @staticmethod
    def schemas() -> dict[str, tuple[str, str, bytes]]:
        """Topic -> (schema name, encoding, FileDescriptorSet bytes)."""
        out = {}
        for topic, cls in ((topics.SCENE, SceneUpdate), (topics.MARKERS, SceneUpdate),
                           (topics.TRANSFORMS, FrameTransforms)):
            s = cls.get_schema()
            out[topic] = (s.name, s.encoding, bytes(s.data))
        return out

    def geometry(self, t_ns: int) -> SceneUpdate:
        """One entity per drawable geom, in its body frame."""
        import mujoco

        m = self.model
        ents = []
        for g in range(m.ngeom):
            if m.geom_group[g] > 2:
                continue
            b = int(m.geom_bodyid[g])
            color = _COLORS["static"] if m.body_weldid[b] == 0 else _COLORS["moving"]
            prims = geom_primitives(m, g, color)
            if not prims:
                continue
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) or f"geom{g}"
            ents.append(SceneEntity(timestamp=_stamp(t_ns), frame_id=self._frames[b], id=f"geom/{name}",
                                    frame_locked=True,
                                    metadata=[KeyValuePair(key="body", value=self._frames[b]),
                                              KeyValuePair(key="geom_id", value=str(g))], **prims))
        return SceneUpdate(entities=ents)

    def transforms(self, t_ns: int, qpos: np.ndarray, mocap_pos: Any = None,
                   mocap_quat: Any = None) -> FrameTransforms:
        """World -> body transforms at ``qpos`` (nq,) (and mocap poses, if given)."""
        import mujoco

        m, d = self.model, self._data
        d.qpos[:] = qpos
        if m.nmocap:
            d.mocap_pos[:] = m.body_pos[m.body_mocapid >= 0] if mocap_pos is None else mocap_pos
            d.mocap_quat[:] = m.body_quat[m.body_mocapid >= 0] if mocap_quat is None else mocap_quat
        mujoco.mj_kinematics(m, d)
        ts = _stamp(t_ns)
        return FrameTransforms(transforms=[
            FrameTransform(timestamp=ts, parent_frame_id=WORLD_FRAME, child_frame_id=self._frames[b],
                           translation=_vec(d.xpos[b]), rotation=fox_quat(d.xquat[b]))
            for b in range(1, m.nbody)])

    @staticmethod
    def witness_markers(t_ns: int, cert: dict[str, Any]) -> SceneUpdate | None:
        """Red sphere + label at the witness (violation) or amber label (uncertain)."""
        verdict = cert.get("verdict")
        if verdict == Verdict.CERTIFIED:
            return None
        ts = _stamp(t_ns)
        wit = cert.get("witness")
        ents = []
        if wit:
            p = wit["point"]
            wt = "unknown" if wit.get("time") is None else f"{wit['time']:.4f}"
            label = f"{verdict}: {wit['geoms'][0]} / {wit['geoms'][1]} at t={wt}s"
            ents.append(SceneEntity(
                timestamp=ts, frame_id=WORLD_FRAME, id="witness",
                spheres=[SpherePrimitive(pose=Pose(position=_vec(p), orientation=Quaternion(w=1.0)),
                                         size=Vector3(x=0.03, y=0.03, z=0.03), color=_COLORS["witness"])],
                texts=[TextPrimitive(pose=Pose(position=_vec(np.asarray(p) + [0, 0, 0.05]),
                                               orientation=Quaternion(w=1.0)),
                                     billboard=True, font_size=14.0, scale_invariant=True,
                                     color=_COLORS["witness"], text=label)],
                metadata=[KeyValuePair(key="distance", value=str(wit.get("distance")))]))
        else:
            ents.append(SceneEntity(
                timestamp=ts, frame_id=WORLD_FRAME, id="witness",
                texts=[TextPrimitive(pose=Pose(position=Vector3(z=0.5), orientation=Quaternion(w=1.0)),
                                     billboard=True, font_size=14.0, scale_invariant=True,
                                     color=_COLORS["uncertain"],
                                     text=f"{verdict} from t={cert.get('earliest_time')}")]))
        return SceneUpdate(entities=ents)

    def window_messages(self, t_ns: int, plan: Any, cert: dict[str, Any]) -> list[tuple[str, bytes]]:
        """Encoded (topic, payload) pairs for one window."""
        out = []
        if not self._geometry_sent:
            out.append((topics.SCENE, self.geometry(t_ns).encode()))
            self._geometry_sent = True
        qpos = np.asarray(plan.qpos, np.float64)[0]
        tf = self.transforms(t_ns, qpos, getattr(plan, "mocap_pos", None), getattr(plan, "mocap_quat", None))
        out.append((topics.TRANSFORMS, tf.encode()))
        marks = self.witness_markers(t_ns, cert)
        if marks is not None:
            out.append((topics.MARKERS, marks.encode()))
            self._marker_shown = True
        elif self._marker_shown:  # first certified window after a marker: remove it
            gone = SceneEntityDeletion(timestamp=_stamp(t_ns), type=SceneEntityDeletionType.MatchingId,
                                       id="witness")
            out.append((topics.MARKERS, SceneUpdate(deletions=[gone]).encode()))
            self._marker_shown = False
        return out


__all__ = ["FoxgloveScene", "fox_quat", "xyzw", "mj_quat", "geom_primitives", "body_frame", "WORLD_FRAME"]
