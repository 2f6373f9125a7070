"""tol[4] (max |qpos| + |qpos0|) of one hinge plan's pack.

0.3 from the sources, 1000.3 with race.py's edit.
"""

import mujoco
import numpy as np

import monitor
from monitor.motion.pack import pack_trajectory

XML = ("<mujoco><worldbody><body><joint type='hinge'/><geom size='.1' pos='.5 0 0'/></body></worldbody>"
       "</mujoco>")
model = mujoco.MjModel.from_xml_string(XML)
plan = monitor.Plan(np.array([0.0, 1.0]), np.array([[0.0], [0.3]]), model=model)
print("tol[QMAG] =", float(pack_trajectory(plan).tol[4]), "from", monitor.__file__)
