"""sha256 of every gated step (decisions, certificates, applied controls, info, full states), old vs new tree.

The report and info keys are tests/test_gate_reports.py's (of the tree under test).

PYTHONPATH=<tree> python docs/notes/issue-12-gate-6/dump.py STEPS [WORKLOAD ...]
WORKLOAD: tunnel | Pusher-v5 | Pusher-nobrake | monitor/Arm-v0 | Arm-nobrake | Arm-violation | Reacher-v5
(default: all). One line per workload: counters and the digest. Per step it hashes the StepReport (verdicts,
proposed / applied controls, flags, time, both certificates' to_dict() without wall_seconds / certify_us,
info() without certify_us), the gym info["safety"] dict, the reward and obs, and the caller's full
MjData state after the step (mjSTATE_FULLPHYSICS + USER + WARMSTART: every integrated array).
The gym actions are resampled in bursts (action_space.sample(), seeded) so that the arm swings hard
(brake rejections, fallbacks, committed-tail reuse).
"""
import hashlib, os, sys
import gymnasium as gym, mujoco, numpy as np
import monitor, monitor.envs  # noqa
from monitor._paths import scene_path
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate

sys.path.insert(0, os.path.join(os.path.dirname(monitor.__file__), os.pardir, "tests"))  # the tree's own tests
from test_gate_reports import _info_key as info_key, report_key as _report_key  # noqa: E402

_ALL = (mujoco.mjtState.mjSTATE_FULLPHYSICS | mujoco.mjtState.mjSTATE_USER
        | mujoco.mjtState.mjSTATE_WARMSTART)
steps = int(sys.argv[1])
which = sys.argv[2:] or ["tunnel", "Pusher-v5", "Pusher-nobrake", "monitor/Arm-v0", "Arm-nobrake",
                         "Arm-violation", "Reacher-v5"]


def report_key(r):
    return repr(_report_key(r))


def state(m, d):
    s = np.empty(mujoco.mj_stateSize(m, _ALL))
    mujoco.mj_getState(m, d, s, _ALL)
    return s.tobytes() + d.warning.number.tobytes()


def tunnel():
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    rng = np.random.default_rng(1)
    ctrls = [np.array([rng.uniform(-6.0, 6.0)]) for _ in range(steps // 20 + 1)]
    d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m, margin=0.001); h = hashlib.sha256()
    for k in range(steps):
        if k % 150 == 149:
            mujoco.mj_resetDataKeyframe(m, d, 0); gate.reset()
        r = gate.step(d, ctrls[k // 20])
        h.update(report_key(r).encode()); h.update(state(m, d))
    return gate.summary(), h.hexdigest()


def gymrun(env_id, **kw):
    env = SafetyGate(gym.make(env_id), **kw)
    env.action_space.seed(0)
    acts = []
    while len(acts) < steps:  # bursts of one held action (hard swings) and of fresh samples
        a = env.action_space.sample()
        acts += [a] * 8 + [env.action_space.sample() for _ in range(8)]
    env.reset(seed=0); h = hashlib.sha256()
    m = env.unwrapped.model
    for a in acts[:steps]:
        obs, rew, te, tr, info = env.step(a)
        d = env.unwrapped.data
        h.update(report_key(env.gate.last_report).encode()); h.update(info_key(info["safety"]).encode())
        h.update(repr((float(rew), float(info["cost"]), te, tr)).encode()); h.update(np.asarray(obs).tobytes())
        h.update(state(m, d))
        if te or tr:
            env.reset(seed=1); env.gate.reset()
    return env.gate.summary(), h.hexdigest()


runs = {"tunnel": tunnel, "Pusher-v5": lambda: gymrun("Pusher-v5", pairs="mujoco"),
        "Pusher-nobrake": lambda: gymrun("Pusher-v5", pairs="mujoco", brake=False),
        "monitor/Arm-v0": lambda: gymrun("monitor/Arm-v0"),
        "Arm-nobrake": lambda: gymrun("monitor/Arm-v0", brake=False),
        "Arm-violation": lambda: gymrun("monitor/Arm-v0", ongoing="violation"),
        "Reacher-v5": lambda: gymrun("Reacher-v5")}
for name in which:
    s, dig = runs[name]()
    keys = ("windows", "certified", "violation", "uncertain", "replaced", "joint", "brake_rejected",
            "tail_reused", "tail_refuted", "committed", "pairs")
    print(f"{name:16s} {steps} " + " ".join(f"{k}={s.get(k, 0)}" for k in keys) + f" {dig[:20]}", flush=True)
