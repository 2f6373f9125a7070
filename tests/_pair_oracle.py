"""Seeded random MJCF and an independent candidate-pair oracle from MuJoCo's documented rules (red team 14).

Written for the red team from MuJoCo's documentation ("Collision detection": same body, parent-child
weld bodies unless ``filterparent`` is disabled or one side is the world, ``<exclude>`` body pairs,
``(contype1 & conaffinity2) || (contype2 & conaffinity1)``, explicit ``<pair>`` bypassing all of it,
no plane-plane collider, bodies without dofs not collided with each other) and from the module
docstring of ``monitor.scene`` for the documented deviations (``"all"``). It shares no code with
``monitor``: the generator keeps its own record of the excluded body pairs and explicit pairs (by
name), and the oracle loops over geom pairs in plain Python.

A second, empirical oracle: the same MJCF with every ``geom_margin`` huge and ``mj_collision``
run once; MuJoCo then reports a contact for every geom pair that passes its filters.
"""

from __future__ import annotations

import re

import mujoco
import numpy as np
import redteam_oracle as O

KINDS = ("sphere", "capsule", "box", "cylinder", "ellipsoid", "mesh")


def _v(rng, n, lo, hi):
    return " ".join(f"{x:.4g}" for x in rng.uniform(lo, hi, n))


