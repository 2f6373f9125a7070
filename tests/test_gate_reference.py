"""allowed="auto" on a plain Gate: the allowed-contact reference is the first state the gate sees.

Issue 13 frees the candidate pairs in contact at the reference pose (reason Default: resting
task contacts). For ``Gate`` that pose must be the first state given to ``decide``/``step``, not
``qpos0`` / keyframe 0: a pair touching at ``qpos0`` but apart at the start is a real hazard and must
stay certified (found by h12aa's review of the gate's log metadata).
"""

import mujoco
import numpy as np

from monitor.gate import Gate

# a box on a vertical slide: at qpos0 (z = 0) it rests on the floor slab (bottom face on the top face)
_XML = """
<mujoco>
  <option timestep="0.002" gravity="0 0 0"/>
  <worldbody>
    <geom name="slab" type="box" size="0.5 0.5 0.05" pos="0 0 -0.05"/>
    <body name="block" pos="0 0 0.05">
      <joint name="z" type="slide" axis="0 0 1"/>
      <geom name="cube" type="box" size="0.05 0.05 0.05" mass="1"/>
    </body>
  </worldbody>
  <actuator><motor joint="z" gear="1" ctrlrange="-2000 2000"/></actuator>
</mujoco>
"""


def _lifted_data(model):
    data = mujoco.MjData(model)
    data.qpos[0] = 0.02         # 2 cm above the slab at the first state
    data.qvel[0] = -4.0         # falling fast: the next 10 ms window goes 4 cm down, into the slab
    mujoco.mj_forward(model, data)
    return data


def test_first_state_is_the_reference_not_qpos0():
    model = mujoco.MjModel.from_xml_string(_XML)
    data = _lifted_data(model)
    gate = Gate(model, allowed="auto", on_violation="warn", brake=False)
    rep = gate.decide(data, np.array([-2000.0]), nstep=5)
    allowed = {frozenset(p[:2]) for p in gate.scene.allowed_pairs}
    assert frozenset(("slab", "cube")) not in allowed, "apart at the first state: not a resting contact"
    np.testing.assert_array_equal(gate.reference_qpos, data.qpos)
    # the window drives the cube into the slab: the gate must not certify it
    assert str(rep.verdict) != "certified"


def test_resting_contact_at_the_first_state_is_still_allowed():
    model = mujoco.MjModel.from_xml_string(_XML)
    data = mujoco.MjData(model)   # qpos0: resting on the slab
    mujoco.mj_forward(model, data)
    gate = Gate(model, allowed="auto", on_violation="warn", brake=False)
    gate.decide(data, np.array([0.0]), nstep=5)
    allowed = {frozenset(p[:2]) for p in gate.scene.allowed_pairs}
    assert frozenset(("slab", "cube")) in allowed
