"""The paper's example scenes for the extrusion checker, as data (no MuJoCo).

* :func:`sphere_cube_pair` -- §4.1: a sphere of radius 4 centred at (5, 5, 5)
  moving with (1, 1, 1) and a cube of side 4 centred at (44, 54, 5) moving with
  (0, 0, 1), t in [0, 64]. True answer: a near miss, min distance
  3 sqrt(2) - 4 ~ 0.243 at t = 44 (derivation in the test).
* The AGV and trays scene of §5 (Figures 3-4), our own geometry with the
  paper's primitive counts: a vehicle of 19 boxes carrying a palletted load and
  moving along +x, and a line of 3 hanging trays (10 boxes, two trays loaded)
  moving along +y under an overhead rail, plus a floor plane 5 mm below the
  wheels. The single source of truth for ``models/agv_trays/scene.xml`` and
  ``scene_skewed.xml`` (written by :func:`agv_scene_xml`; a test checks that
  the committed files match) and for the hand-built
  :class:`~monitor.certify.extrusion.TranslatingBody` lists used before the
  engine exists. Geometry and schedules are stated in
  ``models/agv_trays/README.md``.

Schedules (qpos = [agv_x, tray_y, tray_z], window [0, 20] s):

* ``"straight"``: agv_x = -7.25 + 0.75 t, tray_y = -5 + 0.5 t, tray_z = 0 (trays
  high). The bottom of tray plate 1 (z = 1.20) clears the cab roof (1.15) but
  not the top crate of the vehicle's load (1.27): first contact at t = 29/3 s.
* ``"weaving"``: trays lowered by 0.6 m (plate bottoms at z = 0.60); the vehicle
  drives from agv_x = -7.7 to -0.2 in [0, 6], stops until 12.5 with its low
  centre section (side rails, top z = 0.59) under the tray path while plate 1
  passes over it, then drives on to 7.3 at t = 20. Narrow miss: 1 cm between
  plate 1 and the side rails, 5 cm / 10 cm in x to the cab and the crate.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from monitor.certify.common import Outcome
from monitor.certify.extrusion import TranslatingBody, TranslatingPair
from monitor.geometry.polytope import box_polytope, halfspace_shape, sphere_shape

# (name, centre (3,), half extents (3,)) in the vehicle frame: origin on the floor under its centre
AGV_BOXES: tuple[tuple[str, tuple[float, float, float], tuple[float, float, float]], ...] = (
    ("chassis", (0.0, 0.0, 0.35), (1.2, 0.5, 0.1)),
    ("wheel_fl", (0.85, 0.55, 0.15), (0.15, 0.05, 0.15)),
    ("wheel_fr", (0.85, -0.55, 0.15), (0.15, 0.05, 0.15)),
    ("wheel_rl", (-0.85, 0.55, 0.15), (0.15, 0.05, 0.15)),
    ("wheel_rr", (-0.85, -0.55, 0.15), (0.15, 0.05, 0.15)),
    ("bumper_f", (1.25, 0.0, 0.3), (0.05, 0.45, 0.06)),
    ("bumper_r", (-1.25, 0.0, 0.3), (0.05, 0.45, 0.06)),
    ("cab", (0.95, 0.0, 0.75), (0.25, 0.45, 0.3)),
    ("cab_roof", (0.95, 0.0, 1.1), (0.25, 0.45, 0.05)),
    ("cab_light", (1.22, 0.0, 0.95), (0.02, 0.1, 0.05)),
    ("rail_l", (0.2, 0.47, 0.52), (0.5, 0.03, 0.07)),
    ("rail_r", (0.2, -0.47, 0.52), (0.5, 0.03, 0.07)),
    ("deck", (-0.75, 0.0, 0.5), (0.45, 0.45, 0.05)),
    ("pallet_foot_l", (-0.75, 0.4, 0.59), (0.4, 0.05, 0.04)),
    ("pallet_foot_c", (-0.75, 0.0, 0.59), (0.4, 0.05, 0.04)),
    ("pallet_foot_r", (-0.75, -0.4, 0.59), (0.4, 0.05, 0.04)),
    ("pallet_top", (-0.75, 0.0, 0.65), (0.4, 0.45, 0.02)),
    ("crate", (-0.75, 0.0, 0.87), (0.4, 0.4, 0.2)),
    ("crate_top", (-0.75, 0.0, 1.17), (0.3, 0.3, 0.1)),
)

# tray line frame: plates at y = 0, -4, -8; trays hang from a carriage on the overhead rail
TRAY_BOXES: tuple[tuple[str, tuple[float, float, float], tuple[float, float, float]], ...] = (
    ("plate1", (0.0, 0.0, 1.22), (0.45, 0.3, 0.02)),
    ("plate2", (0.0, -4.0, 1.22), (0.45, 0.3, 0.02)),
    ("plate3", (0.0, -8.0, 1.22), (0.45, 0.3, 0.02)),
    ("hanger1", (0.3, 0.0, 1.74), (0.02, 0.02, 0.5)),
    ("hanger2", (0.3, -4.0, 1.74), (0.02, 0.02, 0.5)),
    ("hanger3", (0.3, -8.0, 1.74), (0.02, 0.02, 0.5)),
    ("load1", (-0.1, 0.0, 1.39), (0.2, 0.2, 0.15)),
    ("load3", (-0.1, -8.0, 1.39), (0.2, 0.2, 0.15)),
    ("carriage", (0.3, -4.0, 2.27), (0.05, 4.4, 0.03)),
    ("tag2", (0.47, -4.0, 1.22), (0.02, 0.1, 0.02)),
)

FLOOR_Z = -0.005
"""Height (m) of the floor plane: 5 mm below the wheels. (An exactly touching floor is
certified by the extrusion checker, regularised semantics, but the engine's start-pose
rule cannot prove a touching pair clear; see docs/notes/issue-4.md.)"""

WINDOW = (0.0, 20.0)
"""Time window (s) of both schedules."""

SKEW_EULER_DEG = (20.0, 30.0, 40.0)
"""Intrinsic-free 'xyz' Euler angles (deg) of the skewed copy: every axis is rotated."""

STRAIGHT_FIRST_CONTACT = 29.0 / 3.0
"""Analytic first contact (s) of crate_top and plate1 in the straight schedule: the
crate's front face (x = agv_x - 0.45) meets the plate's back face (x = -0.45) when
0.75 t = 7.25, while their y ranges already overlap (see README)."""


def skew_rotation() -> np.ndarray:
    """(3, 3) rotation R_WF of the skewed copy's frame."""
    return Rotation.from_euler("xyz", SKEW_EULER_DEG, degrees=True).as_matrix()


