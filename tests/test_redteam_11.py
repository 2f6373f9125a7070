"""Red team 11: review's re-simulation of logged rollouts, the engine's whole-shape route.

Each test is a finding of ``docs/notes/redteam-11.md`` (it failed on 0453413) or a check that held.
Forgeries are made as ``tests/test_review_replay.py`` makes them (``mcap_rewrite.rewrite``, re-sealed).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from test_review_replay import (
    BOUNCE,
    INTEGRATION,
    _bounce_log,
    _edit_plan,
    _findings,
    _forge,
    _recertified,
    _verify,
)

from monitor.gate import Gate
from monitor.log import read_log, replay, topics


@pytest.fixture(scope="module")
def bounce(tmp_path_factory):
    path = tmp_path_factory.mktemp("rt11") / "bounce.mcap"
    model, _ = _bounce_log(path)  # Gate (warn), 6 windows of 50 substeps, window 2 bounces off a wall
    return path, model


@pytest.mark.parametrize("substeps", [51, replay.MAX_SUBSTEPS])
def test_a_forged_substep_count_is_refused_before_it_is_simulated(bounce, tmp_path, monkeypatch, substeps):
    """A rollout whose substeps disagree with its logged rows (51 logged) is a critical finding without
    a re-simulation: on 0453413 review simulated up to MAX_SUBSTEPS (10**6) substeps per plan and kept
    (substeps, nstate) floats, seconds of mj_step and megabytes for every forged plan of a log."""
    path, _ = bounce
    dst = tmp_path / "huge.mcap"

    def more(o):
        o["rollout"]["segments"][0]["substeps"] = substeps

    _forge(path, dst, msg=_edit_plan(1, more))
    simulated = []
    real = replay.resimulate

    def counted(model, data, ro):
        simulated.append(ro.substeps - ro.rows_from + 1)
        assert ro.substeps <= 50, "review re-simulated a rollout longer than its logged rows"
        return real(model, data, ro)

    monkeypatch.setattr(replay, "resimulate", counted)
    code, ver = _verify(dst)
    assert code == 1 and simulated == [51] * 5  # the five genuine windows, not the forged one
    crit = _findings(ver, "critical")
    assert [k for k, _ in crit] == [1], crit
    assert f"51 logged row(s), the rollout makes {substeps + 1}" in crit[0][1]


@pytest.fixture(scope="module")
def edited(tmp_path_factory):
    """The bounce run with a genuine in-place edit (the ball's damping) before window 3."""
    m = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0
    path = tmp_path_factory.mktemp("rt11") / "edited.mcap"
    with Gate(m, log=path, frame_skip=50, allowed=None, on_violation="warn") as g:
        for k in range(5):
            if k == 3:
                m.dof_damping[0] = 1e-3
            g.step(d, np.zeros(1))
    code, ver = _verify(path, trust_model_edits=True)
    assert code == 0 and ver["replayed"] == 5, ver["findings"]
    return path, m


def _edit_record(fields=None, options=None):
    """A forger's rewrite of the log's one model edit record."""
    def metadata(name, values):
        if name == topics.METADATA_MODEL_EDIT:
            assert values["window"] == 3
            values["fields"].update(fields or {})
            values.setdefault("options", {}).update(options or {})
        return values
    return metadata


@pytest.mark.parametrize("field, values", [
    ("jnt_qposadr", [10**8]),          # 0453413: a segmentation fault in the motion packer
    ("body_parentid", [0, 0, 10**6]),  # 0453413: IndexError traceback from Scene.from_model
    ("jnt_dofadr", [-5]),
    ("geom_type", [7, 6]),             # the wall made a mesh with no mesh data
])
def test_a_model_edit_record_that_moves_model_structure_is_malformed(edited, tmp_path, field, values):
    path, m = edited
    dst = tmp_path / "structure.mcap"
    record = {field: {"shape": list(getattr(m, field).shape), "values": values}}
    _forge(path, dst, metadata=_edit_record(record))
    code, ver = _verify(dst, trust_model_edits=True)
    assert code == 2 and not _findings(ver, "critical"), ver["findings"]
    assert any(f"field {field}: changes model structure" in r for _, r in _findings(ver, "unverifiable"))


@pytest.mark.parametrize("field, values", [("geom_type", [2, 2]), ("geom_contype", [1, 2]),
                                           ("geom_condim", [3, 1]), ("geom_priority", [0, 1])])
def test_in_place_edits_of_integer_arrays_users_make_are_still_applied(edited, tmp_path, field, values):
    """Legitimate in-place edits (``tests/test_model_edits.py`` turns geoms into planes; collision
    bits and condim are randomised): not refused as structure (the edit is not the run's: the rows
    may then not re-simulate, which is the forgery's own finding)."""
    path, _ = edited
    dst = tmp_path / "legit.mcap"
    _forge(path, dst, metadata=_edit_record({field: {"shape": [2], "values": values}}))
    code, ver = _verify(dst, trust_model_edits=True)
    assert not any("malformed" in f["reason"] for f in ver["findings"]), ver["findings"]
    assert ver["replayed"] + ver["replay_failed"] == 5


def test_an_option_mujoco_refuses_is_a_finding_not_a_traceback(edited, tmp_path):
    """``integrator`` 99 in a model edit record: 0453413 let ``mujoco.FatalError`` out of review."""
    path, _ = edited
    dst = tmp_path / "integrator.mcap"
    _forge(path, dst, metadata=_edit_record(options={"integrator": 99}))
    code, ver = _verify(dst, trust_model_edits=True)
    crit = _findings(ver, "critical")
    assert code == 1 and [k for k, _ in crit] == [3, 4], crit
    assert all("cannot be re-simulated: mj_step: invalid integrator" in r for _, r in crit)


def test_a_format_3_gate_log_stripped_of_its_rollouts_is_unverifiable(bounce, tmp_path):
    """Every plan's ``rollout`` and ``source`` and the run's ``rollouts`` key removed, ``format_version``
    left at 3: on 0453413 the old-log note and exit 0 (the forger need not even claim format 2)."""
    path, _ = bounce
    dst = tmp_path / "stripped.mcap"

    def strip(topic, o):
        if topic == topics.PLAN:
            o.pop("rollout"), o.pop("source")
        return o

    def unmark(name, values):
        if name == topics.METADATA_RUN:
            assert values.pop(topics.ROLLOUTS_KEY) == "logged" and values["format_version"] == 3
        return values

    _forge(path, dst, msg=strip, metadata=unmark)
    code, ver = _verify(dst)
    assert code == 2 and ver["replayed"] == 0 and not _findings(ver, "critical")
    assert any("which marks its rollouts" in r for _, r in _findings(ver, "unverifiable"))


_FREE_BOX = """<mujoco><worldbody>
  <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.6 0 0.5"/>
  <body name="cart" pos="0 0 0.5"><freejoint/><geom name="box" type="box" size="0.1 0.1 0.1"/></body>
</worldbody></mujoco>"""


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_fuzz_free_body_quaternion_signs_against_the_closed_form_gap(seed):
    """A free box that only translates (x, at the wall's height) while its identity orientation is written as
    q or -q at random per row (the same rotation: slerp takes the shortest arc), so the body may be flagged
    rotating and take the whole-shape route. Oracle: the gap to the wall's face on the piecewise-linear x,
    0.55 - (max x + 0.1). No method certifies a touching path or reports a violation on a clear one."""
    from monitor.certify.engine import certify
    from monitor.errors import InvalidInputError
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    m = mujoco.MjModel.from_xml_string(_FREE_BOX)
    scene = Scene.from_model(m, pairs="all", allowed=None)
    rng = np.random.default_rng(seed)
    seen = set()
    for _ in range(40):
        n = int(rng.integers(2, 6))
        x = np.sort(rng.uniform(-0.2, 0.5, n)) if rng.random() < 0.5 else rng.uniform(0.2, 0.46, n)
        q = np.zeros((n, 7))
        q[:, 0], q[:, 2], q[:, 3] = x, 0.5, rng.choice([-1.0, 1.0], n)
        gap = 0.55 - (x.max() + 0.1)  # x is linear between rows: its max is at a row
        verdicts = {}
        for method in ("auto", "toleranced", "extrusion"):
            try:
                verdicts[method] = str(certify(scene, Plan(np.linspace(0, 0.1, n), q, m), margin=0.0,
                                               epsilon=1e-3, method=method).verdict)
            except InvalidInputError:   # extrusion refuses a body flagged rotating
                continue
            assert not (verdicts[method] == "certified" and gap <= 0), (method, x, q[:, 3])
            assert not (verdicts[method] == "violation" and gap > 1e-9), (method, x, q[:, 3])
        seen |= set(verdicts.values())
        assert len(set(verdicts.values()) - {"uncertain"}) <= 1, verdicts
    assert {"certified", "violation"} <= seen


def test_step_windows_whose_rows_skip_their_logged_start_state_are_unverifiable(bounce, tmp_path):
    """Windows 2..5 re-made from fabricated states one substep earlier (the ball at rest where the run's
    window starts: 51 substeps, ``rows_from`` 1, rows re-simulated bit for bit from them, re-certified): on
    0453413 exit 0 with window 2's violation gone, since a window with ``rows_from > 0`` gave the
    continuity checks no start state (only 1 of 5 left). A gate's step windows start at substep 0."""
    path, model = bounce
    contents = read_log(path)
    forged = {}
    for k in range(2, 6):
        ro = replay.decode(contents.plans_by_index()[k]["rollout"], model)
        pre = ro.state.copy()
        pre[0] -= model.opt.timestep
        pre[1 + model.nq:1 + model.nq + model.nv] = 0.0
        segments = ((ro.segments[0][0], 51),)
        plan, _ = replay.resimulate(model, mujoco.MjData(model), replay.Rollout(pre, segments, 1))
        assert plan.times[0] == ro.state[0]  # the rows start where the run's window starts
        cert = _recertified(model, k, plan.times, plan.qpos, contents)
        assert cert["verdict"] == "certified"
        payload = replay.encode((pre, segments, 1), int(INTEGRATION), pre.size, model.nu)
        forged[k] = ({"times": plan.times.tolist(), "qpos": plan.qpos.tolist(), "rollout": payload}, cert)
    assert contents.certificates()[2]["verdict"] == "violation"

    def msg(topic, o):
        if o.get("index") not in forged:
            return o
        rows, cert = forged[o["index"]]
        if topic == topics.PLAN:
            return {**o, **rows}
        if topic == topics.CERTIFICATE:
            return cert
        return None if topic in (topics.VIOLATION, topics.LOG) else o

    dst = tmp_path / "rows_from.mcap"
    _forge(path, dst, msg=msg)
    code, ver = _verify(dst)
    assert code == 2 and not _findings(ver, "critical"), ver["findings"]
    off = [(k, r) for k, r in _findings(ver, "unverifiable") if "rows start at substep 1" in r]
    assert [k for k, _ in off] == [2, 3, 4, 5], ver["findings"]


def test_a_braking_tail_moved_off_the_substep_times_does_not_skip_the_continuity_checks(tmp_path):
    """SafetyGate(monitor/Arm-v0) run with blocked steps: the first braking-tail record's start time moved by
    5e-13 s (below the applied-motion checks' 1e-12 s slack), its rows re-simulated from it (bit for bit).
    Its rows then miss the next steps' start times, and on 0453413 the continuity of the steps it ran was
    skipped without a word (exit 0; a forger can then also edit what the tail's state holds beyond qpos)."""
    from test_review_applied import _arm_run

    from monitor.log.reader import load_model

    path = tmp_path / "arm.mcap"
    _arm_run(path, steps=12)
    contents = read_log(path)
    model, _ = load_model(contents, "mjb")
    tails = [c["index"] for c in contents.certificates()
             if (c.get("applied") or {}).get("kind") == "brake_tail"]
    assert tails
    k = tails[0]
    p = contents.plans_by_index()[k]
    ro = replay.decode(p["rollout"], model)
    state = ro.state.copy()
    state[0] += 5e-13
    plan, _ = replay.resimulate(model, mujoco.MjData(model), replay.Rollout(state, ro.segments, ro.rows_from))
    assert np.array_equal(plan.qpos, np.asarray(p["qpos"])) and not np.array_equal(plan.times, p["times"])
    payload = replay.encode((state, ro.segments, ro.rows_from), int(INTEGRATION), state.size, model.nu)
    dst = tmp_path / "shifted.mcap"
    _forge(path, dst, msg=_edit_plan(k, lambda o: o.update(times=plan.times.tolist(), rollout=payload)))
    code, ver = _verify(dst)
    assert code == 2 and not _findings(ver, "critical"), ver["findings"]
    off = [r for _, r in _findings(ver, "unverifiable") if f"applied motion record {k} that ran in step" in r]
    assert off and all("without a row there" in r for r in off)
