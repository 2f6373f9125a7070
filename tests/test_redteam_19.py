"""Red team 19: the gate's per-step cuts of c935623 against their former numpy forms.

``gate._row_at_rest`` (the braking tail's stop rule after the first substep, Python floats) must
answer as the former ``np.abs(row).max() <= vel_tol`` (the oracle, float64 throughout) for every
tolerance type: numpy 2 compares a Python float with a numpy float32 / float16 scalar in the narrower
type (NEP 50), so a qvel entry just above a float32 tolerance passed the rule while numpy's form (and
``_first_at_rest``, the loop's rule) failed it. Seeded, no timings.
"""

from __future__ import annotations

import numpy as np
import pytest

from monitor import gate as G


@pytest.mark.parametrize("tol", [np.float32(1e-3), np.float32(0.1), np.float16(1e-3), np.float64(1e-3), 1e-3])
def test_row_at_rest_agrees_with_numpy_form_for_numpy_scalar_tolerances(tol):
    rng = np.random.default_rng(19)
    t64 = float(np.float64(tol))
    edge = [np.nextafter(t64, np.inf), np.nextafter(t64, -np.inf), t64, -np.nextafter(t64, np.inf)]
    rows = [np.array([e, 0.0]) for e in edge]
    rows += [rng.choice(edge + [0.0, -0.0, np.nan, np.inf], size=int(rng.integers(1, 5))) for _ in range(40)]
    seen = set()
    for row in rows:
        expected = bool(np.abs(row).max() <= tol)          # the former form (float64 compare)
        assert G._row_at_rest(row.tolist(), tol) == expected, (row, tol)
        assert (G._first_at_rest(row[None, :], tol) == 0) == expected, (row, tol)  # the loop's rule agrees
        seen.add(expected)
    assert seen == {True, False}