def random_model(seed: int, nbody: int | None = None, max_geoms: int = 4, *, margin: float | None = None,
                 shared: float = 0.3, p_exclude: float = 0.15, p_pair: float = 0.1):
    """(xml, info): a random tree; info = dict(excl=[(body, body)], pairs=[(geom, geom)], filterparent)."""
    rng = np.random.default_rng(seed)
    if nbody is None:
        nbody = int(rng.integers(1, 40))
    nmesh = 2
    assets = "".join(f'<mesh name="m{k}" vertex="{_v(rng, 36, -0.05, 0.05)}"/>' for k in range(nmesh))
    parent = [0] * (nbody + 1)
    kind_of = [""] * (nbody + 1)   # "weld", "hinge", "slide", "ball", "free", "mocap", "hinge+slide"
    for b in range(1, nbody + 1):
        parent[b] = 0 if b == 1 or rng.random() < 0.3 else int(rng.integers(0, b))
        opts = ["weld", "hinge", "slide", "ball", "hinge+slide", "hinge2"]
        if parent[b] == 0:
            opts += ["free", "mocap"]
        kind_of[b] = str(rng.choice(opts))
    static = [True] + [kind_of[b] == "weld" and False for b in range(1, nbody + 1)]
    for b in range(1, nbody + 1):
        static[b] = kind_of[b] == "weld" and static[parent[b]]
    geoms: list[list[str]] = [[] for _ in range(nbody + 1)]
    gnames: list[str] = []
    plane_names: list[str] = []
    gcount = 0
    same_mask = rng.random() < 0.3
    for b in range(0, nbody + 1):
        ng = int(rng.integers(0, max_geoms + 1)) if b else int(rng.integers(0, 4))
        for _ in range(ng):
            kind = str(rng.choice(KINDS))
            if b == 0 and rng.random() < 0.4:
                kind = "plane"
            if b and static[b] and rng.random() < 0.3:
                kind = "plane"     # a plane in a welded body
            named = rng.random() < 0.85
            name = f"g{gcount}"
            attrs = f'type="{kind}"'
            if named:
                attrs = f'name="{name}" ' + attrs
            if kind == "mesh":
                attrs += f' mesh="m{int(rng.integers(nmesh))}"'
            elif kind == "plane":
                attrs += ' size="1 1 0.1"'
            else:
                n = {"sphere": 1, "capsule": 2, "box": 3, "cylinder": 2, "ellipsoid": 3}[kind]
                attrs += f' size="{_v(rng, n, 0.02, 0.1)}"' if rng.random() > shared else \
                    f' size="{" ".join(["0.05"] * n)}"'
            if rng.random() < 0.7:
                attrs += f' pos="{_v(rng, 3, -0.2, 0.2)}"' if rng.random() > shared else ' pos="0.1 0 0"'
            if rng.random() < 0.5:
                attrs += f' quat="{_v(rng, 4, -1, 1)}"'
            if not same_mask and rng.random() < 0.6:
                attrs += f' contype="{int(rng.integers(0, 9))}" conaffinity="{int(rng.integers(0, 9))}"'
            if rng.random() < 0.2:
                attrs += f' group="{int(rng.integers(0, 6))}"'
            if margin is not None:   # the empirical oracle: spheres collide reliably (same rng draws)
                attrs += f' margin="{margin}"'
                if kind != "plane":
                    attrs = re.sub(r' (size|mesh)="[^"]*"', "", attrs)
                    attrs = attrs.replace(f'type="{kind}"', 'type="sphere"')
                    attrs += ' size="0.05"'
            geoms[b].append(f"<geom {attrs}/>")
            gnames.append(name if named else f"geom{gcount}")
            if kind == "plane":
                plane_names.append(gnames[-1])
            gcount += 1

    def body_xml(b: int) -> str:
        k = kind_of[b]
        attrs = f'name="b{b}" pos="{_v(rng, 3, -0.5, 0.5)}"'
        if k == "mocap":
            attrs += ' mocap="true"'
        if rng.random() < 0.3:
            attrs += f' quat="{_v(rng, 4, -1, 1)}"'
        inner = ""
        if k == "hinge":
            inner += f'<joint type="hinge" axis="{_v(rng, 3, -1, 1)}" pos="{_v(rng, 3, -0.1, 0.1)}"/>'
        elif k == "hinge2":
            inner += '<joint type="hinge" axis="1 0 0"/><joint type="hinge" axis="0 1 0"/>'
        elif k == "slide":
            inner += f'<joint type="slide" axis="{_v(rng, 3, -1, 1)}"/>'
        elif k == "ball":
            inner += '<joint type="ball"/>'
        elif k == "free":
            inner += '<freejoint/>'
        elif k == "hinge+slide":
            inner += '<joint type="hinge" axis="0 0 1"/><joint type="slide" axis="1 0 0"/>'
        inner += "".join(geoms[b])
        if k not in ("weld", "mocap") or rng.random() < 0.5 or not geoms[b]:
            inner += '<inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>'
        inner += "".join(body_xml(c) for c in range(b + 1, nbody + 1) if parent[c] == b)
        return f"<body {attrs}>{inner}</body>"

    world = "".join(geoms[0]) + "".join(body_xml(c) for c in range(1, nbody + 1) if parent[c] == 0)
    excl = set()
    for _ in range(int(rng.poisson(p_exclude * nbody))):
        a, b = rng.integers(0, nbody + 1, 2)
        if a != b:
            excl.add((f"b{min(a, b)}" if min(a, b) else "world", f"b{max(a, b)}"))
    pairs = set()
    named = [n for n in gnames if not n.startswith("geom")]
    for _ in range(int(rng.poisson(p_pair * len(named)))):
        a, b = rng.choice(len(named), 2) if len(named) >= 2 else (0, 0)
        if a != b and not (named[a] in plane_names and named[b] in plane_names):
            pairs.add((named[min(a, b)], named[max(a, b)]))
    contact = "".join(f'<exclude body1="{a}" body2="{b}"/>' for a, b in sorted(excl))
    pm = "" if margin is None else f' margin="{margin}"'   # an explicit pair has its own margin
    contact += "".join(f'<pair geom1="{a}" geom2="{b}"{pm}/>' for a, b in sorted(pairs))
    filterparent = rng.random() < 0.75
    flag = "" if filterparent else '<flag filterparent="disable"/>'
    xml = (f'<mujoco><size memory="200M"/><option>{flag}</option><asset>{assets}</asset>'
           f'<worldbody>{world}</worldbody>'
           + (f"<contact>{contact}</contact>" if contact else "") + "</mujoco>")
    return xml, dict(excl=excl, pairs=pairs, filterparent=filterparent, gnames=gnames)


