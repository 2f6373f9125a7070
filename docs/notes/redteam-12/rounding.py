"""python rounding.py [small|huge]: offsets 0..1e7 m (default) or 3e7..9e8 m (rounding2 in the note)."""
import sys
import numpy as np, mujoco, monitor, math, itertools
HUGE = len(sys.argv) > 1 and sys.argv[1] == "huge"
OFFS = [3e7, 1e8, 5e8, 9e8] if HUGE else [0.0, 1e3, 1e4, 1e5, 1e6, 1e7]
RELS = [0.0, 1e-6, 1e-3] if HUGE else [0.0, 1e-9, 1e-6, 1e-3]
XML = """<mujoco><worldbody>
<body name="C" pos="{ox} {oy} {oz}" quat="0.9 0.1 0.3 0.2"><joint name="r0" type="{jt}" {ax}/>
  <geom name="s0" type="sphere" size="0.02" pos="0.1 0 0"/>
  <body name="a" pos="0.15 0.01 0"><joint name="ja" type="hinge" axis="0 0 1" pos="-0.15 -0.01 0"/>
    <geom name="s1" type="sphere" size="0.03" pos="0 0 0"/></body>
</body></worldbody></mujoco>"""
bad = 0; n = 0; cnt = {}
for off, jt, relang, K in itertools.product(OFFS, ["hinge", "ball", "free", "slide"], RELS, [2, 40]):
    ax = 'axis="0 1 3"' if jt in ("hinge", "slide") else ""
    m = mujoco.MjModel.from_xml_string(XML.format(ox=off, oy=-off/3, oz=off/7, jt=jt, ax=ax))
    times = np.linspace(0, 0.1, K); s = times / times[-1]
    q = np.tile(m.qpos0, (K, 1))
    if jt == "hinge": q[:, 0] = 3.0 * s
    elif jt == "slide": q[:, 0] = 0.9 * s
    else:
        a0 = 3 if jt == "free" else 0
        axv = np.array([0.3, -0.5, 0.8]); axv /= np.linalg.norm(axv)
        th = 3.0 * s
        q[:, a0:a0 + 4] = np.stack([np.cos(th/2), *(np.sin(th/2)[None]*axv[:, None])], 1)
        if jt == "free": q[:, :3] = np.array([off, -off/3, off/7]) + np.outer(s, [0.3, 0.2, 0.1])
    ja = m.jnt_qposadr[1]
    q[:, ja] = relang * s
    # exact distance in C's frame: s0 centre (0.1,0,0); s1 centre rotates about hinge anchor (0,0,0) in C frame... a at (0.15,0.01,0), anchor at a's origin + (-0.15,-0.01,0) = C origin
    def d_at(th):
        c1 = np.array([0.15*math.cos(th) - 0.01*math.sin(th), 0.15*math.sin(th) + 0.01*math.cos(th), 0.0])
        return float(np.linalg.norm(c1 - np.array([0.1, 0, 0]))) - 0.05
    ths = np.linspace(0, relang, 2001)
    dtrue = min(d_at(t) for t in ths)
    scene = monitor.Scene.from_model(m, pairs=[("s0", "s1")]); plan = monitor.Plan(times, q, m)
    for dm in [1e-3, 1e-5, 1e-7, 1e-9, 1e-11, -1e-11, -1e-9]:
        mg = dtrue - dm
        if mg < 0: continue
        c = monitor.certify(scene, plan, margin=mg, epsilon=1e-9, method="toleranced", budget={"seconds": 30})
        n += 1; cnt[str(c.verdict)] = cnt.get(str(c.verdict), 0) + 1
        p = c.pairs[0]
        if (c.verdict == "certified" and (mg >= dtrue or c.clearance > dtrue + 1e-15)) or (c.verdict == "violation" and dm > 1e-9):
            bad += 1; print("BAD", off, jt, relang, K, dm, c.verdict, c.clearance, dtrue, p.method)
print(n, cnt, "bad", bad)
