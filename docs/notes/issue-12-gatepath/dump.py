"""Every certificate, applied action, info["safety"] and observation of seeded gated Arm / Pusher steps,
and every certificate, applied control and state of seeded plain-gate tunnel / hand30 steps.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-gatepath/dump.py OUT STEPS
Copied from docs/notes/issue-12-armprof/dump.py (helper gatepath added the plain ``Gate.step`` runs of
the bench's tunnel and hand30 workloads, ``monitor/bench/targets.py``: each report's verdict,
replaced flag and applied control, the state after the step, and the gate's counters).
Extends docs/notes/issue-12-certpy/dump_gym.py: besides each ``engine.certify`` certificate
(``to_dict()`` minus the wall time) and each observation, every step's applied control
(``gate.last_report.applied_ctrl`` bytes), the action the env received, and ``info["safety"]``
(every key; arrays as dtype + bytes / list) are written. Two action streams per env: certpy's
(``default_rng(11)``, saturated every 7th step) and the bench's (``action_space.seed(rep)``).
Prints the md5 of the text.
"""
import hashlib
import sys

import gymnasium as gym
import numpy as np

import monitor.envs  # noqa: F401
from monitor import SafetyGate
from monitor.certify import engine

out = sys.argv[1]
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 150
lines = []
_orig = engine.certify


def rec(*a, **k):
    c = _orig(*a, **k)
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    lines.append(f"  {c.verdict} {d!r}")
    return c


engine.certify = rec
engine._OWN_CERTIFY = rec


def info_text(s):
    parts = []
    for key in sorted(s):
        v = s[key]
        if key == "certify_us":
            continue
        if isinstance(v, np.ndarray):
            v = (str(v.dtype), v.shape, v.tolist() if v.dtype == object else v.tobytes().hex())
        parts.append(f"{key}={v!r}")
    return " ".join(parts)


def run(env_id, stream):
    env = SafetyGate(gym.make(env_id), pairs="mujoco")
    env.reset(seed=5)
    rng = np.random.default_rng(11)
    env.action_space.seed(3)
    for k in range(steps):
        if stream == "certpy":
            a = rng.uniform(env.action_space.low, env.action_space.high) * (3.0 if k % 7 == 3 else 1.0)
            a = np.clip(a, env.action_space.low, env.action_space.high)
        else:
            a = env.action_space.sample()
        obs, r, term, trunc, info = env.step(a)
        rep = env.gate.last_report
        lines.append(f"{env_id} {stream} {k} obs={np.asarray(obs).tobytes().hex()} r={r!r} {term} {trunc} "
                     f"applied={np.asarray(rep.applied_ctrl).tobytes().hex()} "
                     f"{info_text(info['safety'])}")
        if term or trunc:
            env.reset(seed=k)
    lines.append(f"{env_id} {stream} stats {sorted((k, v) for k, v in env.gate.stats.items() if k != 'certify_us')!r}")
    env.close()


def run_plain(kind):
    import mujoco

    from monitor.bench.targets import _scene_file
    from monitor.gate import Gate

    model = mujoco.MjModel.from_xml_path(str(_scene_file(kind)))
    d = mujoco.MjData(model)
    if kind == "tunnel":     # the bench's controller, target side switching every 100 windows
        gate = Gate(model, margin=0.001)
        mujoco.mj_resetDataKeyframe(model, d, 0)

        def ctrl(k):
            return np.clip([12.0 * ((0.3 if (k // 100) % 2 == 0 else -0.3) - d.qpos[0])], -6.0, 6.0)
        nstep = 1
    else:                    # the bench's random joint targets, new every 10 windows of 5 substeps
        gate = Gate(model)
        lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
        tg = np.random.default_rng(0).uniform(lo, hi, size=(64, model.nu))

        def ctrl(k):
            return tg[(k // 10) % 64]
        nstep = 5
    n = steps * 2 if kind == "tunnel" else max(steps // 3, 1)
    for k in range(n):
        rep = gate.step(d, ctrl(k), nstep=nstep)
        lines.append(f"{kind} {k} {rep.verdict} replaced={rep.replaced!r} "
                     f"applied={np.asarray(rep.applied_ctrl).tobytes().hex()} "
                     f"qpos={d.qpos.tobytes().hex()} qvel={d.qvel.tobytes().hex()} t={d.time!r}")
    lines.append(f"{kind} stats {sorted((k, v) for k, v in gate.stats.items() if k != 'certify_us')!r}")
    gate.close()


for env_id in ("monitor/Arm-v0", "Pusher-v5"):
    for stream in ("certpy", "bench"):
        run(env_id, stream)
for kind in ("tunnel", "hand30"):
    run_plain(kind)
text = "\n".join(lines) + "\n"
open(out, "w").write(text)
print(hashlib.md5(text.encode()).hexdigest(), len(lines), "lines",
      sum(1 for x in lines if x.startswith("  ")), "certificates")
