"""Gate + log + model edits at several points; oracle = the motion that ran (exact sphere-box distance per substep)
and review --verify (--trust-model-edits) of the log."""
import copy, sys, io, contextlib, mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
from monitor.gate import Gate
from monitor.cli import main
XML = """
<mujoco>
  <option timestep="0.01" integrator="implicitfast" gravity="0 0 0"/>
  <worldbody>
    <body name="wall" pos="0.1 0 0"><geom name="wall" type="box" size="0.005 0.2 0.2" contype="0" conaffinity="0"/></body>
    <body name="ball">
      <joint name="x" type="slide" axis="1 0 0"/>
      <geom name="ball" type="sphere" size="0.01" mass="0.01" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
  <actuator><velocity name="vx" joint="x" kv="10" ctrlrange="-6 6"/></actuator>
</mujoco>"""
MARGIN = 1e-3
ONGOING = sys.argv[2] if len(sys.argv) > 2 else "violation"
def dist(m, d):
    rot = d.geom_xmat[0].reshape(3, 3); c = rot.T @ (d.geom_xpos[1] - d.geom_xpos[0]); half = m.geom_size[0]
    out = np.linalg.norm(c - np.clip(c, -half, half))
    inside = -float(np.min(half - np.abs(c))) if out == 0.0 else out
    return float(inside - m.geom_size[1, 0])
def run(where, seed, path):
    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(XML); d = mujoco.MjData(m)
    wall = m.body("wall").id
    def edit():
        m.body_pos[wall, 0] = rng.uniform(0.03, 0.15) * rng.choice([-1, 1])
    calls = {"n": 0}
    def maybe():
        calls["n"] += 1
        if rng.uniform() < 0.4: edit()
    kw = {}
    fb = None
    if where == "fallback":
        def fb():
            maybe(); return np.zeros(1)
    g = Gate(m, margin=MARGIN, pairs="all", allowed=None, ongoing=ONGOING, log=path, **kw)
    bad = steps = certified = 0
    for step in range(60):
        if where == "between" and rng.uniform() < 0.3: edit()
        before = copy.copy(d)
        ctrl = np.array([rng.uniform(-6, 6)])
        cast = None
        if where == "cast":
            def cast(c):
                maybe(); return np.asarray(c, float)
        predict = None
        r = g.decide(d, ctrl, fallback=fb, cast=cast)
        # step the data with the applied control (as Gate.step does, but the motion that ran is replayed)
        if not g._rollout.commit(d, r.applied_ctrl, g.frame_skip):
            d.ctrl[:] = r.applied_ctrl; mujoco.mj_step(m, d, nstep=g.frame_skip)
        steps += 1
        applied_ok = r.fallback_certified if r.replaced else r.certificate.verdict == "certified"
        if not applied_ok:
            continue
        certified += 1
        dd = copy.copy(before); dd.ctrl[:] = r.applied_ctrl; mujoco.mj_forward(m, dd)
        xs = [float(dd.qpos[0])]
        for _ in range(g.frame_skip):
            mujoco.mj_step(m, dd); xs.append(float(dd.qpos[0]))
        pr = mujoco.MjData(m); ds = []
        wx = m.body_pos[wall, 0]
        for x0, x1 in zip(xs, xs[1:]):
            for x in (x0, x1, min(max(wx, min(x0, x1)), max(x0, x1))):
                pr.qpos[0] = x; mujoco.mj_forward(m, pr); ds.append(dist(m, pr))
        if dd.qpos.tobytes() != d.qpos.tobytes():
            print("  ran another motion than replayed", where, seed, step)
        if min(ds) <= (MARGIN if ONGOING == "violation" else -0.005):
            bad += 1; print("  FALSE CERT", where, seed, step, min(ds), r.replaced)
    g.close()
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
        code = main(["review", "--verify", "--no-progress", "--trust-model-edits", path])
    out = buf.getvalue()
    crit = [l for l in out.splitlines() if "CRITICAL" in l]
    return steps, certified, bad, code, crit[:3]
import tempfile
LOGDIR = tempfile.mkdtemp()
tot = {}
for where in ("between", "fallback", "cast"):
    for seed in range(int(sys.argv[1]) if len(sys.argv) > 1 else 4):
        s, c, b, code, crit = run(where, seed, f"{LOGDIR}/{where}_{seed}.mcap")
        print(where, seed, "steps", s, "certified", c, "false", b, "review exit", code, crit)
