"""A/B figures for the packscale change (run under each tree's PYTHONPATH; interleave the processes).

  python ab.py gate pusher|arm|hand30 [reps]    -> the bench's own per-step medians (gated, ungated, ratio)
  python ab.py replay pusher|arm|hand30 [steps] [rounds]
        -> per captured gate plan (the plans every certify call of `steps` gated steps packed),
           median us of Plan._trusted, trajectory_pack_memo (pack + _pack_agrees) and certify
           (fresh Plan copies each round), and digests of the packs / certificates.
"""
from __future__ import annotations

import gc
import hashlib
import json
import statistics
import sys
import time
import types

import numpy as np

WL = {"pusher": "Pusher-v5", "arm": "monitor/Arm-v0"}


def gate_fig(name: str, reps: int) -> dict:
    from monitor.bench import targets as T
    if name == "hand30":
        cfg = types.SimpleNamespace(quick=True, smoke=False, seed=7, reps=reps)
        r = T.hand30_gate(cfg)
    else:
        r = T.gym_gate(WL[name], pairs="mujoco", steps_gated=10, steps_ungated=200, reps=reps)
    return {k: r[k] for k in ("gated_s", "ungated_s", "ratio", "verdicts")}


def capture(name: str, steps: int):
    """(scene, [(plan, request)]) of the certify calls of `steps` gated steps."""
    import monitor.certify.kernels as KS
    from monitor.warmup import ensure_warm
    ensure_warm()
    got = []
    orig = KS.trajectory_pack_memo
    holder = {}

    def spy(traj):
        g = holder["gate"]
        got.append((traj, g._call_request or g._request or g.request))
        return orig(traj)

    KS.trajectory_pack_memo = spy
    try:
        if name == "hand30":
            import mujoco

            from monitor.bench.targets import _scene_file
            from monitor.gate import Gate
            model = mujoco.MjModel.from_xml_path(str(_scene_file("hand30")))
            lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
            targets = np.random.default_rng(7).uniform(lo, hi, size=(64, model.nu))
            gate = Gate(model)
            holder["gate"] = gate
            d = mujoco.MjData(model)
            mujoco.mj_resetData(model, d)
            for k in range(steps):
                gate.step(d, targets[(k // 10) % 64], nstep=5)
            scene = gate.scene
        else:
            import gymnasium as gym
            if name == "arm":
                import monitor.envs  # noqa: F401
            from monitor.gym_gate import SafetyGate
            env = SafetyGate(gym.make(WL[name]), pairs="mujoco")
            holder["gate"] = env.gate
            env.reset(seed=3)
            env.action_space.seed(3)
            for _ in range(steps):
                _, _, term, trunc, _ = env.step(env.action_space.sample())
                if term or trunc:
                    env.reset()
            scene = env.gate.scene
    finally:
        KS.trajectory_pack_memo = orig
    return scene, got


def fresh(plan):
    from monitor.motion.plan import Plan
    return Plan._trusted(plan.times.copy(), plan.qpos.copy(), plan.model, mocap_pos=plan.mocap_pos,
                         mocap_quat=plan.mocap_quat, tolerances=plan._tol)


def replay(name: str, steps: int, rounds: int) -> dict:
    import monitor.certify.kernels as KS
    from monitor.certify.engine import certify
    from monitor.motion.kernel import TOL_SCALE
    scene, got = capture(name, steps)
    got = [(p, r) for p, r in got if type(p).__name__ == "Plan"]
    t_trusted, t_pack, t_cert = [], [], []
    h_pack, h_cert = hashlib.sha256(), hashlib.sha256()
    scales = []
    Ks = sorted({p.times.shape[0] for p, _ in got})
    gc.collect()
    for rnd in range(rounds):
        for plan, req in got:
            a = time.perf_counter_ns()
            p1 = fresh(plan)
            b = time.perf_counter_ns()
            mp, _ = KS.trajectory_pack_memo(p1)
            c = time.perf_counter_ns()
            p2 = fresh(plan)
            d = time.perf_counter_ns()
            cert = certify(scene, p2, request=req)
            e = time.perf_counter_ns()
            t_trusted.append((b - a) / 1e3)
            t_pack.append((c - b) / 1e3)
            t_cert.append((e - d) / 1e3)
            if rnd == 0:
                for f, v in zip(mp._fields, mp, strict=True):
                    if f == "tol":
                        v = np.delete(v, TOL_SCALE)
                        scales.append(float(mp.tol[TOL_SCALE]))
                    h_pack.update(f.encode() + v.tobytes())
                for pc in getattr(cert, "pairs", []) or []:
                    h_cert.update(repr((getattr(pc, "verdict", None), getattr(pc, "clearance", None))).encode())
                h_cert.update(repr(cert.verdict).encode())
    med = statistics.median
    verdicts = {}
    for plan, req in got:
        v = str(certify(scene, fresh(plan), request=req).verdict)
        verdicts[v] = verdicts.get(v, 0) + 1
    return {"calls": len(got), "K": Ks, "trusted_us": med(t_trusted), "pack_memo_us": med(t_pack),
            "certify_us": med(t_cert), "pack_digest_wo_scale": h_pack.hexdigest()[:16],
            "cert_digest": h_cert.hexdigest()[:16], "scale_median": med(scales) if scales else None,
            "verdicts": verdicts}


if __name__ == "__main__":
    mode, name = sys.argv[1], sys.argv[2]
    if mode == "gate":
        out = gate_fig(name, int(sys.argv[3]) if len(sys.argv) > 3 else 7)
    else:
        out = replay(name, int(sys.argv[3]) if len(sys.argv) > 3 else 30,
                     int(sys.argv[4]) if len(sys.argv) > 4 else 5)
    import monitor
    out["tree"] = monitor.__file__
    print(json.dumps(out))
