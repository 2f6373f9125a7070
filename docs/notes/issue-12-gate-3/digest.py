"""sha256 of every StepReport (timings excluded) on seeded episodes, for comparing two trees.

PYTHONPATH=<tree> python docs/notes/issue-12-gate-3/digest.py [steps]
Prints one line per episode: name, steps, joint/replaced/brake_rejected counts, digest.
Same report key as tests/test_gate_reports.py (copied so that it runs on trees without that file).
"""
import hashlib, sys
import gymnasium as gym, mujoco, numpy as np
import monitor.envs  # noqa
from monitor._paths import scene_path
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate

_TIMING = ("wall_seconds", "certify_us")
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 120


def cert_key(c):
    if c is None:
        return None
    d = c.to_dict()
    d["stats"] = {k: v for k, v in d["stats"].items() if k not in _TIMING}
    return repr(d)


def info_key(info):
    return repr({k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in sorted(info.items())
                 if k not in _TIMING})


def report_key(r):
    return repr((str(r.verdict), np.asarray(r.proposed_ctrl).tobytes(), np.asarray(r.applied_ctrl).tobytes(),
                 r.replaced, r.terminated, r.unsafe, str(r.applied_verdict), r.fallback_certified, r.time,
                 str(r.brake_verdict), r.stepped, cert_key(r.certificate), cert_key(r.fallback_certificate),
                 info_key(r.info())))


def tunnel(brake=True):
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    rng = np.random.default_rng(1)
    ctrls = [np.array([rng.uniform(-6.0, 6.0)]) for _ in range(steps // 20 + 1)]
    d = mujoco.MjData(m); mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m, brake=brake); h = hashlib.sha256()
    for k in range(steps):
        if k % 100 == 99:
            mujoco.mj_resetDataKeyframe(m, d, 0); gate.reset()
        r = gate.step(d, ctrls[k // 20])
        h.update(report_key(r).encode()); h.update(d.qpos.tobytes()); h.update(d.qvel.tobytes())
    return {**gate.summary(), "pairs_total": gate.stats["pairs"]}, h.hexdigest()


def gymrun(env_id, brake=True, **kw):
    env = SafetyGate(gym.make(env_id), brake=brake, **kw)
    env.action_space.seed(0); acts = [env.action_space.sample() for _ in range(steps)]
    env.reset(seed=0); h = hashlib.sha256()
    for a in acts:
        _, _, te, tr, info = env.step(a)
        d = env.unwrapped.data
        h.update(report_key(env.gate.last_report).encode()); h.update(info_key(info["safety"]).encode())
        h.update(d.qpos.tobytes()); h.update(d.qvel.tobytes())
        if te or tr:
            env.reset(seed=1)
    return {**env.gate.summary(), "pairs_total": env.gate.stats["pairs"]}, h.hexdigest()


for name, f in [("tunnel", lambda: tunnel()), ("Pusher-v5", lambda: gymrun("Pusher-v5", pairs="mujoco")),
                ("Pusher-v5 brake=False", lambda: gymrun("Pusher-v5", brake=False, pairs="mujoco")),
                ("monitor/Arm-v0", lambda: gymrun("monitor/Arm-v0")),
                ("monitor/Arm-v0 brake=False", lambda: gymrun("monitor/Arm-v0", brake=False))]:
    s, dig = f()
    print(f"{name:28s} steps {steps} joint {s.get('joint', 0)} replaced {s['replaced']} "
          f"brake_rejected {s['brake_rejected']} pairs {s['pairs_total']} {dig[:16]}")
