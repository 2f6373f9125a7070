import numpy as np, warnings
warnings.simplefilter("ignore")
from monitor.certify import extrusion
from monitor.geometry.shapes import ConvexShape
from monitor.scene import Scene
import mujoco
XML = """<mujoco><worldbody><geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
<body name="ball"><freejoint/><geom name="ball" type="sphere" size="0.02"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
wall, ball = sc.geom("wall").shape, sc.geom("ball").shape
print([f.name for f in __import__("dataclasses").fields(extrusion.TranslatingPair)])
for dt in (1e-300, 1e-308, 5e-324):
    p = extrusion.TranslatingPair(name=("wall","ball"), shape_a=wall, R_a=np.eye(3), times_a=[0, dt], origins_a=[[0,0,0],[0,0,0]],
                                  shape_b=ball, R_b=np.eye(3), times_b=[0, dt], origins_b=[[-1,0,0],[1,0,0]])
    out = extrusion.check_pairs([p], (0, dt), 0.0)
    print(dt, out[0].verdict)
