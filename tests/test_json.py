"""The one numpy -> strict-JSON converter and its two non-finite policies."""

import json
import math

import numpy as np

from monitor._json import finite_or, jsonable
from monitor.certify.certificate import Certificate, PairResult


def test_policies_differ_only_on_infinities():
    x = {"a": np.array([1.0, np.inf, -np.inf, np.nan]), "b": (np.int64(3), np.bool_(True))}
    assert jsonable(x, "null") == {"a": [1.0, None, None, None], "b": [3, True]}
    assert jsonable(x, "clamp") == {"a": [1.0, 1e308, -1e308, None], "b": [3, True]}
    json.dumps(jsonable(x), allow_nan=False)  # strict JSON
    assert finite_or(2.5) == 2.5 and finite_or(math.nan, "clamp") is None


def test_certificate_round_trip_keeps_the_sign_of_an_infinite_clearance():
    pr = PairResult(("a", "b"), ("A", "B"), "uncertain", "toleranced", clearance=-math.inf)
    c = Certificate("uncertain", (0.0, 1.0), 0.0, 1e-3, "auto", None, 0.0, -math.inf, (pr,),
                    {"wall_seconds": np.float64(0.5), "depth": np.int32(3)})
    d = json.loads(json.dumps(c.to_dict(), allow_nan=False))
    back = Certificate.from_dict(d)
    assert back.clearance < -1e300 and back.pairs[0].clearance < -1e300
    assert back.stats == {"wall_seconds": 0.5, "depth": 3}
