"""Long windows (a fast start and a slow braking tail over many waypoints) in the compiled pair window.

Issue 12, long windows: the gate certifies the window and its braking tail in one call, a
plan of ~130 waypoints whose motion is fast at the start and decays after it. The sweep of
:func:`monitor.certify.kernels.pair_window` retries a failed prefix that crosses waypoints with
a length from the pair's motion profile. Soundness must not depend on that choice:

* every certified pair of seeded Arm windows (3 hinges, mesh gripper, cylinders, boxes,
  capsules, a floor) is checked against MuJoCo's own ``mj_geomDistance`` at dense samples
  and at every waypoint: no certified pair may come within the margin there; every confirmed
  violation is a real one at its witness time (the same oracle);
* the kernel is stepped one test at a time (``max_tests=1``) and the excluded sub-intervals
  are read off the stack (as tests/test_adaptive.py): for a certified pair they tile the
  window exactly, for a violation they all end before the witness; retries of a prefix that
  crosses a waypoint occur (the new code path is exercised).

Seeded; no timings.
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

from monitor import Plan, Scene
from monitor.certify import kernels as K
from monitor.certify.kernels import scene_pack, trajectory_pack

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _intervals import minus  # noqa: E402

MODEL = "models/arm/scene.xml"
REL, ABS = 64 * 2.0**-52, 1e-12


def _plan(m, rng, K_wp=61, dt=0.002, tau=0.012):
    """q(t) = q0 + dq (1 - exp(-t / tau)) at every substep: fast first, then a decaying tail."""
    lo, hi = m.jnt_range[:, 0], m.jnt_range[:, 1]
    q0 = rng.uniform(0.8 * lo, 0.8 * hi)
    dq = rng.uniform(-0.9, 0.9, m.nq)
    times = dt * np.arange(K_wp)
    qpos = q0 + dq * (1.0 - np.exp(-times / tau))[:, None]
    return Plan(times, qpos, model=m)


def _trace(gp, mp, ga, gb, window, margin, eps=1e-3, max_depth=40):
    """Step pair_window (MODE_CERTIFY_ONLY) one test at a time.

    Returns (verdict code, excluded pieces, result row, retries across a waypoint).
    """
    stack = np.empty((max_depth + 2, 3))
    res = K.new_result()
    t0, t1 = window
    times = mp.times
    excluded = []
    retries = 0
    tested = (t0, t1)           # the first test: the whole window
    pending = [[t0, t1]]
    for _ in range(20000):
        state = (res[K.R_WTIME], res[K.R_UNRES])
        v = K.pair_window(gp, mp, ga, gb, t0, t1, margin, eps, max_depth, 1, K.MODE_CERTIFY_ONLY, REL, ABS,
                          stack, res)
        sp = int(res[K.R_SP]) if v == K.PAUSED else 0
        rows = sorted((float(stack[i, 0]), float(stack[i, 1])) for i in range(sp))
        after = []
        for a, b in rows:
            if after and a <= after[-1][1]:
                after[-1][1] = max(after[-1][1], b)
            else:
                after.append([a, b])
        same = all(x == y or (x != x and y != y) for x, y in zip(state, (res[K.R_WTIME], res[K.R_UNRES]),
                                                                    strict=True))
        if same and res[K.R_WTIME] != res[K.R_WTIME]:
            gone = minus(pending, after)
            assert gone == [] or gone == [tested], (gone, tested)
            excluded += gone
            if not gone and sp and stack[sp - 1, 2] < 0.0 and stack[sp - 1, 0] == tested[0]:
                # a retry of a shorter prefix; count those whose failed prefix crossed a waypoint
                if ((times > tested[0]) & (times < tested[1])).any():
                    retries += 1
        pending = after
        if v != K.PAUSED:
            return v, sorted(excluded), res, retries
        a, b, d = (float(x) for x in stack[sp - 1])
        if d < 0.0:
            b = b if not a - d < b + 0.05 * d else a - d
        tested = (a, b)
    raise AssertionError("pair_window did not finish")


def _mj_distances(m, plan, ga, gb, ts):
    d = mujoco.MjData(m)
    out = np.empty(len(ts))
    # one vectorised interpolation for all samples (row i equals qpos_at(ts[i]) bit for bit; a
    # call per sample was ~85 % of these tests' time)
    Q = plan.qpos_at(np.asarray(ts, dtype=float))
    for i in range(len(ts)):
        d.qpos[:] = Q[i]
        mujoco.mj_kinematics(m, d)
        out[i] = mujoco.mj_geomDistance(m, d, ga, gb, 1.0, None)
    return out


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
@pytest.mark.parametrize("margin", [0.0, 0.01])
def test_long_windows_agree_with_mujoco_and_tile(seed, margin):
    m = mujoco.MjModel.from_xml_path(MODEL)
    scene = Scene.from_model(m, pairs="all")
    rng = np.random.default_rng(1000 + seed)
    plan = _plan(m, rng)
    mp = trajectory_pack(plan)
    assert mp is not None
    gp = scene_pack(scene).geoms
    window = (float(plan.times[0]), float(plan.times[-1]))
    ts = np.unique(np.concatenate([np.linspace(*window, 601), plan.times]))
    seen = {K.CERTIFIED: 0, K.VIOLATION: 0, K.UNRESOLVED: 0}
    retries = 0
    for ga, gb in scene.pair_ids.tolist():
        if gp.kind[ga] == -1 and gp.kind[gb] == -1:
            continue
        v, pieces, res, r = _trace(gp, mp, ga, gb, window, margin)
        retries += r
        one = K.check_pair_window(gp, mp, ga, gb, window, margin, 1e-3, certify_only=True)
        assert one["verdict"] == K._NAMES[int(v)] and one["tests"] == int(res[K.R_TESTS])
        seen[int(v)] = seen.get(int(v), 0) + 1
        name = (scene.geoms[ga].name, scene.geoms[gb].name)
        if v == K.CERTIFIED:
            assert pieces[0][0] == window[0] and pieces[-1][1] == window[1], name
            assert all(b == c for (_, b), (c, _) in zip(pieces, pieces[1:], strict=False)), (name, "gap")
            dist = _mj_distances(m, plan, ga, gb, ts)
            # certified: clearance > margin at every instant (MuJoCo's GJK tolerance: 1e-6)
            assert dist.min() > margin - 1e-6, (name, float(dist.min()), float(ts[np.argmin(dist)]))
            assert res[K.R_CLEAR] <= dist.min() + 1e-6, name        # the clearance is a lower bound
        elif v == K.VIOLATION:
            wt = float(res[K.R_WTIME])
            assert not pieces or pieces[-1][1] <= wt, name
            assert _mj_distances(m, plan, ga, gb, [wt])[0] < margin + 1e-6, name
    assert seen[K.CERTIFIED] >= 10, seen
    assert retries > 0


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4, 5])
def test_long_windows_through_the_engine_agree_with_mujoco(seed):
    """monitor.certify on long windows (the compiled window kernel: broad phase, sub-ranges
    cleared by the swept spheres, narrow phase on the rest): every certified pair clear at
    dense samples by MuJoCo's distance, its clearance a lower bound of them; witnesses real."""
    import monitor

    m = mujoco.MjModel.from_xml_path(MODEL)
    scene = Scene.from_model(m, pairs="all")
    rng = np.random.default_rng(2000 + seed)
    plan = _plan(m, rng, K_wp=131)
    ts = np.unique(np.concatenate([np.linspace(plan.times[0], plan.times[-1], 801), plan.times]))
    margin = 0.005
    cert = monitor.certify(scene, plan, margin=margin, epsilon=1e-3)
    n_cert = 0
    for pr in cert.pairs:
        ga, gb = scene.geom(pr.geoms[0]).id, scene.geom(pr.geoms[1]).id
        if pr.verdict == "certified":
            dist = _mj_distances(m, plan, ga, gb, ts)
            assert dist.min() > margin - 1e-6, (pr.geoms, float(dist.min()))
            assert pr.clearance <= dist.min() + 1e-6, (pr.geoms, pr.clearance, float(dist.min()))
            n_cert += 1
        elif pr.verdict == "violation" and pr.witness is not None:
            assert _mj_distances(m, plan, ga, gb, [pr.witness.time])[0] < margin + 1e-6, pr.geoms
    assert n_cert >= 10
