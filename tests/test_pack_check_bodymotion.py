"""The pack check of a plain BodyMotion (kernels._body_motion_agrees): probes once, layout + data per motion.

Oracle: ``BodyMotion.body_poses`` (the motion's own Python lerp/slerp) through ``kernels._poses_match``,
the former per-motion check; every corrupted pack below really moves some body (the former check
refuses it too), and the new check must refuse it without evaluating the motion's poses.
"""

from __future__ import annotations

import numpy as np
import pytest

import monitor
from monitor.bench.suites import scaling_scene
from monitor.certify import kernels as K
from monitor.motion import pack as PK


def _motion(n: int, seed: int, motion: str = "rotating"):
    model, bm = scaling_scene(n, "sparse", motion, seed=seed)
    return model, bm


def _set(field, idx, fn):
    """A pack_trajectory replacement whose packs have ``field[idx]`` replaced by ``fn(old)``."""
    real = PK.pack_trajectory

    def bad(traj):
        mp = real(traj)
        a = getattr(mp, field).copy()
        a[idx] = fn(a[idx])
        return mp._replace(**{field: a})
    return bad


def _fresh(bm):
    """A new BodyMotion object with the same data (the pack cache is per object)."""
    return monitor.BodyMotion(bm.times.copy(), bm.pos.copy(), bm.quat.copy(), ref_points=bm.ref_points.copy())


def test_plain_body_motion_is_packed_without_a_per_motion_pose_evaluation(monkeypatch):
    K._body_motion_probe_ok()                      # the once-per-process probes, outside the spy
    calls = []
    real = K._poses_match
    monkeypatch.setattr(K, "_poses_match", lambda traj, mp: calls.append(traj) or real(traj, mp))
    _, bm = _motion(30, 1)
    mp = K.trajectory_pack(bm)
    assert mp is not None and not calls
    assert real(bm, mp)                            # and the packed poses are the motion's own


@pytest.mark.parametrize("field, idx, fn", [
    ("qpos", (1, 7 * 3 + 1), lambda v: v + 1e-6),            # a waypoint position of body 4
    ("qpos", (0, 7 * 5 + 4), lambda v: v + 1e-3),            # a waypoint quaternion of body 6
    ("qt_target", (2, 0, 1), lambda v: v + 1e-3),            # the slerp target of body 3
    ("times", 1, lambda v: v * 0.9),                         # the window end
    ("body_pos", (0, 1), lambda v: v + 0.01),                # the world's pose
    ("jnt_qposadr", 2, lambda v: 7),                         # body 3 reads body 2's columns
])
def test_a_corrupted_body_motion_pack_is_refused(monkeypatch, field, idx, fn):
    _, bm = _motion(12, 2)
    bad = _set(field, idx, fn)
    mp_bad = bad(bm)
    assert not K._poses_match(bm, mp_bad)          # the corruption moves a body: the oracle sees it
    monkeypatch.setattr(PK, "pack_trajectory", bad)
    assert K.trajectory_pack(_fresh(bm)) is None


def test_a_subclass_keeps_the_full_per_motion_check(monkeypatch):
    class Shifted(monitor.BodyMotion):
        def body_poses(self, times):
            p, r = super().body_poses(times)
            return p + 1e-3, r

    _, bm = _motion(8, 3)
    sub = Shifted(bm.times, bm.pos, bm.quat)
    assert K.trajectory_pack(sub) is None          # its own (shifted) poses differ from the pack's


def test_a_failed_probe_refuses_every_body_motion(monkeypatch):
    monkeypatch.setattr(K, "_BODY_MOTION_PROBE", [])
    monkeypatch.setattr(K, "_poses_match", lambda traj, mp: False)
    _, bm = _motion(8, 4)
    assert K.trajectory_pack(_fresh(bm)) is None


def test_the_probes_cover_the_slerp_edge_cases():
    """Held orientation, tiny turn, turns either side of a half turn, antipodal pair, translation only."""
    probes = K._probe_body_motions()
    assert {bm.pos.shape[0] for bm in probes} == {2, 5}
    for bm in probes:
        tr = bm._tracks
        assert tr[1].same.all() and tr[2].same[0] and not tr[3].same[0]
        assert 0 < tr[3].phi[0] < 1e-8
        assert tr[4].phi[0] < np.pi and abs(tr[4].phi[0] - np.pi) < 1e-5
        assert abs(tr[6].phi[0] - np.pi) < 1e-6 and tr[7].phi[0] == 0.0
        assert not np.array_equal(bm.quat[0, 0], [1.0, 0.0, 0.0, 0.0])
        assert K._poses_match(bm, PK.pack_trajectory(bm))


@pytest.mark.parametrize("motion", ["translating", "rotating"])
def test_certificates_equal_the_full_check(monkeypatch, motion):
    """Same verdicts, clearances and checker mix as with the former per-motion pose check."""
    model, bm = _motion(27, 5, motion)
    scene = monitor.Scene.from_model(model, pairs="all")
    fast = monitor.certify(scene, bm, margin=0.05, epsilon=1e-3)
    monkeypatch.setattr(K, "_pack_agrees", K._poses_match)
    full = monitor.certify(scene, _fresh(bm), margin=0.05, epsilon=1e-3)
    assert fast.verdict == full.verdict and fast.clearance == full.clearance
    assert fast.stats["checker_mix"] == full.stats["checker_mix"]


def test_dense_violations_equal_the_full_check(monkeypatch):
    """Colliding neighbours: same violation, witness time and geoms as with the former full check."""
    model, bm = scaling_scene(27, "dense", "translating", seed=6)
    scene = monitor.Scene.from_model(model, pairs="all")
    fast = monitor.certify(scene, bm, epsilon=1e-3)
    monkeypatch.setattr(K, "_pack_agrees", K._poses_match)
    full = monitor.certify(scene, _fresh(bm), epsilon=1e-3)
    assert fast.verdict == full.verdict == "violation"
    assert fast.witness.time == full.witness.time and fast.witness.geoms == full.witness.geoms
    assert fast.stats["checker_mix"] == full.stats["checker_mix"]
