"""The gate's per-step plumbing, vectorised: same numbers as the scalar definitions (issue 12, item 5).

Oracles are the scalar per-actuator / per-body definitions written out here (independent of
the vectorised code): ``hold_ctrl``'s formula per actuator, and "a body moves when a joint of
its chain (up to the world or a mocap body) changes" walked body by body.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor._paths import scene_path
from monitor.gate import hold_ctrl
from monitor.motion.plan import Plan

_HINGE, _SLIDE = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
_FREE, _BALL = int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL)

_MIXED = """
<mujoco>
  <worldbody>
    <body name="mocap" mocap="true" pos="1 0 0">
      <geom size="0.05"/>
      <body name="under_mocap"><joint type="hinge" axis="0 0 1"/><geom size="0.05" pos="0.2 0 0"/></body>
    </body>
    <body name="free" pos="0 1 0"><freejoint/><geom size="0.05"/>
      <body name="on_free"><joint type="ball"/><geom size="0.05" pos="0 0.2 0"/>
        <body name="slider"><joint type="slide" axis="1 0 0"/><geom size="0.05" pos="0 0.4 0"/></body>
      </body>
    </body>
    <body name="arm" pos="0 -1 0"><joint name="j0" type="hinge" axis="0 0 1"/><geom size="0.05"/>
      <body name="fore" pos="0.3 0 0"><joint name="j1" type="hinge" axis="0 1 0"/><geom size="0.05"/>
        <body name="tip" pos="0.3 0 0"><joint name="j2" type="slide" axis="1 0 0"/><geom size="0.05"/></body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <position joint="j0" kp="10" ctrlrange="-1 1"/>
    <position joint="j1" kp="5" gear="2"/>
    <velocity joint="j2" kv="3"/>
    <motor joint="j1" ctrlrange="-2 2"/>
    <general joint="j2" gaintype="fixed" biastype="affine" gainprm="4" biasprm="0.5 -2 0"/>
  </actuator>
</mujoco>
"""


def _forest(chains: int = 60, depth: int = 5) -> str:
    """chains x depth hinge bodies (nbody * nq > 2^16: the per-depth propagation path)."""
    out = []
    for c in range(chains):
        body = ""
        for k in reversed(range(depth)):
            joint = '<joint type="hinge" axis="0 0 1"/>' if k else '<joint type="slide" axis="1 0 0"/>'
            pos = "0.1 0 0" if k else f"{c} 0 0"
            body = f'<body pos="{pos}">{joint}<geom size="0.01"/>{body}</body>'
        out.append(body)
    return f"<mujoco><worldbody>{''.join(out)}</worldbody></mujoco>"


def _models():
    return {"forest": mujoco.MjModel.from_xml_string(_forest()),
            "mixed": mujoco.MjModel.from_xml_string(_MIXED),
            "arm": mujoco.MjModel.from_xml_path(str(scene_path("arm"))),
            "tunnel": mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))}


def _hold_scalar(model, data):
    """hold_ctrl's documented formula, one actuator at a time."""
    ctrl = np.zeros(model.nu)
    for a in range(model.nu):
        if (model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT
                or model.actuator_biastype[a] != mujoco.mjtBias.mjBIAS_AFFINE
                or model.actuator_gaintype[a] != mujoco.mjtGain.mjGAIN_FIXED):
            continue
        gain = model.actuator_gainprm[a, 0]
        b0, b1 = model.actuator_biasprm[a, 0], model.actuator_biasprm[a, 1]
        j = model.actuator_trnid[a, 0]
        if gain == 0.0 or b1 == 0.0 or model.jnt_type[j] not in (_HINGE, _SLIDE):
            continue
        ctrl[a] = -(b0 + b1 * (model.actuator_gear[a, 0] * data.qpos[model.jnt_qposadr[j]])) / gain
        if model.actuator_ctrllimited[a]:
            ctrl[a] = min(max(ctrl[a], model.actuator_ctrlrange[a, 0]), model.actuator_ctrlrange[a, 1])
    for a in range(model.nu):
        if model.actuator_ctrllimited[a]:
            ctrl[a] = min(max(ctrl[a], model.actuator_ctrlrange[a, 0]), model.actuator_ctrlrange[a, 1])
    return ctrl


