"""Property test: the certified motion bound of Plan is never exceeded.

Oracle: an independent interpolation of the waypoints (numpy ``interp`` for
hinge/slide/free position, scipy ``Slerp`` for ball/free quaternions) fed into
MuJoCo ``mj_kinematics`` on a fresh ``MjData``, sampled densely on each
sub-interval, at random body points near and far from the body.
"""

from __future__ import annotations

import os

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from monitor.motion.base import chord
from monitor.motion.plan import Plan

# Soak runs (not CI): MONITOR_SOAK_CHAINS=500 MONITOR_SOAK_SEED=777 pytest ... -k random_chains
N_CHAINS = int(os.environ.get("MONITOR_SOAK_CHAINS", "220"))
SEED = int(os.environ.get("MONITOR_SOAK_SEED", "20261122"))
N_SAMPLES = 200


def _rand_quat(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def _fmt(v):
    return " ".join(f"{x:.6g}" for x in v)


def _random_chain_xml(rng) -> str:
    """MJCF string of a random kinematic tree with hinge/slide/ball/free joints."""
    body_id = [0]
    geom_id = [0]

    def geoms(indent):
        out = []
        for _ in range(rng.integers(0, 3)):
            kind = rng.choice(["sphere", "capsule", "box"])
            size = {"sphere": [rng.uniform(0.02, 0.2)],
                    "capsule": [rng.uniform(0.02, 0.1), rng.uniform(0.05, 0.3)],
                    "box": rng.uniform(0.02, 0.2, 3)}[kind]
            out.append(f'{indent}<geom name="g{geom_id[0]}" type="{kind}" size="{_fmt(size)}" '
                       f'pos="{_fmt(rng.uniform(-0.4, 0.4, 3))}" quat="{_fmt(_rand_quat(rng))}"/>')
            geom_id[0] += 1
        return out

    def body(depth, top, indent):
        body_id[0] += 1
        name = f"b{body_id[0]}"
        lines = []
        pos = rng.uniform(-0.6, 0.6, 3)
        mocap = top and rng.random() < 0.1
        attrs = f'name="{name}" pos="{_fmt(pos)}" quat="{_fmt(_rand_quat(rng))}"'
        if mocap:
            attrs += ' mocap="true"'
        lines.append(f"{indent}<body {attrs}>")
        if not mocap:
            if top and rng.random() < 0.3:
                lines.append(f'{indent}  <freejoint name="j{name}f"/>')
            else:
                had_ball = False  # MuJoCo: no rotation after a ball joint in one body
                for k in range(rng.integers(0, 4)):
                    kind = "slide" if had_ball else rng.choice(["hinge", "slide", "ball", "hinge"])
                    had_ball = had_ball or kind == "ball"
                    if kind == "ball":
                        lines.append(f'{indent}  <joint name="j{name}_{k}" type="ball" '
                                     f'pos="{_fmt(rng.uniform(-0.3, 0.3, 3))}"/>')
                    else:
                        ax = rng.normal(size=3)
                        extra = f' ref="{rng.uniform(-1, 1):.4g}"' if rng.random() < 0.3 else ""
                        lines.append(f'{indent}  <joint name="j{name}_{k}" type="{kind}" axis="{_fmt(ax)}" '
                                     f'pos="{_fmt(rng.uniform(-0.3, 0.3, 3))}"{extra}/>')
        g = geoms(indent + "  ")
        if not g:  # massless moving bodies do not compile; also exercises the body_ipos reference
            ipos = _fmt(rng.uniform(-0.3, 0.3, 3))
            g = [f'{indent}  <inertial pos="{ipos}" mass="1" diaginertia=".01 .01 .01"/>']
        lines += g
        if depth > 0:
            for _ in range(rng.integers(1, 3) if rng.random() < 0.3 else 1):
                lines += body(depth - 1, False, indent + "  ")
        lines.append(f"{indent}</body>")
        return lines

    lines = ['<mujoco><option><flag contact="disable"/></option><worldbody>']
    for _ in range(rng.integers(1, 3)):
        lines += body(int(rng.integers(0, 4)), True, "  ")
    lines.append("</worldbody></mujoco>")
    return "\n".join(lines)


def _random_qpos(rng, m, K):
    q = np.tile(np.array(m.qpos0), (K, 1))
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        hold = rng.random() < 0.15
        typ = m.jnt_type[j]
        for k in range(K):
            if hold and k > 0:
                q[k, a:a + (7 if typ == 0 else 4 if typ == 1 else 1)] = \
                    q[0, a:a + (7 if typ == 0 else 4 if typ == 1 else 1)]
                continue
            if typ == mujoco.mjtJoint.mjJNT_FREE:
                q[k, a:a + 3] = rng.uniform(-1, 1, 3)
                q[k, a + 3:a + 7] = _rand_quat(rng)
            elif typ == mujoco.mjtJoint.mjJNT_BALL:
                q[k, a:a + 4] = _rand_quat(rng)
            elif typ == mujoco.mjtJoint.mjJNT_HINGE:
                q[k, a] = rng.uniform(-4, 4)
            else:
                q[k, a] = rng.uniform(-0.5, 0.5)
    # Sometimes small steps (deep-subdivision regime).
    if rng.random() < 0.3:
        for k in range(1, K):
            q[k] = q[0] + 1e-3 * (q[k] - q[0])
            for j in range(m.njnt):
                typ = m.jnt_type[j]
                if typ in (0, 1):
                    a = m.jnt_qposadr[j] + (3 if typ == 0 else 0)
                    q[k, a:a + 4] /= np.linalg.norm(q[k, a:a + 4])
    return q


def _oracle_qpos(m, times, qpos, t):
    """Independent interpolation: numpy interp + scipy Slerp (geodesic)."""
    out = np.empty((t.shape[0], m.nq))
    quat_cols = set()
    for j in range(m.njnt):
        typ = m.jnt_type[j]
        if typ in (0, 1):
            a = m.jnt_qposadr[j] + (3 if typ == 0 else 0)
            quat_cols.update(range(a, a + 4))
            wxyz = qpos[:, a:a + 4]
            rot = Rotation.from_quat(wxyz[:, [1, 2, 3, 0]])
            r = Slerp(times, rot)(t).as_quat()
            out[:, a:a + 4] = r[:, [3, 0, 1, 2]]
            if (wxyz == wxyz[0]).all():  # held joint: the exact value, not a rounded round trip
                out[:, a:a + 4] = wxyz[0]
    for c in range(m.nq):
        if c not in quat_cols:
            out[:, c] = np.interp(t, times, qpos[:, c])
    return out


def _oracle_poses(m, Q, mocap_pos=None):
    d = mujoco.MjData(m)
    if mocap_pos is not None:
        d.mocap_pos[:] = mocap_pos
    pos = np.empty((Q.shape[0], m.nbody, 3))
    mat = np.empty((Q.shape[0], m.nbody, 3, 3))
    for k in range(Q.shape[0]):
        d.qpos[:] = Q[k]
        mujoco.mj_kinematics(m, d)
        pos[k] = d.xpos
        mat[k] = d.xmat.reshape(-1, 3, 3)
    return pos, mat


def test_random_chains_never_exceed_bound(record_property):
    rng = np.random.default_rng(SEED)
    ratios_near = []
    ratios_far = []
    n_checked = 0
    joint_kinds = set()
    for chain in range(N_CHAINS):
        xml = _random_chain_xml(rng)
        m = mujoco.MjModel.from_xml_string(xml)
        joint_kinds.update(int(x) for x in m.jnt_type)
        K = int(rng.integers(2, 6))
        times = np.cumsum(rng.uniform(0.05, 1.0, K)) + rng.uniform(-1, 1)
        qpos = _random_qpos(rng, m, K)
        mocap_pos = None
        if m.nmocap:
            mocap_pos = rng.uniform(-1, 1, (m.nmocap, 3))
        plan = Plan(times, qpos, model=m, mocap_pos=mocap_pos)
        # Sub-intervals: each segment, the whole window, random ones, tiny ones.
        iv = [(times[k], times[k + 1]) for k in range(K - 1)] + [(times[0], times[-1])]
        for _ in range(3):
            a, b = np.sort(rng.uniform(times[0], times[-1], 2))
            iv.append((a, b))
        c = rng.uniform(times[0], times[-1])
        w = 1e-3 * (times[-1] - times[0])
        iv.append((max(c - w, times[0]), min(c + w, times[-1])))
        ta = np.array([x[0] for x in iv])
        tb = np.array([x[1] for x in iv])
        mb = plan.motion_bounds(ta, tb)
        ref = plan.ref_points
        for i in range(len(iv)):
            ts = np.concatenate([np.linspace(ta[i], tb[i], N_SAMPLES), rng.uniform(ta[i], tb[i], 20)])
            tm = 0.5 * (ta[i] + tb[i])
            Q = _oracle_qpos(m, times, plan.qpos, np.concatenate([[tm], ts]))
            pos, mat = _oracle_poses(m, Q, mocap_pos)
            for b in range(1, m.nbody):
                near = ref[b] + rng.uniform(-0.5, 0.5, (12, 3))
                d = rng.normal(size=(6, 3))
                far = ref[b] + d / np.linalg.norm(d, axis=1, keepdims=True) * rng.uniform(5, 50, (6, 1))
                pts = np.concatenate([near, far, ref[b][None], np.zeros((1, 3))])
                world = pos[:, b, None, :] + np.einsum("tij,nj->tni", mat[:, b], pts)
                dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)  # (n,)
                bound = mb.trans[i, b] + chord(mb.angle[i, b]) * np.linalg.norm(pts - ref[b], axis=-1)
                viol = dev > bound
                assert not viol.any(), (
                    f"chain {chain} body {b} interval {iv[i]}: deviation {dev[viol]} "
                    f"> bound {bound[viol]}\n{xml}"
                )
                n_checked += pts.shape[0]
                if mb.trans[i, b] > 0 and dev[:12].max() > 1e-9:
                    ratios_near.append(dev[:12].max() / bound[:12][np.argmax(dev[:12])])
                    ratios_far.append((dev[12:18] / bound[12:18]).max())
    # The generator covered every joint kind.
    assert joint_kinds == {0, 1, 2, 3}
    med_near = float(np.median(ratios_near))
    med_far = float(np.median(ratios_far))
    record_property("tightness_median_near", med_near)
    record_property("tightness_median_far", med_far)
    print(f"\nmotion-bound tightness over {N_CHAINS} chains, {len(ratios_near)} (body, interval) cases, "
          f"{n_checked} point checks: median sampled-max/bound near geoms = {med_near:.3f}, "
          f"far points (5-50 m) = {med_far:.3f}")
    assert len(ratios_near) > 500


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_deep_subdivision_bounds_hold(seed):
    """Thousands of tiny sub-intervals (as the checkers request) stay certified."""
    rng = np.random.default_rng(seed)
    m = mujoco.MjModel.from_xml_string(_random_chain_xml(rng))
    while m.nv == 0:
        m = mujoco.MjModel.from_xml_string(_random_chain_xml(rng))
    K = 4
    times = np.cumsum(rng.uniform(0.1, 1.0, K))
    qpos = _random_qpos(rng, m, K)
    plan = Plan(times, qpos, model=m)
    edges = np.linspace(times[0], times[-1], 2049)
    mb = plan.motion_bounds(edges[:-1], edges[1:])
    assert mb.trans.shape == (2048, m.nbody)
    pick = rng.choice(2048, 40, replace=False)
    for i in pick:
        ts = np.linspace(edges[i], edges[i + 1], 50)
        tm = 0.5 * (edges[i] + edges[i + 1])
        Q = _oracle_qpos(m, times, plan.qpos, np.concatenate([[tm], ts]))
        pos, mat = _oracle_poses(m, Q)
        for b in range(1, m.nbody):
            pts = plan.ref_points[b] + rng.uniform(-1, 1, (8, 3))
            world = pos[:, b, None, :] + np.einsum("tij,nj->tni", mat[:, b], pts)
            dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)
            bound = mb.trans[i, b] + chord(mb.angle[i, b]) * np.linalg.norm(pts - plan.ref_points[b], axis=-1)
            assert (dev <= bound).all()


