import mujoco, numpy as np
from monitor import Scene, Plan, certify
from monitor.errors import MonitorError
XML = """<mujoco><asset><hfield name="h" nrow="3" ncol="3" size="1 1 0.1 0.1"/></asset><worldbody>
<geom name="hf" type="hfield" hfield="h"/><geom name="pl" type="plane" size="1 1 0.1"/>
<body name="m" mocap="true"><geom name="pl2" type="plane" size="1 1 0.1"/></body>
<body name="b"><joint type="slide" axis="0 0 1"/><geom name="s" type="sphere" size="0.05"/></body></worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
for pairs in ("mujoco", "all", [("hf", "s")], [("pl", "pl2")], [("pl2", "s")]):
    try:
        sc = Scene.from_model(m, pairs=pairs)
        print(pairs, "pairs", sc.candidate_pairs)
        c = certify(sc, Plan([0, 1], [[0.2], [0.04]], m), margin=0.01, ongoing="deepen")
        print("   ", c.verdict, [(p.geoms, p.verdict.value, p.note) for p in c.pairs])
    except MonitorError as e:
        print(pairs, "typed", type(e).__name__, str(e)[:100])