@pytest.mark.parametrize("name", ["mixed", "arm", "tunnel"])
def test_hold_ctrl_matches_the_per_actuator_formula(name):
    m = _models()[name]
    d = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    nonzero = 0
    for _ in range(40):
        mujoco.mj_resetData(m, d)
        d.qpos[:] += rng.normal(0.0, 0.7, m.nq)
        got = hold_ctrl(m, d)
        assert np.array_equal(got, _hold_scalar(m, d))
        nonzero += int(np.count_nonzero(got))
    if name != "tunnel":  # the tunnel has a velocity servo only: hold = 0
        assert nonzero > 0


def test_hold_ctrl_reads_an_edited_model():
    m = mujoco.MjModel.from_xml_string(_MIXED)
    d = mujoco.MjData(m)
    d.qpos[m.jnt_qposadr[m.joint("j1").id]] = 0.3
    before = hold_ctrl(m, d)
    m.actuator_gear[1, 0] = 3.0  # domain randomisation of the gear, in place
    after = hold_ctrl(m, d)
    assert before[1] == pytest.approx(0.6) and after[1] == pytest.approx(0.9)
    assert np.array_equal(after, _hold_scalar(m, d))


def test_hold_ctrl_sees_in_place_edits_of_the_structure_it_caches():
    """hold_ctrl caches which actuators it computes per model; every structure or value array
    it reads, edited in place after a first call, must still be read as it is now."""
    m = mujoco.MjModel.from_xml_string(_MIXED)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(3)
    d.qpos[:] = rng.normal(0.0, 0.7, m.nq)
    pos = 1  # the unlimited <position> actuator on j1 (gear 2)
    jnt = int(m.actuator_trnid[pos, 0])
    assert m.actuator_biastype[pos] == mujoco.mjtBias.mjBIAS_AFFINE and not m.actuator_ctrllimited[pos]

    def limit(lo, hi):
        m.actuator_ctrllimited[pos] = 1
        m.actuator_ctrlrange[pos] = (lo, hi)
    edits = [
        ("actuator_biastype", lambda: m.actuator_biastype.__setitem__(pos, mujoco.mjtBias.mjBIAS_NONE)),
        ("actuator_gaintype", lambda: m.actuator_gaintype.__setitem__(pos, mujoco.mjtGain.mjGAIN_USER)),
        ("actuator_trntype", lambda: m.actuator_trntype.__setitem__(pos, mujoco.mjtTrn.mjTRN_SITE)),
        ("actuator_ctrllimited", lambda: m.actuator_ctrllimited.__setitem__(pos, 1)),  # range (0, 0)
        ("actuator_ctrlrange", lambda: limit(-1e-3, 1e-3)),
        ("actuator_gainprm", lambda: m.actuator_gainprm.__setitem__((pos, 0), 0.0)),
        ("actuator_biasprm", lambda: m.actuator_biasprm.__setitem__((pos, 1), 0.0)),
        ("jnt_type", lambda: m.jnt_type.__setitem__(jnt, mujoco.mjtJoint.mjJNT_FREE)),
    ]
    for name, edit in edits:
        saved = {f: np.array(getattr(m, f)) for f in (
            "actuator_biastype", "actuator_gaintype", "actuator_trntype", "actuator_ctrllimited",
            "actuator_ctrlrange", "actuator_gainprm", "actuator_biasprm", "jnt_type")}
        before = hold_ctrl(m, d)  # fills the cache
        assert before[pos] != 0.0 and np.array_equal(before, _hold_scalar(m, d))
        edit()
        after = hold_ctrl(m, d)
        assert np.array_equal(after, _hold_scalar(m, d)), name
        assert after[pos] != before[pos], name
        for f, v in saved.items():
            getattr(m, f)[...] = v


