import sys
sys.path.insert(0, "tests")
from pathlib import Path
import numpy as np
from test_review_replay import _forge, _verify, _recertified
from monitor.log import topics, read_log
import mujoco
out = Path("/tmp/rt11"); src = out / "bounce.mcap"
c = read_log(src)
# D1: duplicate window 2 plan (2nd copy straight rows) + cert certified
p = c.plans_by_index()[2]; times = np.asarray(p["times"]); qpos = np.asarray(p["qpos"])
s = (times - times[0]) / (times[-1] - times[0]); forged = qpos[0] + s[:, None] * (qpos[-1] - qpos[0])
model = mujoco.MjModel.from_xml_string(__import__("test_review_replay").BOUNCE)
cert = _recertified(model, 2, times, forged, c)
def dup(topic, o):
    if o.get("index") != 2: return o
    if topic == topics.PLAN: return [o, {**o, "qpos": forged.tolist()}]
    if topic == topics.CERTIFICATE: return [o, cert]
    return o
_forge(src, out / "D1.mcap", msg=dup)
code, ver = _verify(out / "D1.mcap"); print("D1 dup", code, [(f["severity"], f["index"], f["reason"][:120]) for f in ver["findings"]][:4])
# D2: reorder: swap index of windows 3 and 4 in all messages
def swap(topic, o):
    k = o.get("index")
    if k in (3, 4): o["index"] = 7 - k
    return o
_forge(src, out / "D2.mcap", msg=swap)
code, ver = _verify(out / "D2.mcap"); print("D2 swap", code, [(f["severity"], f["index"], f["reason"][:120]) for f in ver["findings"]][:4])
# D3: NaN / inf in state of window 3 (physics part) and in ctrl
import base64
def nan_state(topic, o):
    if topic == topics.PLAN and o.get("index") == 3:
        st = np.frombuffer(base64.b64decode(o["rollout"]["state"]), "<f8").copy(); st[2] = np.nan
        o["rollout"]["state"] = base64.b64encode(st.tobytes()).decode()
        o["rollout"]["segments"][0]["ctrl"] = base64.b64encode(np.array([np.inf]).tobytes()).decode()
    return o
_forge(src, out / "D3.mcap", msg=nan_state)
code, ver = _verify(out / "D3.mcap"); print("D3 nan", code, [(f["severity"], f["index"], f["reason"][:140]) for f in ver["findings"]][:4])
