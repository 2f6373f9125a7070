"""Fallback windows in which nothing moves, answered from the reuse cache without a Plan (issue 12).

Oracle: the same gate with ``Gate._certify_static`` declining (the general path: the window's
Plan, its poses, ``_split_reuse``), compared report by report (certificates field for field
without wall time, ``info()``, states) on the tunnel held against its wall, with a setting
reassigned, the ball put at rest at other places, and the wall moved (a model edit: new scene
version) midway.
"""

from __future__ import annotations

import mujoco
import numpy as np

from monitor._paths import scene_path
from monitor.gate import Gate


def _key(r):
    def cert(c):
        if c is None:
            return None
        d = c.to_dict()
        d["stats"] = {k: v for k, v in d["stats"].items() if k != "wall_seconds"}
        return repr(d)

    info = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in sorted(r.info().items())}
    return repr((str(r.verdict), r.replaced, str(r.applied_verdict), r.fallback_certified, r.time,
                 np.asarray(r.applied_ctrl).tobytes(), cert(r.certificate), cert(r.fallback_certificate),
                 info))


def _run(static: bool, steps: int = 150):
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate = Gate(m, margin=0.001)
    if not static:
        gate._certify_static = lambda win: None
    wall = m.geom("wall").id
    out, hits = [], []
    for k in range(steps):
        if k in (40, 55, 62, 70, 110):
            hits.append(gate.stats["static_reused"])
        if k in (40, 55, 62):  # the ball put at rest at A, B, A: other poses, other cache keys
            d.qpos[0], d.qvel[0] = (-0.04 if k == 55 else -0.03), 0.0
        if k == 70:
            gate.margin = 0.002  # a new reuse context: the cache and the memo start over
        if k == 110:
            m.geom_pos[wall, 0] += 1e-4  # a model edit: the scene's version changes
        target = 0.3 if k < 70 or (k // 40) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0))
        out.append((_key(r), d.qpos.tobytes(), d.qvel.tobytes(), d.time))
    hits.append(gate.stats["static_reused"])
    return out, gate.summary(), np.diff([0, *hits])


def test_static_fallback_windows_give_the_general_paths_reports():
    fast, s_fast, hits = _run(True)
    slow, s_slow, _ = _run(False)
    assert fast == slow
    for k in ("windows", "certified", "violation", "replaced", "reused_pairs", "pairs", "tail_reused"):
        assert s_fast[k] == s_slow[k], k
    assert s_slow["static_reused"] == 0
    assert (hits >= 3).all()  # the path was taken before and after each context change


def test_pairs_moving_memo_equals_the_formula():
    """``Gate._pairs_moving`` (memoised on its last call) against ``moving[body_a] | moving[body_b]``.

    Oracle: the formula computed afresh. Seeded calls that repeat the last ``moving`` (memo hits),
    change it, and switch between body-id arrays of different contents (a rebuilt scene); the
    result is read-only and ``all`` is ``either.all()``.
    """
    g = Gate(mujoco.MjModel.from_xml_path(str(scene_path("tunnel"))), margin=0.001)
    rng = np.random.default_rng(15)
    pools = [tuple(rng.integers(0, 6, size=(2, p))) for p in (1, 4, 9)]
    moving = rng.random(6) < 0.5
    hits = 0
    for t in range(300):
        if t % 5 == 0:
            moving = rng.random(6) < 0.7
        body_a, body_b = pools[int(rng.integers(len(pools)))] if t % 7 == 0 else pools[0]
        memo = g._moving_memo
        either, all_move = g._pairs_moving(moving.copy(), body_a, body_b)
        want = moving[body_a] | moving[body_b]
        hits += memo is not None and g._moving_memo is memo
        assert either.tobytes() == want.tobytes() and either.shape == want.shape
        assert all_move is bool(want.all())
        assert not either.flags.writeable
    assert 100 <= hits <= 250, hits  # both memo hits and misses
