"""Per-call certify cost and a gated Pusher step (PYTHONPATH = the tree to measure).

PYTHONPATH=<tree> python docs/notes/issue-12-request/bench.py [calls] [steps]
Prints one JSON line: medians (µs) of a plain certify call on a two-body scene (keywords, and with
request= when the tree has it) and of a gated Pusher-v5 step (pairs="mujoco"), plus the ungated step.
"""
import json
import statistics
import sys
import time

import gymnasium as gym
import mujoco
import numpy as np

import monitor.envs  # noqa: F401
from monitor.certify.engine import certify
from monitor.gym_gate import SafetyGate
from monitor.motion.bodymotion import BodyMotion
from monitor.scene import Scene

calls, steps = (int(a) for a in (sys.argv[1:3] if len(sys.argv) > 2 else ("3000", "300")))
pc = time.perf_counter
XML = """<mujoco><worldbody><geom name="floor" type="plane" size="2 2 .1"/>
<body name="ball" pos="0 0 .2"><freejoint/><geom name="ball" type="sphere" size=".05"/></body>
</worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML)
d = mujoco.MjData(m)
mujoco.mj_kinematics(m, d)
pos = np.repeat(np.array(d.xpos)[None], 2, axis=0)
quat = np.repeat(np.array(d.xquat)[None], 2, axis=0)
pos[1, 1, 0] += 0.05
plan = BodyMotion(np.array([0.0, 1.0]), pos, quat)
scene = Scene.from_model(m, pairs="all")


def med(f, n):
    f()
    ts = []
    for _ in range(n):
        t = pc()
        f()
        ts.append(pc() - t)
    return statistics.median(ts) * 1e6


out = {"certify_kw_us": med(lambda: certify(scene, plan, margin=0.001), calls)}
try:
    from monitor.certify.request import CertifyRequest
    req = CertifyRequest(margin=0.001)
    certify(scene, plan, request=req)
    out["certify_req_us"] = med(lambda: certify(scene, plan, request=req), calls)
except TypeError:
    pass
u = gym.make("Pusher-v5")
u.reset(seed=0)
u.action_space.seed(0)
acts = [u.action_space.sample() for _ in range(steps + 1)]
env = SafetyGate(gym.make("Pusher-v5"), pairs="mujoco")
env.reset(seed=0)
env.step(acts[0])
ts = []
for a in acts[1:]:
    t = pc()
    env.step(a)
    ts.append(pc() - t)
out["gated_pusher_step_us"] = statistics.median(ts) * 1e6
ts = []
for a in acts[1:]:
    t = pc()
    u.step(a)
    ts.append(pc() - t)
out["ungated_pusher_step_us"] = statistics.median(ts) * 1e6
print(json.dumps({k: round(v, 2) for k, v in out.items()}))