def rotating_chain_xml(rng) -> str:
    """A random hinge / ball chain (no slide or free joint) among static obstacles (``rng``: a Generator)."""
    mesh = f'<mesh name="m0" vertex="{_v(rng, 30, -0.06, 0.06)}"/>'
    obst = []
    for k in range(int(rng.integers(1, 5))):
        kind = str(rng.choice(("box", "capsule", "sphere", "cylinder", "mesh")))
        size = {"box": _v(rng, 3, 0.03, 0.15), "capsule": _v(rng, 2, 0.02, 0.1),
                "sphere": _v(rng, 1, 0.03, 0.1), "cylinder": _v(rng, 2, 0.03, 0.1), "mesh": ""}[kind]
        sz = 'mesh="m0"' if kind == "mesh" else f'size="{size}"'
        obst.append(f'<geom name="o{k}" type="{kind}" {sz} pos="{_v(rng, 3, -0.45, 0.45)}" '
                    f'quat="{_v(rng, 4, -1, 1)}"/>')
    if rng.random() < 0.3:
        obst.append('<geom name="floor" type="plane" size="2 2 0.1" pos="0 0 -0.6"/>')

    def chain(depth: int, name: str) -> str:
        if depth <= 0:
            return ""
        j = ('<joint type="ball"/>' if rng.random() < 0.25 else
             f'<joint type="hinge" axis="{_v(rng, 3, -1, 1)}" pos="{_v(rng, 3, -0.05, 0.05)}"/>')
        kind = str(rng.choice(KINDS))
        size = {"box": _v(rng, 3, 0.02, 0.08), "capsule": _v(rng, 2, 0.02, 0.1),
                "sphere": _v(rng, 1, 0.02, 0.08), "cylinder": _v(rng, 2, 0.02, 0.08),
                "ellipsoid": _v(rng, 3, 0.02, 0.08), "mesh": ""}[kind]
        sz = 'mesh="m0"' if kind == "mesh" else f'size="{size}"'
        g = (f'<geom name="{name}g" type="{kind}" {sz} pos="{_v(rng, 3, -0.15, 0.15)}" '
             f'quat="{_v(rng, 4, -1, 1)}"/>')
        pos = _v(rng, 3, -0.25, 0.25)
        kids = chain(depth - 1, name + "a") + (chain(depth - 2, name + "b") if rng.random() < 0.3 else "")
        return f'<body name="{name}" pos="{pos}">{j}{g}{kids}</body>'

    arm = chain(int(rng.integers(1, 5)), "L")
    return (f'<mujoco><asset>{mesh}</asset><worldbody>{"".join(obst)}'
            f'<body name="base" pos="0 0 0">{arm}</body></worldbody></mujoco>')