STRESS_XML = """
<mujoco><worldbody>
  <body name="far" pos="3000 -2000 1000">
    <joint name="h" type="hinge" axis="0.3 0.4 0.866" pos="5 0 0"/>
    <joint name="s" type="slide" axis="1 1 0"/>
    <geom type="capsule" size=".05 20" pos="0 0 20"/>
    <body name="tip" pos="0 0 40">
      <joint name="b" type="ball" pos="0 0 1"/>
      <geom type="box" size="1 2 3" pos="0 3 0"/>
    </body>
  </body>
  <body name="free"><freejoint/><geom type="sphere" size="1" pos="2 0 0"/></body>
</worldbody></mujoco>
"""


def stress_plan(step: float, rng: np.random.Generator) -> tuple[mujoco.MjModel, Plan, np.ndarray]:
    """The STRESS_XML plan: coordinates ~1e4 m, joint values ~1e3, waypoint steps of ``step``, times ~1e4 s.

    Returns:
        (model, plan, times (3,)).
    """
    m = mujoco.MjModel.from_xml_string(STRESS_XML)
    K = 3
    q0 = np.array([1234.5, -876.0, *_rand_quat(rng), 9000.0, -7000.0, 5000.0, *_rand_quat(rng)])
    qpos = np.tile(q0, (K, 1))
    for k in range(1, K):
        qpos[k, :2] += step * rng.normal(size=2) * 1e3
        for a in (2, 9):
            qq = qpos[0, a:a + 4] + step * rng.normal(size=4)
            qpos[k, a:a + 4] = qq / np.linalg.norm(qq)
        qpos[k, 6:9] += step * rng.normal(size=3) * 1e3
    times = np.array([0.0, 0.5, 1.5]) + 1e4  # large times as well
    return m, Plan(times, qpos, model=m), times


