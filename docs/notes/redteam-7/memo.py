"""Call-memo attacks: each scenario compares the memoised call with a fresh plan copy (memo miss) on the same scene."""
import copy, mujoco, numpy as np, warnings
from monitor import Plan, Scene, certify, BodyMotion
from monitor.certify import engine
from monitor.certify.request import CertifyRequest
from monitor.certify.common import Budget
from monitor.tolerances import Tolerances, DEFAULT
XML = """
<mujoco>
  <worldbody>
    <body name="wall" pos="0.3 0 0"><geom name="wall" type="box" size="0.01 0.2 0.2"/></body>
    <geom name="floor" type="plane" size="1 1 0.1" pos="0 0 -0.3"/>
    <body name="ball"><joint name="x" type="slide" axis="1 0 0"/><joint name="z" type="slide" axis="0 0 1"/>
      <geom name="ball" type="sphere" size="0.02"/></body>
    <body name="m" mocap="true" pos="-0.3 0 0"><geom name="mg" type="sphere" size="0.05"/></body>
  </worldbody>
</mujoco>"""
def fresh(plan):
    return Plan(np.array(plan.times), np.array(plan.qpos), plan.model, mocap_pos=np.array(plan.mocap_pos), mocap_quat=np.array(plan.mocap_quat))
def key(c):
    return (str(c.verdict), c.window, round(c.clearance, 12) if np.isfinite(c.clearance) else c.clearance,
            tuple((p.geoms, str(p.verdict)) for p in c.pairs))
bad = 0; n = 0
def cmp(name, a, b):
    global bad, n
    n += 1
    if key(a) != key(b):
        bad += 1; print("DIFF", name, key(a)[:3], key(b)[:3])
    else:
        print("same", name, key(a)[:3])
m = mujoco.MjModel.from_xml_string(XML)
sc = Scene.from_model(m, pairs="all", allowed=None)
P = Plan([0, 0.5, 1], [[0, 0], [0.1, 0], [0.2, 0]], m)
# 1 baseline: same objects twice -> memo hit; compare with fresh
c1 = certify(sc, P, 0.01); c2 = certify(sc, P, 0.01); cmp("repeat", c2, certify(sc, fresh(P), 0.01))
# 2 positional margin vs request
req = CertifyRequest(margin=0.01)
cmp("request", certify(sc, P, request=req), certify(sc, fresh(P), 0.01))
cmp("request again", certify(sc, P, request=req), certify(sc, fresh(P), request=req))
# 3 margin changes with same plan -> must change
cmp("margin 0.09", certify(sc, P, 0.09), certify(sc, fresh(P), 0.09))
cmp("margin 0.09 request", certify(sc, P, request=req.replace(margin=0.09)), certify(sc, fresh(P), 0.09))
# 4 windows
for w in ((0.0, 0.5), (0.5, 1.0), (0.25, 0.75)):
    certify(sc, P, 0.05, window=w)
    cmp(f"window {w}", certify(sc, P, 0.05, window=w), certify(sc, fresh(P), 0.05, window=w))
    cmp(f"window {w} then full", certify(sc, P, 0.05), certify(sc, fresh(P), 0.05))
# 5 pairs=
for prs in ([("wall", "ball")], [("floor", "ball")], [("mg", "ball")]):
    cmp(f"pairs {prs}", certify(sc, P, 0.1, pairs=prs), certify(sc, fresh(P), 0.1, pairs=prs))
    r = CertifyRequest(margin=0.1, pairs=prs)
    certify(sc, P, request=r)
    cmp(f"pairs req {prs}", certify(sc, P, request=r), certify(sc, fresh(P), request=r))
# 6 Budget mutated in place
b = Budget(seconds=1.0)
certify(sc, P, 0.01, budget=b)
b2 = Budget(seconds=1.0, tests=1)
cmp("budget tests=1", certify(sc, P, 0.01, budget=b2), certify(sc, fresh(P), 0.01, budget=Budget(seconds=1.0, tests=1)))
# 7 model edits: wall moved onto the path (body_pos), geom_size, mocap via data (plan holds mocap)
certify(sc, P, 0.01)
m.body_pos[m.body("wall").id, 0] = 0.2
cmp("wall body_pos edit", certify(sc, P, 0.01), certify(Scene.from_model(m, pairs="all", allowed=None), fresh(P), 0.01))
m.geom_size[m.geom("wall").id, 0] = 0.05
cmp("wall size edit", certify(sc, P, 0.01), certify(Scene.from_model(m, pairs="all", allowed=None), fresh(P), 0.01))
m.body_pos[m.body("wall").id, 0] = 0.3; m.geom_size[m.geom("wall").id, 0] = 0.01
cmp("edit back", certify(sc, P, 0.01), certify(Scene.from_model(m, pairs="all", allowed=None), fresh(P), 0.01))
# unwatched edits that MuJoCo ignores for geometry (no change expected)
m.geom_friction[:] = 0.3; m.body_mass[:] = 2
cmp("unwatched edits", certify(sc, P, 0.01), certify(Scene.from_model(m, pairs="all", allowed=None), fresh(P), 0.01))
# 8 second scene sharing the plan, other pairs / allowed
sc2 = Scene.from_model(m, pairs=[("floor", "ball")])
certify(sc, P, 0.01)
cmp("second scene", certify(sc2, P, 0.35), certify(sc2, fresh(P), 0.35))
cmp("back to first", certify(sc, P, 0.35), certify(sc, fresh(P), 0.35))
# 9 deepen via positional / request
cmp("deepen", certify(sc, P, 0.35, ongoing="deepen"), certify(sc, fresh(P), 0.35, ongoing="deepen"))
# 10 object.__setattr__ on a frozen request / Tolerances (abuse, expected to fool the memo)
r = CertifyRequest(margin=0.01); certify(sc, P, request=r)
object.__setattr__(r, "margin", 0.2)
cmp("ABUSE request.margin via object.__setattr__", certify(sc, P, request=r), certify(sc, fresh(P), request=CertifyRequest(margin=0.2)))
tol = Tolerances(); certify(sc, P, 0.01, tolerances=tol)
# 11 scene attributes reassigned by user
certify(sc, P, 0.01)
old = sc.allowed_pairs
sc.allowed_pairs = (("wall", "ball", "User"),)
a = certify(sc, P, 0.01); sc.allowed_pairs = old
print("allowed reassigned: cert.allowed", a.allowed_pairs if hasattr(a, "allowed_pairs") else None)
# 12 mocap plan: plan holds mocap; two plans with different mocap poses
Pm = Plan([0, 1], [[0, 0], [-0.2, 0]], m, mocap_pos=[[-0.3, 0, 0]], mocap_quat=[[1, 0, 0, 0]])
Pm2 = Plan([0, 1], [[0, 0], [-0.2, 0]], m, mocap_pos=[[-0.1, 0, 0]], mocap_quat=[[1, 0, 0, 0]])
certify(sc, Pm, 0.01)
cmp("mocap plan 2", certify(sc, Pm2, 0.01), certify(sc, fresh(Pm2), 0.01))
cmp("mocap plan 1", certify(sc, Pm, 0.01), certify(sc, fresh(Pm), 0.01))
# 13 -0.0 margin / windows with -0.0
cmp("margin -0.0", certify(sc, P, -0.0), certify(sc, fresh(P), 0.0))
print("scenarios", n, "differ", bad)
