"""Save the captured rare calls as .npz (plan rows + request fields) and rebuild them from the Arm model; check the certificate matches."""
import pickle, numpy as np, sys
import gymnasium as gym
import monitor.envs  # noqa
from monitor.motion.plan import Plan
from monitor.gym_gate import SafetyGate
import monitor.certify.engine as E
caps = pickle.load(open("/tmp/armrare/caps.pkl", "rb"))
env = SafetyGate(gym.make("monitor/Arm-v0"))
env.reset(seed=0)
for j, c in enumerate(caps):
    scene, plan, a, k = pickle.loads(c["blob"])
    req = k["request"]
    np.savez(f"/tmp/armrare/rare{j}.npz", times=plan._times, qpos=plan._qpos,
             mocap_pos=plan._mocap_pos if plan._mocap_pos is not None else np.zeros((0,)),
             mocap_quat=plan._mocap_quat if plan._mocap_quat is not None else np.zeros((0,)),
             margin=req.margin, epsilon=req.epsilon, ongoing=req.ongoing, pairs=np.array(scene.candidate_pairs, dtype=object) if False else np.zeros(0))
    ref = E.certify(scene, plan, request=req)
    z = np.load(f"/tmp/armrare/rare{j}.npz")
    mp = z["mocap_pos"] if z["mocap_pos"].size else None
    mq = z["mocap_quat"] if z["mocap_quat"].size else None
    p2 = Plan(z["times"], z["qpos"], env.gate.scene.model, mocap_pos=mp, mocap_quat=mq)
    r2 = E.certify(env.gate.scene, p2, request=req)
    print(j, c["where"], "pickled:", ref.verdict, ref.clearance, ref.earliest_time, ref.stats["tests"], "| rebuilt:", r2.verdict, r2.clearance, r2.earliest_time, r2.stats["tests"])
