"""Red-team soundness tests for ``monitor.certify`` (independent oracle: tests/redteam_oracle.py).

Tests named ``test_fn_*`` reproduce confirmed FALSE NEGATIVES (certified while the motion really
collides / comes closer than the margin). Every one of them is fixed now and must pass: they are
regressions (each section comment names the fixing commit), none is expected to fail.
Every "collides" label is backed by a witness verified with the oracle's closed-form
membership tests (``check_witness``). Other tests are attacks that failed (regressions).
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from redteam_oracle import (  # noqa: E402
    PlanOracle,
    TrajectoryOracle,
    check_witness,
    motion_min,
    upper_distance,
)

from monitor import Plan, Scene, certify  # noqa: E402

# --------------------------------------------------------------------------- helpers


def _model(xml: str) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(xml)


def _f(x: float) -> str:
    return repr(float(x))


def _assert_not_certified(cert, what: str) -> None:
    assert cert.verdict != "certified", (
        f"FALSE NEGATIVE ({what}): certified with clearance {cert.clearance} "
        f"[{[(p.geoms, p.verdict, p.method) for p in cert.pairs]}]")


# --------------------------------------------------------------------------- FN 1 (fixed in 08df94a; regressi
# Slerp of a free joint over (almost exactly) 180 degrees: the waypoint quaternions are
# orthogonal as 4-vectors up to rounding. QuatTrack decides the slerp branch with an
# einsum dot (= +0.0 here, no flip) but QuatTrack.angular_velocity takes the sign of the
# w component of target * conj(q) (= -5.6e-17 here) and flips the rotation vector. The
# velocity (Taylor) motion bound of Plan then uses the reversed angular velocity; with the
# translation chosen along omega x (R g) the bound drops to second order (100x too small)
# and broad phase and toleranced checker certify a 5 cm penetration.
_Q0 = [0.5504207098412514, -0.456445950657196, -0.26889619378333285, -0.6452820881407898]
_Q1 = [-0.7910162989756422, -0.06852764355246847, -0.39609601931187544, -0.4611996534141259]
_V = [0.37415413296939626, 1.9616105029521874, -2.275317051708056]  # omega x R(0.5) g


def _half_turn_case(t_hit: float, offset: float) -> tuple[mujoco.MjModel, Plan]:
    qpos = np.array([[*(-0.5 * np.array(_V)), *_Q0], [*(0.5 * np.array(_V)), *_Q1]])
    probe = _model('<mujoco><worldbody><body name="b"><freejoint/>'
                   '<geom name="s" type="sphere" size=".1" pos="1 0 0"/></body></worldbody></mujoco>')
    pl = Plan([0.0, 1.0], qpos, probe)
    dt = 1e-4
    pos, rot = pl.body_poses(np.array([t_hit - dt, t_hit, t_hit + dt]))
    c = np.einsum("tij,j->ti", rot[:, 1], [1.0, 0.0, 0.0]) + pos[:, 1]
    vel = (c[2] - c[0]) / np.linalg.norm(c[2] - c[0])
    perp = np.cross(vel, [0.0, 0.0, 1.0])
    perp /= np.linalg.norm(perp)
    ob = c[1] + offset * perp
    xml = (f'<mujoco><worldbody><geom name="obs" type="sphere" size=".1" pos="{_f(ob[0])} {_f(ob[1])} '
           f'{_f(ob[2])}"/><body name="b"><freejoint/><geom name="s" type="sphere" size=".1" pos="1 0 0"/>'
           '</body></worldbody></mujoco>')
    m = _model(xml)
    return m, Plan([0.0, 1.0], qpos, m)


@pytest.mark.parametrize("t_hit", [0.5, 0.53])
@pytest.mark.parametrize("method", ["auto", "toleranced"])
def test_half_turn_slerp_velocity_bound(t_hit, method):
    m, pl = _half_turn_case(t_hit, 0.15)  # centres 0.15 apart, radii 0.1 + 0.1: 5 cm overlap
    oracle = TrajectoryOracle(m, pl)
    a, b = oracle.geoms(t_hit, (0, 1))
    w = upper_distance(a, b)
    assert check_witness(a, b, w) and w.upper < -0.02  # verified penetration at t_hit
    cert = certify(Scene.from_model(m, pairs="all"), pl, 0.0, 1e-3, method)
    _assert_not_certified(cert, f"half-turn slerp, penetration at t={t_hit}")


def test_half_turn_motion_bound_contract():
    """The motion-bound contract itself on the half-turn plan (reference point displacement)."""
    m, pl = _half_turn_case(0.5, 5.0)
    ref = pl.ref_points[1]
    h = 1e-3
    mb = pl.motion_bounds(np.array([0.5 - h]), np.array([0.5 + h]))
    ts = np.linspace(0.5 - h, 0.5 + h, 201)
    P, R = pl.body_poses(ts)
    pr = np.einsum("tij,j->ti", R[:, 1], ref) + P[:, 1]
    true = float(np.linalg.norm(pr - pr[100], axis=1).max())
    assert true <= mb.trans[0, 1], f"FALSE NEGATIVE source: true displacement {true} > bound {mb.trans[0, 1]}"


def test_half_turn_ball_joint():
    """Half-turn slerp through a ball joint carried by three slides: not fooled (regression)."""
    probe_xml = ('<mujoco><worldbody>{obs}<body name="c"><inertial pos="0 0 0" mass="1" diaginertia=".1 .1 .1"/><joint name="x" type="slide" axis="1 0 0"/>'  # noqa: E501
                 '<joint name="y" type="slide" axis="0 1 0"/><joint name="z" type="slide" axis="0 0 1"/>'
                 '<body name="b"><joint name="ball" type="ball"/><geom name="s" type="sphere" size=".1" '
                 'pos="1 0 0"/></body></body></worldbody></mujoco>')
    qpos = np.array([[*(-0.5 * np.array(_V)), *_Q0], [*(0.5 * np.array(_V)), *_Q1]])
    probe = _model(probe_xml.format(obs=""))
    pl = Plan([0.0, 1.0], qpos, probe)
    t_hit, dt = 0.53, 1e-4
    pos, rot = pl.body_poses(np.array([t_hit - dt, t_hit, t_hit + dt]))
    c = np.einsum("tij,j->ti", rot[:, 2], [1.0, 0.0, 0.0]) + pos[:, 2]
    vel = (c[2] - c[0]) / np.linalg.norm(c[2] - c[0])
    perp = np.cross(vel, [0.0, 0.0, 1.0])
    perp /= np.linalg.norm(perp)
    ob = c[1] + 0.15 * perp
    obs = f'<geom name="obs" type="sphere" size=".1" pos="{_f(ob[0])} {_f(ob[1])} {_f(ob[2])}"/>'
    m = _model(probe_xml.format(obs=obs))
    pl = Plan([0.0, 1.0], qpos, m)
    a, b = TrajectoryOracle(m, pl).geoms(t_hit, (0, 1))
    w = upper_distance(a, b)
    assert check_witness(a, b, w) and w.upper < -0.02
    cert = certify(Scene.from_model(m, pairs="all"), pl, 0.0, 1e-3, "auto")
    _assert_not_certified(cert, "half-turn slerp of a ball joint")


# --------------------------------------------------------------------------- generic attack harness


def _attack(xml: str, times, qpos, margin: float = 0.0, methods=("auto", "toleranced"), *,
            epsilon: float = 1e-3, window=None, n: int = 200, pairs="all", expect_violation: bool | None = True,  # noqa: E501
            budget=None, known=None):
    """Certify with each method and check every verdict contract against the oracle.

    * certified  => the oracle has no verified witness below the margin, and the certified
      clearance is <= the oracle's verified minimum distance;
    * violation  => the witness is confirmed by the oracle at witness.time (exact shapes), and
      earliest_time <= the first sampled time at which the oracle verified a violation.
    Returns {method: certificate}.
    """
    m = _model(xml)
    scene = Scene.from_model(m, pairs=pairs)
    times = np.asarray(times, float)
    qpos = np.asarray(qpos, float)
    plan = Plan(times, qpos, m)
    oracle = PlanOracle(m, times, qpos)
    w0, w1 = window if window is not None else (times[0], times[-1])
    mins = {}
    for (na, nb), ids in zip(scene.candidate_pairs, scene.pair_ids):
        mins[(na, nb)] = (tuple(int(i) for i in ids),
                          motion_min(oracle, int(ids[0]), int(ids[1]), w0, w1, n=n, threshold=margin))
    if known is not None:  # (pair ids, MinResult) found by a finer search of the caller
        for key, (ids, r) in mins.items():
            if ids == known[0] and known[1].upper < r.upper:
                first = r.first_below if r.first_below is not None else known[1].time
                if known[1].upper < margin:
                    first = min(first, known[1].time)
                mins[key] = (ids, type(r)(known[1].upper, known[1].time, known[1].witness,
                                          first if known[1].upper < margin or r.first_below is not None else None))  # noqa: E501
    true_min = min(r.upper for _, r in mins.values())
    if expect_violation is not None:
        assert (true_min < margin) == expect_violation, f"attack set-up: oracle min {true_min} vs margin {margin}"  # noqa: E501
    out = {}
    for meth in methods:
        cert = certify(scene, plan, margin, epsilon, meth, window=window, budget=budget)
        out[meth] = cert
        if true_min < margin:
            _assert_not_certified(cert, f"{meth}: oracle min {true_min} < margin {margin}")
        if cert.verdict == "certified":
            assert cert.clearance >= margin, f"{meth}: certified with clearance {cert.clearance} < margin"
            assert cert.clearance <= true_min + 1e-12, f"{meth}: clearance {cert.clearance} > true min {true_min}"  # noqa: E501
        if cert.verdict == "violation":
            w = cert.witness
            for (na, nb), (ids, _r) in mins.items():
                if set(w.geoms) != {na, nb}:
                    continue
                a, b = oracle.geoms(w.time, ids)
                ow = upper_distance(a, b)
                exact = all(int(m.geom_type[i]) not in (4, 5) for i in ids)  # no ellipsoid/cylinder
                if exact and w.distance < margin - 1e-9:
                    # the oracle's bound is an upper bound; it must not exceed the margin by much
                    assert ow.upper < margin + 1e-7, f"{meth}: witness at {w.time} not confirmed: {ow.upper}"
            firsts = [r.first_below for _, r in mins.values() if r.first_below is not None]
            if firsts:
                assert cert.earliest_time <= min(firsts) + 1e-12, (
                    f"{meth}: earliest_time {cert.earliest_time} later than verified violation {min(firsts)}")
    return out


def _free(x, q=(1.0, 0.0, 0.0, 0.0)):
    return [*x, *q]


_BOX_WALL = ('<mujoco><worldbody><geom name="wall" type="box" size=".005 1 1"/>'
             '<body name="b"><freejoint/><geom name="mv" type="box" size=".05 .05 .05"/></body></worldbody></mujoco>')  # noqa: E501


def test_thin_wall_tunnelling_translation():
    """A box crosses a 1 cm wall at 1000 m/s: no sample time inside, extrusion must see it."""
    _attack(_BOX_WALL, [0.0, 0.01], [_free([-5.0, 0, 0]), _free([5.0, 0, 0])], n=101)


def test_thin_wall_tunnelling_rotating():
    """The same with a rotation (toleranced checker in all methods)."""
    _attack(_BOX_WALL, [0.0, 0.01], [_free([-5.0, 0, 0]), _free([5.0, 0, 0], (0.0, 0.0, 0.0, 1.0))], n=101)


def test_extrusion_sub_window():
    """Sub-window of a multi-waypoint translation: the collision is inside the sub-window only."""
    q = [_free([-5.0, 0, 0]), _free([-1.0, 0, 0]), _free([1.0, 0, 0]), _free([5.0, 0, 0])]
    _attack(_BOX_WALL, [0.0, 1.0, 2.0, 3.0], q, window=(1.2, 1.8), methods=("auto", "extrusion", "toleranced"))  # noqa: E501
    _attack(_BOX_WALL, [0.0, 1.0, 2.0, 3.0], q, window=(2.1, 3.0), methods=("auto", "extrusion"),
            expect_violation=False)


def test_tiny_budget_never_certifies():
    """An exhausted budget may only give 'uncertain' (or a confirmed violation), never 'certified'."""
    from monitor.certify.common import Budget

    xml = ('<mujoco><worldbody><geom name="blk" type="box" size=".1 .1 .1"/><body name="b">'
           '<joint name="h" type="hinge" axis="0 0 1"/><geom name="arm" type="box" size=".5 .01 .01" '
           'pos=".62 0 0"/></body></worldbody></mujoco>')
    m = _model(xml)
    plan = Plan([0.0, 1.0], [[0.1], [6.0]], m)
    cert = certify(Scene.from_model(m, pairs="all"), plan, 0.0, 1e-6, "toleranced", budget=Budget(tests=1))
    assert cert.verdict in ("uncertain", "violation")


# --------------------------------------------------------------------------- grazing (margin trick)


def _graze(xml: str, times, qpos, deltas=(1e-9, 1e-6), methods=("auto", "toleranced"), n: int = 300,
           **kw) -> None:
    """Certify with margin = verified oracle minimum + delta: a violation exists by construction."""
    m = _model(xml)
    oracle = PlanOracle(m, np.asarray(times, float), np.asarray(qpos, float))
    scene = Scene.from_model(m, pairs=kw.get("pairs", "all"))
    (ga, gb), = [tuple(int(i) for i in ids) for ids in scene.pair_ids]
    r = motion_min(oracle, ga, gb, float(times[0]), float(times[-1]), n=n, refine=4)
    for d in deltas:
        margin = max(r.upper + d, 0.0)
        _attack(xml, times, qpos, margin, methods, n=n, known=((ga, gb), r), **kw)


def test_graze_sphere_box_corner_translation():
    xml = ('<mujoco><worldbody><geom name="box" type="box" size=".2 .3 .4" euler="12 34 56"/>'
           '<body name="b"><freejoint/><geom name="s" type="sphere" size=".05"/></body></worldbody></mujoco>')
    _graze(xml, [0.0, 1.0], [_free([-1.0, 0.3, 0.45]), _free([1.0, 0.31, 0.44])])


def test_graze_sphere_box_corner_rotating():
    xml = ('<mujoco><worldbody><geom name="box" type="box" size=".2 .3 .4" euler="12 34 56"/>'
           '<body name="b"><joint name="h" type="hinge" axis="0 0 1"/><geom name="s" type="sphere" size=".05" '  # noqa: E501
           'pos=".55 0 .3"/></body></worldbody></mujoco>')
    _graze(xml, [0.0, 1.0], [[-2.0], [2.0]])


@pytest.mark.slow
def test_graze_long_thin_box_several_turns():
    """A 2 m thin box spinning 3 turns in one window past a small sphere."""
    xml = ('<mujoco><worldbody><geom name="ball" type="sphere" size=".02" pos="1.5 .3 .0"/>'
           '<body name="b"><joint name="h" type="hinge" axis="0 0 1"/><geom name="rod" type="box" '
           'size="1 .005 .005" pos=".9 0 0" euler="0 0 7"/></body></worldbody></mujoco>')
    _graze(xml, [0.0, 0.1], [[0.0], [6 * np.pi]], n=600)


@pytest.mark.slow
def test_graze_floor_rotating_box_corner():
    xml = ('<mujoco><worldbody><geom name="floor" type="plane" size="5 5 .1"/>'
           '<body name="b" pos="0 0 .5"><freejoint/><geom name="bx" type="box" size=".2 .1 .3"/></body>'
           '</worldbody></mujoco>')
    q1 = np.array([0.9, 0.3, -0.2, 0.25])
    q1 /= np.linalg.norm(q1)
    _graze(xml, [0.0, 1.0], [_free([0, 0, 0.32]), _free([0.4, 0, 0.3], tuple(q1))], n=400)


def test_graze_hinge_chain_long_lever():
    xml = ('<mujoco><worldbody><geom name="post" type="capsule" size=".03 .5" pos="3.9 .4 0"/>'
           '<body name="l1"><joint name="h1" type="hinge" axis="0 0 1"/><geom name="g1" type="box" size=".1 .1 .1" '  # noqa: E501
           'contype="0" conaffinity="0"/><body name="l2" pos="2 0 0"><joint name="h2" type="hinge" axis="0 1 .3"/>'  # noqa: E501
           '<geom name="tip" type="box" size="1 .02 .02" pos="1 0 0"/></body></body></worldbody></mujoco>')
    _graze(xml, [0.0, 0.5, 1.0], [[-0.3, 0.2], [0.4, -0.3], [0.1, 0.5]], pairs=[("post", "tip")], n=150,
           deltas=(1e-7,))


def test_graze_capsule_pierces_box():
    """Capsule segment crossing the box with both caps outside (MuJoCo 4.0 misses it)."""
    xml = ('<mujoco><worldbody><geom name="blk" type="box" size=".1 .1 .1"/>'
           '<body name="b"><freejoint/><geom name="cap" type="capsule" size=".01 1" euler="0 90 0"/></body>'
           '</worldbody></mujoco>')
    _graze(xml, [0.0, 1.0], [_free([0, 0.3, 0.3]), _free([0, 0.0, 0.0], tuple(np.array([0.9, 0.1, 0.0, 0.2]) / np.linalg.norm([0.9, 0.1, 0.0, 0.2])))])  # noqa: E501


def test_graze_both_bodies_moving_opposite():
    xml = ('<mujoco><worldbody><body name="a"><freejoint/><geom name="ga" type="box" size=".1 .2 .05"/></body>'  # noqa: E501
           '<body name="b"><freejoint/><geom name="gb" type="capsule" size=".05 .2"/></body></worldbody></mujoco>')  # noqa: E501
    qa = [_free([-2, 0.0, 0.0]), _free([2, 0.0, 0.0], (0.8, 0.0, 0.6, 0.0))]
    qb = [_free([2, 0.31, 0.1]), _free([-2, 0.3, 0.12], (0.6, 0.8, 0.0, 0.0))]
    _graze(xml, [0.0, 1.0], [qa[0] + qb[0], qa[1] + qb[1]])


# --------------------------------------------------------------------------- scales, windows, tolerances


def _corner_case(offset: float, scale: float) -> str:
    o, s = offset, scale
    return (f'<mujoco><worldbody><geom name="box" type="box" size="{.2 * s!r} {.3 * s!r} {.4 * s!r}" '
            f'pos="{o!r} {o!r} {o!r}" euler="12 34 56"/><body name="b" pos="{o!r} {o!r} {o!r}">'
            f'<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
            f'<joint name="h" type="hinge" axis="0 0 1"/><geom name="s" type="sphere" size="{.05 * s!r}" '
            f'pos="{.55 * s!r} 0 {.3 * s!r}"/></body></worldbody></mujoco>')


@pytest.mark.parametrize("offset,scale", [(1e4, 1.0), (0.0, 1e-3), (1e3, 1e-3)])
def test_graze_offsets_and_scales(offset, scale):
    _graze(_corner_case(offset, scale), [0.0, 1.0], [[-2.0], [2.0]], deltas=(1e-9 * max(scale, 1e-2), 1e-6 * scale))  # noqa: E501


@pytest.mark.parametrize("t0,T", [(0.0, 1e-6), (1e3, 1e-6), (0.0, 1e3)])
def test_graze_window_lengths(t0, T):
    _graze(_corner_case(0.0, 1.0), [t0, t0 + T], [[-2.0], [2.0]])


@pytest.mark.parametrize("epsilon", [1e-1, 1e-6])
def test_graze_epsilon(epsilon):
    _graze(_corner_case(0.0, 1.0), [0.0, 1.0], [[-2.0], [2.0]], epsilon=epsilon)


def test_extrusion_shallow_overlap_2e10():
    """Penetration depth 2e-10 m (below extrusion_slack 1e-9): must not be certified."""
    xml = ('<mujoco><worldbody><geom name="wall" type="box" size=".5 .5 .5"/><body name="b">'
           '<joint name="sx" type="slide" axis="1 0 0"/><geom name="mv" type="box" size=".1 .1 .1"/></body>'
           '</worldbody></mujoco>')
    _attack(xml, [0.0, 1.0, 2.0], [[2.0], [0.6 - 2e-10], [2.0]], methods=("auto", "extrusion", "toleranced"), n=201)  # noqa: E501


def test_extrusion_margin_shortfall_2e10():
    """Distance margin - 2e-10 at the closest approach (quadratic path of the extrusion checker)."""
    xml = ('<mujoco><worldbody><geom name="wall" type="box" size=".5 .5 .5"/><body name="b">'
           '<joint name="sx" type="slide" axis="1 0 0"/><geom name="mv" type="sphere" size=".1"/></body>'
           '</worldbody></mujoco>')
    _attack(xml, [0.0, 1.0, 2.0], [[2.0], [0.61 - 2e-10], [2.0]], margin=0.01,
            methods=("auto", "extrusion", "toleranced"), n=201)


def test_graze_cylinder_and_ellipsoid():
    """Circumscribed shapes: never certify what the true shape hits."""
    xml = ('<mujoco><worldbody><geom name="cyl" type="cylinder" size=".2 .3" euler="20 0 10"/>'
           '<body name="b"><joint name="h" type="hinge" axis="0 0 1"/><geom name="ell" type="ellipsoid" '
           'size=".05 .1 .07" pos=".5 0 .1"/></body></worldbody></mujoco>')
    _graze(xml, [0.0, 1.0], [[-1.0], [1.0]], deltas=(1e-6,), n=120)


def test_graze_mesh_near_coplanar_faces():
    """A hull with nearly coplanar faces (bent by 1e-7) grazing a box edge."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 1e-7], [0, 0, .3], [1, 0, .3], [0, 1, .3],
                  [1, 1, .3 + 1e-7]]) * 0.3
    verts = " ".join(repr(float(x)) for x in v.ravel())
    xml = (f'<mujoco><asset><mesh name="m" vertex="{verts}"/></asset><worldbody>'
           '<geom name="box" type="box" size=".1 .1 .1" euler="45 0 45"/><body name="b">'
           '<joint name="h" type="hinge" axis="0 1 0"/><geom name="hull" type="mesh" mesh="m" pos=".3 0 0"/>'
           '</body></worldbody></mujoco>')
    _graze(xml, [0.0, 1.0], [[-1.5], [1.5]], n=200)


