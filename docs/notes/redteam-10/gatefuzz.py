"""Gate fuzz: in-place model edits and data edits between steps, the applied window replayed as oracle.

A ball on a slide joint (x), a velocity servo; a wall on its own static body and a mocap box, both
boxes spanning y, z: the exact gap along x is |x - c| - h - r (0 when the centre crosses). Between
steps: random edits of geometry (wall body_pos / geom_pos / geom_size, ball radius, mocap pose), of
dynamics (timestep, gravity, servo gain, damping, mass, disableflags, frame_skip) and of the data
(qvel, xfrc_applied, qfrc_applied, time, reset). Every step whose applied window the gate calls
certified is replayed substep by substep from a copy of the state on the live model (its end state
must equal the live data bit for bit: the replay is the motion that ran); the certified motion is
the rows' piecewise-linear interpolation, so each segment's least gap is 0 when it crosses, else
the smaller end. Usage: gatefuzz.py SEED STEPS
"""
import sys

import mujoco
import numpy as np

from monitor import Gate
from monitor.errors import InvalidInputError

XML = """
<mujoco><option timestep="0.01"/>
  <worldbody>
    <body name="wallbody" pos="0.3 0 0"><geom name="wall" type="box" size="0.01 0.3 0.3" contype="0" conaffinity="0"/></body>
    <body name="obst" mocap="true" pos="-0.3 0 0"><geom name="obst" type="box" size="0.02 0.3 0.3" contype="0" conaffinity="0"/></body>
    <body name="ball"><joint name="x" type="slide" axis="1 0 0" damping="0.1"/>
      <geom name="ball" type="sphere" size="0.02" mass="1" contype="0" conaffinity="0"/></body>
  </worldbody>
  <actuator><velocity name="v" joint="x" kv="50" ctrlrange="-3 3" ctrllimited="true"/></actuator>
</mujoco>"""


def seg_gap(xa, xb, c, h, r):
    lo, hi = min(xa, xb), max(xa, xb)
    if lo <= c <= hi:
        return -h - r
    return min(abs(xa - c), abs(xb - c)) - h - r


def main(seed, steps):
    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(XML)
    d = mujoco.MjData(m)
    wall_b, wall_g, ob_g, ball_g = m.body("wallbody").id, m.geom("wall").id, m.geom("obst").id, m.geom("ball").id
    margin = float(rng.choice([0.0, 0.01]))
    gate = Gate(m, pairs=[("wall", "ball"), ("obst", "ball")], margin=margin, frame_skip=int(rng.integers(1, 6)),
                ongoing="violation", allowed=None, brake=bool(rng.integers(2)))
    counts = dict(steps=0, certified=0, bad=0, typed=0, edits=0)
    for _ in range(steps):
        # ---- edits between steps
        for _k in range(int(rng.integers(0, 3))):
            counts["edits"] += 1
            e = int(rng.integers(14))
            if e == 0:
                m.body_pos[wall_b, 0] = rng.uniform(0.1, 0.5)
            elif e == 1:
                m.geom_pos[wall_g, 0] = rng.uniform(-0.1, 0.1)
            elif e == 2:
                m.geom_size[wall_g, 0] = rng.uniform(0.002, 0.05)
            elif e == 3:
                m.geom_size[ball_g, 0] = rng.uniform(0.005, 0.05)
            elif e == 4:
                d.mocap_pos[0, 0] = rng.uniform(-0.5, 0.0)
            elif e == 5:
                m.opt.timestep = float(rng.choice([0.002, 0.005, 0.01, 0.02]))
            elif e == 6:
                m.opt.gravity[0] = rng.uniform(-20, 20)
            elif e == 7:
                kv = rng.uniform(5, 200)
                m.actuator_gainprm[0, 0] = kv
                m.actuator_biasprm[0, 2] = -kv
            elif e == 8:
                m.dof_damping[0] = rng.uniform(0, 5)
            elif e == 9:
                m.opt.disableflags ^= int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
            elif e == 10:
                d.qvel[0] = rng.uniform(-5, 5)
            elif e == 11:
                d.xfrc_applied[m.body("ball").id, 0] = rng.uniform(-30, 30)
            elif e == 12:
                d.qfrc_applied[0] = rng.uniform(-30, 30)
            else:
                gate.frame_skip = int(rng.integers(1, 6))
        if rng.random() < 0.03:
            mujoco.mj_resetData(m, d)
            d.qpos[0] = rng.uniform(-0.2, 0.2)
            gate.reset()
        # ---- the step and its oracle
        saved = mujoco.MjData(m)
        mujoco.mj_copyData(saved, m, d)
        n = gate.frame_skip
        ctrl = np.array([rng.uniform(-3, 3)])
        try:
            r = gate.step(d, ctrl)
        except InvalidInputError:
            counts["typed"] += 1
            mujoco.mj_copyData(d, m, saved)
            continue
        counts["steps"] += 1
        if r.applied_verdict != "certified":
            continue
        counts["certified"] += 1
        rep = mujoco.MjData(m)
        mujoco.mj_copyData(rep, m, saved)
        rep.ctrl[:] = r.applied_ctrl
        xs = [float(rep.qpos[0])]
        for _k in range(n):
            mujoco.mj_step(m, rep)
            xs.append(float(rep.qpos[0]))
        assert rep.qpos.tobytes() == d.qpos.tobytes(), "replay is not the motion that ran"
        mujoco.mj_kinematics(m, rep)
        wall_c = float(rep.geom_xpos[wall_g, 0])
        ob_c = float(rep.geom_xpos[ob_g, 0])
        r_ball = float(m.geom_size[ball_g, 0])
        least = min(min(seg_gap(a, b, wall_c, m.geom_size[wall_g, 0], r_ball),
                        seg_gap(a, b, ob_c, m.geom_size[ob_g, 0], r_ball)) for a, b in zip(xs, xs[1:]))
        if not least > margin - 1e-12:
            counts["bad"] += 1
            print("BAD", seed, counts["steps"], least, margin, xs[0], xs[-1], wall_c, ob_c)
    return counts


if __name__ == "__main__":
    tot = {}
    for s in range(int(sys.argv[1]), int(sys.argv[1]) + int(sys.argv[3] if len(sys.argv) > 3 else 1)):
        c = main(s, int(sys.argv[2]))
        for k, v in c.items():
            tot[k] = tot.get(k, 0) + v
    print(tot)
