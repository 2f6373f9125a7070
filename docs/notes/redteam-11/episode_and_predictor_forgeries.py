import sys, time
sys.path.insert(0, "tests")
import numpy as np, mujoco
from pathlib import Path
from test_review_replay import _bounce_log, _forge, _recertified, _verify, _findings, BOUNCE_STEP, INTEGRATION
from monitor.log import read_log, replay, topics
out = Path("/tmp/rt11"); src = out / "bounce.mcap"
if src.exists(): src.unlink()
model, starts = _bounce_log(src)
contents = read_log(src)
code, ver = _verify(src); print("genuine", code, ver["replayed"], ver["continuity_checked"])
# A: episode split: window 2 fabricated from a state with qvel 0 (ball stays put), in its own episode
p = contents.plans_by_index()[2]
ro = replay.decode(p["rollout"], model)
st = ro.state.copy(); st[1 + model.nq] = 0.0  # qvel
fab = replay.Rollout(st, ro.segments, 0)
plan, _ = replay.resimulate(model, mujoco.MjData(model), fab)
payload = replay.encode((st, ((ro.segments[0][0], 50),), 0), int(INTEGRATION), st.size, model.nu)
cert = _recertified(model, 2, plan.times, plan.qpos, contents); print("fab verdict", cert["verdict"], contents.certificates()[2]["verdict"])
def msgA(topic, o):
    k = o.get("index")
    if k is None: return o
    if k == 2:
        if topic == topics.PLAN: o = {**o, "qpos": plan.qpos.tolist(), "rollout": payload}
        elif topic == topics.CERTIFICATE: o = dict(cert)
        elif topic in (topics.VIOLATION, topics.LOG): return None
    if "episode" in o and k >= 2: o["episode"] = 1 if k == 2 else 2
    return o
_forge(src, out / "A.mcap", msg=msgA)
code, ver = _verify(out / "A.mcap"); print("A episode split", code, ver["replayed"], ver["continuity_checked"], ver["findings"])
# B: predictor relabel
def msgB(topic, o):
    if o.get("index") != 2: return o
    if topic == topics.PLAN:
        o = dict(o); o.pop("rollout"); o["source"] = "user"; o["qpos"] = plan.qpos.tolist(); return o
    if topic == topics.CERTIFICATE: return dict(cert)
    return None if topic in (topics.VIOLATION, topics.LOG) else o
def metaB(name, v):
    if name == topics.METADATA_RUN: v["predictor"] = "callable"
    return v
_forge(src, out / "B.mcap", msg=msgB, metadata=metaB)
code, ver = _verify(out / "B.mcap"); print("B predictor relabel", code, ver["replayed"], ver["continuity_checked"], [f for f in ver["findings"]], ver["notes"][-3:])
print(contents.run.get("predictor"))
