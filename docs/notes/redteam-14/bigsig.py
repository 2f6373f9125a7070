"""Red team 14: exclusion signatures near MuJoCo's body limit (scene._SIGNATURE_BODIES).

Usage: PYTHONPATH=<tree> python bigsig.py N

N bodies besides the world, free spheres on bodies 1-3, N-1 and N, <exclude> (world, b[N-1]) and
(b1, bN). MuJoCo 4.0.0 refuses N + 1 >= 65534 bodies ("number of bodies plus flexes must be less
than 65534"), so the > 65 536-body signature path cannot be reached; N = 65532 takes ~5 minutes
to compile and mj_collision then asks for ~8.6 GB (use N of a few thousand to compare pairs).
"""
import sys
import time

import mujoco

import monitor


def main() -> None:
    """Build the model of the given size; print its signatures and the pairs of both sides."""
    n = int(sys.argv[1])
    free = {1, 2, 3, n - 1, n}
    parts = [f'<body name="b{b}"><freejoint/><geom name="s{b}" type="sphere" size="0.1" margin="100"/></body>'
             if b in free else f'<body name="b{b}"/>' for b in range(1, n + 1)]
    excl = f'<exclude body1="world" body2="b{n - 1}"/><exclude body1="b1" body2="b{n}"/>'
    world = '<geom name="w" type="box" size="0.1 0.1 0.1" margin="100"/>' + "".join(parts)
    xml = f'<mujoco><size memory="500M"/><worldbody>{world}</worldbody><contact>{excl}</contact></mujoco>'
    t = time.time()
    m = mujoco.MjModel.from_xml_string(xml)
    print("compile", time.time() - t, "nbody", m.nbody)
    print("signatures", [(int(s) >> 16, int(s) & 0xFFFF) for s in m.exclude_signature])
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    mj = {(min(int(c.geom1), int(c.geom2)), max(int(c.geom1), int(c.geom2))) for c in d.contact[:d.ncon]}
    got = set(map(tuple, monitor.Scene.from_model(m).pair_ids.tolist()))
    names = [m.geom(g).name for g in range(m.ngeom)]
    print("missing from the scene:", sorted((names[a], names[b]) for a, b in mj - got),
          "extra:", sorted((names[a], names[b]) for a, b in got - mj))


if __name__ == "__main__":
    main()
