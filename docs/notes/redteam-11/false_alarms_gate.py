import warnings; warnings.simplefilter("ignore")
import numpy as np, mujoco, sys
sys.path.insert(0, "tests")
from test_review_replay import BOUNCE
from monitor.gate import Gate
from monitor import review
from monitor.log import read_log
def rep(tag, path, **kw):
    v = review.verify(read_log(path), progress=False, **kw)
    print(tag, "exit", review.verify_exit_code(v), {k: v.get(k) for k in ("windows", "replayed", "replay_failed", "replay_user", "continuity_checked")},
          [(f["severity"], f["index"], f["reason"][:160]) for f in v["findings"]][:4], flush=True)
m = mujoco.MjModel.from_xml_string(BOUNCE); d = mujoco.MjData(m)
# 1: state set by hand + gate.reset() with time continuing; mocap/ctrl/userdata untouched; xfrc edits between steps
path = "/tmp/rt11/fa2_reset.mcap"
d.qpos[0], d.qvel[0] = -0.4, 0.3
with Gate(m, log=path, frame_skip=25, allowed=None, on_violation="warn") as g:
    for k in range(12):
        if k == 5:
            d.qpos[0], d.qvel[0] = -0.35, 0.2; mujoco.mj_forward(m, d); g.reset()
        if k == 8:
            d.xfrc_applied[2, 0] = 0.001  # user force between steps (not a state edit)
        g.step(d, np.array([0.1 * np.sin(k)]))
rep("reset+force", path)
# 2: mujoco rollout via Gate.decide + user's own mj_step (same ctrl), no commit helper
path = "/tmp/rt11/fa2_decide.mcap"
d = mujoco.MjData(m); d.qpos[0], d.qvel[0] = -0.4, 0.3
with Gate(m, log=path, frame_skip=25, allowed=None, on_violation="warn") as g:
    for k in range(8):
        r = g.decide(d, np.array([0.05]))
        d.ctrl[:] = r.applied_ctrl
        for _ in range(25): mujoco.mj_step(m, d)
rep("decide+own mj_step", path)
# 3: the user runs mj_forward / mj_rnePostConstraint between steps (rendering / sensors)
path = "/tmp/rt11/fa2_fwd.mcap"
d = mujoco.MjData(m); d.qpos[0], d.qvel[0] = -0.4, 0.3
with Gate(m, log=path, frame_skip=25, allowed=None, on_violation="warn") as g:
    for k in range(8):
        g.step(d, np.array([0.05])); mujoco.mj_forward(m, d); mujoco.mj_rnePostConstraint(m, d)
rep("mj_forward between", path)