def oracle_pairs(model, info, mode: str) -> set[tuple[int, int]]:
    """Candidate geom pairs (a < b) by the documented rules, geom pair by geom pair."""
    G = model.ngeom
    body_name = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or "world" for b in range(model.nbody)]
    gid = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g): g for g in range(G)}
    excl = {tuple(sorted(p)) for p in info["excl"]}
    explicit = {(min(gid[a], gid[b]), max(gid[a], gid[b])) for a, b in info["pairs"]}
    # weld body: the nearest ancestor-or-self with a joint or mocap (computed here, not read)
    has_joint = [False] * model.nbody
    for j in range(model.njnt):
        has_joint[int(model.jnt_bodyid[j])] = True
    par = [int(x) for x in model.body_parentid]
    mocap = [int(x) >= 0 for x in model.body_mocapid]
    weld = [0] * model.nbody
    for b in range(1, model.nbody):
        weld[b] = b if (has_joint[b] or mocap[b]) else weld[par[b]]
    dof = [0] * model.nbody
    for j in range(model.njnt):
        dof[int(model.jnt_bodyid[j])] += {0: 6, 1: 3, 2: 1, 3: 1}[int(model.jnt_type[j])]
    planeish = {int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_HFIELD)}
    out = set()
    for a in range(G):
        for b in range(a + 1, G):
            ta, tb = int(model.geom_type[a]), int(model.geom_type[b])
            if ta in planeish and tb in planeish:
                continue
            if mode == "mujoco" and (a, b) in explicit:
                out.add((a, b))
                continue
            ba, bb = int(model.geom_bodyid[a]), int(model.geom_bodyid[b])
            wa, wb = weld[ba], weld[bb]
            if wa == wb:
                continue
            if mode == "all":
                if wa == 0 and wb == 0:
                    continue
                if wa and wb and (wa == weld[par[wb]] or wb == weld[par[wa]]):
                    continue
                out.add((a, b))
                continue
            if dof[wa] == 0 and dof[wb] == 0:
                continue
            if info["filterparent"] and wa and wb and (wa == weld[par[wb]] or wb == weld[par[wa]]):
                continue
            if tuple(sorted((body_name[ba], body_name[bb]))) in excl:
                continue
            ca, fa = int(model.geom_contype[a]), int(model.geom_conaffinity[a])
            cb, fb = int(model.geom_contype[b]), int(model.geom_conaffinity[b])
            if not ((ca & fb) or (cb & fa)):
                continue
            out.add((a, b))
    return out


def anchor_dropped(m, pairs, depth: float = -1e-9) -> set:
    """The pairs of ``pairs`` that ``"all"`` drops by its documented rule: a world geom and a geom of a
    world child moved only by rotational joints sharing one anchor, the anchor inside both geoms (at
    least ``depth`` m inside the true geoms: the scene tests its circumscribed shapes)."""
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    weld = m.body_weldid
    out = set()
    for a, b in pairs:
        wa, wb = weld[m.geom_bodyid[a]], weld[m.geom_bodyid[b]]
        child = wb if wa == 0 else wa
        if (wa == 0) == (wb == 0) or weld[m.body_parentid[child]] != 0:
            continue
        jnts = np.flatnonzero(m.jnt_bodyid == child)
        rot = (int(mujoco.mjtJoint.mjJNT_BALL), int(mujoco.mjtJoint.mjJNT_HINGE))
        if not len(jnts) or not np.isin(m.jnt_type[jnts], rot).all():
            continue
        anchor = d.xanchor[jnts[0]]
        if not (d.xanchor[jnts] == anchor).all():
            continue
        pa = O.geom_pose(m, a, d.geom_xmat[a].reshape(3, 3), d.geom_xpos[a])
        pb = O.geom_pose(m, b, d.geom_xmat[b].reshape(3, 3), d.geom_xpos[b])
        if min(O.depth(pa, anchor), O.depth(pb, anchor)) >= depth:
            out.add((a, b))
    return out


def rotating_qpos(m, rng, K: int) -> np.ndarray:
    """(K, nq) waypoints from ``qpos0``: each hinge turned linearly by up to +-2 rad, each ball joint
    about a random axis by 1.5 rad (no slide or free coordinate changes)."""
    q = np.repeat(m.qpos0[None], K, axis=0)
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            q[:, a] += np.linspace(0.0, rng.uniform(-2.0, 2.0), K)
        elif m.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:
            axis = rng.normal(size=3)
            for k in range(K):
                q[k, a:a + 4] = O.axis_quat(axis, 1.5 * k / (K - 1))
    return q


def mujoco_contact_pairs(xml_with_margin: str) -> set[tuple[int, int]]:
    """Geom pairs mj_collision reports when every geom_margin is huge (MuJoCo's own filter)."""
    m = mujoco.MjModel.from_xml_string(xml_with_margin)
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    return {(min(int(c.geom1), int(c.geom2)), max(int(c.geom1), int(c.geom2))) for c in d.contact[:d.ncon]}