@pytest.mark.parametrize("step", [1e-11, 1e-8, 1e-4])
def test_rounding_stress_large_coordinates_tiny_motions(step):
    """Coordinates ~1e4 m, joint values ~1e3, motions down to 1e-11: pads must cover rounding."""
    rng = np.random.default_rng(int(-np.log10(step)))
    m, plan, times = stress_plan(step, rng)
    edges = np.linspace(times[0], times[-1], 65)
    mb = plan.motion_bounds(edges[:-1], edges[1:])
    for i in range(0, 64, 3):
        ts = np.linspace(edges[i], edges[i + 1], 40)
        tm = 0.5 * (edges[i] + edges[i + 1])
        samples = [plan.body_poses(np.concatenate([[tm], ts])),
                   _oracle_poses(m, _oracle_qpos(m, times, plan.qpos, np.concatenate([[tm], ts])))]
        for pos, mat in samples:
            for b in range(1, m.nbody):
                spread = np.array([1, 1, 1, 1, 1, 100, 100, 100, 1e3, 0])[:, None]
                pts = plan.ref_points[b] + rng.normal(size=(10, 3)) * spread
                world = pos[:, b, None, :] + np.einsum("tij,nj->tni", mat[:, b], pts)
                dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)
                r = np.linalg.norm(pts - plan.ref_points[b], axis=-1)
                bound = mb.trans[i, b] + chord(mb.angle[i, b]) * r
                assert (dev <= bound).all(), (step, i, b, dev, bound)


