import warnings, sys; warnings.simplefilter("ignore")
import gymnasium as gym, numpy as np
import monitor.envs  # noqa
from monitor.gym_gate import SafetyGate
from monitor import review
from monitor.log import read_log
for env_id in sys.argv[1:]:
    path = f"/tmp/rt11/stock_{env_id}.mcap"
    try:
        env = SafetyGate(gym.make(env_id), log=path)
    except Exception as e:
        print(env_id, "skip", type(e).__name__, str(e)[:80]); continue
    env.reset(seed=0); env.action_space.seed(0)
    for k in range(25):
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        if term or trunc: env.reset(seed=k)
    env.close()
    v = review.verify(read_log(path), progress=False)
    print(env_id, "exit", review.verify_exit_code(v), {k: v.get(k) for k in ("windows", "replayed", "replay_failed", "replay_user", "continuity_checked", "critical", "unverifiable")},
          [f["reason"][:150] for f in v["findings"]][:3])
