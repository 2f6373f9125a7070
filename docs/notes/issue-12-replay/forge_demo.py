"""Make the red-team forgery of tests/test_review_replay.py as files (genuine + forged), for base/new review."""
import sys
from pathlib import Path
import numpy as np
sys.path.insert(0, "tests")  # run from the tree root
import test_review_replay as T
from monitor.log import read_log, topics
out = Path("/tmp/replay/demo"); out.mkdir(exist_ok=True)
path = out / "bounce.mcap"
model, _ = T._bounce_log(path)
contents = read_log(path)
k = T.BOUNCE_STEP
p = contents.plans_by_index()[k]
times, qpos = np.asarray(p["times"]), np.asarray(p["qpos"])
s = (times - times[0]) / (times[-1] - times[0])
forged = qpos[0] + s[:, None] * (qpos[-1] - qpos[0])
cert = T._recertified(model, k, times, forged, contents)
def msg(topic, o):
    if o.get("index") != k:
        return o
    if topic == topics.PLAN:
        return {**o, "qpos": forged.tolist()}
    if topic == topics.CERTIFICATE:
        return cert
    return None if topic in (topics.VIOLATION, topics.LOG) else o
T._forge(path, out / "forged.mcap", msg=msg)
print("written", out)
