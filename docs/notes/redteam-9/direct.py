import numpy as np, mujoco
from monitor import Plan, Scene
from monitor.certify import extrusion_swept as ES, engine
from monitor.tolerances import DEFAULT
XML = open(__file__.rsplit('/', 1)[0] + '/overflow.py').read().split('XML = """')[1].split('"""')[0]
m = mujoco.MjModel.from_xml_string(XML)
scene = Scene.from_model(m, pairs="all", allowed=None)
wall, ball = scene.geom("wall"), scene.geom("ball")
for dt, a in [(1e-308, 1.0), (5e-324, 1.0), (1e-300, 5e9), (1.0, 9e307), (20.0, 9e307)]:
    plan = Plan([0.0, dt], [[-a], [a]], m)
    with np.errstate(all="ignore"):
        o1 = ES.decide_plan_pair(wall.shape, ball.shape, np.eye(3), np.eye(3), plan._times, plan._wp_pos, wall.body_id, ball.body_id,
                                 bool(plan._moving[wall.body_id]), bool(plan._moving[ball.body_id]), (0.0, dt), 0.0, 0.0, DEFAULT, ("wall", "ball"))
        sa, sb = plan.translation_segments(wall.body_id), plan.translation_segments(ball.body_id)
        o2 = ES.decide_pair(wall.shape, np.eye(3), sa[0], sa[1], ball.shape, np.eye(3), sb[0], sb[1], (0.0, dt), 0.0, 0.0, DEFAULT, ("wall", "ball"))
    print(dt, a, "plan:", o1 and o1.outcome, " general:", o2 and o2.outcome)