# --------------------------------------------------------------------------- FN 2 (fixed in 0860931)


def test_bodymotion_moves_welded_body_explicit_pair():
    """BodyMotion moves a body that the Scene calls static (welded, no dof) straight through
    another welded body; the explicitly requested pair is culled as static-static and certified.

    The engine decides the cull from ``scene.body_static`` instead of the trajectory's own
    ``moving_bodies()``; a BodyMotion may move any non-world body.
    """
    from monitor import BodyMotion

    xml = ('<mujoco><worldbody><body name="a"><geom name="ga" type="box" size=".1 .1 .1"/></body>'
           '<body name="b" pos="1 0 0"><geom name="gb" type="sphere" size=".1"/></body></worldbody></mujoco>')
    m = _model(xml)
    pos = np.zeros((2, 3, 3))
    pos[:, 2] = [[1.0, 0, 0], [-1.0, 0, 0]]
    quat = np.zeros((2, 3, 4))
    quat[..., 0] = 1.0
    bm = BodyMotion([0.0, 1.0], pos, quat)
    assert bm.moving_bodies()[2]
    oracle = TrajectoryOracle(m, bm)
    a, b = oracle.geoms(0.5, (0, 1))  # sphere centre at the box centre
    w = upper_distance(a, b)
    assert check_witness(a, b, w) and w.upper < -0.04
    cert = certify(Scene.from_model(m, pairs=[("ga", "gb")]), bm, 0.0, 1e-3)
    _assert_not_certified(cert, "BodyMotion moving a welded body through another")


