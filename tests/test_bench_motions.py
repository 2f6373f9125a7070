"""Screw and Bézier motions in the bench case set (issue 14, item 4): poses, speed bounds, oracle, peers.

Independent checks: the bench's own pose formulas (closed-form twist exponential from
``scipy.linalg.logm``; hand-written de Casteljau) against ``monitor.motion``; the Lipschitz
speed bounds against dense sampling; the oracle against closed forms (a sphere on a circular
screw arc past a sphere; a straight Bézier pass over a box); python-fcl's ``CCDM_SCREW``
against an obstacle placed on the screw path and off the lerp path.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")

from monitor.bench import oracle  # noqa: E402
from monitor.bench.cases import PairCase, ShapeSpec, _motion_cases, planar_bezier  # noqa: E402

IDQ = np.array([1.0, 0.0, 0.0, 0.0])


def _zquat(angle: float) -> np.ndarray:
    return np.array([math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)])


def circle_case(gap: float) -> PairCase:
    """Sphere A (r 0.05) turns about the world z axis on the circle of radius 0.5 from angle
    -0.6 to +0.6 rad (its two poses differ by a pure rotation about z: a screw of pitch 0).
    Sphere B (r 0.1) is fixed at (0.65 + gap, 0, 0), so the minimum distance is exactly
    ``gap`` (at angle 0). The lerp of the same poses cuts the chord at x = 0.5 cos 0.6 = 0.41,
    far from B: only the screw comes close."""
    a, b = ShapeSpec("sphere", radius=0.05), ShapeSpec("sphere", radius=0.1)
    pos = np.zeros((2, 2, 3))
    quat = np.tile(IDQ, (2, 2, 1))
    for k, ang in enumerate((-0.6, 0.6)):
        pos[0, k] = [0.5 * math.cos(ang), 0.5 * math.sin(ang), 0.0]
        quat[0, k] = _zquat(ang)
    pos[1, :] = [0.65 + gap, 0.0, 0.0]
    return PairCase(f"circle{gap}", "screw", "near", gap, (a, b), pos, quat, (True, False),
                    interpolation="screw")


def line_bezier_case(gap: float) -> PairCase:
    """Box A (half 0.1, 0.08, 0.05) on a Bézier with constant rotation and collinear control
    points along x at height y = 0.18 + gap over box B (half 0.1): min distance exactly ``gap``."""
    a, b = ShapeSpec.box([0.1, 0.08, 0.05]), ShapeSpec.box([0.1, 0.1, 0.1])
    Q = np.tile(IDQ, (3, 1))
    y = 0.1 + 0.08 + gap
    T = np.stack([np.linspace(-0.6, 0.6, 5), np.full(5, y), np.zeros(5)], axis=1)
    pos = np.zeros((2, 2, 3))
    pos[0, 0], pos[0, 1] = T[0], T[-1]
    quat = np.tile(IDQ, (2, 2, 1))
    return PairCase(f"line{gap}", "bezier", "near", gap, (a, b), pos, quat, (True, False),
                    interpolation="bezier", bezier=(Q, T))


def test_circle_case_is_the_screw():
    case = circle_case(0.0)
    P, _ = case.poses(np.linspace(0, 1, 101))
    assert np.allclose(np.linalg.norm(P[:, 0, :2], axis=1), 0.5, atol=1e-12)  # on the circle
    lerp = PairCase("l", "rotating", "near", 0.0, case.shapes, case.pos, case.quat, (True, False))
    assert lerp.poses(np.array([0.5]))[0][0, 0, 0] == pytest.approx(0.5 * math.cos(0.6))


@pytest.mark.parametrize("gap", [1e-2, 1e-4, -1e-4])
def test_oracle_closed_form_screw_and_bezier(gap):
    for case in (circle_case(gap), line_bezier_case(gap)):
        lab = oracle.label(case)
        if gap > 0:
            assert lab.label == "clear", case.name
            assert 0.0 < lab.clearance_lower <= gap + 1e-9
            assert lab.distance_upper >= gap - 1e-6
        else:
            assert lab.label == "collide", case.name


def _cases():
    rng = np.random.default_rng(11)
    out = []
    for _ in range(3):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        Q, T = planar_bezier(rng, rng.uniform(0.5, 0.9), u)
        pos = np.zeros((2, 2, 3))
        pos[0, 0], pos[0, 1] = T[0], T[-1]
        quat = np.tile(IDQ, (2, 2, 1))
        quat[0, 0], quat[0, 1] = Q[0] / np.linalg.norm(Q[0]), Q[-1] / np.linalg.norm(Q[-1])
        out.append(PairCase("b", "bezier", "near", 0.0, (ShapeSpec.box(rng.uniform(0.05, 0.2, 3)),
                                                         ShapeSpec.box([0.1, 0.1, 0.1])),
                            pos, quat, (True, False), interpolation="bezier", bezier=(Q, T)))
        from scipy.spatial.transform import Rotation

        q = Rotation.random(2, random_state=rng).as_quat(scalar_first=True)
        q1 = (Rotation.from_rotvec(rng.uniform(0.5, 2.5) * u) * Rotation.from_quat(q[0], scalar_first=True)
              ).as_quat(scalar_first=True)
        pos = rng.normal(size=(2, 2, 3))
        quat = np.stack([[q[0], q1 if q1 @ q[0] >= 0 else -q1], [q[1], q[1]]])
        out.append(PairCase("s", "screw", "near", 0.0, (ShapeSpec.box(rng.uniform(0.05, 0.2, 3)),
                                                        ShapeSpec.box([0.1, 0.1, 0.1])),
                            pos, quat, (True, True), interpolation="screw"))
    return out


def test_poses_match_monitor_motion():
    ts = np.linspace(0.0, 1.0, 17)
    for case in _cases():
        pos, rot = case.body_motion().body_poses(ts)
        P, R = case.poses(ts)
        assert np.abs(pos[:, 1:] - P).max() < 1e-12, case.name
        assert np.abs(rot[:, 1:] - R).max() < 1e-12, case.name


def test_speed_bounds_are_conservative():
    ts = np.linspace(0.0, 1.0, 20001)
    for case in _cases():
        P, R = case.poses(ts)
        bound = case.speed_bounds()
        for b in range(2):
            X = np.einsum("tij,nj->tni", R[:, b], case.shapes[b].vertices) + P[:, b, None, :]
            speed = np.linalg.norm(np.diff(X, axis=0), axis=2).max() / (ts[1] - ts[0])
            # 1e-9 relative: rounding of the finite differences (a translation's bound is exact)
            assert speed <= bound[b] * (1 + 1e-9), (case.name, b, speed, bound[b])
            assert speed >= 0.2 * bound[b] or bound[b] < 1e-9  # not uselessly loose


def test_fcl_screw_follows_the_screw():
    from monitor.bench import peers

    if not peers.have_fcl():
        pytest.skip("python-fcl not installed")
    case = circle_case(-1e-3)
    screw = peers.FclPeer("CCDM_SCREW", "CCDC_CONSERVATIVE_ADVANCEMENT")
    linear = peers.FclPeer("CCDM_LINEAR", "CCDC_CONSERVATIVE_ADVANCEMENT")
    assert screw.query(screw.prepare(case))[0] is True
    assert linear.query(linear.prepare(case))[0] is False  # the lerp cuts the chord, far from B
    assert peers.peer_support(linear, case, {}) is not None
    assert peers.peer_support(peers.MujocoSampler(10), case) is None


def test_peers_suite_screw_and_bezier_rows(tmp_path):
    from monitor.bench import peers
    from monitor.bench.oracle import mujoco_distance
    from monitor.bench.suites import BenchConfig, suite_peers

    cases = _motion_cases(np.random.default_rng(5), True, mujoco_distance)
    assert [c.group for c in cases] == ["screw"] * 3 + ["bezier"] * 3
    labels = [oracle.label(c) for c in cases]
    assert {lab.label for lab in labels} >= {"collide", "clear"}
    cfg = BenchConfig(quick=True, out=tmp_path, reps=1, log=lambda s: None, smoke=True)
    cfg.shared["cases"], cfg.shared["labels"] = cases, labels
    res = suite_peers(cfg)
    if res.get("skipped"):
        pytest.skip(res["skipped"])
    rows = {(r["checker"], r["group"]): r for r in res["rows"]}
    for group in ("screw", "bezier"):
        for name in ("ours/toleranced eps=1e-3", "ours/auto eps=1e-3"):
            assert rows[(name, group)]["misses"] == 0
            assert rows[(name, group)]["unsupported"] == 0
        assert rows[("mujoco/N=1000", group)]["unsupported"] == 0
    if peers.have_fcl():
        fcl_rows = [r for (n, g), r in rows.items() if n.startswith("fcl/") and g == "bezier"]
        assert fcl_rows and all(r["unsupported"] == r["n"] for r in fcl_rows)
        for (n, g), r in rows.items():  # other fcl motion types interpolate differently
            if n.startswith("fcl/") and not n.startswith("fcl/SCREW/") and g == "screw":
                assert r["unsupported"] == r["n"], n
        assert any(n.startswith("fcl/SCREW/") and g == "screw" and r["unsupported"] < r["n"]
                   for (n, g), r in rows.items())


@pytest.mark.slow
@pytest.mark.parametrize("group", ["screw", "bezier"])
def test_full_motion_cases_no_misses(group):
    """The full-size screw / Bézier case group (25 cases): ours never certifies an oracle collision."""
    from monitor.bench.oracle import mujoco_distance
    from monitor.bench.suites import run_ours

    cases = _motion_cases(np.random.default_rng(7), False, mujoco_distance, groups=(group,))
    counts: dict[tuple[str, str], int] = {}
    for case in cases:
        lab = oracle.label(case)
        r = run_ours(case, "auto", 1e-3, 1, budget_s=10.0)
        counts[(lab.label, r["verdict"])] = counts.get((lab.label, r["verdict"]), 0) + 1
        assert r["verdict"] in ("certified", "violation", "uncertain"), r
        assert not (lab.label == "collide" and r["verdict"] == "certified"), case.name
        assert not (lab.label == "clear" and r["verdict"] == "violation"), case.name
    print(f"\n{group}: (oracle label, verdict) counts {sorted(counts.items())}")
    assert len(cases) == 25
