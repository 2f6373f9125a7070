"""Generate ``scene.xml``: a 5-finger mesh hand on a gantry over a table with objects.

Run from anywhere: ``python models/hand30/make_scene.py`` (deterministic; the XML is
committed). Every collision geom is a mesh with its vertices inline in the MJCF
(``<mesh vertex="...">``): convex point sets, so MuJoCo's collision hull and the
monitor's hull of all compiled vertices coincide.

Layout (metres, z up; see README.md): a table top at z = 0.40 with six static objects
(at most 0.12 m tall); a gantry (slides x, y, z), a forearm (yaw) and a palm (pitch)
carrying four fingers and a thumb, 4 bodies each (metacarpal: abduction; proximal,
middle, distal: flexion). The hand hangs with its fingers down; the lift's range keeps
the lowest fingertip at least 2 cm above the tallest object in every joint
configuration, the abduction ranges keep neighbouring fingers apart, and fingers curl
towards +y, in front of the palm. Random joint targets therefore move the hand without
collisions nearly always, while many pairs stay within a few centimetres (fingers side
by side), which is what makes the scene expensive to certify.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

TABLE_TOP = 0.40
"""z (m) of the table's top face."""

GANTRY_Z = 0.765
"""z (m) of the gantry's origin (the lift adds 0..0.08 m)."""

FINGER_X = (-0.036, -0.012, 0.012, 0.036)
"""x (m) of the four fingers' knuckles in the palm frame (8 mm gaps between fingers)."""

SEGMENTS = (("meta", 0.020, 0.0085), ("prox", 0.045, 0.008), ("mid", 0.030, 0.0075), ("dist", 0.025, 0.007))
"""(name, length m, half width m) of a finger's four segments, knuckle to tip."""

ABDUCTION = ((0.0, 0.10), (-0.03, 0.03), (-0.03, 0.03), (-0.10, 0.0))
"""Abduction ranges (rad) of the four fingers about the palm's y axis (index .. little);
the outer two only spread outwards (a positive angle swings a fingertip towards -x)."""

FLEXION = (0.0, 0.9)
"""Flexion range (rad) of the proximal, middle and distal joints (curl towards +y)."""


def _fmt(v: np.ndarray) -> str:
    return " ".join(f"{x:.5g}" for x in np.asarray(v, float).ravel())


def octagon_prism(half_w: float, length: float, taper: float = 0.85) -> np.ndarray:
    """(16, 3) vertices of a tapered octagonal prism from z = 0 down to z = -length.

    The cross-section is a regular-ish octagon of half width ``half_w`` at the top and
    ``taper * half_w`` at the bottom; both end caps are chamfered by 15 % of the width.
    """
    ang = (np.arange(8) + 0.5) * (2 * math.pi / 8)
    ring = np.stack([np.cos(ang), np.sin(ang)], axis=1) / math.cos(math.pi / 8)
    top = np.column_stack([half_w * ring, np.full(8, -0.0)])
    bot = np.column_stack([taper * half_w * ring, np.full(8, -length)])
    return np.vstack([top, bot])


def rounded_box(hx: float, hy: float, hz: float, c: float) -> np.ndarray:
    """(24, 3) vertices of a box of half sizes (hx, hy, hz) with every corner cut by ``c``."""
    out = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            for sz in (-1, 1):
                corner = np.array([sx * hx, sy * hy, sz * hz])
                for axis in range(3):
                    v = corner.copy()
                    v[axis] -= np.sign(v[axis]) * c
                    out.append(v)
    return np.array(out)


def frustum(r0: float, r1: float, h: float, n: int = 10) -> np.ndarray:
    """(2n, 3) vertices of an n-gon frustum from z = 0 (radius r0) to z = h (radius r1)."""
    ang = np.arange(n) * (2 * math.pi / n)
    ring = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    return np.vstack([np.column_stack([r0 * ring, np.zeros(n)]), np.column_stack([r1 * ring, np.full(n, h)])])


def wedge(hx: float, hy: float, h: float) -> np.ndarray:
    """(6, 3) vertices of a triangular prism lying on z = 0, ridge along x at height h."""
    return np.array([[-hx, -hy, 0], [hx, -hy, 0], [-hx, hy, 0], [hx, hy, 0], [-hx, 0, h], [hx, 0, h]])


def meshes() -> dict[str, np.ndarray]:
    """Every mesh of the scene by name: (V, 3) vertices in the geom frame."""
    out = {
        "forearm": rounded_box(0.035, 0.025, 0.07, 0.008) + [0, 0, 0.075],
        "palm": rounded_box(0.048, 0.012, 0.05, 0.006),
        "obj_box": rounded_box(0.04, 0.03, 0.05, 0.006) + [0, 0, 0.05],
        "obj_can": frustum(0.035, 0.035, 0.11),
        "obj_cone": frustum(0.045, 0.015, 0.09),
        "obj_wedge": wedge(0.05, 0.04, 0.06),
        "obj_bottle": np.vstack([frustum(0.03, 0.03, 0.08, 8), frustum(0.012, 0.012, 0.12, 8)[8:]]),
        "obj_block": rounded_box(0.06, 0.02, 0.015, 0.004) + [0, 0, 0.015],
    }
    for name, length, hw in SEGMENTS:
        out[f"seg_{name}"] = octagon_prism(hw, length)
    out["seg_thumb_meta"] = octagon_prism(0.0095, 0.025)
    return out


OBJECTS = (
    ("obj_box", (-0.20, -0.12), 0.3),
    ("obj_can", (0.18, -0.10), 0.0),
    ("obj_cone", (0.02, 0.17), 0.0),
    ("obj_wedge", (-0.15, 0.14), 0.8),
    ("obj_bottle", (0.22, 0.15), 0.0),
    ("obj_block", (0.0, -0.02), 0.4),
)
"""(mesh, (x, y) on the table, yaw rad) of the six static objects."""


