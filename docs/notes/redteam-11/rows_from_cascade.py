import sys
sys.path.insert(0, "tests")
from pathlib import Path
import numpy as np, mujoco
from test_review_replay import _forge, _verify, _recertified, BOUNCE, INTEGRATION
from monitor.log import topics, read_log, replay
out = Path("/tmp/rt11"); src = out / "bounce.mcap"
c = read_log(src); model = mujoco.MjModel.from_xml_string(BOUNCE)
forged = {}
first = int(sys.argv[1]) if len(sys.argv) > 1 else 2
for k in range(first, 6):
    p = c.plans_by_index()[k]; ro = replay.decode(p["rollout"], model)
    pre = ro.state.copy(); pre[0] -= model.opt.timestep; pre[1 + model.nq:1 + model.nq + model.nv] = 0.0
    fab = replay.Rollout(pre, ((ro.segments[0][0], 51),), 1)
    plan, _ = replay.resimulate(model, mujoco.MjData(model), fab)
    payload = replay.encode((pre, ((ro.segments[0][0], 51),), 1), int(INTEGRATION), pre.size, model.nu)
    cert = _recertified(model, k, plan.times, plan.qpos, c)
    forged[k] = (plan, payload, cert)
    print(k, cert["verdict"], c.certificates()[k]["verdict"], plan.times[0], p["times"][0])
def msg(topic, o):
    k = o.get("index")
    if k not in forged: return o
    plan, payload, cert = forged[k]
    if topic == topics.PLAN: return {**o, "times": plan.times.tolist(), "qpos": plan.qpos.tolist(), "rollout": payload}
    if topic == topics.CERTIFICATE: return cert
    return None if topic in (topics.VIOLATION, topics.LOG) else o
_forge(src, out / "H.mcap", msg=msg)
code, ver = _verify(out / "H.mcap"); print("H rows_from cascade", code, ver["replayed"], ver["continuity_checked"], [(f["severity"], f["index"], f["reason"][:160]) for f in ver["findings"]][:4])
