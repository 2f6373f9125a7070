"""``review --verify`` re-simulates the gate's own windows from their logged rollouts.

A gate logs, with every plan whose rows come from its MuJoCo rollout, the integration state the
rollout started from and the control of every substep (``monitor.log.replay``); review re-simulates
those rows on the attached model and checks them bit for bit, and checks that consecutive steps
continue each other. Oracles: the live ``MjData`` (the test reads its integration state before
every step), a closed-form bounce (a free sphere with zero control reflected by an elastic wall:
its end points clear the wall, its interior does not), and the forger's edit, which we know.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from mcap_rewrite import rewrite
from test_log_digest import seal_copy
from test_review_applied import _arm_run

from monitor import review
from monitor.certify.engine import certify
from monitor.gate import Gate
from monitor.log import read_log, replay, topics
from monitor.log.writer import _null_unknown
from monitor.motion.plan import Plan

INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION
BOUNCE = """
<mujoco model="bounce">
  <option timestep="0.002" gravity="0 0 0"/>
  <worldbody>
    <body name="wall"><geom name="wall" type="box" size="0.005 0.2 0.2" solref="-20000 -5"/></body>
    <body name="ball">
      <joint name="x" type="slide" axis="1 0 0" damping="0"/>
      <geom name="ball" type="sphere" size="0.01" mass="0.01" solref="-20000 -5"/>
    </body>
  </worldbody>
  <actuator><motor name="fx" joint="x" ctrlrange="-1 1"/></actuator>
