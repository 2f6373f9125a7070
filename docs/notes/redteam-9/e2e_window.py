import numpy as np, mujoco
from monitor import Plan, Scene, certify
from monitor.certify import engine
from monitor.errors import InvalidInputError
XML = open(__file__.rsplit('/', 1)[0] + '/overflow.py').read().split('XML = """')[1].split('"""')[0]
m = mujoco.MjModel.from_xml_string(XML)
scene = Scene.from_model(m, pairs="all", allowed=None)
for q, win in [([0.0, 2.0, 0.1], (0.5, 1.0)), ([0.0, 2.0, 0.6], (0.5, 1.0)), ([0.0, 2.0, 0.1], (1e-308, 1.0))]:
    plan = Plan([0.0, 1e-308, 1.0], [[x] for x in q], m)
    for lazy in (True, False):
        engine._LAZY_SEGMENTS = lazy
        for meth in ("auto", "extrusion"):
            with np.errstate(all="ignore"):
                try:
                    c = certify(scene, plan, margin=0.0, method=meth, window=win)
                    r = (str(c.verdict), [ (p.geoms, str(p.method)) for p in c.pairs])
                except InvalidInputError as e:
                    r = ("InvalidInput", str(e)[:70])
            print(q, win, "lazy" if lazy else "general", meth, r)
