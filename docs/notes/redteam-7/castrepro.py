import copy, sys, mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
sys.argv = ["x", "1", "violation"]
exec(open("gatelog.py").read().split("tot = {}")[0])
# replay seed 5 'cast' with tracing
import monitor.gate as G
orig_joint = G.Gate._certify_joint
orig_cert = G.Gate._certify
def tj(self, *a, **k):
    out = orig_joint(self, *a, **k)
    print("   joint ->", None if out is None else (out[0].verdict, out[1].verdict), "wall x", self.model.body_pos[0+1, 0], "scene ver", self.scene.version)
    return out
G.Gate._certify_joint = tj
rng_trace = []
m_holder = {}
import builtins
def run2(seed):
    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(XML); d = mujoco.MjData(m)
    wall = m.body("wall").id
    def cast(c):
        if rng.uniform() < 0.4:
            m.body_pos[wall, 0] = rng.uniform(0.03, 0.15) * rng.choice([-1, 1]); print("   cast edit -> wall x", m.body_pos[wall, 0])
        return np.asarray(c, float)
    g = Gate(m, margin=MARGIN, pairs="all", allowed=None, ongoing="violation")
    for step in range(12):
        before = copy.copy(d)
        ctrl = np.array([rng.uniform(-6, 6)])
        print("step", step, "ball x", d.qpos[0], "wall x", m.body_pos[wall, 0], "ctrl", ctrl)
        r = g.decide(d, ctrl, cast=cast)
        print("  verdict", r.certificate.verdict, "replaced", r.replaced, "applied", r.applied_ctrl, "fb", None if r.fallback_certificate is None else r.fallback_certificate.verdict, "brake", r.brake_verdict)
        if not g._rollout.commit(d, r.applied_ctrl, g.frame_skip):
            print("  (not committed: mj_step)")
            d.ctrl[:] = r.applied_ctrl; mujoco.mj_step(m, d, nstep=g.frame_skip)
        mujoco.mj_forward(m, d)
        print("  after: ball x", d.qpos[0], "dist", dist(m, d))
run2(5)