@pytest.mark.slow
def test_moving_plane_mocap_bodymotion():
    """A plane on a mocap body, moved and tilted by a BodyMotion, sweeps into a static box."""
    from monitor import BodyMotion

    xml = ('<mujoco><worldbody><geom name="bx" type="box" size=".1 .2 .3" pos="0 0 -1" euler="10 20 30"/>'
           '<body name="p" mocap="true"><geom name="pl" type="plane" size="1 1 .1"/></body></worldbody></mujoco>')  # noqa: E501
    m = _model(xml)
    rng = np.random.default_rng(3)
    scene = Scene.from_model(m, pairs="all")
    for k in range(6):
        q1 = np.array([1.0, *rng.normal(scale=0.3, size=3)])
        q1 /= np.linalg.norm(q1)
        pos = np.zeros((2, 2, 3))
        pos[:, 1] = [[0, 0, 0.0], [0, 0, rng.uniform(-1.2, -0.4)]]
        quat = np.zeros((2, 2, 4))
        quat[..., 0] = 1.0
        quat[1, 1] = q1
        bm = BodyMotion([0.0, 1.0], pos, quat)
        oracle = TrajectoryOracle(m, bm)
        r = motion_min(oracle, 0, 1, 0.0, 1.0, n=200)
        for d in (1e-9, 1e-6):
            margin = max(r.upper + d, 0.0)
            for meth in ("auto", "toleranced"):
                cert = certify(scene, bm, margin, 1e-3, meth)
                _assert_not_certified(cert, f"moving plane case {k}, margin {margin}, {meth}")


