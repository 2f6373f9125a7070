"""Whole StepReports on seeded episodes do not depend on how the braking tail is simulated (issue 12, item 5).

Oracle: the same gate with ``Rollout.c_tail = False`` (every tail substep by a Python
``mj_step`` loop, the implementation before the C rollout). Compared per step: the whole
report (verdict, applied control, flags, brake verdict, fallback certificate), every
certificate field except wall-clock timings (pairs with methods, tests, intervals,
clearances, witnesses; stats), ``info["safety"]`` and the live state after the step.
Episodes: tunnel ``Gate.step`` (rejections, fallbacks, tail-covered windows), ``SafetyGate``
on Pusher-v5 (``pairs="mujoco"``) and monitor/Arm-v0 (brake rejections, replacements).

``docs/notes/issue-12-gate-3/digest.py`` prints the same digest for any tree; it was
compared against main (see the notes).
"""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np

import monitor.envs  # noqa: F401  (registers monitor/Arm-v0)
from monitor._paths import scene_path
from monitor.gate import Gate
from monitor.gym_gate import SafetyGate

_TIMING = ("wall_seconds", "certify_us")


def _cert_key(c):
    if c is None:
        return None
    d = c.to_dict()
    d["stats"] = {k: v for k, v in d["stats"].items() if k not in _TIMING}
    return repr(d)


def _info_key(info):
    return repr({k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in sorted(info.items())
                 if k not in _TIMING})


def report_key(r):
    """Everything a StepReport says, timings excluded (a string: compares bit for bit via repr)."""
    return (str(r.verdict), np.asarray(r.proposed_ctrl).tobytes(), np.asarray(r.applied_ctrl).tobytes(),
            r.replaced, r.terminated, r.unsafe, str(r.applied_verdict), r.fallback_certified, r.time,
            str(r.brake_verdict), r.stepped, _cert_key(r.certificate), _cert_key(r.fallback_certificate),
            _info_key(r.info()))


