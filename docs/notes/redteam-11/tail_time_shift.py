import sys, warnings; warnings.simplefilter("ignore")
sys.path.insert(0, "tests")
from pathlib import Path
import numpy as np, mujoco
from test_review_applied import _arm_run
from test_review_replay import _forge, _verify
from monitor.log import topics, read_log, replay
from monitor.log.reader import load_model
out = Path("/tmp/rt11"); src = out / "arm.mcap"
if not src.exists(): _arm_run(src, steps=30)
c = read_log(src); model, _ = load_model(c, "mjb")
code, ver = _verify(src); print("genuine", code, ver["replayed"], ver["continuity_checked"])
plans = c.plans_by_index(); certs = {x["index"]: x for x in c.certificates()}
tails = [k for k, x in certs.items() if (x.get("applied") or {}).get("kind") == "brake_tail"]
print("tails", tails)
k = tails[0]
ro = replay.decode(plans[k]["rollout"], model)
st = ro.state.copy(); st[0] = st[0] + float(sys.argv[1]); st[1 + model.nq:1 + model.nq + model.nv] *= float(sys.argv[2])
shifted = replay.Rollout(st, ro.segments, ro.rows_from)
plan, _ = replay.resimulate(model, mujoco.MjData(model), shifted)
print("max dq", np.abs(plan.qpos - np.asarray(plans[k]["qpos"])).max(), "dt0", plan.times[0] - plans[k]["times"][0])
payload = replay.encode((st, tuple((cc, n) for cc, n in ro.segments), ro.rows_from), int(mujoco.mjtState.mjSTATE_INTEGRATION), st.size, model.nu)
def msg(topic, o):
    if topic == topics.PLAN and o.get("index") == k:
        return {**o, "times": plan.times.tolist(), "qpos": plan.qpos.tolist(), "rollout": payload}
    return o
_forge(src, out / "T.mcap", msg=msg)
code, ver = _verify(out / "T.mcap"); print("T tail time +1ulp", code, ver["replayed"], ver["continuity_checked"], [(f["severity"], f["index"], f["reason"][:160]) for f in ver["findings"]][:4])