# --------------------------------------------------------------------------- start pose


def test_start_penetration_1e13_extrusion():
    """Start 1e-13 m inside the box, then leave by translation: extrusion certifies (see FN 3)."""
    test_start_penetration_moving_away(1e-13, "auto")


@pytest.mark.parametrize("pen", [1e-6, 1e-9, 1e-11])
@pytest.mark.parametrize("method", ["auto", "toleranced"])
def test_start_penetration_moving_away(pen, method):
    """The sphere starts pen metres inside the box face and leaves: never 'certified'."""
    xml = ('<mujoco><worldbody><geom name="box" type="box" size=".5 .5 .5"/><body name="b">'
           '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
           '<joint name="x" type="slide" axis="1 0 0"/><joint name="h" type="hinge" axis="0 0 1"/>'
           '<geom name="s" type="sphere" size=".1"/></body></worldbody></mujoco>')
    x0 = 0.6 - pen
    assert 0.5 - (x0 - 0.1) > 0  # the sphere's leftmost point is inside the box face at t0
    q1 = [[x0 + 1.0, 0.0 if method == "auto" else 1.0]]
    m = _model(xml)
    plan = Plan([0.0, 1.0], [[x0, 0.0], *q1], m)
    cert = certify(Scene.from_model(m, pairs="all"), plan, 0.0, 1e-3, method)
    _assert_not_certified(cert, f"start penetration {pen}")


