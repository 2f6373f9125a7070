"""Red-team soundness tests for ``monitor.certify`` (independent oracle: tests/redteam_oracle.py).

Tests named ``test_fn_*`` are confirmed FALSE NEGATIVES (certified while the motion really
collides / comes closer than the margin); they are left failing on purpose until fixed.
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


# --------------------------------------------------------------------------- FN 1
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
def test_fn_half_turn_slerp_velocity_bound(t_hit, method):
    m, pl = _half_turn_case(t_hit, 0.15)  # centres 0.15 apart, radii 0.1 + 0.1: 5 cm overlap
    oracle = TrajectoryOracle(m, pl)
    a, b = oracle.geoms(t_hit, (0, 1))
    w = upper_distance(a, b)
    assert check_witness(a, b, w) and w.upper < -0.02  # verified penetration at t_hit
    cert = certify(Scene.from_model(m, pairs="all"), pl, 0.0, 1e-3, method)
    _assert_not_certified(cert, f"half-turn slerp, penetration at t={t_hit}")


def test_fn_half_turn_motion_bound_contract():
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
