"""Red team 16, idea (2): probes of the scene flag cache (model copies sharing Plan._moving, a plan of
another model, an unpickled plan, the seal, in-place edits with and without Scene.sync). Run in both trees
and diff."""
import pickle
import mujoco, numpy as np, monitor
XML = '''<mujoco><worldbody><geom name="w" type="box" size=".1 .1 .1" pos="0.5 0 0"/>
<body name="a" pos="0 0 0"><joint name="ja" type="slide" axis="1 0 0"/><geom name="ga" type="sphere" size=".1"/></body>
<body name="b" pos="0 0.5 0"><joint name="jb" type="slide" axis="0 1 0"/><geom name="gb" type="sphere" size=".1"/></body>
</worldbody></mujoco>'''
XML2 = XML.replace('<joint name="jb" type="slide" axis="0 1 0"/>', '<joint name="jb" type="hinge" axis="0 0 1"/>')
m = mujoco.MjModel.from_xml_string(XML); m2 = mujoco.MjModel.from_xml_string(XML)
mh = mujoco.MjModel.from_xml_string(XML2)
sc = monitor.Scene.from_model(m, pairs="all")
t = np.array([0., 1.])
def P(mod, qa, qb):
    return monitor.Plan(t, np.array([[qa[0], qb[0]], [qa[1], qb[1]]]), model=mod)
def v(s, p, **k):
    try:
        c = monitor.certify(s, p, margin=0.01, **k); return c.verdict.value, c.witness and round(c.witness.time, 6)
    except Exception as e:
        return type(e).__name__ + ": " + str(e)[:90]
p1 = P(m, (0, 0.35), (0, 0))       # a moves into wall at 0.5-0.1-0.1=0.3 -> violation
p2 = P(m2, (0, 0.1), (0, 0))       # model copy: same structure, certified
print("p1", v(sc, p1), "p2(model copy on scene of m)", v(sc, p2))
print("same _moving object:", p1._moving is p2._moving)
ph = P(mh, (0, 0.35), (0, 3.0))
print("hinge model plan on slide scene", v(sc, ph))
q = pickle.loads(pickle.dumps(p1)); print("unpickled moving writeable", q._moving.flags.writeable, v(sc, q))
try:
    q._moving.setflags(write=True); print("could make writable")
except Exception as e: print("seal holds:", type(e).__name__)
# scene sync after in-place edit (weld body b: body_static change is not possible in place; move the wall)
m.geom_pos[0] = [0.2, 0, 0]
print("after in-place edit, no sync:", v(sc, P(m, (0, 0.05), (0, 0))))
sc.sync(); print("after sync:", v(sc, P(m, (0, 0.05), (0, 0))))