def schedule(name: str) -> dict[str, Any]:
    """Joint waypoints of a schedule.

    Args:
        name: ``"straight"`` or ``"weaving"``.

    Returns:
        ``{"times": (K,) s, "qpos": (K, 3) [agv_x, tray_y, tray_z] m, "window": (t0, t1)}``.
    """
    if name == "straight":
        times = np.array([0.0, 20.0])
        agv = -7.25 + 0.75 * times
        tray_z = np.zeros(2)
    elif name == "weaving":
        times = np.array([0.0, 6.0, 12.5, 20.0])
        agv = np.array([-7.7, -0.2, -0.2, 7.3])
        tray_z = np.full(4, -0.6)
    else:
        raise ValueError(f"unknown schedule {name!r} (straight | weaving)")
    tray_y = -5.0 + 0.5 * times
    return {"times": times, "qpos": np.stack([agv, tray_y, tray_z], axis=1), "window": WINDOW}


def _fmt(v) -> str:
    return " ".join(repr(float(x)) for x in v)  # shortest round-trip form


def agv_scene_xml(skewed: bool = False) -> str:
    """MJCF text of the AGV and trays scene (straight and weaving share it; tray_z lowers the trays).

    Args:
        skewed: wrap everything in a ``<frame>`` rotated by :func:`skew_rotation`.
    """
    agv = "\n".join(f'      <geom name="{n}" type="box" pos="{_fmt(c)}" size="{_fmt(h)}"/>'
                    for n, c, h in AGV_BOXES)
    trays = "\n".join(f'      <geom name="{n}" type="box" pos="{_fmt(c)}" size="{_fmt(h)}"/>'
                      for n, c, h in TRAY_BOXES)
    body = f"""    <geom name="floor" type="plane" pos="0 0 {FLOOR_Z!r}" size="0 0 1"/>
    <body name="agv">
      <joint name="agv_x" type="slide" axis="1 0 0"/>
{agv}
    </body>
    <body name="trays">
      <joint name="tray_y" type="slide" axis="0 1 0"/>
      <joint name="tray_z" type="slide" axis="0 0 1"/>
{trays}
    </body>"""
    if skewed:
        q = Rotation.from_matrix(skew_rotation()).as_quat(scalar_first=True)
        body = f'    <frame quat="{_fmt(q)}">\n' + "\n".join("  " + ln for ln in body.splitlines()) \
            + "\n    </frame>"
    title = "agv_trays_skewed" if skewed else "agv_trays"
    return f"""<!-- Generated by monitor.bench.extrusion_scenes.agv_scene_xml({skewed}); see README.md. -->
<mujoco model="{title}">
  <option timestep="0.01" gravity="0 0 0"/>
  <worldbody>
{body}
  </worldbody>
</mujoco>
"""


def _boxes(table) -> tuple[tuple, ...]:
    return tuple(box_polytope(np.array(h, float)).transformed(np.eye(3), np.array(c, float))
                 for _, c, h in table)


