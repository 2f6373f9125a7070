import numpy as np, mujoco, sys
from monitor import Plan, Scene, certify
from monitor.certify import engine
from monitor.errors import InvalidInputError
XML = """
<mujoco><worldbody>
<geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.02"/></body>
</worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
scene = Scene.from_model(m, pairs="all", allowed=None)
for dt, a in [(1e-308, 1.0), (5e-324, 1.0), (1e-300, 5e9), (1.0, 9e307), (20.0, 9e307)]:
    for lazy in (True, False):
        engine._LAZY_SEGMENTS = lazy
        for meth in ("auto", "extrusion"):
            with np.errstate(all="ignore"):
                try:
                    c = certify(scene, Plan([0.0, dt], [[-a], [a]], m), margin=0.0, method=meth)
                    r = (c.verdict, c.method if hasattr(c,'method') else '')
                except InvalidInputError as e:
                    r = ("InvalidInput", str(e)[:60])
            print(dt, a, "lazy" if lazy else "general", meth, r)
