"""Byte-identity dump of gated steps: Arm, Pusher (SafetyGate), tunnel and hand30 (plain Gate.step), MCAP logs.

Usage: PYTHONPATH=<tree> python docs/notes/issue-12-gatechecks/dump.py OUT STEPS
Run it on the base tree and on this tree (separate processes) and compare the files (cmp / md5).

Extends docs/notes/issue-12-armprof/dump.py (itself from certpy's dump_gym.py). Per step:
* every ``engine.certify`` certificate (``to_dict()`` minus the wall time);
* SafetyGate (Arm-v0, Pusher-v5; certpy's action stream and the bench's): observation, reward,
  termination flags, the applied control's bytes, ``info["safety"]`` (every key but the wall time;
  arrays as dtype + bytes / list), ``info["cost"]`` and the env data's full state
  (``mjSTATE_FULLPHYSICS | USER | WARMSTART``) with the warning counters;
* plain ``Gate.step`` (tunnel with the bench's controller, nstep 1 and 2; hand30 with the bench's
  seeded joint targets, nstep 5): every StepReport field (certificates' ``to_dict``), ``info()``
  and the data's full state;
* each gate's counters (``stats`` without the wall time), at the end of a run;
* the MCAP log of a short seeded run (Arm SafetyGate, tunnel Gate): every decoded message per topic,
  without the wall-clock fields (``_log_time``, ``wall_time``, ``timestamp``, ``wall_seconds``, ``certify_us``,
  ``created_utc``, ``finalised_utc``) and the journal's byte size (``source_bytes``: its JSON holds
  wall times, whose text length varies), and the metadata records likewise.
Prints the md5 of the text and the counts.
"""
import hashlib
import json
import os
import sys
import tempfile

import gymnasium as gym
import mujoco
import numpy as np

import monitor
import monitor.envs  # noqa: F401
from monitor import SafetyGate
from monitor.certify import engine
from monitor.gate import Gate

out = sys.argv[1]
print("monitor from", monitor.__file__, file=sys.stderr)
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 150
lines = []
_orig = engine.certify
_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS | mujoco.mjtState.mjSTATE_USER | mujoco.mjtState.mjSTATE_WARMSTART
_WALL = {"_log_time", "wall_seconds", "certify_us", "wall_time", "timestamp", "created_utc", "finalised_utc", "mean_certify_us",
         "source_bytes"}  # wall-clock fields, and the journal size (its JSON holds wall times of varying length)


def rec(*a, **k):
    c = _orig(*a, **k)
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    lines.append(f"  {c.verdict} {d!r}")
    return c


engine.certify = rec
engine._OWN_CERTIFY = rec


def state_hex(m, d):
    s = np.empty(mujoco.mj_stateSize(m, _STATE))
    mujoco.mj_getState(m, d, s, _STATE)
    return s.tobytes().hex() + " w=" + d.warning.number.tobytes().hex()


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


def cert_text(c):
    if c is None:
        return "None"
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    return repr(d)


def stats_text(gate):
    return repr(sorted((k, v) for k, v in gate.stats.items() if k != "certify_us"))


def run_gym(env_id, stream, n, log=None):
    env = SafetyGate(gym.make(env_id), pairs="mujoco", log=log)
    env.reset(seed=5)
    rng = np.random.default_rng(11)
    env.action_space.seed(3)
    u = env.unwrapped
    for k in range(n):
        if stream == "certpy":
            a = rng.uniform(env.action_space.low, env.action_space.high) * (3.0 if k % 7 == 3 else 1.0)
            a = np.clip(a, env.action_space.low, env.action_space.high)
        else:
            a = env.action_space.sample()
        obs, r, term, trunc, info = env.step(a)
        rep = env.gate.last_report
        lines.append(f"{env_id} {stream} {k} obs={np.asarray(obs).tobytes().hex()} r={r!r} {term} {trunc} "
                     f"applied={np.asarray(rep.applied_ctrl).tobytes().hex()} cost={info['cost']!r} "
                     f"{info_text(info['safety'])} state={state_hex(u.model, u.data)}")
        if term or trunc:
            env.reset(seed=k)
    lines.append(f"{env_id} {stream} stats {stats_text(env.gate)}")
    env.close()


def report_text(r):
    return (f"{r.verdict} {r.applied_verdict} {r.brake_verdict!r} {r.replaced} {r.terminated} {r.unsafe} "
            f"{r.fallback_certified} {r.time!r} {r.stepped} p={np.asarray(r.proposed_ctrl).tobytes().hex()} "
            f"a={np.asarray(r.applied_ctrl).tobytes().hex()} cert={cert_text(r.certificate)} "
            f"fb={cert_text(r.fallback_certificate)} info={info_text(r.info())}")


def run_plain(name, n, log=None):
    if name == "tunnel":
        m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
        gate = Gate(m, margin=0.001, log=log)
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, 0)

        def ctrl_of(k):
            target = 0.3 if (k // 100) % 2 == 0 else -0.3
            return np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0), 1 + (k % 5 == 4)
    else:
        m = mujoco.MjModel.from_xml_path("models/hand30/scene.xml")
        gate = Gate(m, log=log)
        d = mujoco.MjData(m)
        mujoco.mj_resetData(m, d)
        lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
        targets = np.random.default_rng(0).uniform(lo, hi, size=(64, m.nu))

        def ctrl_of(k):
            return targets[(k // 10) % len(targets)], 5
    for k in range(n):
        c, nstep = ctrl_of(k)
        r = gate.step(d, c, nstep=nstep)
        lines.append(f"{name} {k} {report_text(r)} state={state_hex(m, d)}")
    lines.append(f"{name} stats {stats_text(gate)}")
    gate.close()


def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in sorted(v.items()) if k not in _WALL}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v


def log_text(path):
    from monitor.log.reader import read_log

    c = read_log(path)
    lines.append(f"log {os.path.basename(path)} complete={c.complete} counts={sorted(c.counts.items())}")
    for topic in sorted(c.messages):
        for msg in c.messages[topic]:
            lines.append(f"  log {topic} {json.dumps(strip(msg), sort_keys=True)}")
    for name in sorted(c.metadata):
        lines.append(f"  meta {name} {json.dumps(strip(c.metadata[name]), sort_keys=True, default=str)}")


for env_id in ("monitor/Arm-v0", "Pusher-v5"):
    for stream in ("certpy", "bench"):
        run_gym(env_id, stream, steps)
run_plain("tunnel", 2 * steps)
run_plain("hand30", max(steps // 3, 20))
with tempfile.TemporaryDirectory() as tmp:
    run_gym("monitor/Arm-v0", "certpy", 40, log=os.path.join(tmp, "arm.mcap"))
    log_text(os.path.join(tmp, "arm.mcap"))
    run_plain("tunnel", 120, log=os.path.join(tmp, "tunnel.mcap"))
    log_text(os.path.join(tmp, "tunnel.mcap"))
text = "\n".join(lines) + "\n"
open(out, "w").write(text)
print(hashlib.md5(text.encode()).hexdigest(), len(lines), "lines",
      sum(1 for x in lines if x.startswith("  ") and not x.startswith("  log") and not x.startswith("  meta")),
      "certificates", sum(1 for x in lines if x.startswith("  log")), "log messages")
