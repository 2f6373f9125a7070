"""Red team 16: tonight's certify-path changes (packscale's rounding scale, certpy's one-call,
first-witness and flag-cache paths). Notes: docs/notes/redteam-16.md.

Finding (fixed): the new rounding scale ``S = max_b (|x_b(m)| + 2 |ref_b| + W_b) + max_b W_b +
3 max_b |ref_b|`` (plan.py, "The rounding scale") claims (a) S bounds every body origin over the
window and (b) S >= the former scale (max over waypoints of |FK origin| + max W + 3 max |ref|).
Both failed by 1-2 ulps on a far static body (|P| ~ 1e5-2e8 m) whose child slides by a few
ulps of that distance, every geom at its body's origin (|ref| = 0): the computed midpoint origin
and the scale-0 bound W (no FK-rounding pad) are rounded, so the computed waypoint origins could
exceed S. Oracle: MuJoCo FK origins at the waypoints and 64 dense times (``Plan.body_poses``) and
the former definition, compared exactly (no relative slack).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from monitor.motion import kernel as KN
from monitor.motion.pack import pack_trajectory
from monitor.motion.plan import Plan

# (parent pos, parent quat, child pos, slide axis, times, slide coordinate per waypoint): cases the
# fuzzer docs/notes/redteam-16/scale_ulp.py found on 5165cd9 (S below the former scale and below a
# computed FK origin)
_ULP_CASES = [
    ("-23506943.000939254 -12142997.262402773 6999551.6510149306",
     "-0.40659670158990052 0.41244310733103701 0.44430064834922267 -0.68349596878678986",
     "-0.22165939043358104 -1.0719984301299426 -0.58763555797440503",
     "0.18173590861834377 -1.0782462828068573 -1.8183888972072959",
     [0.19160279972398095, 0.8728361808352197, 1.8426741168069452],
     [-0.8417288473688949, -0.8417288468490582, -0.8417288485234555]),
    ("160997.3632467213 -40682.815270907267 -46784.39509457301",
     "-0.047352348486278853 -0.26328871619681798 -0.8158343821731624 0.51269003099377697",
     "0.74536010428342347 2.604804452473493 1.080177302034488",
     "0.022602170799187391 0.9585319096656929 -0.028462786079131705",
     [0.17795802644003553, 0.3480050804819298],
     [-0.037875282957621215, -0.03787528298280554]),
    ("127635459.0298516 -182702148.14814162 -28089560.993050449",
     "-0.071326185637276149 -0.42611898934233328 -0.76237568843758818 0.48178677010023691",
     "0.61933885305537018 0.31811408698454846 -0.1492461065965224",
     "0.7090061891258016 0.48447433273892115 -1.6023626506573188",
     [0.08084651929926201, 0.762008495085922, 1.4689724116329004, 1.6350740547376712],
     [-0.9781337832854677, -0.9781337763002653, -0.97813377564718, -0.978133771735557]),
]


def _far_slider(parent_pos, parent_quat, child_pos, axis):
    return mujoco.MjModel.from_xml_string(
        f'<mujoco><worldbody><body name="p" pos="{parent_pos}" quat="{parent_quat}">'
        f'<geom type="sphere" size="0.1"/><body name="c" pos="{child_pos}">'
        f'<joint name="j" type="slide" axis="{axis}"/><geom type="sphere" size="0.1"/>'
        f'</body></body></worldbody></mujoco>')


@pytest.mark.parametrize("case", range(len(_ULP_CASES)))
def test_rounding_scale_not_below_former_scale_nor_computed_origins(case):
    """Plan._scale and the pack's tol[3] >= the former scale and >= every computed FK origin, exactly."""
    pp, pq, cp, ax, times, q = _ULP_CASES[case]
    m = _far_slider(pp, pq, cp, ax)
    plan = Plan(np.array(times), np.array(q)[:, None], model=m)
    assert plan.moving_bodies()[2]
    dense = np.linspace(plan.t0, plan.t1, 64)
    pos, _ = plan.body_poses(np.concatenate([plan.times, dense]))      # MuJoCo FK
    origins = float(np.linalg.norm(pos, axis=-1).max())
    whole = plan._bounds(plan.times[:1].copy(), plan.times[-1:].copy(), scale=0.0,
                         kinds=Plan._bound_kinds)[0][0]
    rho = float(np.linalg.norm(plan.ref_points, axis=-1).max())
    wp = float(np.linalg.norm(pos[:len(times)], axis=-1).max())
    former = wp + rho + float(whole.max()) + 2.0 * rho                   # the former Plan._scale
    for scale in (plan._scale, float(pack_trajectory(plan).tol[KN.TOL_SCALE])):
        assert scale >= former
        assert scale >= origins


def test_scale_round_up_is_one_value():
    """The Plan's and the compiled pack's factor are one number (the pack == Plan scale tests rely on it)."""
    from monitor.motion import plan as plan_mod

    assert plan_mod._SCALE_ROUND_UP == KN.SCALE_ROUND_UP > 1.0
