"""The pose validation of ``shape_distance`` (``geometry.distance._check_pose``): its Python-float fast
path accepts exactly what the numpy checks accept and leaves every error to them (issue 12).

Oracle: the numpy checks alone (the function as it was, copied here), on seeded valid poses,
every entry set to NaN / +-inf / just beyond or exactly at its bound, huge finite entries whose
sum overflows, and -0.0: the same arrays back, or the same InvalidInputError message.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from monitor.errors import InvalidInputError
from monitor.geometry import distance as D


def _reference(X, name):
    R, p = X
    R = np.ascontiguousarray(R, dtype=np.float64)
    p = np.ascontiguousarray(p, dtype=np.float64)
    if R.shape != (3, 3) or p.shape != (3,):
        raise InvalidInputError(f"{name}: expected R (3, 3) and p (3,), got {R.shape} and {p.shape}")
    if not math.isfinite(R.sum() + p.sum()):
        raise InvalidInputError(f"{name}: pose is not finite")
    if max(p.max(), -p.min()) > D._MAX_COORD or max(R.max(), -R.min()) > D._MAX_ROT:
        raise InvalidInputError(f"{name}: translation beyond {D._MAX_COORD:g} m or rotation entry beyond "
                                f"{D._MAX_ROT:g}: p={p.tolist()}, max |R_ij|={float(np.abs(R).max()):g}")
    return R, p


def _outcome(f, R, p):
    try:
        Rc, pc = f((R, p), "X_a")
    except InvalidInputError as e:
        return ("error", str(e))
    return ("ok", Rc.tobytes(), pc.tobytes())


def _poses():
    rng = np.random.default_rng(12)
    for _ in range(20):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        w, x, y, z = q
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        yield R, rng.normal(size=3) * 10.0 ** rng.integers(-3, 8)
    yield -0.0 * np.eye(3), np.array([-0.0, 0.0, -0.0])
    yield np.full((3, 3), D._MAX_ROT), np.full(3, D._MAX_COORD)          # exactly at the bounds
    yield np.full((3, 3), -D._MAX_ROT), np.full(3, -D._MAX_COORD)


def _bad_entries(R, p):
    big_p = [math.nan, math.inf, -math.inf, np.nextafter(D._MAX_COORD, math.inf), -1e308, 1e308]
    big_r = [math.nan, math.inf, -math.inf, np.nextafter(D._MAX_ROT, math.inf), -3.0, 1e308]
    for k in range(3):
        for v in big_p:
            q = p.copy()
            q[k] = v
            yield R, q
    for k in range(9):
        for v in big_r:
            S = R.copy()
            S.flat[k] = v
            yield S, p
    yield np.full((3, 3), 1e308), p                                           # finite, sum overflows
    yield R, np.array([math.nan, math.inf, 0.0])


def test_same_answers_as_the_numpy_checks():
    n_ok = n_err = 0
    for R, p in _poses():
        want = _outcome(_reference, R, p)
        assert _outcome(D._check_pose, R, p) == want
        n_ok += want[0] == "ok"
        for S, q in _bad_entries(R, p):
            want = _outcome(_reference, S, q)
            assert _outcome(D._check_pose, S, q) == want
            n_err += want[0] == "error"
    assert n_ok == 23 and n_err > 23 * 60


def test_shapes_and_types_still_rejected():
    for X in [(np.eye(3), np.zeros(2)), (np.eye(2), np.zeros(3)), ("R", np.zeros(3))]:
        with pytest.raises(InvalidInputError):
            D._check_pose(X, "X_a")