def _moving_scalar(model, changes):
    """(moving, rotating) body masks walked body by body from the changed qpos columns."""
    width = {_FREE: 7, _BALL: 4, _SLIDE: 1, _HINGE: 1}
    moving = np.zeros(model.nbody, bool)
    rotating = np.zeros(model.nbody, bool)
    for b in range(1, model.nbody):
        if model.body_mocapid[b] >= 0:
            continue
        own_m = own_r = False
        for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            a, typ = model.jnt_qposadr[j], model.jnt_type[j]
            cols = changes[a:a + width[typ]]
            own_m |= bool(cols.any())
            if typ in (_HINGE, _BALL):
                own_r |= bool(cols.any())
            elif typ == _FREE:
                own_r |= bool(changes[a + 3:a + 7].any())
        p = model.body_parentid[b]
        moving[b] = own_m or moving[p]
        rotating[b] = own_r or rotating[p]
    return moving, rotating


@pytest.mark.parametrize("name", ["mixed", "arm", "tunnel", "forest"])
def test_plan_moving_and_rotating_bodies_match_the_chain_walk(name):
    m = _models()[name]
    d = mujoco.MjData(m)
    mujoco.mj_resetData(m, d)
    rng = np.random.default_rng(1)
    for trial in range(30):
        q0 = np.array(d.qpos)
        q1 = q0.copy()
        changes = rng.random(m.nq) < (0.3 if trial % 3 else 0.0)  # some windows move nothing
        q1[changes] += rng.normal(0.0, 0.2, int(changes.sum()))
        mujoco.mj_normalizeQuat(m, q1)
        changes = q1 != q0
        for ctor in ("public", "trusted"):
            if ctor == "public":
                plan = Plan(np.array([0.0, 0.1]), np.stack([q0, q1]), m)
            else:
                plan = Plan._trusted(np.array([0.0, 0.1]), np.stack([q0, q1]), model=m,
                                     mocap_pos=np.array(d.mocap_pos), mocap_quat=np.array(d.mocap_quat))
            moving, rotating = _moving_scalar(m, changes)
            assert np.array_equal(plan.moving_bodies(), moving), (trial, ctor)
            assert np.array_equal(plan._rotating, rotating), (trial, ctor)


