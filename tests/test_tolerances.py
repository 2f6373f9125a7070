"""Issue 11: every ``Tolerances`` field is validated at construction.

A negative pad turned a real collision into "certified" (the arm yawing through
``post_a``), ``abs_pad=nan`` hung the checker, and ``review --verify`` builds a
``Tolerances`` from values stored in a log, so each bad value must raise
``InvalidInputError`` naming its field.
"""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np
import pytest

from monitor.errors import InvalidInputError
from monitor.tolerances import DEFAULT, Tolerances

FLOAT_FIELDS = ("quat_norm_tol", "rel_pad", "abs_pad", "scale_pad", "extrusion_slack")
INT_FIELDS = ("max_depth", "facets", "witness_candidates", "max_frontier")

BAD = [
    # (field, value): one row per field and failure mode
    ("rel_pad", -1.0), ("rel_pad", math.nan), ("rel_pad", math.inf), ("rel_pad", "1e-14"),
    ("abs_pad", -1.0), ("abs_pad", math.nan), ("abs_pad", -math.inf), ("abs_pad", None),
    ("scale_pad", -1.0), ("scale_pad", math.nan), ("scale_pad", True),
    ("extrusion_slack", -1.0), ("extrusion_slack", math.nan), ("extrusion_slack", [1e-9]),
    ("quat_norm_tol", 10.0), ("quat_norm_tol", 0.0), ("quat_norm_tol", -1e-6), ("quat_norm_tol", math.nan),
    ("max_depth", -1), ("max_depth", 0), ("max_depth", 2.5), ("max_depth", True), ("max_depth", "40"),
    ("facets", 2), ("facets", 16.0), ("facets", -3),
    ("witness_candidates", 0), ("witness_candidates", -9), ("witness_candidates", 9.5),
    ("max_frontier", -1), ("max_frontier", 1.5), ("max_frontier", None),
]


def test_every_field_has_a_bad_value_row():
    covered = {f for f, _ in BAD}
    assert covered == {f.name for f in fields(Tolerances)}
    assert set(FLOAT_FIELDS) | set(INT_FIELDS) == covered


@pytest.mark.parametrize(("name", "value"), BAD, ids=[f"{f}={v!r}" for f, v in BAD])
def test_bad_value_raises_naming_the_field(name, value):
    with pytest.raises(InvalidInputError, match=rf"Tolerances\.{name}\b"):
        Tolerances(**{name: value})


def test_defaults_and_edge_values_are_accepted():
    assert Tolerances() == DEFAULT
    t = Tolerances(rel_pad=0.0, abs_pad=0.0, scale_pad=0.0, extrusion_slack=0.0, quat_norm_tol=1e-2,
                   max_depth=1, facets=3, witness_candidates=1, max_frontier=0)
    assert t.max_frontier == 0  # 0 = no cap, documented
    # numpy scalars are normalised to Python numbers
    t = Tolerances(abs_pad=np.float32(1e-9), max_depth=np.int64(12))
    assert type(t.abs_pad) is float and t.abs_pad == pytest.approx(1e-9)
    assert type(t.max_depth) is int and t.max_depth == 12

