"""``engine._find_witness`` poses its first candidate alone on a Plan without quaternion tracks.

Oracle: the former loop (every candidate posed in one ``body_poses`` call, then the first
confirmed one), on a slide + hinge arm against a wall; the witness (time, pair, point bytes,
distance) must be the same object value whichever candidate confirms (the first, a later one,
none), and a plan with a ball joint keeps the one-batch path. Seeded, no timings.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify import engine
from monitor.certify.common import Budget
from monitor.geometry.distance import shape_distance
from monitor.tolerances import DEFAULT

_XML = """<mujoco><worldbody>
  <geom name="wall" type="box" size="0.05 0.5 0.5" pos="0.6 0 0"/>
  <body name="b"><joint name="s" type="slide" axis="1 0 0"/><joint name="h" type="hinge" axis="0 0 1"/>
    <geom name="arm" type="capsule" size="0.03 0.1" pos="0.2 0 0" euler="0 90 0"/>
    {ball}
  </body>
</worldbody></mujoco>"""
_BALL = '<body name="c" pos="0 0.3 0"><joint type="ball"/><geom name="knob" size="0.02"/></body>'


def _old_find_witness(plan, ga, gb, times, margin, tol):
    pos, rot = plan.body_poses(times)
    slack = engine._approx(ga, gb)
    for k, t in enumerate(times):
        d = shape_distance(ga.shape, (rot[k, ga.body_id], pos[k, ga.body_id]),
                           gb.shape, (rot[k, gb.body_id], pos[k, gb.body_id]), tolerances=tol)
        if d.upper + slack < margin:
            return (float(t), (ga.name, gb.name), (0.5 * (d.p_a + d.p_b)).tobytes(), float(d.upper + slack))
    return None


def _key(w):
    return None if w is None else (w.time, w.geoms, np.asarray(w.point).tobytes(), w.distance)


@pytest.mark.parametrize("ball", [False, True])
@pytest.mark.parametrize("seed", range(4))
def test_lazy_first_candidate_gives_the_batch_witness(ball, seed):
    m = mujoco.MjModel.from_xml_string(_XML.format(ball=_BALL if ball else ""))
    rng = np.random.default_rng(seed)
    K = int(rng.integers(2, 5))
    q = np.tile(np.array(m.qpos0), (K, 1))
    q[:, 0] = np.linspace(0.0, 0.4, K)      # towards the wall: clear by > 0.2 at t0, inside it at t1
    q[:, 1] = rng.uniform(-0.4, 0.4, K)
    plan = monitor.Plan(np.cumsum(rng.uniform(0.02, 0.1, K)), q, m)
    assert bool(plan._quat_tracks) == ball
    scene = monitor.Scene.from_model(m, pairs="all")
    ga, gb = scene.geom("arm"), scene.geom("wall")
    t0, t1 = plan.window
    seen = set()
    queries = [np.array([t0, t1]), np.array([t1, t0]), np.array([t0, 0.999 * t0 + 0.001 * t1])]
    queries += [np.sort(rng.uniform(t0, t1, n)) for n in (1, 2, 9, 20)]
    for times in queries:
        for margin in (0.0, 0.01, 0.05, 0.2):
            want = _old_find_witness(plan, ga, gb, times, margin, DEFAULT)
            plan._pose_cache.clear()
            got = engine._find_witness(plan, ga, gb, times, margin, DEFAULT, Budget())
            assert _key(got) == want
            assert _key(engine._find_witness(plan, ga, gb, times, margin, DEFAULT)) == want
            seen.add(None if want is None else int(np.searchsorted(times, want[0]) > 0))
    assert seen >= {0, 1, None}, seen    # the first, a later and no candidate confirm


def test_an_exhausted_budget_still_gives_no_witness():
    m = mujoco.MjModel.from_xml_string(_XML.format(ball=""))
    plan = monitor.Plan([0.0, 0.1], [[0.0, 0.0], [0.4, 0.0]], m)
    scene = monitor.Scene.from_model(m, pairs="all")
    bud = Budget(seconds=0.0)
    assert bud.exhausted
    times = np.linspace(0.0, 0.1, 9)
    assert _old_find_witness(plan, scene.geom("arm"), scene.geom("wall"), times, 0.2, DEFAULT) is not None
    assert engine._find_witness(plan, scene.geom("arm"), scene.geom("wall"), times, 0.2, DEFAULT, bud) is None