@pytest.mark.parametrize("method", ["auto", "toleranced"])
def test_start_touching_margin_zero_not_violation(method):
    """Exactly touching at t0 (distance 0) and moving away: distance 0 is not < margin 0."""
    xml = ('<mujoco><worldbody><geom name="box" type="box" size=".5 .5 .5"/><body name="b">'
           '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
           '<joint name="x" type="slide" axis="1 0 0"/><joint name="h" type="hinge" axis="0 0 1"/>'
           '<geom name="s" type="sphere" size=".125"/></body></worldbody></mujoco>')
    m = _model(xml)
    plan = Plan([0.0, 1.0], [[0.625, 0.0], [1.625, 0.0 if method == "auto" else 1.0]], m)
    cert = certify(Scene.from_model(m, pairs="all"), plan, 0.0, 1e-3, method)
    assert cert.verdict != "violation", f"touching reported as violation: {cert.witness}"


# --------------------------------------------------------------------------- FN 3 (passes since the extrusion


@pytest.mark.parametrize("margin", [0.0, 0.01])
def test_extrusion_picometre_shortfall(margin):
    """A translating sphere reaches distance margin - 1e-12 m from a box (a 1e-12 m penetration at
    margin 0): the extrusion checker certifies it, with a certificate clearance BELOW the margin
    (-3.6e-12 at margin 0, 0.0099999999964 at margin 0.01). The toleranced checker says "uncertain".

    Cause (monitor/certify/extrusion*.py): the quadratic path certifies when the core distance is
    >= r - extrusion_slack / the LP slack <= extrusion_slack, i.e. it accepts shortfalls below the
    slack instead of returning "unresolved" (which the engine would turn into "uncertain").
    """
    xml = ('<mujoco><worldbody><geom name="wall" type="box" size=".5 .5 .5"/><body name="b">'
           '<joint name="sx" type="slide" axis="1 0 0"/><geom name="mv" type="sphere" size=".1"/></body>'
           '</worldbody></mujoco>')
    m = _model(xml)
    pen = 1e-12
    plan = Plan([0.0, 1.0, 2.0], [[2.0], [0.6 + margin - pen], [2.0]], m)
    # verified: at t = 1 the sphere centre is at x_c; the point z is in the box and within
    # (0.1 + margin) of x_c, i.e. distance(box, sphere) < margin (penetration when margin = 0)
    x_c = float(plan.body_poses(np.array([1.0]))[0][0, 1, 0])
    z = 0.5 - 0.25 * pen if margin == 0.0 else 0.5
    assert 0.5 - abs(z) >= 0.0 and (0.1 + margin) - abs(x_c - z) > 0.25 * pen
    for method in ("auto", "extrusion"):
        cert = certify(Scene.from_model(m, pairs="all"), plan, margin, 1e-3, method)
        _assert_not_certified(cert, f"{method}: shortfall {pen} m below margin {margin}")


