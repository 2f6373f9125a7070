import numpy as np, mujoco
from monitor import Plan, Scene, certify
from monitor.certify import engine
XML = """<mujoco><worldbody>
<geom name="post" type="sphere" size="0.125" pos="0 0.5 0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.125"/></body>
<body name="cube" pos="0 -2 0"><joint name="cx" type="slide" axis="2 0 0"/><geom name="cube" type="box" size="0.25 0.25 0.25"/></body>
</worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
scene = Scene.from_model(m, pairs=[("post","ball")], allowed=None) if False else Scene.from_model(m, pairs="all", allowed=None)
for q, marg in [([[-1, 0], [1, 0]], 0.25), ([[-1, 0], [1, 0]], np.nextafter(0.25, 1)), ([[-1,0],[0,0]], 0.25), ([[0,0],[1,0]], np.nextafter(0.25, 1)), ([[-1,0],[0,0]], np.nextafter(0.25, 1))]:
    for lazy in (True, False):
        for comp in (True, False):
            engine._LAZY_SEGMENTS, engine._CONFIRM_COMPILED = lazy, comp
            c = certify(scene, Plan([0.0, 1.0], q, m), margin=marg, pairs=[("post", "ball")])
            print(q, marg, lazy, comp, c.verdict, c.witness and (c.witness.time, c.witness.distance), c.clearance, [str(p.method) for p in c.pairs])