def _null_unknown_reference(x):
    """The log's rule, written out: floats that are not < 1e308 in magnitude (stand-ins, NaN) -> None."""
    if isinstance(x, dict):
        return {k: _null_unknown_reference(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_null_unknown_reference(v) for v in x]
    if isinstance(x, float) and not abs(x) < 1e308:
        return None
    return x


def test_log_null_unknown_fast_path_matches_the_rule():
    from collections import OrderedDict

    from monitor.log.writer import _null_unknown

    value = {"a": 1e308, "b": -1e308, "c": 1.5, "d": float("nan"), "e": [1, (2.0, 1e308), None, "x", True],
             "f": {"g": np.float64(1e308), "h": np.float64(0.25), "i": np.int64(3)},
             "j": OrderedDict(k=-1e308, m=[np.float32(2.0)]), "n": float("inf"), "o": 1.7976931348623157e308,
             "p": 9.999999999999999e307}
    got, want = _null_unknown(value), _null_unknown_reference(value)
    assert got == want
    assert [type(v) for v in got.values()] == [type(v) for v in want.values()]
    assert got["a"] is None and got["o"] is None and got["p"] == 9.999999999999999e307
    assert got["f"]["g"] is None and got["j"]["k"] is None and got["e"][1] == [2.0, None]


def test_hold_ctrl_clip_follows_ctrllimited_edits_on_an_all_limited_model():
    """Every actuator limited: the clip runs on whole columns; unlimiting one in place is seen."""
    m = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
    d = mujoco.MjData(m)
    assert m.actuator_ctrllimited.all()
    d.qpos[:] = 10.0  # far outside every ctrlrange: each position servo's hold is clipped
    before = hold_ctrl(m, d)
    assert np.array_equal(before, _hold_scalar(m, d))
    assert np.array_equal(before, m.actuator_ctrlrange[:, 1])
    m.actuator_ctrllimited[0] = 0
    after = hold_ctrl(m, d)
    assert np.array_equal(after, _hold_scalar(m, d))
    assert after[0] != before[0] and np.array_equal(after[1:], before[1:])
    # every actuator position-like (whole-column formula) until a value edit makes one of
    # them hold 0: then the per-actuator selection decides
    rng = np.random.default_rng(5)
    for field, col in (("actuator_gainprm", 0), ("actuator_biasprm", 1)):
        d.qpos[:] = rng.normal(0.0, 0.3, m.nq)
        whole = hold_ctrl(m, d)
        assert np.array_equal(whole, _hold_scalar(m, d)) and np.count_nonzero(whole) == m.nu
        saved = getattr(m, field)[1, col]
        getattr(m, field)[1, col] = 0.0
        edited = hold_ctrl(m, d)
        assert np.array_equal(edited, _hold_scalar(m, d)), field
        assert edited[1] == 0.0 and np.array_equal(edited[[0, 2]], whole[[0, 2]]), field
        getattr(m, field)[1, col] = saved


def test_step_report_fast_constructors_match_the_dataclass():
    """StepReport._trusted / _stepped write the same instance state as the dataclass's
    __init__ / dataclasses.replace (compared field by field and as whole __dict__s)."""
    import dataclasses

    from monitor.certify.certificate import Certificate
    from monitor.gate import StepReport

    cert = Certificate("certified", (0.0, 0.1), 0.0, 1e-3, "auto", None, None, 0.5, (), {"pairs": 0}, ())
    args = ("certified", cert, np.zeros(2), np.ones(2), True, False, True, "violation", cert, False, 12.5,
            0.25, "plan-object", "certified")
    slow = StepReport(*args[:13], brake_verdict=args[13])
    fast = StepReport._trusted(*args)
    assert fast.__dict__ == slow.__dict__ and fast == slow
    assert all(getattr(fast, f.name) is getattr(slow, f.name) for f in dataclasses.fields(StepReport))
    stepped = fast._stepped()
    assert stepped.__dict__ == dataclasses.replace(slow, stepped=True).__dict__ and not fast.stepped
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.verdict = "violation"


def test_window_rows_are_the_states_with_row_zero_normalised():
    """Rollout.states / window_rows: the state at the window start with its quaternions
    normalised (a hand-set, non-unit one too), then each substep's state as an independent
    MjData stepped from a copy gives it; the caller's data untouched; window_rows read-only."""
    from monitor.gate import Rollout

    m = mujoco.MjModel.from_xml_string(_MIXED)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(11)
    d.qpos[:] = rng.normal(0.0, 0.5, m.nq)
    free = m.jnt_qposadr[next(j for j in range(m.njnt) if m.jnt_type[j] == _FREE)]
    d.qpos[free + 3:free + 7] = [0.6, 0.8, 0.0, 0.0]
    d.qpos[free + 3:free + 7] *= 1.0 + 1e-7  # a state set by hand: not unit
    d.ctrl[:] = rng.normal(0.0, 1.0, m.nu)
    before = np.array(d.qpos)
    ro = Rollout(m)
    times, qpos = ro.states(d, None, 3)
    oracle = mujoco.MjData(m)
    mujoco.mj_copyData(oracle, m, d)
    q0 = np.array(d.qpos)
    mujoco.mj_normalizeQuat(m, q0)
    want_t, want_q = [d.time], [q0]
    for _ in range(3):
        mujoco.mj_step(m, oracle)
        want_t.append(oracle.time)
        want_q.append(np.array(oracle.qpos))
    assert np.array(want_t).tobytes() == times.tobytes()
    assert np.array(want_q).tobytes() == qpos.tobytes()
    assert not np.array_equal(q0, before)  # row 0 really was normalised
    assert d.qpos.tobytes() == before.tobytes()  # the caller's data untouched
    rows = ro.window_rows
    assert rows[:, 0].tobytes() == times.tobytes() and rows[:, 1:].tobytes() == qpos.tobytes()
    assert not rows.flags.writeable
    qpos[0, 0] += 1.0  # states' arrays are the caller's own
    assert rows[0, 1] != qpos[0, 0]