@pytest.mark.parametrize("q_off", [1e5, -3e6])
def test_graze_large_hinge_coordinates(q_off):
    """Hinge coordinates around 1e5..3e6 rad: lerp rounding ~1e-10 rad must be padded."""
    _graze(_corner_case(0.0, 1.0), [0.0, 1.0], [[q_off - 2.0], [q_off + 2.0]], n=300)


def test_graze_box_box_edge_edge_rotating():
    """Edge-edge grazing of two boxes, one spinning about a skew axis (toleranced fat edges)."""
    xml = ('<mujoco><worldbody><geom name="b1" type="box" size=".3 .02 .02" euler="0 0 45"/>'
           '<body name="b" pos="0 0 .2"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
           '<joint name="h" type="hinge" axis=".2 .1 1"/><geom name="b2" type="box" size=".02 .4 .02" '
           'pos=".1 0 -.14"/></body></worldbody></mujoco>')
    _graze(xml, [0.0, 1.0], [[-1.0], [1.2]], n=300)


def test_graze_mesh_mesh_free_motion():
    rng = np.random.default_rng(7)
    va = " ".join(repr(float(x)) for x in (rng.normal(size=(10, 3)) * 0.2).ravel())
    vb = " ".join(repr(float(x)) for x in (rng.normal(size=(10, 3)) * 0.2).ravel())
    xml = (f'<mujoco><asset><mesh name="ma" vertex="{va}"/><mesh name="mb" vertex="{vb}"/></asset><worldbody>'
           '<geom name="ga" type="mesh" mesh="ma"/><body name="b"><freejoint/><geom name="gb" type="mesh" mesh="mb"/>'  # noqa: E501
           '</body></worldbody></mujoco>')
    q1 = np.array([0.7, 0.5, -0.3, 0.4])
    q1 /= np.linalg.norm(q1)
    _graze(xml, [0.0, 1.0], [_free([-1.0, 0.4, 0.1]), _free([1.0, 0.35, 0.0], tuple(q1))], n=200)


# --------------------------------------------------------------------------- random sweep (slow)

_KINDS = ("box", "sphere", "capsule", "mesh", "cylinder", "ellipsoid")
_INERTIA = '<inertial pos="0 0 0" mass="1" diaginertia=".1 .1 .1"/>'


def _random_geom(kind: str, rng: np.random.Generator, name: str) -> tuple[str, str]:
    e = " ".join(f"{x:.3f}" for x in rng.uniform(-180, 180, 3))
    size = " ".join(f"{x:.6g}" for x in rng.uniform(0.05, 0.4, 3))
    if kind == "mesh":
        v = " ".join(f"{x:.6g}" for x in (rng.normal(size=(8, 3)) * 0.3).ravel())
        return (f'<geom name="{name}" type="mesh" mesh="m{name}" euler="{e}"/>',
                f'<mesh name="m{name}" vertex="{v}"/>')
    return f'<geom name="{name}" type="{kind}" size="{size}" euler="{e}"/>', ""