TIGHT_XML = """
<mujoco><worldbody>
  <body pos="3000 -2000 1000"><joint type="hinge" axis="0 0 1" pos="7 0 0"/>
    <geom size=".5" pos="0 3 0"/></body>
  <body pos="-4000 100 10"><joint type="slide" axis="0.6 0.8 0"/><geom size=".5"/></body>
  <body pos="10 20 30"><joint type="ball" pos="0 0 0"/><geom size=".5" pos="0 0 9"/></body>
  <body><freejoint/><geom size=".5"/></body>
</worldbody></mujoco>
"""


def test_tight_cases_rounding():
    """Single-joint bodies, where the bound is exact in real arithmetic: only the pads absorb rounding."""
    m = mujoco.MjModel.from_xml_string(TIGHT_XML)
    rng = np.random.default_rng(7)
    worst = 0.0
    for trial in range(40):
        step = 10.0 ** rng.uniform(-12, -2)
        q0 = np.array([rng.uniform(-1e3, 1e3), rng.uniform(-1e3, 1e3), *_rand_quat(rng),
                       *rng.uniform(-1e4, 1e4, 3), 1, 0, 0, 0])
        q1 = q0.copy()
        q1[:2] += step * rng.normal(size=2)
        q1[2:6] = q0[2:6] + step * rng.normal(size=4)
        q1[2:6] /= np.linalg.norm(q1[2:6])
        q1[6:9] += step * rng.normal(size=3)
        times = np.array([0.0, 1.0]) + rng.uniform(0, 1e5)
        plan = Plan(times, np.stack([q0, q1]), model=m)
        mb = plan.motion_bounds(times[:1], times[1:])
        pos, mat = plan.body_poses(np.array([0.5 * (times[0] + times[1]), times[0], times[1]]))
        for b in range(1, m.nbody):
            pts = np.concatenate([plan.ref_points[b][None], rng.normal(size=(5, 3)) * 1e3])
            world = pos[:, b, None, :] + np.einsum("tij,nj->tni", mat[:, b], pts)
            dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)
            bound = mb.trans[0, b] + chord(mb.angle[0, b]) * np.linalg.norm(pts - plan.ref_points[b], axis=-1)
            assert (dev <= bound).all(), (trial, b, dev, bound)
            worst = max(worst, float((dev / bound).max()))
    assert worst > 0.3  # the cases are tight: a loose bound would not exercise the pads


