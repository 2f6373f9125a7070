"""Typed verdicts and methods: ``Verdict`` / ``Method`` StrEnums on certificates, the checkers' ``Outcome``.

Oracles: plain-string dicts written by hand (JSON and MCAP bytes must match them exactly),
the enum members themselves (``type(...) is Verdict``), and the lazy pair builder's output.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify.certificate import Certificate, PairResult, Witness, combine_verdicts
from monitor.certify.common import Outcome, PairOutcome
from monitor.certify.engine import certify
from monitor.certify.types import Method, Verdict
from monitor.errors import InvalidInputError
from monitor.scene import Scene

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_engine import XML, _plan  # noqa: E402  (the engine tests' small scene)
from test_log import fake_plan, small_model  # noqa: E402


def _cert(verdict, method="auto") -> Certificate:
    """A two-pair certificate; ``verdict`` and ``method`` as given (enum or string)."""
    wit = Witness(0.005, ("hand_mesh", "table_top"), np.array([0.5, 0.0, 0.2]), -1e-3) \
        if verdict == "violation" else None
    ok = verdict == "certified"
    pr = PairResult(("hand_mesh", "table_top"), ("hand", "table"), verdict, "toleranced", 10, 3,
                    () if ok else ((0.0, 0.01),), 0.01 if ok else float("-inf"), wit)
    culled = PairResult(("link1_geom", "cube_geom"), ("link1", "cube"), Verdict.CERTIFIED, "culled",
                        0, 0, (), 0.5)
    return Certificate(verdict, (0.0, 0.01), 0.001, 1e-3, method, wit, None if ok else 0.0,
                       0.01 if ok else float("-inf"), (pr, culled), {"checker_mix": {"toleranced": 1}})


def _plain_dict(verdict: str, method: str = "auto") -> dict:
    """The same certificate as :func:`_cert`, written by hand with plain strings."""
    ok = verdict == "certified"
    wit = {"time": 0.005, "geoms": ["hand_mesh", "table_top"], "point": [0.5, 0.0, 0.2],
           "distance": -1e-3} if verdict == "violation" else None
    return {"verdict": verdict, "window": [0.0, 0.01], "margin": 0.001, "epsilon": 1e-3, "method": method,
            "witness": wit, "earliest_time": None if ok else 0.0, "clearance": 0.01 if ok else -1e308,
            "pairs": [{"geoms": ["hand_mesh", "table_top"], "bodies": ["hand", "table"], "verdict": verdict,
                       "method": "toleranced", "tests": 10, "max_depth": 3,
                       "intervals": [] if ok else [[0.0, 0.01]], "clearance": 0.01 if ok else -1e308,
                       "witness": wit},
                      {"geoms": ["link1_geom", "cube_geom"], "bodies": ["link1", "cube"],
                       "verdict": "certified", "method": "culled", "tests": 0, "max_depth": 0,
                       "intervals": [], "clearance": 0.5, "witness": None}],
            "stats": {"checker_mix": {"toleranced": 1}}}


VERDICT_STRINGS = ("certified", "violation", "uncertain")


def test_enums_are_their_strings():
    assert [v.value for v in Verdict] == list(VERDICT_STRINGS)
    assert [m.value for m in Method] == ["auto", "toleranced", "extrusion"]
    assert [o.value for o in Outcome] == ["certified", "violation", "unresolved"]
    for v in Verdict:
        assert v == v.value and str(v) == v.value and f"{v}" == v.value and f"{v:>10}" == f"{v.value:>10}"
        assert json.dumps(v) == json.dumps(v.value) and hash(v) == hash(v.value)
        assert {v.value: 1}[v] == 1  # dicts keyed by the plain string still find it
    assert monitor.Verdict is Verdict and monitor.Method is Method


@pytest.mark.parametrize("given", [*VERDICT_STRINGS, *Verdict])
def test_certificate_and_pairs_hold_a_verdict(given):
    cert = _cert(given)
    assert type(cert.verdict) is Verdict and cert.verdict == str(given)
    assert all(type(p.verdict) is Verdict for p in cert.pairs)
    assert type(cert.method) is Method and cert.method == "auto"
    assert cert.certified == (given == "certified")


@pytest.mark.parametrize("verdict", VERDICT_STRINGS)
def test_json_is_byte_identical_to_plain_strings(verdict):
    d = _cert(Verdict(verdict), Method.AUTO).to_dict()
    assert json.dumps(d) == json.dumps(_plain_dict(verdict))
    # to_dict carries plain str (no enum leaks to other serialisers, e.g. yaml or pickle of the dict)
    assert type(d["verdict"]) is str and type(d["method"]) is str
    assert all(type(p["verdict"]) is str for p in d["pairs"])
    back = Certificate.from_dict(json.loads(json.dumps(d)))
    assert back.to_dict() == d and type(back.verdict) is Verdict and type(back.method) is Method
    assert all(type(p.verdict) is Verdict for p in back.pairs)


def test_log_bytes_identical_to_plain_string_dicts(tmp_path):
    """An MCAP log written from enum-typed certificates holds, byte for byte, the messages of the log
    written from hand-made plain-string dicts; the reader returns plain strings that read back as Verdicts."""
    from mcap.reader import make_reader

    from monitor.log import MonitorLog, read_log, topics

    model = small_model()
    order = ["certified", "violation", "uncertain", "certified"]

    def write(path, as_enum):
        rng = np.random.default_rng(3)
        with MonitorLog(path, model=model, metadata={"margin": 0.001}, foxglove=True) as log:
            for k, v in enumerate(order):
                c = _cert(Verdict(v), Method.AUTO) if as_enum else _plain_dict(v)
                log.write_window(0.01 * k, fake_plan(model, 0.01 * k, rng=rng), c, np.array([0.1, 0.2]),
                                 np.array([0.1, 0.2]), replaced=v != "certified", wall_time=1e9 + k)

    def messages(path):  # the file itself differs run to run (created_utc metadata, chunking)
        with open(path, "rb") as f:
            return [(c.topic, m.log_time, m.publish_time, m.data)
                    for _s, c, m in make_reader(f).iter_messages()]

    write(tmp_path / "enum.mcap", True)
    write(tmp_path / "plain.mcap", False)
    enum_msgs = messages(tmp_path / "enum.mcap")
    assert len(enum_msgs) >= 3 * len(order) and enum_msgs == messages(tmp_path / "plain.mcap")
    raw = (tmp_path / "enum.mcap").read_bytes()
    assert b"Verdict." not in raw and b"Method." not in raw
    got = read_log(tmp_path / "enum.mcap").certificates()
    assert [m["verdict"] for m in got] == order and all(type(m["verdict"]) is str for m in got)
    back = [Certificate.from_dict(m) for m in got]
    assert [b.verdict for b in back] == [Verdict(v) for v in order]
    assert all(type(b.verdict) is Verdict for b in back)
    assert len(read_log(tmp_path / "enum.mcap").topic(topics.VIOLATION)) == 2


@pytest.mark.parametrize("bad", ["Certified", "unresolved", "", None, 1, ["certified"]])
def test_unknown_verdict_is_rejected_naming_it(bad):
    with pytest.raises(InvalidInputError, match=r"verdict must be one of .*got " + re.escape(repr(bad))):
        _cert(bad)
    with pytest.raises(InvalidInputError, match=r"PairResult verdict"):
        PairResult(("a", "b"), ("A", "B"), bad, "culled")
    with pytest.raises(InvalidInputError, match="verdict"):
        Certificate.from_dict({**_plain_dict("certified"), "verdict": bad})
    with pytest.raises(InvalidInputError, match="verdict"):
        combine_verdicts(["certified", bad])


def test_unknown_certificate_method_is_rejected():
    with pytest.raises(InvalidInputError, match=r"Certificate method must be one of .*got 'fast'"):
        _cert("certified", "fast")
    with pytest.raises(InvalidInputError, match="method"):
        Certificate.from_dict({**_plain_dict("certified"), "method": "culled"})


def test_combine_verdicts_typed():
    assert combine_verdicts([]) is Verdict.CERTIFIED
    assert combine_verdicts(["certified", "uncertain"]) is Verdict.UNCERTAIN
    assert combine_verdicts([Verdict.UNCERTAIN, "violation", "certified"]) is Verdict.VIOLATION


def test_pair_outcome_coerces_and_rejects():
    assert type(PairOutcome("unresolved").verdict) is Outcome
    assert PairOutcome(Outcome.VIOLATION).verdict == "violation"
    with pytest.raises(InvalidInputError, match=r"PairOutcome verdict .*got 'uncertain'"):
        PairOutcome("uncertain")  # the public word is not the checkers' word


@pytest.fixture(scope="module")
def scene_model():
    model = mujoco.MjModel.from_xml_string(XML)
    return Scene.from_model(model, pairs="all"), model


@pytest.mark.parametrize("budget", [None, {"tests": 1}, {"seconds": 0.0}])
def test_lazy_and_budget_pairs_carry_verdict(scene_model, budget):
    """Pairs built by the engine's lazy builder (culled / budget-unfinished, made without the
    constructor) hold Verdict members like every other pair."""
    scene, model = scene_model
    cert = certify(scene, _plan(model, arm_end=(0.3, 0.2)), budget=budget)
    assert type(cert.verdict) is Verdict and type(cert.method) is Method
    pairs = cert.pairs
    quick = [p for p in pairs if p.method in ("culled", "budget")]
    assert quick, "the scene must produce culled or budget pairs"
    assert all(type(p.verdict) is Verdict for p in pairs)
    assert {p.verdict for p in quick if p.method == "culled"} <= {Verdict.CERTIFIED}
    assert {p.verdict for p in quick if p.method == "budget"} <= {Verdict.UNCERTAIN}
    if budget == {"seconds": 0.0}:
        assert {p.method for p in pairs} == {"budget"} and cert.verdict is Verdict.UNCERTAIN


@pytest.mark.parametrize("method", ["auto", "toleranced", Method.AUTO, Method.TOLERANCED])
def test_certify_accepts_method_enum_or_string(scene_model, method):
    scene, model = scene_model
    plan = _plan(model, arm_end=(0.3, 0.2))
    cert = certify(scene, plan, method=method)
    ref = certify(scene, plan, method=str(method))
    assert cert.method is Method(str(method)) and cert.verdict is ref.verdict is Verdict.CERTIFIED
    assert [p.verdict for p in cert.pairs] == [p.verdict for p in ref.pairs]
    assert monitor.certify(scene, plan, method=method).method is Method(str(method))


def test_certify_rejects_unknown_method_with_the_old_message(scene_model):
    scene, model = scene_model
    with pytest.raises(InvalidInputError,
                       match=r"^method must be one of \('auto', 'toleranced', 'extrusion'\), got 'fast'$"):
        certify(scene, _plan(model), method="fast")


def test_gate_brake_verdicts_are_verdict_members():
    """StepReport.brake_verdict is a Verdict whenever a braking tail was judged (it was a plain str on
    the two-call path); "" only when no tail was checked."""
    import mujoco

    from monitor._paths import scene_path
    from monitor.gate import Gate

    model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    gate = Gate(model, margin=0.001)
    judged = []
    for k in range(40):  # toward the wall and back: accepted steps, refused ones, braking tails
        r = gate.step(data, np.array([6.0 if k < 25 else -6.0]))
        assert r.brake_verdict == "" or type(r.brake_verdict) is Verdict, repr(r.brake_verdict)
        judged += [r.brake_verdict] if r.brake_verdict else []
    assert judged  # the loop judged some tails (the assertion above ran on them)

    # a scene with no candidate pair: its tails are certified without a call
    lone = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint name="x" type="slide" axis="1 0 0"/><geom size="0.1"/></body>'
        '</worldbody><actuator><velocity joint="x" kv="10"/></actuator></mujoco>')
    lone_data = mujoco.MjData(lone)
    with pytest.warns(UserWarning):
        lone_gate = Gate(lone)
        r = lone_gate.step(lone_data, np.array([0.5]))
    assert type(r.brake_verdict) is Verdict and r.brake_verdict == Verdict.CERTIFIED