def agv_translating_bodies(name: str, skewed: bool = False, floor: bool = True) -> list[TranslatingBody]:
    """Hand-built translating bodies of the AGV scene (the engine's view of the MJCF).

    Args:
        name: schedule, ``"straight"`` or ``"weaving"``.
        skewed: rotate every axis by :func:`skew_rotation` (the ``scene_skewed.xml`` copy).
        floor: include the static floor half-space (5 mm below the wheels).

    Returns:
        ``[agv, trays]`` (+ ``floor``) bodies with world-frame origins at the breakpoints.
    """
    sch = schedule(name)
    R = skew_rotation() if skewed else np.eye(3)
    t = sch["times"]
    q = sch["qpos"]
    o_agv = np.stack([q[:, 0], np.zeros(len(t)), np.zeros(len(t))], axis=1) @ R.T
    o_tray = np.stack([np.zeros(len(t)), q[:, 1], q[:, 2]], axis=1) @ R.T
    out = [TranslatingBody("agv", _boxes(AGV_BOXES), tuple(n for n, _, _ in AGV_BOXES), R, t, o_agv),
           TranslatingBody("trays", _boxes(TRAY_BOXES), tuple(n for n, _, _ in TRAY_BOXES), R, t, o_tray)]
    if floor:
        plane = halfspace_shape().transformed(np.eye(3), np.array([0.0, 0.0, FLOOR_Z]))
        out.append(TranslatingBody("world", (plane,), ("floor",), R, np.array(WINDOW), np.zeros((2, 3))))
    return out


def sphere_cube_pair(sphere_as_polytope: int = 0) -> TranslatingPair:
    """The §4.1 example as a pair (t in [0, 64]).

    Args:
        sphere_as_polytope: 0 = exact sphere; n > 0 = a circumscribed polytope with
            about n directions (reported in the shape's ``approx_error``).
    """
    if sphere_as_polytope:
        from monitor.geometry.polytope import ellipsoid_polytope

        sph = ellipsoid_polytope(np.array([4.0, 4.0, 4.0]), facets=int(sphere_as_polytope))
    else:
        sph = sphere_shape(4.0)
    cube = box_polytope(np.array([2.0, 2.0, 2.0]))
    times = np.array([0.0, 64.0])
    return TranslatingPair(sph, np.eye(3), times, np.array([[5.0, 5, 5], [69, 69, 69]]),
                           cube, np.eye(3), times, np.array([[44.0, 54, 5], [44, 54, 69]]),
                           ("sphere", "cube"))


__all__ = ["AGV_BOXES", "TRAY_BOXES", "WINDOW", "FLOOR_Z", "SKEW_EULER_DEG", "STRAIGHT_FIRST_CONTACT",
           "skew_rotation", "schedule", "agv_scene_xml", "agv_translating_bodies", "sphere_cube_pair"]


def report(benchmark: bool = True) -> dict[str, Any]:
    """Figures of the paper examples for the notes (``python -m monitor.bench.extrusion_scenes``).

    Args:
        benchmark: also time the pairwise loop against the n-ary search on the AGV scenes.

    Returns:
        JSON-serialisable dict: sphere-cube clearance and S-bound region, AGV verdicts,
        first-contact times, S-bound statistics, and pairwise-vs-n-ary timings.
    """
    import time

    from monitor.certify.extrusion import check_pairs, compare_pairwise_nary, earliest_violation, search_many

    out: dict[str, Any] = {}
    sc = check_pairs([sphere_cube_pair()], (0.0, 64.0))[0]
    span = sc.info["stats"]["spans"][0]
    out["sphere_cube"] = {"verdict": sc.verdict, "clearance": sc.clearance,
                          "analytic": 3 * 2**0.5 - 4, "time_bounds": span["time_bounds"][0],
                          "sbound_region": span["sbound_regions"][0],
                          "frame_velocity": span["frame_velocity"]}
    for facets in (6, 16):
        o = check_pairs([sphere_cube_pair(facets)], (0.0, 64.0))[0]
        out[f"sphere_cube_polytope_{facets}"] = {
            "verdict": o.verdict, "clearance": o.clearance,
            "approx_error": float(sphere_cube_pair(facets).shape_a.approx_error)}
    for name in ("straight", "weaving"):
        for skewed in (False, True):
            for floor in (False, True):
                t0 = time.perf_counter()
                res = search_many(agv_translating_bodies(name, skewed, floor), None, WINDOW)
                dt = time.perf_counter() - t0
                e = earliest_violation(res.outcomes)
                verdicts: dict[str, int] = {}
                for o in res.outcomes:
                    verdicts[o.verdict] = verdicts.get(o.verdict, 0) + 1
                out[f"agv_{name}{'_skewed' if skewed else ''}{'_floor' if floor else ''}"] = {
                    "seconds": dt, "verdicts": verdicts,
                    "earliest": None if e is None else [e.info["geoms"], e.info["earliest_time"],
                                                        e.witness_time],
                    "min_clearance": min((o.clearance for o in res.outcomes
                                          if o.verdict == Outcome.CERTIFIED), default=None),
                    "lps": res.stats["lps"], "regions": res.stats["regions"],
                    "spans": [{k: v for k, v in s.items() if k != "sbound_regions"}
                              for s in res.stats["spans"]]}
            if benchmark:
                out[f"bench_{name}{'_skewed' if skewed else ''}"] = compare_pairwise_nary(
                    agv_translating_bodies(name, skewed), None, WINDOW)
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(report(), indent=1, default=float))
