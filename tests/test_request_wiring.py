"""Issue 12 item 6: the typed request end to end (certify -> certificate -> gate -> log -> review).

* ``certify`` builds one :class:`CertifyRequest` from its keywords or takes one as ``request=``
  (never both); the certificate carries it (``cert.request``), outside equality and ``to_dict``.
* The gate builds one request per setting and passes it to every certify call.
* A gate's log stores it (run metadata ``"request"``) and ``review --verify`` re-derives every
  window with it: a gate's ``ongoing="deepen"`` rule included (before, review re-derived with the
  plain rule and reported a resting contact's certified windows as critical flips).
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
import pytest

from monitor.certify.common import Budget
from monitor.certify.engine import certify
from monitor.certify.request import BudgetLimits, CertifyRequest
from monitor.errors import InvalidInputError
from monitor.motion.bodymotion import BodyMotion
from monitor.scene import Scene

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <body name="ball" pos="0 0 .06"><freejoint/><geom name="ball" type="sphere" size=".05"/></body>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(XML)


def _drop(model, dz):
    """BodyMotion over [0, 1]: the ball moves from its model pose by dz (m) along z."""
    d = mujoco.MjData(model)
    mujoco.mj_kinematics(model, d)
    pos = np.repeat(np.array(d.xpos)[None], 2, axis=0)
    quat = np.repeat(np.array(d.xquat)[None], 2, axis=0)
    pos[1, model.body("ball").id, 2] += dz
    return BodyMotion(np.array([0.0, 1.0]), pos, quat)


def _same(a, b):
    da, db = a.to_dict(), b.to_dict()
    da["stats"].pop("wall_seconds"), db["stats"].pop("wall_seconds")
    return da == db


# ------------------------------------------------------------------------------------ certify


def test_keywords_and_request_give_the_same_certificate(model):
    scene = Scene.from_model(model, pairs="all")
    for dz in (-0.005, -0.02):  # clear (certified), then into the floor (violation)
        plan = _drop(model, dz)
        kw = certify(scene, plan, margin=0.002, epsilon=2e-3, window=(0.0, 0.5))
        req = CertifyRequest(margin=0.002, epsilon=2e-3, window=(0.0, 0.5))
        given = certify(scene, plan, request=req)
        assert _same(kw, given)
        assert given.request is req
        assert kw.request == req and kw.request.window == (0.0, 0.5)
    assert {kw.verdict, certify(scene, _drop(model, -0.005)).verdict} == {"violation", "certified"}


def test_request_is_not_part_of_equality_repr_or_json(model):
    scene = Scene.from_model(model, pairs="all")
    plan = _drop(model, -0.005)
    a = certify(scene, plan)
    b = certify(scene, plan, request=CertifyRequest(ongoing="deepen"))
    assert a.request.ongoing == "violation" and b.request.ongoing == "deepen"
    assert _same(a, b) and "request" not in a.to_dict() and "request" not in repr(a)
    twin = copy.copy(a)
    twin.__dict__["request"] = b.request
    assert twin == a and twin.request is not a.request
    back = type(a).from_dict(a.to_dict())
    assert back == a and back.request is None


def test_plain_keywords_share_one_validated_request(model):
    scene = Scene.from_model(model, pairs="all")
    plan = _drop(model, -0.005)
    r1 = certify(scene, plan, margin=0.001).request
    r2 = certify(scene, plan, margin=0.001).request
    assert r1 is r2
    assert certify(scene, plan, margin=0.002).request.margin == 0.002


@pytest.mark.parametrize("kw", [{"margin": 0.1}, {"epsilon": 1e-2}, {"method": "toleranced"},
                                {"window": (0.0, 0.5)}, {"budget": {"seconds": 1.0}},
                                {"pairs": [("floor", "ball")]}, {"ongoing": "deepen"},
                                {"penetration_tol": 0.01}])
def test_request_with_a_keyword_setting_is_refused_naming_it(model, kw):
    scene = Scene.from_model(model, pairs="all")
    with pytest.raises(InvalidInputError, match=f"request= together with {next(iter(kw))}="):
        certify(scene, _drop(model, -0.005), request=CertifyRequest(), **kw)


def test_request_must_be_a_request(model):
    scene = Scene.from_model(model, pairs="all")
    with pytest.raises(InvalidInputError, match="request must be a CertifyRequest"):
        certify(scene, _drop(model, -0.005), request={"margin": 0.0})


def test_keyword_errors_name_the_keyword_not_the_request(model):
    scene = Scene.from_model(model, pairs="all")
    plan = _drop(model, -0.005)
    with pytest.raises(InvalidInputError, match=r"^margin must be >= 0"):
        certify(scene, plan, margin=-1.0)
    with pytest.raises(InvalidInputError, match=r"^penetration_tol must be > 0"):
        certify(scene, plan, penetration_tol=0.0)
    with pytest.raises(InvalidInputError, match=r"not inside the plan span"):
        certify(scene, plan, window=(0.0, 2.0))
    with pytest.raises(InvalidInputError, match=r"not inside the plan span"):
        certify(scene, plan, request=CertifyRequest(window=(0.5, 1.5)))


def test_a_live_budget_keeps_its_clock_and_count(model):
    """A spent Budget object makes the window uncertain; the same limits as a request start afresh."""
    scene = Scene.from_model(model, pairs="all")
    plan = _drop(model, -0.005)
    spent = Budget(tests=1)
    spent.charge(5)
    assert spent.exhausted
    assert certify(scene, plan, budget=spent).verdict == "uncertain"
    fresh = certify(scene, plan, request=CertifyRequest(budget=BudgetLimits(tests=1)))
    assert fresh.verdict == "certified" and fresh.request.budget == BudgetLimits(tests=1)


# --------------------------------------------------------------------------------- gate + log


def _gated_log(model, path, steps=30, **gate_kw):
    """A gated run of the ball dropping 1 cm onto the floor and resting there (an ongoing contact)."""
    from monitor.gate import Gate

    data = mujoco.MjData(model)
    reports = []
    with Gate(model, pairs="all", allowed=None, log=path, frame_skip=5, **gate_kw) as gate:
        for _ in range(steps):
            reports.append(gate.step(data, np.zeros(0)))
        req = gate.request
    return reports, req


def test_gate_passes_one_request_per_setting(model):
    from monitor.gate import Gate

    gate = Gate(model, pairs="all", allowed=None, frame_skip=5)
    data = mujoco.MjData(model)
    r1 = gate.step(data, np.zeros(0))
    r2 = gate.step(data, np.zeros(0))
    req = gate.request
    assert r1.certificate.request is req and r2.certificate.request is req
    assert req.ongoing == "deepen" and req.window is None and req.pairs is None
    gate.margin = 0.003
    assert gate.request is not req and gate.request.margin == 0.003
    gate.budget = {"tests": 10**6}
    assert gate.request.budget == BudgetLimits(tests=10**6)
    gate.ongoing = "violation"
    gate.penetration_tol = 0.01
    assert (gate.request.ongoing, gate.request.penetration_tol) == ("violation", 0.01)
    assert gate.step(data, np.zeros(0)).certificate.request is gate.request
    with pytest.raises(InvalidInputError, match="ongoing"):
        gate.ongoing = "ignore"
    with pytest.raises(InvalidInputError, match="penetration_tol"):
        gate.penetration_tol = -1.0
    with pytest.raises(InvalidInputError, match="budget"):
        gate.budget = "lots"


def test_review_rederives_with_the_logged_ongoing_rule(model, tmp_path):
    """Regression: a deepen gate's resting-contact windows are certified, and review agrees now.

    Before (review re-derived with the plain rule; the same log without its request shows it)
    every window with the ball resting on the floor was a critical certified -> violation flip.
    """
    from monitor import review
    from monitor.log import read_log

    path = tmp_path / "ball.mcap"
    reports, req = _gated_log(model, path)
    ongoing = [r for r in reports if r.certificate.verdict == "certified" and r.certificate.ongoing]
    assert len(ongoing) >= 10  # the rule decided windows in this run
    contents = read_log(path)
    assert CertifyRequest.from_json(contents.run["request"]) == req
    ver = review.verify(contents)
    assert ver["checked"] >= len(reports)  # every window (and the logged fallback window)
    assert ver["mismatches"] == [] and ver["critical"] == 0, ver["findings"]

    # an old log (no request record): re-derived as before, with the plain rule
    old = read_log(path)
    old.run.pop("request")
    ver_old = review.verify(old)
    assert ver_old["checked"] == ver["checked"]
    flips = [m for m in ver_old["mismatches"]
             if m["logged"] == "certified" and m["recomputed"] == "violation"]
    assert len(flips) == len(ongoing) and ver_old["critical"] >= len(ongoing)


@pytest.mark.parametrize("forged", ["not json", {"margin": 0.0, "speed": 1}, {"ongoing": "ignore"},
                                    {"tolerances": {"max_depth": "x"}}, [1, 2],
                                    {"pairs": [["floor", "ball"]]}])
def test_a_forged_request_record_is_a_critical_finding(model, tmp_path, forged):
    from monitor import review
    from monitor.log import read_log

    path = tmp_path / "ball.mcap"
    reports, _ = _gated_log(model, path, steps=6)
    contents = read_log(path)
    if isinstance(forged, dict):
        forged = {**contents.run["request"], **forged}
    contents.run["request"] = forged
    ver = review.verify(contents)
    reasons = [f["reason"] for f in ver["findings"] if f["severity"] == "critical"]
    assert any("request" in r for r in reasons), reasons
    assert ver["critical"] >= 1 and ver["errors"] == []


def test_the_request_memo_never_skips_validation(model):
    """Memo hits only for values validation accepts; a Budget is keyed by its limits."""
    scene = Scene.from_model(model, pairs="all")
    plan = _drop(model, -0.005)
    one = 1.0
    assert certify(scene, plan, margin=one).request.margin == 1.0
    for bad in (True, float("nan"), "1.0", -1.0):
        with pytest.raises(InvalidInputError, match="margin"):
            certify(scene, plan, margin=bad)
    assert certify(scene, plan, margin=one).request.margin == 1.0
    b = Budget(seconds=30.0)
    assert certify(scene, plan, budget=b).request.budget == BudgetLimits(seconds=30.0)
    b.tests = 0  # a mutable Budget edited between calls: the new limits apply
    cert = certify(scene, plan, budget=b)
    assert cert.request.budget == BudgetLimits(seconds=30.0, tests=0) and cert.verdict == "uncertain"
    with pytest.raises(InvalidInputError, match="ongoing"):
        certify(scene, plan, ongoing="ignore")


def test_a_forged_request_in_the_file_is_found_by_the_cli(model, tmp_path, capsys):
    """The request record edited on disk (ongoing rule swapped): CRITICAL, exit 1, no traceback."""
    from mcap_rewrite import rewrite

    from monitor.cli import main
    from monitor.log import topics

    path, forged = tmp_path / "ball.mcap", tmp_path / "forged.mcap"
    _gated_log(model, path, steps=6)

    def edit(name, values):
        if name == topics.METADATA_RUN:
            values["request"] = {**values["request"], "penetration_tol": "5 mm"}
        return values

    rewrite(path, forged, metadata=edit)
    assert main(["review", "--verify", str(forged)]) == 1
    out = capsys.readouterr().out
    assert "request is malformed" in out and "penetration_tol" in out


def test_review_of_a_default_gate_knows_its_allowed_resting_contact(model, tmp_path):
    """Regression: with the default ``allowed="auto"`` the ball resting on the floor at the first
    state is an allowed pair (never certified); review rebuilt the scene without it, so every
    window was a CRITICAL "certificate pairs differ". The log now carries the allowed pairs."""
    from monitor import review
    from monitor.gate import Gate
    from monitor.log import read_log

    path = tmp_path / "ball_auto.mcap"
    data = mujoco.MjData(model)
    with Gate(model, pairs="all", log=path, frame_skip=5) as gate:
        for _ in range(10):
            gate.step(data, np.zeros(0))
        allowed = gate.scene.allowed_pairs
    assert [tuple(a[:2]) for a in allowed] in ([("floor", "ball")], [("ball", "floor")])
    contents = read_log(path)
    ver = review.verify(contents)
    assert ver["checked"] >= 10 and ver["critical"] == 0, ver["findings"]
    assert any("allowed 1 candidate pair" in n for n in ver["notes"]), ver["notes"]
    # without the record (a log from before): the pair sets differ on every window, as before
    old = read_log(path)
    old.run.pop("allowed_pairs")
    assert review.verify(old)["critical"] >= 10
    # a forged record (unknown reason) is a critical finding, never a traceback
    bad = read_log(path)
    bad.run["allowed_pairs"] = [["floor", "ball", "Because"]]
    assert review.verify(bad)["critical"] > 0
