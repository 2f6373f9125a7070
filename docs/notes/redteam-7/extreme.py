import mujoco, numpy as np
from monitor import Plan, Scene, certify, BodyMotion
from monitor.errors import MonitorError
XML = """
<mujoco>
  <worldbody>
    <geom name="wall" type="box" size="0.01 0.2 0.2" pos="0.3 0 0"/>
    <body name="ball"><joint name="x" type="slide" axis="1 0 0"/><joint name="y" type="hinge" axis="0 0 1"/>
      <geom name="ball" type="capsule" size="0.02 0.05" pos="0.05 0 0"/></body>
  </worldbody>
</mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
cases = []
for a in (1e10, 1e100, 1e150, 1e200, 1e300, 1.7e308):
    cases.append(("slide through", [0, 1], [[-a, 0], [a, 0]]))
    cases.append(("slide far", [0, 1], [[-a, 0], [-a * 0.5, 0]]))
    cases.append(("hinge spin", [0, 1], [[0.0, 0], [0.0, a]]))
    cases.append(("times", [0, a], [[-1.0, 0], [1.0, 0]]))
    cases.append(("times tiny", [0, 1 / a], [[-1.0, 0], [1.0, 0]]))
    cases.append(("times offset", [a, a * (1 + 1e-15)], [[-1.0, 0], [1.0, 0]]))
cases.append(("denormal", [0, 1], [[5e-324, 0], [1e-323, 5e-324]]))
cases.append(("denormal times", [0, 5e-324], [[-1.0, 0], [1.0, 0]]))
for name, t, q in cases:
    try:
        p = Plan(t, q, m)
        for meth in ("auto", "toleranced", "extrusion"):
            c = certify(sc, p, margin=0.0, method=meth, budget={"seconds": 5.0})
            flag = "  <-- CERTIFIED (passes the wall?)" if c.verdict == "certified" and name in ("slide through", "hinge spin", "times", "times tiny", "times offset") else ""
            print(f"{name:15s} {t[-1]:.3g} {q[-1]} {meth:10s} {c.verdict} {c.clearance:.3g}{flag}")
    except MonitorError as e:
        print(f"{name:15s} {t[-1]:.3g} typed {type(e).__name__}: {str(e)[:100]}")
    except Exception as e:
        print(f"{name:15s} {t[-1]:.3g} UNTYPED {type(e).__name__}: {str(e)[:100]}")
