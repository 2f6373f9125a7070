import numpy as np, mujoco, monitor
from monitor.motion.pack import pack_trajectory
xml = "<mujoco><worldbody><body><joint type='hinge'/><geom size='.1' pos='.5 0 0'/></body></worldbody></mujoco>"
m = mujoco.MjModel.from_xml_string(xml)
plan = monitor.Plan(np.array([0.0, 1.0]), np.array([[0.0], [0.3]]), model=m)
print("tol[QMAG] =", float(pack_trajectory(plan).tol[4]), "from", monitor.__file__)