</mujoco>"""
CONTACT_X = -0.015  # the ball (r 0.01) touches the wall (half thickness 0.005) at x > -0.015
BOUNCE_STEP = 2  # windows 0, 1 approach (0.1 s at 1 m/s each), window 2 bounces, 3..5 retreat


def _bounce_log(path):
    """A Gate (warn) on a ball flying at an elastic wall; per step the live integration state before it."""
    m = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0
    starts = []
    with Gate(m, log=path, frame_skip=50, allowed=None, on_violation="warn") as g:
        for _ in range(6):
            s = np.empty(mujoco.mj_stateSize(m, INTEGRATION))
            mujoco.mj_getState(m, d, s, INTEGRATION)
            starts.append(s)
            g.step(d, np.zeros(1))
    return m, starts


@pytest.fixture(scope="module")
def bounce(tmp_path_factory):
    path = tmp_path_factory.mktemp("replay") / "bounce.mcap"
    model, starts = _bounce_log(path)
    return path, model, starts


def _verify(path, **kw):
    ver = review.verify(read_log(path), **kw)
    return review.verify_exit_code(ver), ver


def _findings(ver, severity):
    return [(f["index"], f["reason"]) for f in ver["findings"] if f["severity"] == severity]


def test_a_genuine_gate_log_re_simulates_bit_for_bit(bounce):
    path, model, starts = bounce
    contents = read_log(path)
    plans = contents.plans_by_index()
    assert contents.run[topics.ROLLOUTS_KEY] == "logged" and len(plans) == 6
    for k, p in plans.items():  # the logged start state is the live data's (oracle: read by the test)
        assert p["source"] == "rollout"
        ro = replay.decode(p["rollout"], model)
        assert ro.state.tobytes() == starts[k].tobytes() and ro.rows_from == 0 and ro.substeps == 50
    q = np.asarray(plans[BOUNCE_STEP]["qpos"])[:, 0]  # the closed-form story: clear ends, a dip inside
    assert q[0] < CONTACT_X and q[-1] < CONTACT_X and q.max() > CONTACT_X
    code, ver = _verify(path)
    assert code == 0, ver["findings"]
    assert ver["replayed"] == 6 and ver["continuity_checked"] == 5 and ver["replay_failed"] == 0


def test_arm_safety_gate_log_with_braking_tail_records_re_simulates(tmp_path):
    path = tmp_path / "arm.mcap"
    stats, _ = _arm_run(path, steps=30)  # SafetyGate(monitor/Arm-v0), seeded random actions
    assert stats["replaced"] >= 3  # blocked steps: their braking-tail records are re-simulated too
    contents = read_log(path)
    tails = [c["index"] for c in contents.certificates()
             if (c.get("applied") or {}).get("kind") == "brake_tail"]
    assert tails and all(contents.plans_by_index()[k]["rollout"]["rows_from"] > 0 for k in tails)
    code, ver = _verify(path)
    assert code == 0, ver["findings"]
    assert ver["replayed"] == len(contents.topic(topics.PLAN)) and ver["continuity_checked"] >= 25


def test_in_place_dynamics_edits_are_logged_and_re_simulated(tmp_path):
    """Physics randomised in place between steps (mass, damping, gravity, timestep): none is a scene
    field, all change the motion; the log records them and every window still re-simulates."""
    m = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0
    path = tmp_path / "dr.mcap"
    rng = np.random.default_rng(3)
    with Gate(m, log=path, frame_skip=50, allowed=None, on_violation="warn") as g:
        for k in range(6):
            if k % 2:
                m.body_mass[2] = rng.uniform(0.005, 0.02)
                m.dof_damping[0] = rng.uniform(0.0, 0.01)
                m.opt.gravity[0] = rng.uniform(-0.5, 0.5)
                m.opt.timestep = rng.choice([0.002, 0.0025])
            g.step(d, np.zeros(1))
    contents = read_log(path)
    edited = {k for e in contents.model_edits for k in e["fields"]} | {
        f"opt.{k}" for e in contents.model_edits for k in e.get("options", {})}
    assert {"body_mass", "dof_damping", "opt.gravity"} <= edited, edited
    code, ver = _verify(path, trust_model_edits=True)
    assert code == 0, ver["findings"]
    assert ver["replayed"] == 6 and ver["continuity_checked"] == 5


def test_a_cast_that_edits_the_model_leaves_its_rows_not_re_simulable_but_never_critical(tmp_path):
    """User code in ``Gate.decide(cast=)`` edits the dynamics after the window's rollout, before its
    braking tail (red team 7's case): those rows are on no single logged model, so they are logged as
    not re-simulable (review: unverifiable, exit 2), never a false critical finding."""
    m = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0

    def cast(c):
        m.dof_damping[0] += 1e-3
        return np.asarray(c, dtype=np.float64)

    path = tmp_path / "cast.mcap"
    with Gate(m, log=path, frame_skip=50, allowed=None) as g:
        for _ in range(4):
            r = g.decide(d, np.zeros(1), cast=cast)
            if not g._rollout.commit(d, r.applied_ctrl, 50):
                d.ctrl[:] = r.applied_ctrl
                mujoco.mj_step(m, d, nstep=50)
    code, ver = _verify(path, trust_model_edits=True)
    assert code == 2 and not _findings(ver, "critical") and ver["replay_failed"] == 0, ver["findings"]
    assert ver["replay_user"] >= 2 and ver["replayed"] >= 2


def _forge(src, dst, msg=None, metadata=None):
    """Rewrite ``src`` as a forger would, then seal it again (``monitor.log.digest``)."""
    tmp = dst.with_suffix(".unsealed.mcap")
    rewrite(src, tmp, msg=msg, metadata=metadata)
    seal_copy(tmp, dst)
    assert read_log(dst).seal_status == "sealed"


def _recertified(model, k, times, qpos, contents):
    """A certificate payload for the forged rows, made by the real engine (the forger has the library)."""
    from monitor.scene import Scene

    scene = Scene.from_model(model, pairs="mujoco", allowed=None)
    cert = certify(scene, Plan(times, qpos, model=model), margin=0.0, epsilon=1e-3,
                   window=(float(times[0]), float(times[-1])))
    keep = ("index", "episode", "sim_time", "wall_time", "request_id")
    head = {key: contents.certificates()[k][key] for key in keep}
    return {**head, **_null_unknown(cert.to_dict())}


def forge_interior_rows(path, model, dst):
    """Red team 7's forgery of ``path`` into ``dst``: the bounce's interior rows straightened between its
    (kept) end rows, certified by the real engine, its violation messages dropped, the file re-sealed.

    Returns (logged verdict, forged verdict) of the window (also used by the note's ``forge_demo.py``).
    """
    contents = read_log(path)
    p = contents.plans_by_index()[BOUNCE_STEP]
    times, qpos = np.asarray(p["times"]), np.asarray(p["qpos"])
    s = (times - times[0]) / (times[-1] - times[0])
    forged = qpos[0] + s[:, None] * (qpos[-1] - qpos[0])  # first and last rows kept, never near the wall
    cert = _recertified(model, BOUNCE_STEP, times, forged, contents)

    def msg(topic, o):
        if o.get("index") != BOUNCE_STEP:
            return o
        if topic == topics.PLAN:
            return {**o, "qpos": forged.tolist()}
        if topic == topics.CERTIFICATE:
            return cert
        return None if topic in (topics.VIOLATION, topics.LOG) else o

    _forge(path, dst, msg=msg)
    return contents.certificates()[BOUNCE_STEP]["verdict"], cert["verdict"]


def test_the_red_team_forgery_of_consistent_interior_rows_is_caught(bounce, tmp_path):
    path, model, _ = bounce
    dst = tmp_path / "forged.mcap"
    assert forge_interior_rows(path, model, dst) == ("violation", "certified")
    code, ver = _verify(dst)
    assert code == 1 and not ver["mismatches"]  # re-certifying the forged rows agrees with the claim
    crit = _findings(ver, "critical")
    assert [k for k, _ in crit] == [BOUNCE_STEP], crit
    assert "not the re-simulation of its logged rollout" in crit[0][1]
    assert "first differing row 1 " in crit[0][1]


def _edit_plan(index, edit):
    def msg(topic, o):
        if topic == topics.PLAN and o.get("index") == index:
            edit(o)
        return o
    return msg


@pytest.mark.parametrize("drop", [("rollout",), ("rollout", "source")])
def test_dropping_the_rollout_of_a_certified_window_is_critical(bounce, tmp_path, drop):
    path, _, _ = bounce
    dst = tmp_path / "dropped.mcap"
    _forge(path, dst, msg=_edit_plan(4, lambda o: [o.pop(key) for key in drop]))
    code, ver = _verify(dst)
    assert code == 1
    assert [k for k, _ in _findings(ver, "critical")] == [4]
    # the other steps still re-simulate, and the continuity around window 4 is not checked
    assert ver["replayed"] == 5 and ver["continuity_checked"] == 3


def test_a_plan_switched_to_a_body_motion_without_its_source_is_critical(bounce, tmp_path):
    path, _, _ = bounce
    dst = tmp_path / "kind.mcap"

    def to_body_motion(o):
        o.pop("rollout"), o.pop("source")
        o["kind"] = "bodymotion"

    _forge(path, dst, msg=_edit_plan(4, to_body_motion))
    code, ver = _verify(dst)
    assert code == 1
    assert 4 in [k for k, _ in _findings(ver, "critical")]


def test_marking_rollout_rows_as_user_rows_is_not_accepted(bounce, tmp_path):
    path, _, _ = bounce
    dst = tmp_path / "user.mcap"
    _forge(path, dst, msg=_edit_plan(4, lambda o: (o.pop("rollout"), o.update(source="user"))))
    code, ver = _verify(dst)
    assert code == 2 and ver["replay_user"] == 1
    assert any("rows from user code" in r and "predictor is the gate's own rollout" in r
               for _, r in _findings(ver, "unverifiable"))


def test_an_edited_ctrl_with_consistently_re_simulated_rows_breaks_the_continuity(bounce, tmp_path):
    """Window 3's control changed, its rows re-simulated with it: window 4 does not follow it."""
    path, model, _ = bounce
    contents = read_log(path)
    p = contents.plans_by_index()[3]
    ro = replay.decode(p["rollout"], model)
    pushed = replay.Rollout(ro.state, ((np.array([-0.5]), 50),), 0)
    plan, _ = replay.resimulate(model, mujoco.MjData(model), pushed)
    payload = replay.encode((pushed.state, ((pushed.segments[0][0], 50),), 0),
                            int(INTEGRATION), ro.state.size, model.nu)
    cert = _recertified(model, 3, plan.times, plan.qpos, contents)
    assert cert["verdict"] == "certified"

    def msg(topic, o):
        if o.get("index") != 3:
            return o
        if topic == topics.PLAN:
            return {**o, "qpos": plan.qpos.tolist(), "rollout": payload}
        if topic == topics.ACTION:
            return {**o, "proposed": [-0.5], "applied": [-0.5]}
        return cert if topic == topics.CERTIFICATE else o

    dst = tmp_path / "ctrl.mcap"
    _forge(path, dst, msg=msg)
    code, ver = _verify(dst)
    assert code == 1 and ver["replayed"] == 6
    crit = _findings(ver, "critical")
    assert [k for k, _ in crit] == [3], crit
    assert "motion that ran in step 3" in crit[0][1] and "than window 4 starts from" in crit[0][1]


def test_a_removed_step_leaves_a_gap_that_is_reported(bounce, tmp_path):
    path, _, _ = bounce
    dst = tmp_path / "gap.mcap"
    _forge(path, dst, msg=lambda topic, o: None if o.get("index") == 3 else o)
    code, ver = _verify(dst)
    assert code == 2 and not _findings(ver, "critical")
    gaps = [k for k, r in _findings(ver, "unverifiable") if "steps 2 and 4 of one episode do not meet" in r]
    assert gaps == [4]


def _as_old_log(name, values):
    if name == topics.METADATA_RUN:
        values.pop(topics.ROLLOUTS_KEY, None)
        values["format_version"] = 2
    return values


def test_an_old_log_without_rollouts_still_verifies_with_a_note(bounce, tmp_path):
    path, _, _ = bounce
    dst = tmp_path / "old.mcap"

    def msg(topic, o):
        if topic == topics.PLAN:
            o.pop("rollout")
            o.pop("source")
        return o

    _forge(path, dst, msg=msg, metadata=_as_old_log)
    code, ver = _verify(dst)
    assert code == 0, ver["findings"]
    assert ver["replayed"] == 0 and any("no rollouts logged" in n for n in ver["notes"])


def test_another_mujoco_version_is_a_note_and_a_difference_only_unverifiable(bounce, tmp_path):
    path, _, _ = bounce

    def old_mujoco(name, values):
        if name == topics.METADATA_RUN:
            values["mujoco_version"] = "0.0.1"
        return values

    genuine, forged = tmp_path / "v.mcap", tmp_path / "vf.mcap"
    _forge(path, genuine, metadata=old_mujoco)
    code, ver = _verify(genuine)
    assert code == 0 and ver["replayed"] == 6
    assert any("MuJoCo 0.0.1" in n and "need not be bit-exact" in n for n in ver["notes"])

    def nudge(o):
        o["qpos"][1][0] += 1e-9

    _forge(path, forged, msg=_edit_plan(3, nudge), metadata=old_mujoco)
    code, ver = _verify(forged)
    assert code == 2 and [k for k, _ in _findings(ver, "unverifiable")] == [3]


def test_writer_validates_rollouts(tmp_path):
    from monitor.certify.certificate import Certificate
    from monitor.errors import InvalidInputError
    from monitor.log import MonitorLog

    m = mujoco.MjModel.from_xml_string(BOUNCE)
    plan = Plan(np.array([0.0, 0.1]), np.array([[0.0], [0.1]]), model=m)
    state = np.zeros(mujoco.mj_stateSize(m, INTEGRATION))
    c = Certificate("certified", (0.0, 0.1), 0.0, 1e-3, "auto", None, None, 1.0, (), {})
    with MonitorLog(tmp_path / "w.mcap", model=m, foxglove=False) as log:
        for bad in ("rollout", (state[:-1], ((np.zeros(1), 5),), 0), (state, ((np.zeros(2), 5),), 0),
                    (state, ((np.zeros(1), 0),), 0), (state, ((np.zeros(1), 5),), 6), 7):
            with pytest.raises(InvalidInputError, match="rollout"):
                log.write_window(0.0, plan, c, rollout=bad)
        log.write_window(0.0, plan, c, rollout="user")
        log.write_window(0.1, plan, c, rollout=(state, ((np.zeros(1), 5),), 0))
    plans = read_log(tmp_path / "w.mcap").topic(topics.PLAN)
    assert [p.get("source") for p in plans] == ["user", "rollout"]


def test_a_window_logged_uncertain_that_certifies_now_is_a_non_critical_mismatch(bounce, tmp_path):
    """A log may claim less than the checker proves now (a newer monitor: red team 12 counted 2 151 such
    windows in 25 340 after the relative motion bounds). "uncertain" is always a sound answer and the
    gate acted on it, so the flip is listed with its reason, not critical."""
    path, _, _ = bounce
    dst = tmp_path / "weaker.mcap"

    def weaker(topic, o):
        if topic == topics.CERTIFICATE and o.get("index") == 4:
            assert o["verdict"] == "certified"
            o = {**o, "verdict": "uncertain"}
        return o

    _forge(path, dst, msg=weaker)
    code, ver = _verify(dst)
    (m,) = ver["mismatches"]
    assert (m["index"], m["logged"], m["recomputed"], m["critical"]) == (4, "uncertain", "certified", False)
    assert "claimed less" in m["reason"]
    assert ver["critical"] == 0 and not _findings(ver, "critical")
    assert code == 0


_EDIT_KEY = b"0123456789abcdef0123456789abcdef"


@pytest.fixture(scope="module")
def signed_edits(tmp_path_factory):
    """A bounce run logged with a key (``_EDIT_KEY``) whose model is edited in place before step 2."""
    m = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0
    path = tmp_path_factory.mktemp("signed_edits") / "signed_edits.mcap"
    with Gate(m, log=path, frame_skip=50, allowed=None, on_violation="warn",
              log_options={"key": _EDIT_KEY}) as g:
        for k in range(4):
            if k == 2:
                m.body_mass[2] *= 1.5
                m.geom_size[0, 0] *= 0.9     # a scene field: the pair's shapes are rebuilt
            g.step(d, np.zeros(1))
    return path, _EDIT_KEY


def test_signed_model_edit_records_need_no_trust_flag(signed_edits):
    """Unsigned, an edit record is the run's claim (a forger's added record reads the same), so the
    edited windows are unverifiable without ``trust_model_edits``. Signed and verified with the key,
    the records are the key holder's own: accepted, with a note; a wrong key or no key: as unsigned."""
    path, key = signed_edits
    assert read_log(path).model_edits
    code, ver = _verify(path, key=key)
    assert code == 0, ver["findings"]
    assert any("covered by the log's valid signature" in n for n in ver["notes"])
    code, ver = _verify(path)
    assert code == 2 and _findings(ver, review.UNVERIFIABLE)
    code, ver = _verify(path, key=b"another key, 16+ bytes long")
    assert code == 1


def test_ray_path_accepts_signed_model_edits_like_the_plain_path(signed_edits):
    """``review --ray`` verifies without the key, then adds the signature (``add_signature``): a
    verified signature drops the edit finding as :func:`review.verify` with the key does; a wrong key
    leaves it (and is critical itself)."""
    path, key = signed_edits
    contents = read_log(path)
    ver = review.verify(contents)
    assert review.verify_exit_code(ver) == 2 and _findings(ver, review.UNVERIFIABLE)
    ver = review.add_signature(ver, contents, key)
    assert review.verify_exit_code(ver) == 0, ver["findings"]
    assert any("covered by the log's valid signature" in n for n in ver["notes"])
    ver = review.add_signature(review.verify(contents), contents, b"another key, 16+ bytes long")
    assert review.verify_exit_code(ver) == 1 and _findings(ver, review.UNVERIFIABLE)
