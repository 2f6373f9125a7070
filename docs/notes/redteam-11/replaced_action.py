import sys
sys.path.insert(0, "tests")
from pathlib import Path
import numpy as np, mujoco
from test_review_replay import _forge, _verify, _recertified, BOUNCE, INTEGRATION
from monitor.log import topics, read_log, replay
out = Path("/tmp/rt11"); src = out / "bounce.mcap"
c = read_log(src); model = mujoco.MjModel.from_xml_string(BOUNCE)
p = c.plans_by_index()[2]; ro = replay.decode(p["rollout"], model)
braked = replay.Rollout(ro.state, ((np.array([-1.0]), 50),), 0)
plan, _ = replay.resimulate(model, mujoco.MjData(model), braked)
print("min gap", -0.015 - plan.qpos[:, 0].max())
payload = replay.encode((ro.state, ((np.array([-1.0]), 50),), 0), int(INTEGRATION), ro.state.size, model.nu)
cert = _recertified(model, 2, plan.times, plan.qpos, c); print(cert["verdict"])
acts = {a["index"]: a for a in c.topic(topics.ACTION)}; print("action 2", acts[2])
for variant in ("999", "self", "user3"):
    def msg(topic, o):
        if o.get("index") != 2: return o
        if topic == topics.PLAN: return {**o, "qpos": plan.qpos.tolist(), "rollout": payload}
        if topic == topics.CERTIFICATE: return cert
        if topic == topics.ACTION:
            o = {**o, "proposed": [-1.0], "applied": [-1.0], "replaced": True}
            o["applied_window"] = {"999": 999, "self": 2, "user3": 3}[variant]
            return o
        return None if topic in (topics.VIOLATION, topics.LOG) else o
    _forge(src, out / f"G_{variant}.mcap", msg=msg)
    code, ver = _verify(out / f"G_{variant}.mcap"); print("G", variant, code, ver["continuity_checked"], [(f["severity"], f["index"], f["reason"][:160]) for f in ver["findings"]][:4])
