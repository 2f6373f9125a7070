"""The committed braking tail is read from its rows, without building its Plan (issue 12, gate pass 6).

``Gate._tail_covers`` (is the next window inside the committed tail?) and ``Gate._tail_refuted``
(the pose at the tail's start, for the ongoing-contact rule) read the tail Plan's times, qpos
row, held mocap poses and start poses. They now take them from the tail's rows
(:meth:`monitor.gate._Tail.plan_qpos_row`, :meth:`~monitor.gate._Tail.plan_mocap_quat`) and
from the failed joint call's Plan (:meth:`monitor.gate.Gate._joint_poses_at_tail_start`).
Oracles: the tail's own Plan (built from the same rows as before), and the same gate with the
shortcuts off (every read through the Plan) on a seeded Arm episode: every report equal.
"""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import monitor.envs  # noqa: F401  (registers monitor/Arm-v0)
from monitor.errors import InvalidInputError
from monitor.gate import _Tail
from monitor.gym_gate import SafetyGate
from monitor.motion import plan as plan_mod
from monitor.tolerances import DEFAULT

_HINGE_MOCAP = """<mujoco><worldbody>
  <body name="m" mocap="true" pos="0 0 1"><geom type="box" size=".1 .1 .1"/></body>
  <body name="a"><joint type="hinge" axis="0 0 1"/><geom type="capsule" size=".05" fromto="0 0 0 .5 0 0"/>
    <body name="b" pos=".5 0 0"><joint type="slide" axis="1 0 0"/><geom type="sphere" size=".05"/></body>
  </body></worldbody></mujoco>"""
_FREE = """<mujoco><worldbody>
  <body name="f"><freejoint/><geom type="sphere" size=".1"/></body>
  <body name="m" mocap="true"><geom type="box" size=".1 .1 .1"/></body></worldbody></mujoco>"""


def _tail(xml: str, seed: int, mocap_quat: np.ndarray | None = None) -> tuple[mujoco.MjModel, _Tail]:
    """A _Tail of 6 random rows (time, qpos (quaternions off unit by up to 1e-7), qvel)."""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1, 1, (6, m.nq))
    if m.nq != m.nv:  # the free joint's quaternion, slightly off unit (the Plan normalises it)
        quat = rng.normal(size=(6, 4))
        q[:, 3:7] = quat / np.linalg.norm(quat, axis=1)[:, None] * (1 + rng.uniform(-1e-7, 1e-7, (6, 1)))
    if mocap_quat is not None:
        d.mocap_quat[:] = mocap_quat
    rows = np.c_[np.arange(6) * 0.01, q, rng.normal(size=(6, m.nv))]
    return m, _Tail(rows, m, d)


@pytest.mark.parametrize("xml", [_HINGE_MOCAP, _FREE])
def test_the_tails_plan_values_read_from_its_rows_are_the_plans_own(xml):
    off_unit = np.array([[1.0 + 3e-7, 1e-7, -2e-7, 0.0]])  # within quat_norm_tol: normalised by the Plan
    for seed in range(3):
        m, tail = _tail(xml, seed, off_unit)
        got = [tail.plan_qpos_row(k).tobytes() for k in range(6)], tail.plan_mocap_quat().tobytes()
        assert tail._plan is None or m.nq != m.nv  # hinge / slide only: no Plan was built for it
        _, oracle = _tail(xml, seed, off_unit)  # a fresh tail of the same rows: its Plan
        plan = oracle.plan
        assert got == ([plan.qpos[k].tobytes() for k in range(6)], plan.mocap_quat.tobytes())
        assert tail.mocap_pos.tobytes() == plan.mocap_pos.tobytes()
        assert tail.rows[:, 0].tobytes() == plan.times.tobytes()
    # the raw rows differ from the Plan's where it normalises: the shortcut is not a tautology
    assert tail.mocap_quat.tobytes() != plan.mocap_quat.tobytes()
    if m.nq != m.nv:
        assert tail.rows[0, 1:].tobytes() != plan.qpos[0].tobytes()


def test_a_mocap_quaternion_out_of_tolerance_raises_as_the_plan_does():
    _, tail = _tail(_HINGE_MOCAP, 0, np.array([[2.0, 0.0, 0.0, 0.0]]))
    with pytest.raises(InvalidInputError, match="mocap_quat"):
        tail.plan_mocap_quat()