def _random_case(seed: int) -> tuple[str, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    ga, ma = _random_geom(str(rng.choice(_KINDS)), rng, "A")
    gb, mb = _random_geom(str(rng.choice(_KINDS)), rng, "B")
    motion = str(rng.choice(["trans", "free", "hinge2", "ball"]))
    if motion in ("trans", "free"):
        body = f'<body name="ba">{_INERTIA}<freejoint/>{ga}</body>'
    elif motion == "hinge2":
        ax1 = " ".join(f"{x:.4f}" for x in rng.normal(size=3))
        ax2 = " ".join(f"{x:.4f}" for x in rng.normal(size=3))
        body = (f'<body name="l1">{_INERTIA}<joint name="h1" type="hinge" axis="{ax1}"/><body name="l2" pos=".8 0 0">'  # noqa: E501
                f'{_INERTIA}<joint name="h2" type="hinge" axis="{ax2}"/><body name="ba" pos=".6 0 0">{_INERTIA}{ga}'  # noqa: E501
                '</body></body></body>')
    else:
        body = f'<body name="l1">{_INERTIA}<joint name="bj" type="ball"/><body name="ba" pos=".9 0 0">{_INERTIA}{ga}</body></body>'  # noqa: E501
    xml = f'<mujoco><asset>{ma}{mb}</asset><worldbody>{gb}{body}</worldbody></mujoco>'
    m = _model(xml)
    K = int(rng.integers(2, 5))
    T = float(10.0 ** rng.uniform(-3, 1))
    times = np.sort(np.concatenate([[0.0, T], rng.uniform(0, T, K - 2)]))
    Q = np.tile(m.qpos0, (K, 1))
    for j in range(m.njnt):
        a, typ = int(m.jnt_qposadr[j]), int(m.jnt_type[j])
        if typ == 0:
            Q[:, a:a + 3] = rng.normal(size=(K, 3)) * 0.7
            qs = rng.normal(size=(1 if motion == "trans" else K, 4))
            Q[:, a + 3:a + 7] = qs / np.linalg.norm(qs, axis=1, keepdims=True)
        elif typ == 1:
            qs = rng.normal(size=(K, 4))
            Q[:, a:a + 4] = qs / np.linalg.norm(qs, axis=1, keepdims=True)
        elif typ == 3:
            Q[:, a] = rng.uniform(-4, 4, K)
    return xml, times, Q


@pytest.mark.slow
def test_random_sweep_margin_trick():
    """Random shapes and motions, margin = verified oracle minimum + delta (REDTEAM_SEEDS, default 20)."""
    import os

    from monitor.certify.common import Budget

    n_seeds = int(os.environ.get("REDTEAM_SEEDS", "20"))
    for seed in range(n_seeds):
        xml, times, Q = _random_case(seed)
        m = _model(xml)
        scene = Scene.from_model(m, pairs="all")
        plan = Plan(times, Q, m)
        oracle = PlanOracle(m, times, Q)
        r = motion_min(oracle, 0, int(m.ngeom) - 1, float(times[0]), float(times[-1]), n=80)
        if not np.isfinite(r.upper):
            continue
        for d in (1e-9, 1e-6, 1e-3):
            margin = max(r.upper + d, 0.0)
            for meth in ("auto", "toleranced"):
                cert = certify(scene, plan, margin, 1e-3, meth, budget=Budget(seconds=3.0))
                _assert_not_certified(cert, f"seed {seed}, margin {margin}, {meth}")


# ------------------------------------------------------------------- FN 4 (fixed in b11fdf3; regression)


def test_fn_mesh_maxhullvert_reduced_hull():
    """A mesh with maxhullvert="4": MuJoCo 4.0 still collides the sphere with the full mesh
    (mj_forward reports a contact, mj_geomDistance -0.031 m) when the sphere crosses a corner
    outside the reduced hull. The Scene used to take the 4-vertex hull from mesh_graph and
    certified this motion; since b11fdf3 it takes the hull of all compiled vertices.
    """
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1], [.6, .6, .6],
                  [-.6, -.6, .6]]) * 0.3
    verts = " ".join(repr(float(x)) for x in v.ravel())
    xml = (f'<mujoco><asset><mesh name="m" vertex="{verts}" maxhullvert="4"/></asset><worldbody>'
           '<geom name="hull" type="mesh" mesh="m"/><body name="b"><freejoint/>'
           '<geom name="s" type="sphere" size=".02"/></body></worldbody></mujoco>')
    m = _model(xml)
    q = np.array([[0.17 - 0.5, 0.17 + 0.5, 0.17, 1, 0, 0, 0], [0.17 + 0.5, 0.17 - 0.5, 0.17, 1, 0, 0, 0]])
    plan = Plan([0.0, 1.0], q, m)
    # independent evidence at t = 0.5 (sphere centre at (0.17, 0.17, 0.17)): MuJoCo's own contact ...
    d = mujoco.MjData(m)
    d.qpos[:] = [0.17, 0.17, 0.17, 1, 0, 0, 0]
    mujoco.mj_forward(m, d)
    assert d.ncon >= 1 and mujoco.mj_geomDistance(m, d, 0, 1, 1.0, np.zeros(6)) < -0.01
    # ... and the oracle's verified witness against the hull of all mesh vertices
    a, b = PlanOracle(m, [0.0, 1.0], q).geoms(0.5, (0, 1))
    w = upper_distance(a, b)
    assert check_witness(a, b, w) and w.upper < 0
    cert = certify(Scene.from_model(m, pairs="all"), plan, 0.0, 1e-3)
    _assert_not_certified(cert, "sphere through the corner of a maxhullvert-reduced mesh hull")


@pytest.mark.parametrize("small", ["sphere", "box", "capsule"])
@pytest.mark.parametrize("method", ["auto", "toleranced"])
def test_containment_whole_window(small, method):
    """A small geom fully inside a big box for the whole window (no boundary contact ever)."""
    size = {"sphere": ".1", "box": ".1 .05 .08", "capsule": ".05 .1"}[small]
    xml = ('<mujoco><worldbody><geom name="big" type="box" size="1 1 1"/><body name="b"><freejoint/>'
           f'<geom name="s" type="{small}" size="{size}"/></body></worldbody></mujoco>')
    q1 = (1.0, 0.0, 0.0, 0.0) if method == "auto" else (0.0, 1.0, 0.0, 0.0)
    out = _attack(xml, [0.0, 1.0], [_free([-0.5, 0, 0]), _free([0.5, 0.2, 0], q1)], methods=(method,), n=60)
    assert out[method].verdict == "violation"


