"""Deepen rule with the plane as the SECOND geom (on a moving or welded body), sphere / capsule first.
Closed-form distances (linear motions: min at the waypoints). Checks every certified window against the rule."""
import sys, mujoco, numpy as np, warnings
warnings.simplefilter("ignore")
from monitor import Plan, Scene, certify
seed = int(sys.argv[1]) if len(sys.argv) > 1 else 0
ncase = int(sys.argv[2]) if len(sys.argv) > 2 else 60
rng = np.random.default_rng(seed)
def model(kind, plane_moves, tilt):
    shape = '<geom name="s" type="sphere" size="0.03"/>' if kind == "sphere" else \
            '<geom name="s" type="capsule" size="0.02" fromto="-0.05 0 0 0.05 0.01 0.03"/>'
    pj = ''
    return f"""<mujoco><worldbody>
      <body name="S"><joint name="sx" type="slide" axis="1 0 0"/><joint name="sz" type="slide" axis="0 0 1"/>{shape}</body>
      <body name="P" euler="{tilt[0]} {tilt[1]} 0" mocap="{'true' if plane_moves else 'false'}">{pj}<geom name="plane" type="plane" size="1 1 0.1"/></body>
    </worldbody></mujoco>"""
def sd(m, d):
    g_s, g_p = m.geom("s").id, m.geom("plane").id
    n = d.geom_xmat[g_p].reshape(3, 3)[:, 2]; p0 = d.geom_xpos[g_p]
    if m.geom_type[g_s] == mujoco.mjtGeom.mjGEOM_SPHERE:
        return float(n @ (d.geom_xpos[g_s] - p0) - m.geom_size[g_s, 0])
    R = d.geom_xmat[g_s].reshape(3, 3); c = d.geom_xpos[g_s]; hl = m.geom_size[g_s, 1]
    e = [c + R[:, 2] * hl, c - R[:, 2] * hl]
    return float(min(n @ (x - p0) for x in e) - m.geom_size[g_s, 0])
bad = calls = certs = ong = 0
for case in range(ncase):
    kind = ["sphere", "capsule"][case % 2]
    plane_moves = bool(rng.integers(0, 2))
    tilt = rng.uniform(-30, 30, 2)
    m = mujoco.MjModel.from_xml_string(model(kind, plane_moves, tilt)); d = mujoco.MjData(m)
    assert m.geom("s").id < m.geom("plane").id
    sc = Scene.from_model(m, pairs=[("s", "plane")])
    # place the shape near the plane: start distance in [-0.01, 0.06]
    q0 = np.zeros(m.nq); d.qpos[:] = q0; mujoco.mj_forward(m, d)
    base = sd(m, d)
    want = rng.uniform(-0.012, 0.06)
    # move along z (slide sz) by (want - base)/n_z
    g_p = m.geom("plane").id; n = d.geom_xmat[g_p].reshape(3, 3)[:, 2]
    q0[1] += (want - base) / n[2]
    K = int(rng.integers(2, 4))
    Q = [q0]
    for k in range(K - 1):
        step = rng.normal(0, 0.01, m.nq)
        Q.append(Q[-1] + step)
    Q = np.array(Q); T = np.linspace(0, 0.1, K)
    dists = []
    for q in Q:
        d.qpos[:] = q; mujoco.mj_forward(m, d); dists.append(sd(m, d))
    d0, dmin = dists[0], min(dists)
    use_bm = plane_moves and case % 3 == 0
    if plane_moves:   # a mocap plane: held pose given in the plan (as in d)
        pass
    plan = Plan(T, Q, m, mocap_pos=np.array(d.mocap_pos), mocap_quat=np.array(d.mocap_quat)) if plane_moves else Plan(T, Q, m)
    if use_bm:   # BodyMotion: every body's pose at the waypoints, plane translating linearly too
        from monitor import BodyMotion
        dp = rng.normal(0, 0.01, 3)
        pos = np.zeros((K, m.nbody, 3)); quat = np.zeros((K, m.nbody, 4)); quat[..., 0] = 1
        dists = []
        for k, q in enumerate(Q):
            d.qpos[:] = q; d.mocap_pos[0] = d.mocap_pos[0] * 0 + m.body_pos[m.body("P").id] + dp * k
            mujoco.mj_forward(m, d)
            pos[k] = d.xpos; quat[k] = d.xquat; dists.append(sd(m, d))
        d0, dmin = dists[0], min(dists)
        plan = BodyMotion(T, pos, quat)
    for margin in (0.0, 1e-9, 0.02, 0.05):
        for pen in (1e-12, 0.001, 0.005, 0.03):
            for meth in ("auto", "toleranced", "extrusion"):
                calls += 1
                try:
                    c = certify(sc, plan, margin=margin, method=meth, ongoing="deepen", penetration_tol=pen)
                except Exception as e:
                    print("ERR", type(e).__name__, str(e)[:80]); continue
                if c.verdict != "certified":
                    continue
                certs += 1
                if d0 > margin + 1e-9:
                    ok = dmin > margin - 1e-9
                elif d0 - pen > 1e-9:
                    ok = dmin >= d0 - pen - 1e-9; ong += 1
                else:
                    ok = dmin > -pen - 1e-9; ong += 1
                # claimed clearance must be a lower bound
                ok = ok and c.clearance <= dmin + 1e-9
                if not ok:
                    bad += 1
                    print("BAD", case, kind, "moves" if plane_moves else "welded", meth, "margin", margin, "pen", pen,
                          "d0 %.5f dmin %.5f clear %.5f" % (d0, dmin, c.clearance), [p.note for p in c.pairs])
print("seed", seed, "cases", ncase, "calls", calls, "certified", certs, "ongoing-certified", ong, "bad", bad)