def _finger(prefix: str, x: float, abd: tuple[float, float], tilt: float, meta_mesh: str, ind: str) -> str:
    """MJCF of one finger (4 nested bodies) hanging from the palm's bottom face at x."""
    seg = {name: (length, hw) for name, length, hw in SEGMENTS}
    quat = f"{math.cos(tilt / 2):.6g} 0 {math.sin(tilt / 2):.6g} 0"
    meta_len = seg["meta"][0] if meta_mesh == "seg_meta" else 0.025
    lines = [
        f'{ind}<body name="{prefix}_meta" pos="{x:.4g} 0 -0.05" quat="{quat}" gravcomp="1">',
        f'{ind}  <joint name="{prefix}_abd" axis="0 1 0" range="{abd[0]} {abd[1]}"/>',
        f'{ind}  <geom name="{prefix}_meta" type="mesh" mesh="{meta_mesh}"/>',
    ]
    z, depth = -meta_len, 1
    for name in ("prox", "mid", "dist"):
        length = seg[name][0]
        pad = ind + "  " * depth
        lines += [
            f'{pad}<body name="{prefix}_{name}" pos="0 0 {z:.4g}" gravcomp="1">',
            f'{pad}  <joint name="{prefix}_{name}" axis="1 0 0" range="{FLEXION[0]} {FLEXION[1]}"/>',
            f'{pad}  <geom name="{prefix}_{name}" type="mesh" mesh="seg_{name}"/>',
        ]
        z, depth = -length, depth + 1
    for d in range(depth - 1, -1, -1):
        lines.append(f"{ind + '  ' * d}</body>")
    return "\n".join(lines)


def scene_xml() -> str:
    """The complete MJCF text."""
    asset = "\n".join(f'    <mesh name="{k}" vertex="{_fmt(v)}"/>' for k, v in meshes().items())
    objects = "\n".join(
        f'    <body name="{m}" pos="{x} {y} {TABLE_TOP}" euler="0 0 {yaw}" childclass="obstacle">\n'
        f'      <geom name="{m}" type="mesh" mesh="{m}"/>\n    </body>'
        for m, (x, y), yaw in OBJECTS
    )
    ind = " " * 14
    fingers = "\n".join(_finger(f"f{i}", FINGER_X[i], ABDUCTION[i], 0.0, "seg_meta", ind) for i in range(4))
    thumb = _finger("th", -0.062, (0.0, 0.30), 0.35, "seg_thumb_meta", ind)
    joints = [("gx", 300), ("gy", 300), ("gz", 300), ("yaw", 20), ("pitch", 20)]
    joints += [
        (f"{p}_{s}", 1.0) for p in ("f0", "f1", "f2", "f3", "th") for s in ("abd", "prox", "mid", "dist")
    ]
    actuators = "\n".join(
        f'    <position name="{j}" joint="{j}" kp="{kp}" inheritrange="1"/>' for j, kp in joints
    )
    return f"""<mujoco model="hand30">
  <!-- A 5-finger mesh hand on a gantry over a table with six objects: 32 bodies, 28 mesh
       geoms and the table box, 25 position-controlled joints. Generated by make_scene.py
       (do not edit by hand); see README.md. Units: metres, radians, seconds. -->
  <compiler angle="radian"/>
  <option timestep="0.002" integrator="implicitfast"/>

  <default>
    <joint type="hinge" damping="0.05" armature="0.001" limited="true"/>
    <geom rgba="0.85 0.75 0.65 1" density="500" friction="0.8 0.005 0.0001"/>
    <default class="obstacle">
      <geom rgba="0.45 0.55 0.75 1"/>
    </default>
    <default class="gantry">
      <joint type="slide" damping="40" armature="0.1"/>
    </default>
  </default>

  <asset>
{asset}
  </asset>

  <worldbody>
    <light pos="0 0 2" dir="0 0 -1"/>
    <body name="table" pos="0 0 {TABLE_TOP - 0.02}" childclass="obstacle">
      <geom name="table" type="box" size="0.35 0.3 0.02" rgba="0.55 0.45 0.35 1"/>
    </body>
{objects}

    <!-- The gantry: three slides, then the forearm (yaw) and the palm (pitch). -->
    <body name="carriage_x" pos="0 0 {GANTRY_Z}" gravcomp="1">
      <inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/>
      <joint name="gx" class="gantry" axis="1 0 0" range="-0.15 0.15"/>
      <body name="carriage_y" gravcomp="1">
        <inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/>
        <joint name="gy" class="gantry" axis="0 1 0" range="-0.12 0.12"/>
        <body name="lift" gravcomp="1">
          <inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/>
          <joint name="gz" class="gantry" axis="0 0 1" range="0 0.08"/>
          <body name="forearm" gravcomp="1">
            <joint name="yaw" axis="0 0 1" range="-1.0 1.0" damping="2" armature="0.01"/>
            <geom name="forearm" type="mesh" mesh="forearm"/>
            <body name="palm" pos="0 0 -0.05" gravcomp="1">
              <joint name="pitch" axis="0 1 0" pos="0 0 0.05" range="-0.3 0.3" damping="2" armature="0.01"/>
              <geom name="palm" type="mesh" mesh="palm"/>
{fingers}
{thumb}
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>

  <actuator>
{actuators}
  </actuator>
</mujoco>
"""


def main() -> None:
    """Write ``scene.xml`` next to this script."""
    out = Path(__file__).resolve().parent / "scene.xml"
    out.write_text(scene_xml())
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
