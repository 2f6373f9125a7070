"""CertifyRequest (monitor/certify/request.py): validation names the field, JSON round trip."""

import dataclasses
import json
import math

import pytest

from monitor.certify.request import BudgetLimits, CertifyRequest
from monitor.certify.types import Method
from monitor.errors import InvalidInputError
from monitor.tolerances import Tolerances


def test_defaults_are_the_engine_defaults():
    r = CertifyRequest()
    assert (r.margin, r.epsilon, r.method, r.window, r.pairs, r.ongoing) == (0.0, 1e-3, Method.AUTO, None,
                                                                             None, "violation")
    assert r.budget == BudgetLimits(seconds=10.0)


def test_method_string_is_converted_to_the_enum():
    r = CertifyRequest(method="toleranced")
    assert r.method is Method.TOLERANCED


@pytest.mark.parametrize("kw, field_name", [
    ({"margin": -1e-3}, "margin"),
    ({"margin": math.nan}, "margin"),
    ({"margin": "0.1"}, "margin"),
    ({"margin": True}, "margin"),
    ({"epsilon": 0.0}, "epsilon"),
    ({"epsilon": math.inf}, "epsilon"),
    ({"method": "fcl"}, "method"),
    ({"window": (1.0, 1.0)}, "window"),
    ({"window": (0.0, math.nan)}, "window[1]"),
    ({"window": 3.0}, "window"),
    ({"budget": {"seconds": -1}}, "budget.seconds"),
    ({"budget": {"tests": 1.5}}, "budget.tests"),
    ({"budget": {"wall": 1}}, "unknown field"),
    ({"pairs": "ab"}, "pairs"),
    ({"pairs": [("a",)]}, "pairs[0]"),
    ({"pairs": [("a", 3)]}, "pairs[0]"),
    ({"tolerances": {"rel_pad": 0}}, "tolerances"),
    ({"ongoing": "ignore"}, "ongoing"),
    ({"penetration_tol": 0.0}, "penetration_tol"),
])
def test_bad_field_raises_naming_it(kw, field_name):
    with pytest.raises(InvalidInputError, match=field_name.replace("[", r"\[").replace("]", r"\]")):
        CertifyRequest(**kw)


def test_frozen_and_replace_validates_again():
    r = CertifyRequest(margin=0.01)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.margin = 0.0  # type: ignore[misc]
    assert r.replace(margin=0.02).margin == 0.02
    with pytest.raises(InvalidInputError, match="margin"):
        r.replace(margin=-1.0)


def test_json_round_trip_is_exact():
    r = CertifyRequest(margin=0.0123456789, epsilon=1e-4, method="extrusion", window=(0.1, 0.35),
                       budget={"seconds": 2.5, "tests": 1000}, pairs=[("a", "b"), ("c", "d")],
                       tolerances=Tolerances(max_depth=30, facets=24), ongoing="deepen",
                       penetration_tol=0.002)
    back = CertifyRequest.from_json(json.loads(json.dumps(r.to_json())))
    assert back == r
    assert CertifyRequest.from_json(json.loads(json.dumps(CertifyRequest().to_json()))) == CertifyRequest()


def test_from_json_rejects_unknown_fields():
    d = CertifyRequest().to_json()
    d["speed"] = 1
    with pytest.raises(InvalidInputError, match="speed"):
        CertifyRequest.from_json(d)
    d = CertifyRequest().to_json()
    d["tolerances"]["rel_padd"] = 1e-14
    with pytest.raises(InvalidInputError, match="rel_padd"):
        CertifyRequest.from_json(d)
    with pytest.raises(InvalidInputError, match="dict"):
        CertifyRequest.from_json([1, 2])


def test_new_budget_has_the_limits_and_a_fresh_clock():
    r = CertifyRequest(budget={"seconds": 1.0, "tests": 7})
    b1, b2 = r.new_budget(), r.new_budget()
    assert (b1.seconds, b1.tests) == (1.0, 7)
    b1.charge(7)
    assert b1.exhausted and not b2.exhausted
