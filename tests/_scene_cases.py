"""Seeded random MJCF for the pair filter and per-geom packing tests (``tests/test_scene.py``,
``tests/test_packed.py``, ``docs/notes/issue-12-scenepack/``).

:func:`random_mjcf` draws a body tree with every case the candidate filter and the packing
distinguish: free / hinge / slide / ball joints, bodies welded to their parent (no joint, in
world groups and in moving ones, so weld groups are not contiguous in geom order), mocap
bodies, static world geoms and planes, planes in welded world children, meshes (random
convex point clouds), every primitive type at random geom frames (and at the body frame,
where MuJoCo's ``geom_sameframe`` takes over), repeated identical geoms, random
contype/conaffinity, ``<exclude>`` body pairs, explicit ``<pair>`` geoms (planes among them)
and ``filterparent`` on or off.
"""

from __future__ import annotations

import numpy as np

PRIMITIVES = ("sphere", "capsule", "box", "cylinder", "ellipsoid", "mesh")


def _vec(rng: np.random.Generator, n: int, lo: float, hi: float) -> str:
    return " ".join(f"{x:.4g}" for x in rng.uniform(lo, hi, n))


def _geom(rng: np.random.Generator, name: str, kind: str, nmesh: int, *, at_origin: bool) -> str:
    size = {"sphere": _vec(rng, 1, 0.02, 0.1), "capsule": _vec(rng, 2, 0.02, 0.1),
            "box": _vec(rng, 3, 0.02, 0.1), "cylinder": _vec(rng, 2, 0.02, 0.1),
            "ellipsoid": _vec(rng, 3, 0.02, 0.1)}
    if rng.random() < 0.3:  # a repeated geom (shared shapes in the packing)
        size = {"sphere": "0.05", "capsule": "0.03 0.06", "box": "0.04 0.05 0.06", "cylinder": "0.05 0.03",
                "ellipsoid": "0.03 0.04 0.05"}
    attrs = f'name="{name}" type="{kind}"'
    if kind == "mesh":
        attrs += f' mesh="m{int(rng.integers(nmesh))}"'
    else:
        attrs += f' size="{size[kind]}"'
    if not at_origin:
        attrs += f' pos="{_vec(rng, 3, -0.1, 0.1)}"'
        if rng.random() < 0.6:
            attrs += f' quat="{_vec(rng, 4, -1, 1)}"'
    if rng.random() < 0.4:
        attrs += f' contype="{int(rng.integers(0, 4))}" conaffinity="{int(rng.integers(0, 4))}"'
    return f"<geom {attrs}/>"


def random_mjcf(seed: int, nbody: int = 24) -> str:
    """A random valid MJCF string (see the module docstring); same seed, same string."""
    rng = np.random.default_rng(seed)
    nmesh = 3
    assets = "".join(
        f'<mesh name="m{k}" vertex="{" ".join(f"{x:.4g}" for x in rng.normal(0, 0.05, (12, 3)).ravel())}"/>'
        for k in range(nmesh))
    children: list[list[str]] = [[] for _ in range(nbody + 1)]   # index 0: the world
    parent = [0] * (nbody + 1)
    body_geoms: list[list[str]] = [[] for _ in range(nbody + 1)]
    head: list[str] = [""] * (nbody + 1)
    moving = [False] * (nbody + 1)
    gid = 0
    for k in range(3):   # static world geoms, one plane (two when filterparent is off: a plane pair)
        kind = "plane" if k == 0 else str(rng.choice(PRIMITIVES))
        size = ' size="5 5 0.1"' if kind == "plane" else ""
        g = _geom(rng, f"w{gid}", kind, nmesh, at_origin=False) if kind != "plane" else \
            f'<geom name="w{gid}" type="plane"{size} pos="0 0 -1"/>'
        body_geoms[0].append(g)
        gid += 1
    for b in range(1, nbody + 1):
        p = int(rng.integers(0, b)) if rng.random() < 0.6 else 0
        parent[b] = p
        children[p].append(b)
        r = rng.random()
        if p == 0 and r < 0.3:
            joint = "<freejoint/>"
        elif p == 0 and r < 0.4:
            joint = "mocap"
        elif r < 0.55:
            joint = f'<joint type="hinge" axis="{_vec(rng, 3, -1, 1)}" pos="{_vec(rng, 3, -0.05, 0.05)}"/>'
        elif r < 0.65:
            joint = '<joint type="slide" axis="1 0 0"/>'
        elif r < 0.75:
            joint = '<joint type="ball"/>'
        else:
            joint = ""   # welded to its parent
        moving[b] = (joint != "" and joint != "mocap") or moving[p]
        mocap = ' mocap="true"' if joint == "mocap" else ""
        head[b] = (f'<body name="b{b}" pos="{_vec(rng, 3, -1, 1)}"{mocap}>'
                   + ("" if joint in ("", "mocap") else joint))
        for _ in range(int(rng.integers(0, 4))):
            if not moving[b] and rng.random() < 0.15:
                body_geoms[b].append(f'<geom name="g{gid}" type="plane" size="1 1 0.1"/>')
            else:
                body_geoms[b].append(_geom(rng, f"g{gid}", str(rng.choice(PRIMITIVES)), nmesh,
                                           at_origin=rng.random() < 0.25))
            gid += 1

    def emit(b: int) -> str:
        inner = "".join(body_geoms[b]) + "".join(emit(c) for c in children[b])
        if b and not body_geoms[b]:
            inner = '<inertial pos="0 0 0" mass="0.1" diaginertia="1e-3 1e-3 1e-3"/>' + inner
        return inner if b == 0 else head[b] + inner + "</body>"

    names = [f"w{k}" for k in range(3)] + [f"g{k}" for k in range(3, gid)]
    contact = []
    for _ in range(int(rng.integers(0, 8))):
        a, c = rng.choice(nbody + 1, 2, replace=False)
        if a != c:
            contact.append(f'<exclude body1="{"world" if a == 0 else f"b{a}"}" '
                           f'body2="{"world" if c == 0 else f"b{c}"}"/>')
    for _ in range(int(rng.integers(0, 6))):
        a, c = rng.choice(len(names), 2, replace=False)
        contact.append(f'<pair geom1="{names[a]}" geom2="{names[c]}"/>')
    option = '<option><flag filterparent="disable"/></option>' if rng.random() < 0.3 else ""
    return (f"<mujoco>{option}<asset>{assets}</asset><worldbody>{emit(0)}</worldbody>"
            f"<contact>{''.join(contact)}</contact></mujoco>")
