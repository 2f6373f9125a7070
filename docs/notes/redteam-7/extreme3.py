import mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
from monitor import Plan, Scene, certify, BodyMotion
from monitor.errors import MonitorError
XML = """
<mujoco>
  <worldbody>
    <geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.1 0 0"/>
    <body name="arm"><joint name="h" type="hinge" axis="0 0 1"/>
      <geom name="tip" type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/></body>
  </worldbody>
</mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
for dt in (1e-300, 1e-308, 5e-324):
    p = Plan([0, dt], [[-2.0], [-1.0]], m)   # arm at -2 rad..-1 rad? check distance at ends
    for meth in ("auto", "toleranced"):
        c = certify(sc, p, margin=0.0, method=meth)
        print("hinge clear", dt, meth, c.verdict, c.clearance)
    p = Plan([0, dt], [[-1.0], [1.0]], m)   # sweeps through the wall at angle 0
    for meth in ("auto", "toleranced"):
        c = certify(sc, p, margin=0.0, method=meth)
        print("hinge through", dt, meth, c.verdict, c.clearance)
# BodyMotion
pos = np.zeros((2, 3, 3)); quat = np.zeros((2, 3, 4)); quat[..., 0] = 1
XML2 = """<mujoco><worldbody><geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
<body name="ball"><freejoint/><geom name="ball" type="sphere" size="0.02"/></body></worldbody></mujoco>"""
m2 = mujoco.MjModel.from_xml_string(XML2)
sc2 = Scene.from_model(m2, pairs="all", allowed=None)
for dt in (1e-300, 1e-308, 5e-324):
    pos = np.zeros((2, 2, 3)); pos[0, 1, 0] = -1; pos[1, 1, 0] = 1
    quat = np.zeros((2, 2, 4)); quat[..., 0] = 1
    try:
        bm = BodyMotion([0, dt], pos, quat)
        for meth in ("auto", "toleranced", "extrusion"):
            c = certify(sc2, bm, margin=0.0, method=meth)
            print("bodymotion through", dt, meth, c.verdict, c.clearance)
    except MonitorError as e:
        print("bm typed", e)
