"""One numba specialisation per kernel on the certify path (issue 12 item 7: cold start).

numba compiles a kernel again for every new combination of argument types, and an array's
readonly flag is part of its type. Two calls that differ only in that flag cost a second
compile (~20 s for ``window_kernel``) in the middle of a run, after ``monitor warmup``. Found
on monitor/Arm-v0: the gate's reuse cache certifies a pair subset, whose pair array was a
writable copy while the full one is the pack's read-only array; ``shape_distance_batch`` passed
read-only broadcast views when nothing broadcast.
"""

from __future__ import annotations

import mujoco
import numpy as np

from monitor.certify import kernels
from monitor.certify.engine import certify
from monitor.geometry import _gjk
from monitor.geometry.distance import shape_distance_batch
from monitor.geometry.polytope import box_polytope, sphere_shape
from monitor.motion.plan import Plan
from monitor.scene import Scene
from monitor.warmup import _XML


def test_a_pair_subset_uses_the_window_kernel_of_the_full_set():
    model = mujoco.MjModel.from_xml_string(_XML)
    scene = Scene.from_model(model, pairs="all")
    plan = Plan(np.array([0.0, 0.1]), np.array([[-1.0, 0.0, -0.5], [-0.3, 0.0, -0.5]]), model)
    certify(scene, plan)
    n = len(kernels.window_kernel.signatures)
    assert len(scene.candidate_pairs) >= 2
    for k in range(len(scene.candidate_pairs)):
        certify(scene, plan, pairs=[scene.candidate_pairs[k]])
    certify(scene, plan, pairs=list(scene.candidate_pairs[:2]))
    assert len(kernels.window_kernel.signatures) == n, kernels.window_kernel.signatures


def test_distance_batch_arrays_are_typed_alike_with_or_without_broadcasting():
    box, ball = box_polytope(np.array([0.1, 0.1, 0.1])), sphere_shape(0.1)
    R = np.repeat(np.eye(3)[None], 3, axis=0)
    p = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.3], [0.0, 0.5, 0.0]])
    shape_distance_batch(box, (np.eye(3), np.zeros(3)), ball, (R, p))   # A broadcasts
    n = len(_gjk.core_distance_batch.signatures)
    shape_distance_batch(box, (R, p), ball, (R, p))                     # nothing broadcasts
    R_ro, p_ro = R.copy(), p.copy()
    R_ro.flags.writeable = p_ro.flags.writeable = False                 # a caller's read-only arrays
    shape_distance_batch(box, (R_ro, p_ro), ball, (np.eye(3), np.zeros(3)))
    assert len(_gjk.core_distance_batch.signatures) == n, _gjk.core_distance_batch.signatures


_BALL = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <body name="ball" pos="0 0 .049"><freejoint/><geom name="ball" type="sphere" size=".05"/></body>
    <body name="box" pos=".5 0 .2"><freejoint/><geom name="box" type="box" size=".05 .05 .05"/></body>
  </worldbody>
</mujoco>
"""


def test_the_ongoing_contact_rule_uses_the_same_window_kernel():
    """Regression: the ongoing-contact rule (``ongoing="deepen"``, a resting ball 1 mm deep)
    certifies pair subsets whose pair array was writable: a second window_kernel compile."""
    model = mujoco.MjModel.from_xml_string(_XML)
    scene = Scene.from_model(model, pairs="all")
    certify(scene, Plan(np.array([0.0, 0.1]), np.array([[-1.0, 0.0, -0.5], [-0.3, 0.0, -0.5]]), model))
    n = len(kernels.window_kernel.signatures)
    ball = mujoco.MjModel.from_xml_string(_BALL)
    q0 = np.array(ball.qpos0)
    q1 = q0.copy()
    q1[0] += 0.02          # the ball slides 2 cm along x while resting 1 mm deep
    q1[7 + 2] -= 0.05      # the box drops 5 cm
    plan = Plan(np.array([0.0, 0.1]), np.stack([q0, q1]), ball)
    bscene = Scene.from_model(ball, pairs="all")
    cert = certify(bscene, plan, ongoing="deepen")
    assert cert.stats.get("ongoing", 0) >= 1  # the rule ran
    certify(bscene, plan)
    assert len(kernels.window_kernel.signatures) == n, kernels.window_kernel.signatures