def _tunnel(c_tail: bool, steps: int):
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    rng = np.random.default_rng(1)
    ctrls = [np.array([rng.uniform(-6.0, 6.0)]) for _ in range(steps // 20 + 1)]
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m)
    gate._rollout.c_tail = c_tail
    out = []
    for k in range(steps):
        if k % 100 == 99:
            mujoco.mj_resetDataKeyframe(m, d, 0)
            gate.reset()
        r = gate.step(d, ctrls[k // 20])
        out.append((report_key(r), d.qpos.tobytes(), d.qvel.tobytes()))
    return out, gate.summary()


def _gym(env_id: str, c_tail: bool, steps: int, **kw):
    env = SafetyGate(gym.make(env_id), **kw)
    env.gate._rollout.c_tail = c_tail
    env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(steps)]
    env.reset(seed=0)
    out = []
    for a in acts:
        _, _, term, trunc, info = env.step(a)
        d = env.unwrapped.data
        out.append((report_key(env.gate.last_report), _info_key(info["safety"]), d.qpos.tobytes(),
                    d.qvel.tobytes()))
        if term or trunc:
            env.reset(seed=1)
    summary = env.gate.summary()
    env.close()
    return out, summary


def _same(new, old):
    assert len(new) == len(old)
    for k, (a, b) in enumerate(zip(new, old)):
        assert a == b, f"step {k}: C tail {a[0][:3]} != loop tail {b[0][:3]}"


def test_tunnel_reports_do_not_depend_on_the_tail_simulator():
    new, s = _tunnel(True, 120)
    old, _ = _tunnel(False, 120)
    _same(new, old)
    assert s["replaced"] > 0 and s["joint"] > 0  # both decision paths ran


def test_pusher_reports_do_not_depend_on_the_tail_simulator():
    new, s = _gym("Pusher-v5", True, 40, pairs="mujoco")
    old, _ = _gym("Pusher-v5", False, 40, pairs="mujoco")
    _same(new, old)
    assert s["joint"] > 0


def test_arm_reports_do_not_depend_on_the_tail_simulator():
    new, s = _gym("monitor/Arm-v0", True, 40)
    old, _ = _gym("monitor/Arm-v0", False, 40)
    _same(new, old)
    assert s["replaced"] > 0 and s["brake_rejected"] > 0 and s["joint"] > 0


def test_the_all_culled_shortcut_gives_the_info_built_from_the_pairs():
    """info["safety"] without building PairResults (every pair culled) equals the one built from them."""
    from collections import Counter

    from monitor.gate import _all_culled

    shortcuts = others = 0
    for env_id, kw in (("Pusher-v5", {"pairs": "mujoco"}), ("monitor/Arm-v0", {})):
        env = SafetyGate(gym.make(env_id), **kw)
        env.action_space.seed(0)
        env.reset(seed=0)
        pairs_seen = 0
        for _ in range(25):
            _, _, term, trunc, info = env.step(env.action_space.sample())
            cert = env.gate.last_report.certificate
            if _all_culled(cert) is not None:
                shortcuts += 1
            else:
                others += 1
            names = [str(p.method) for p in cert.pairs]  # the oracle: the pairs themselves
            pairs_seen += len(cert.pairs)
            counts = Counter(names)
            assert info["safety"]["checker"].tolist() == names
            assert info["safety"]["checker_mix"] == " ".join(f"{m}:{counts[m]}" for m in sorted(counts))
            assert info["safety"]["monitored_pairs"] == len(names)
            if term or trunc:
                env.reset(seed=1)
        env.close()
    assert shortcuts > 0 and others > 0  # both branches ran


def test_the_pair_count_from_the_stats_equals_the_built_pairs(monkeypatch):
    """Gate.stats["pairs"] is summed from each certificate's stats (no PairResult built); it must
    equal the number of pair results of every certificate the gate made: joint and two-call
    steps, reuse subsets (merged certificates), fallbacks and tail-covered windows. (The
    ongoing-contact rule's recombined certificates keep their pair list and stats; no episode
    here starts in contact.)"""
    from monitor.gate import Gate as _Gate

    certs = []
    real = _Gate._certify

    def spy(self, plan):
        cert, us = real(self, plan)
        certs.append(cert)
        return cert, us

    monkeypatch.setattr(_Gate, "_certify", spy)
    for run in (lambda: _tunnel(True, 120), lambda: _gym("monitor/Arm-v0", True, 30),
                lambda: _gym("Pusher-v5", True, 20, pairs="mujoco")):
        certs.clear()
        _, summary = run()
        assert certs
        assert sum(len(c.pairs) for c in certs) == sum(c.stats["pairs"] for c in certs)
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m, ongoing="deepen")
    certs.clear()
    for _ in range(60):
        gate.step(d, np.array([3.0]))
    assert gate.stats["pairs"] == sum(len(c.pairs) for c in certs)
    assert gate.stats["reused_pairs"] > 0 and gate.stats["replaced"] > 0


def _warm_arm_gate():
    m = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
    rng = np.random.default_rng(0)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m)
    for _ in range(3):
        gate.step(d, rng.uniform(m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]))
    return gate, d


def test_a_copied_gate_gives_the_same_reports():
    """A deep-copied or pickled Gate (after steps: its scratches, C tail and caches in use) decides
    exactly as the original on the same states. Regression: the copy's scratch control was a
    detached copy of the old view (every copied prediction ran under a stale control) and, with the
    C tail, the rollout object did not pickle."""
    import copy
    import pickle

    for clone in (copy.deepcopy, lambda g: pickle.loads(pickle.dumps(g))):
        gate, d = _warm_arm_gate()
        g2 = clone(gate)
        d2 = mujoco.MjData(g2.model)
        mujoco.mj_copyData(d2, g2.model, d)
        m = gate.model
        ctrls = np.random.default_rng(5).uniform(m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1],
                                                 size=(15, m.nu))
        for c in ctrls:
            r = gate.step(d, c)
            r2 = g2.step(d2, c)
            assert report_key(r2) == report_key(r)
            assert np.array_equal(d2.qpos, d.qpos) and np.array_equal(d2.qvel, d.qvel)
        assert g2.stats["joint"] > 0  # the braking tail ran in the copy
