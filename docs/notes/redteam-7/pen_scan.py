import mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
from monitor import Plan, Scene, certify
XML = """<mujoco><worldbody>
  <body name="S"><joint name="sz" type="slide" axis="0 0 1"/><geom name="s" type="sphere" size="0.03"/></body>
  <body name="P" euler="7 3 0"><geom name="plane" type="plane" size="1 1 0.1"/></body>
</worldbody></mujoco>"""
m = mujoco.MjModel.from_xml_string(XML); d = mujoco.MjData(m)
sc = Scene.from_model(m, pairs=[("s", "plane")])
rng = np.random.default_rng(0)
worst = {}
def sd(z):
    d.qpos[0] = z; mujoco.mj_forward(m, d)
    n = d.geom_xmat[1].reshape(3, 3)[:, 2]; return float(n @ (d.geom_xpos[0] - d.geom_xpos[1]) - 0.03)
for k in range(300):
    z0, z1 = rng.uniform(-0.02, 0.05, 2)
    tmin = min(sd(z0), sd(z1))
    p = Plan([0, 1], [[z0], [z1]], m)
    for pen in (0.05, 1.0, 1e3, 1e6, 1e8, 3e8, 1e9):
        for meth in ("auto", "toleranced", "extrusion"):
            try:
                c = certify(sc, p, margin=0.0, ongoing="deepen", penetration_tol=pen, method=meth)
            except Exception as e:
                continue
            if c.verdict == "certified":
                worst[(pen, meth)] = max(worst.get((pen, meth), -1), c.clearance - tmin)
for k, v in sorted(worst.items()): print(k, "max clearance - true min: %.3g" % v)
