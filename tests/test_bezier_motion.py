"""Public rational Bézier motions: monitor.motion.bezier.{RigidBezier, BezierMotion}.

Oracles: an independent evaluation of the motion (de Casteljau written here on the
quaternion polynomial and on the weighted translation), the R^12 curve of the toleranced
checker, and dense sampling of the motion-bound contract of monitor/motion/base.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from monitor.errors import InvalidInputError
from monitor.motion.bezier import BezierMotion, RigidBezier


def _dc(ctrl, s):
    """Plain de Casteljau of (n+1, d) control points at scalar s."""
    c = np.array(ctrl, float)
    while len(c) > 1:
        c = (1 - s) * c[:-1] + s * c[1:]
    return c[0]


def _qmat(q):
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _oracle_pose(rb: RigidBezier, s: float):
    q = _dc(rb.quat_ctrl, s)
    W = rb.weights
    x = _dc(W[:, None] * rb.trans_ctrl, s) / _dc(W[:, None], s)[0]
    return x, _qmat(q)


def random_rigid(rng, m=None, spread=0.6):
    m = int(rng.integers(1, 5)) if m is None else m
    q0 = rng.normal(size=4)
    q0 /= np.linalg.norm(q0)
    Q = q0 + rng.normal(scale=spread, size=(m + 1, 4))
    for _ in range(20):
        try:
            return RigidBezier(Q, np.cumsum(rng.normal(scale=0.4, size=(2 * m + 1, 3)), axis=0))
        except InvalidInputError:
            Q = q0 + 0.5 * (Q - q0)
    raise AssertionError("could not build positive weights")


def random_motion(rng, nbody=3, window=None):
    t0 = float(rng.uniform(0, 1))
    window = (t0, t0 + float(rng.uniform(0.1, 2.0))) if window is None else window
    pos = rng.normal(size=(nbody, 3))
    pos[0] = 0.0
    quat = np.zeros((nbody, 4))
    quat[:, 0] = 1.0
    motions = {b: random_rigid(rng) for b in range(1, nbody) if b == 1 or rng.random() < 0.7}
    ref = rng.normal(scale=0.3, size=(nbody, 3))
    ref[0] = 0.0
    return BezierMotion(window, pos, quat, motions, ref_points=ref)


def test_poses_match_independent_evaluation_and_r12_curve():
    rng = np.random.default_rng(0)
    for _ in range(10):
        bm = random_motion(rng)
        ts = np.linspace(bm.t0, bm.t1, 11)
        pos, rot = bm.body_poses(ts)
        for b, rb in bm.motions.items():
            L, p = rb.curve().evaluate((ts - bm.t0) / (bm.t1 - bm.t0))
            for j, t in enumerate(ts):
                x, R = _oracle_pose(rb, (t - bm.t0) / (bm.t1 - bm.t0))
                assert np.allclose(pos[j, b], x, atol=1e-12) and np.allclose(rot[j, b], R, atol=1e-12)
                assert np.allclose(L[j], R, atol=1e-12) and np.allclose(p[j], x, atol=1e-12)
        static = ~bm.moving_bodies()
        assert np.array_equal(pos[:, static], np.broadcast_to(bm._pos[static], pos[:, static].shape))


def _check_contract(bm, rng, n_int=30, n_pts=16, n_t=60):
    ratios = []
    for _ in range(n_int):
        a, b = np.sort(rng.uniform(bm.t0, bm.t1, size=2))
        if rng.random() < 0.4:
            b = min(bm.t1, a + rng.choice([1e-3, 0.05]) * (bm.t1 - bm.t0))
        mb = bm.motion_bounds(np.array([a]), np.array([b]))
        ts = np.concatenate([np.linspace(a, b, n_t), [0.5 * (a + b)]])
        pos, rot = bm.body_poses(ts)
        for body in range(bm.nbody):
            pts = bm.ref_points[body] + rng.normal(scale=rng.choice([0.01, 0.5, 3.0]), size=(n_pts, 3))
            pts[0] = bm.ref_points[body]
            W = np.einsum("tij,nj->tni", rot[:, body], pts) + pos[:, body, None, :]
            disp = np.linalg.norm(W[:-1] - W[-1], axis=-1).max(axis=0)
            bound = mb.displacement(body, pts, bm.ref_points[body])[0]
            assert np.all(disp <= bound), (body, (disp - bound).max())
            c = np.clip((np.einsum("tij,ij->t", rot[:-1, body], rot[-1, body]) - 1) / 2, -1, 1)
            assert np.all(np.arccos(c) <= mb.angle[0, body] + 1e-7)
            if bm.moving_bodies()[body] and bound[0] > 0:
                ratios.append(float(disp[0] / bound[0]))
    return ratios


def test_bezier_motion_bound_property_dense_sampling():
    rng = np.random.default_rng(1)
    ratios = []
    for _ in range(30):
        ratios += _check_contract(random_motion(rng), rng)
    med = float(np.median(ratios))
    print(f"Bezier motion bound: ref-point tightness (sampled / bound) median {med:.4f}, "
          f"min {min(ratios):.4f} over {len(ratios)} (interval, body)")
    assert med > 0.3


def test_bezier_bounds_shrink_with_interval():
    rng = np.random.default_rng(2)
    bm = random_motion(rng)
    c = 0.5 * (bm.t0 + bm.t1)
    widths = np.array([0.1, 0.01, 0.001]) * (bm.t1 - bm.t0)
    mb = bm.motion_bounds(c - widths / 2, c + widths / 2)
    assert np.all(np.diff(mb.trans[:, 1]) < 0) and mb.trans[2, 1] < 0.2 * mb.trans[1, 1]
    z = bm.motion_bounds(np.array([c]), np.array([c]))
    assert z.trans[0, 1] < 1e-9 and z.angle[0, 1] < 1e-9


def test_protocol_and_inputs():
    from monitor.motion.base import Trajectory

    rng = np.random.default_rng(3)
    bm = random_motion(rng, nbody=3)
    assert isinstance(bm, Trajectory)
    assert bm.translation_segments(1) is None
    assert bm.translation_segments(0)[1].shape == (2, 3)
    rb = random_rigid(rng, m=2)
    pos, quat = np.zeros((2, 3)), np.tile([1.0, 0, 0, 0], (2, 1))
    with pytest.raises(InvalidInputError, match="body index"):
        BezierMotion((0, 1), pos, quat, {0: rb})
    with pytest.raises(InvalidInputError, match="body index"):
        BezierMotion((0, 1), pos, quat, {2: rb})
    with pytest.raises(InvalidInputError, match="RigidBezier"):
        BezierMotion((0, 1), pos, quat, {1: "x"})
    with pytest.raises(InvalidInputError, match="window"):
        BezierMotion((0, 1, 2), pos, quat, {1: rb})
    with pytest.raises(InvalidInputError, match="trans_ctrl"):
        RigidBezier(np.eye(4)[:3], np.zeros((4, 3)))
    with pytest.raises(InvalidInputError, match="non-positive"):
        RigidBezier([[1.0, 0, 0, 0], [-1.0, 0, 0, 0]], np.zeros((3, 3)))


def test_paper71_fixture_as_public_motion():
    from monitor.bench.paper_bezier import paper71_motion, paper71_rigid

    rb = paper71_rigid(0.1)
    assert np.allclose(rb.curve().H, paper71_motion(0.1).H)


# --------------------------------------------------------------------------- certify vs oracle
def _bezier_case(rng):
    from _motion_oracle_cases import scene_model

    model = scene_model(rng)
    m = int(rng.integers(1, 4))
    q0 = rng.normal(size=4)
    q0 /= np.linalg.norm(q0)
    for _ in range(30):
        Q = q0 + rng.normal(scale=0.5, size=(m + 1, 4))
        T = rng.uniform(-0.6, 0.6, size=3) + rng.normal(scale=0.2, size=(2 * m + 1, 3))
        try:
            rb = RigidBezier(Q, T)
            break
        except InvalidInputError:
            continue
    pos = np.zeros((2, 3))
    quat = np.tile([1.0, 0, 0, 0], (2, 1))
    bm = BezierMotion((0.0, 1.0), pos, quat, {1: rb})
    return model, bm, lambda t: _oracle_pose(rb, t)


def _run_bezier_hunt(n, seed):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _motion_oracle_cases import hunt

    c = hunt(_bezier_case, n, seed=seed, label="bezier")
    print(f"bezier hunt: {c}")
    assert c["false_negatives"] == 0 and c["targeted_fn"] == 0, c["fn_cases"]
    assert c["certified"] > 0 and c["oracle_contact"] > 0   # both sides exercised


def test_bezier_certify_no_false_negatives_quick():
    _run_bezier_hunt(12, 7)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [70, 71])
def test_bezier_certify_no_false_negatives_200(seed):
    """200 seeded cases in two halves of 100 (each run stays short)."""
    _run_bezier_hunt(100, seed)


def test_logging_a_bezier_motion_is_a_typed_error():
    """The log format has no Bézier plan kind yet: the writer must refuse, not drop or re-interpret it."""
    from monitor.log.writer import _plan_payload

    rng = np.random.default_rng(4)
    with pytest.raises(InvalidInputError, match="BezierMotion"):
        _plan_payload(random_motion(rng))
