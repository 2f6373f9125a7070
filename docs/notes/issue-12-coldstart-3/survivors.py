"""Which window_kernel calls the bench start-up certify makes on the arm scene, and the survivors S of each."""
import numpy as np, mujoco, monitor
from monitor._paths import scene_path
import monitor.certify.engine as E
orig = E._window_kernel
def spy(KS, gp, mp, pairs, fixed, moving, route, stage, k0, k1, *rest):
    out = orig(KS, gp, mp, pairs, fixed, moving, route, stage, k0, k1, *rest)
    print("window_kernel stage", stage, "k0", k0, "k1", k1, "pairs", len(pairs), "-> S", out)
    return out
E._window_kernel = spy
model = mujoco.MjModel.from_xml_path(str(scene_path("arm")))
scene = monitor.Scene.from_model(model)
q0 = model.qpos0.copy(); q1 = q0.copy(); q1[0] += 0.05; q1[2] += 0.05
plan = monitor.Plan(np.array([0.0, 0.01]), np.stack([q0, q1]), model=model)
cert = monitor.certify(scene, plan)
print(cert.verdict, len(scene.candidate_pairs), [ (p.verdict if hasattr(p,'verdict') else p) for p in list(cert.pairs)[:5]])