def test_held_mocap_normalisation_memo_gives_the_plain_result_and_fresh_copies():
    rng = np.random.default_rng(3)
    refused = 0
    for _ in range(20):
        mq = rng.normal(size=(2, 4))
        mq /= np.linalg.norm(mq, axis=1)[:, None] * (1 + rng.uniform(-5e-7, 5e-7, (2, 1)))
        want = plan_mod._normalized(mq, DEFAULT).tobytes()
        a = plan_mod._normalized_mocap(mq, DEFAULT)
        a[:] = 0.0  # the caller owns it: the memo must not hand out its own array
        b = plan_mod._normalized_mocap(mq, DEFAULT)
        assert a is not b and b.tobytes() == want
        # another tolerance is another key: this one refuses offsets above 1e-9
        tight = dataclasses.replace(DEFAULT, quat_norm_tol=1e-9)
        if plan_mod._normalized(mq, tight) is None:
            with pytest.raises(InvalidInputError):
                plan_mod._normalized_mocap(mq, tight)
            refused += 1
    assert refused


def _arm_run(shortcuts: bool, steps: int):
    env = SafetyGate(gym.make("monitor/Arm-v0"))
    gate = env.gate
    built, poses = [], []
    if not shortcuts:
        gate._joint_poses_at_tail_start = lambda tail: None
    else:
        joint_poses = gate._joint_poses_at_tail_start

        def spy(tail):
            got = joint_poses(tail)
            if got is not None:
                poses.append((got, np.array(tail.rows), tail.mocap_pos.copy(), tail.mocap_quat.copy()))
            return got

        gate._joint_poses_at_tail_start = spy
    orig_qrow, orig_mq = _Tail.plan_qpos_row, _Tail.plan_mocap_quat
    env.action_space.seed(0)
    acts = []
    while len(acts) < steps:
        a = env.action_space.sample()
        acts += [a] * 6 + [env.action_space.sample() for _ in range(6)]
    env.reset(seed=0)
    out = []
    try:
        if not shortcuts:
            _Tail.plan_qpos_row = lambda self, k: self.plan.qpos[k]
            _Tail.plan_mocap_quat = lambda self: self.plan.mocap_quat
        for a in acts[:steps]:
            _, _, te, tr, info = env.step(a)
            r = gate.last_report
            tail = gate._tail
            built.append(tail is not None and tail[0]._plan is not None)
            cert = {k: v for k, v in r.certificate.to_dict().items() if k != "stats"}
            fb = r.fallback_certificate
            out.append((str(r.verdict), str(r.brake_verdict), r.applied_ctrl.tobytes(), r.replaced,
                        repr(cert), None if fb is None else repr(fb.to_dict()["pairs"]),
                        env.unwrapped.data.qpos.tobytes(), env.unwrapped.data.qvel.tobytes()))
            if te or tr:
                env.reset(seed=1)
    finally:
        _Tail.plan_qpos_row, _Tail.plan_mocap_quat = orig_qrow, orig_mq
    s = gate.summary()
    env.close()
    return out, s, built, poses


def test_arm_reports_equal_with_the_tail_read_through_its_plan():
    steps = 60
    new, s_new, built_new, poses = _arm_run(True, steps)
    old, s_old, built_old, _ = _arm_run(False, steps)
    # the joint Plan's poses at the tail's start are its own Plan's, bit for bit
    m = mujoco.MjModel.from_xml_path(gym.make("monitor/Arm-v0").unwrapped.fullpath)
    assert poses
    for (pos, rot), rows, mp, mq in poses:
        own = plan_mod.Plan._trusted(rows[:, 0].copy(), rows[:, 1:].copy(), model=m, mocap_pos=mp,
                                     mocap_quat=mq)
        p, r = own.body_poses(np.array([rows[0, 0]]))
        assert p.tobytes() == pos.tobytes() and r.tobytes() == rot.tobytes()
    assert new == old and s_new["tail_reused"] == s_old["tail_reused"]
    assert s_new["tail_reused"] > 0 and s_new["tail_refuted"] > 0 and s_new["joint"] > 0  # the paths ran
    assert sum(built_new) < sum(built_old)  # the shortcuts left tail Plans unbuilt
