import mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
from monitor import Plan, Scene, certify
XML = """<mujoco><worldbody><geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
<body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.02"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
p = Plan([0, 1], [[-1.0], [1.0]], m)   # at t = 0.65 the ball is at x = 0.3 (inside the wall)
for w in ((0.65, 0.65 + 5e-324), (0.65, np.nextafter(0.65, 1)), (0.649, 0.651), (0.0, 5e-324), (1 - 1e-16, 1.0)):
    for meth in ("auto", "toleranced", "extrusion"):
        try:
            c = certify(sc, p, margin=0.0, method=meth, window=w)
            print(w, meth, c.verdict, c.clearance)
        except Exception as e:
            print(w, meth, "ERR", type(e).__name__, str(e)[:80])