def _serial_chain_xml(rng, n):
    lines = ['<mujoco><worldbody>']
    close = []
    for k in range(n):
        pos = rng.uniform(-0.5, 0.5, 3)
        lines.append(f'<body pos="{_fmt(pos)}" quat="{_fmt(_rand_quat(rng))}">')
        if k == 0 and rng.random() < 0.5:
            lines.append('<freejoint/>')
        else:
            kind = rng.choice(["hinge", "hinge", "ball", "slide"])
            if kind == "ball":
                lines.append(f'<joint type="ball" pos="{_fmt(rng.uniform(-0.3, 0.3, 3))}"/>')
            else:
                lines.append(f'<joint type="{kind}" axis="{_fmt(rng.normal(size=3))}" '
                             f'pos="{_fmt(rng.uniform(-0.3, 0.3, 3))}"/>')
        lines.append(f'<geom size=".05" pos="{_fmt(rng.uniform(-0.3, 0.3, 3))}"/>')
        close.append('</body>')
    lines += close[::-1] + ['</worldbody></mujoco>']
    return "\n".join(lines)


@pytest.mark.parametrize("kinds", [("chain",), ("velocity",)])
def test_each_bound_alone_on_long_chains(kinds):
    """The chain bound and the velocity (second-order) bound are each sound on their own.

    Long serial chains (6-9 joints, free roots, balls, slides), large sweeps, sub-intervals
    inside one segment (where the velocity bound applies) from the whole segment down to 1e-3 of it.
    """
    rng = np.random.default_rng(31 if kinds == ("chain",) else 32)
    ratios = []
    for _ in range(12):
        m = mujoco.MjModel.from_xml_string(_serial_chain_xml(rng, int(rng.integers(6, 10))))
        K = 3
        times = np.cumsum(rng.uniform(0.1, 1.0, K))
        qpos = _random_qpos(rng, m, K)
        plan = Plan(times, qpos, model=m)
        plan._bound_kinds = kinds
        ta, tb = [], []
        for k in range(K - 1):
            for frac in (1.0, 0.5, 0.1, 1e-3):
                w = frac * (times[k + 1] - times[k])
                a = rng.uniform(times[k], times[k + 1] - w)
                ta.append(a)
                tb.append(min(a + w, times[k + 1]))
        ta, tb = np.array(ta), np.array(tb)
        mb = plan.motion_bounds(ta, tb)
        for i in range(ta.shape[0]):
            ts = np.linspace(ta[i], tb[i], 300)
            Q = _oracle_qpos(m, times, plan.qpos, np.concatenate([[0.5 * (ta[i] + tb[i])], ts]))
            pos, mat = _oracle_poses(m, Q)
            for b in range(1, m.nbody):
                pts = np.concatenate([plan.ref_points[b][None],
                                      plan.ref_points[b] + rng.normal(size=(6, 3))])
                world = pos[:, b, None, :] + np.einsum("tij,nj->tni", mat[:, b], pts)
                dev = np.linalg.norm(world[1:] - world[0], axis=-1).max(axis=0)
                r = np.linalg.norm(pts - plan.ref_points[b], axis=-1)
                bound = mb.trans[i, b] + chord(mb.angle[i, b]) * r
                assert (dev <= bound).all(), (kinds, i, b, dev, bound)
                if dev[0] > 1e-9:
                    ratios.append(dev[0] / bound[0])
    print(f"\n{kinds[0]} bound alone on long chains: median ref-point tightness {np.median(ratios):.3f}")


def test_poses_match_fk_at_waypoints_random_chains():
    """Plan poses equal MuJoCo FK (fresh MjData) at every waypoint to 1e-12, on random trees."""
    rng = np.random.default_rng(4242)
    for _ in range(60):
        m = mujoco.MjModel.from_xml_string(_random_chain_xml(rng))
        K = int(rng.integers(2, 6))
        times = np.cumsum(rng.uniform(0.05, 1.0, K))
        qpos = _random_qpos(rng, m, K)
        mocap_pos = rng.uniform(-1, 1, (m.nmocap, 3)) if m.nmocap else None
        plan = Plan(times, qpos, model=m, mocap_pos=mocap_pos)
        pos, mat = plan.body_poses(times)
        ref_pos, ref_mat = _oracle_poses(m, qpos, mocap_pos)
        np.testing.assert_allclose(pos, ref_pos, rtol=0, atol=1e-12)
        np.testing.assert_allclose(mat, ref_mat, rtol=0, atol=1e-12)