def _rot_angle(R: np.ndarray) -> np.ndarray:
    """Rotation angle, well conditioned for small angles: ||R - I||_F = 2 sqrt(2) sin(angle / 2)."""
    f = np.linalg.norm(R - np.eye(3), axis=(-2, -1))
    return 2.0 * np.arcsin(np.clip(f / (2.0 * np.sqrt(2.0)), 0.0, 1.0))


@pytest.mark.parametrize("chain", ["free", "hinge_ball"])
def test_near_half_turn_motion_bound_contract(chain):
    """Random (near-)orthogonal quaternion pairs (+-1e-17 along q0): the motion-bound contract
    (reference-point displacement and rotation angle) on sub-intervals, checked by sampling."""
    xml = {"free": ('<mujoco><worldbody><body name="b"><freejoint/><geom name="s" type="sphere" size=".1" '
                    'pos="1 0 0"/></body></worldbody></mujoco>'),
           "hinge_ball": ('<mujoco><worldbody><body name="h"><inertial pos="0 0 0" mass="1" diaginertia=".1 .1 .1"/>'  # noqa: E501
                          '<joint name="hh" type="hinge" axis="0 0 1"/><body name="c" pos=".5 0 0">'
                          '<inertial pos="0 0 0" mass="1" diaginertia=".1 .1 .1"/><joint name="ball" type="ball"/>'  # noqa: E501
                          '<geom name="s" type="sphere" size=".1" pos="1 0 0"/></body></body></worldbody></mujoco>')}[chain]  # noqa: E501
    m = _model(xml)
    body = m.nbody - 1
    rng = np.random.default_rng(11)
    for _ in range(40):
        q0 = rng.normal(size=4)
        q0 /= np.linalg.norm(q0)
        r = rng.normal(size=4)
        r -= (r @ q0) * q0
        r /= np.linalg.norm(r)
        r = r + rng.choice([0.0, 1e-17, -1e-17]) * q0
        if chain == "free":
            Q = np.array([[0, 0, 0, *q0], [0, 0, 0, *r]])
            P, R = Plan([0.0, 1.0], Q, m).body_poses(np.array([0.5 - 1e-6, 0.5, 0.5 + 1e-6]))
            W = (R[2, body] - R[0, body]) @ R[1, body].T / 2e-6
            v = np.cross([W[2, 1], W[0, 2], W[1, 0]], R[1, body] @ np.array([1.0, 0, 0]))
            Q[0, :3], Q[1, :3] = -0.5 * v, 0.5 * v  # translation along omega x (R g): worst case for a sign flip  # noqa: E501
        else:
            Q = np.array([[0.0, *q0], [rng.uniform(-2, 2), *r]])
        pl = Plan([0.0, 1.0], Q, m)
        ref = pl.ref_points[body]
        for tm, h in ((0.5, 1e-3), (0.5, 1e-2), (float(rng.uniform(0.1, 0.9)), 1e-4)):
            mb = pl.motion_bounds(np.array([tm - h]), np.array([tm + h]))
            ts = np.linspace(tm - h, tm + h, 101)
            P, R = pl.body_poses(ts)
            pr = np.einsum("tij,j->ti", R[:, body], ref) + P[:, body]
            assert np.linalg.norm(pr - pr[50], axis=1).max() <= mb.trans[0, body]
            ang = _rot_angle(np.einsum("tij,kj->tik", R[:, body], R[50, body]))
            assert ang.max() <= mb.angle[0, body] + 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_graze_bodymotion_long_lever_many_waypoints(seed):
    """BodyMotion, default reference point (body origin) 10 m from the geom, 5 waypoints with
    rotations, grazing a static box (independent lerp/slerp oracle)."""
    from redteam_oracle import BodyMotionOracle

    from monitor import BodyMotion

    xml = ('<mujoco><worldbody><geom name="box" type="box" size=".3 .2 .1" pos="10 0 0" euler="5 10 15"/>'
           '<body name="b" mocap="true"><geom name="cap" type="capsule" size=".05 .3" pos="10 0 0"/></body>'
           '</worldbody></mujoco>')
    m = _model(xml)
    rng = np.random.default_rng(seed)
    K = 5
    times = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, K - 2)]))
    pos = np.zeros((K, 2, 3))
    pos[:, 1] = rng.normal(scale=0.2, size=(K, 3)) + [0.0, 0.0, 0.5]
    quat = np.zeros((K, 2, 4))
    quat[:, 0, 0] = 1.0
    qs = np.array([1.0, 0, 0, 0]) + rng.normal(scale=0.02, size=(K, 4))
    quat[:, 1] = qs / np.linalg.norm(qs, axis=1, keepdims=True)
    bm = BodyMotion(times, pos, quat)
    oracle = BodyMotionOracle(m, times, pos, quat)
    r = motion_min(oracle, 0, 1, 0.0, 1.0, n=300, refine=4)
    scene = Scene.from_model(m, pairs="all")
    for d in (1e-9, 1e-6):
        margin = max(r.upper + d, 0.0)
        for meth in ("auto", "toleranced"):
            cert = certify(scene, bm, margin, 1e-3, meth)
            _assert_not_certified(cert, f"BodyMotion lever seed {seed}, margin {margin}, {meth}")
