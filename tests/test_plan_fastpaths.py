"""Plan's small-query fast paths (issue 12, tunnel gate) against the general numpy path, bit for bit.

``Plan._times_ok`` / ``Plan._locate`` replace ``check_times_in_window`` / ``Segments.locate``
for up to 64 / 16 query times; the oracle is the general path itself (the module functions),
compared by bytes, including waypoint times, both window ends, segment boundaries and the
error messages for times outside the window or non-finite.
"""
from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor.errors import InvalidInputError
from monitor.motion import _kinematics as K
from monitor.motion.plan import Plan

XML = """
<mujoco>
  <worldbody>
    <body name="a" pos="0 0 .1">
      <joint name="h" type="hinge" axis="0 1 1"/><joint name="s" type="slide" axis="1 0 0"/>
      <geom name="a" type="capsule" size=".03 .2"/>
      <body name="b" pos="0 0 .4"><joint name="ball" type="ball"/><geom name="b" size=".05"/></body>
    </body>
    <body name="c" pos="1 0 1"><freejoint/><geom name="c" type="box" size=".1 .1 .1"/></body>
  </worldbody>
</mujoco>
"""


def _plan(seed: int, K_: int) -> Plan:
    model = mujoco.MjModel.from_xml_string(XML)
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(1e-4, 0.5, K_)) - rng.uniform(0, 2)
    q = np.tile(np.array(model.qpos0), (K_, 1))
    q[:, 0] = rng.uniform(-3, 3, K_)
    q[:, 1] = rng.uniform(-1, 1, K_)
    for k in range(K_):
        for a in (2, 9):
            v = rng.normal(size=4)
            q[k, a:a + 4] = v / np.linalg.norm(v)
        q[k, 6:9] = rng.uniform(-1, 1, 3)
    return Plan(times, q, model=model)


def _queries(plan: Plan, rng: np.random.Generator) -> list[np.ndarray]:
    t = np.array(plan.times)
    w0, w1 = t[0], t[-1]
    out = [t.copy(), np.array([w0]), np.array([w1]), np.array([w1, w0, w1]),
           np.nextafter(t[1:-1], np.inf), np.nextafter(t[1:-1], -np.inf)]
    for n in (1, 2, 9, 16, 17, 64, 65):
        out.append(rng.uniform(w0, w1, n))
    return out


@pytest.mark.parametrize("seed", range(6))
def test_locate_and_poses_match_the_general_path(seed):
    rng = np.random.default_rng(100 + seed)
    plan = _plan(seed, int(rng.integers(2, 7)))
    for t in _queries(plan, rng):
        ok = plan._times_ok(t)
        ref = K.check_times_in_window(t, plan.window)
        assert ok.dtype == ref.dtype and ok.tobytes() == ref.tobytes()
        assert ok is not t          # a copy, as the general check returns
        for a, b in zip(plan._locate(ref), plan._seg.locate(ref)):
            assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()
        plan._pose_cache.clear()
        pos, mat = plan.body_poses(t)
        pos_ref, mat_ref = plan._fk(plan._qpos_many(ref, plan._seg.locate(ref)))
        assert pos.tobytes() == pos_ref.tobytes() and mat.tobytes() == mat_ref.tobytes()


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, "below", "above"])
def test_bad_times_raise_the_general_message(bad):
    plan = _plan(3, 4)
    w0, w1 = plan.window
    x = {"below": np.nextafter(w0, -np.inf), "above": np.nextafter(w1, np.inf)}.get(bad, bad)
    t = np.array([0.5 * (w0 + w1), x])
    with pytest.raises(InvalidInputError) as ref:
        K.check_times_in_window(t, plan.window)
    with pytest.raises(InvalidInputError) as got:
        plan.body_poses(t)
    assert str(got.value) == str(ref.value)
    # other input types take the general check unchanged
    assert plan._times_ok([w0, w1]).tolist() == [w0, w1]
    assert plan._times_ok(np.array([w0, w1], np.float32)).dtype == np.float64
