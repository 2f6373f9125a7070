"""Stage 0 of the window kernel by sort-and-sweep (issue 12, sparse scaling) against its pair loop.

Above ``engine.SWEEP_MIN_GEOMS`` geoms the window kernel visits only the pairs whose swept boxes a
sort-and-sweep produces (``monitor.certify.kernels.sweep_rows``); below it, every selected pair.
These tests force the cutover both ways on small seeded random scenes (free bodies with boxes,
spheres, capsules and meshes, welded children, static world geoms, a floor plane; pair policies
``"all"``, ``"mujoco"`` with contype masks / ``<exclude>`` / ``<pair>``, explicit lists, allowed
pairs, pair subsets) and check:

* the survivors, their order and codes, and ``info`` are the pair loop's; every pair the sweep
  left out is one the pair loop culled, and its swept spheres are apart by more than the margin
  by the independent numpy broad phase (``broadphase.swept_geom_spheres``);
* the certificates are equal: verdict, clearance, witness, checker mix, and every pair's
  verdict, method and clearance (a left-out pair's gap is computed when ``cert.pairs`` is read,
  as for a pair the pair loop culled by its box test, so nothing visible changes).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import monitor
from monitor.certify import engine
from monitor.certify import kernels as KS
from monitor.certify.broadphase import sphere_pair_gaps, swept_geom_spheres

_MESH = "0 0 0  0.1 0 0  0 0.1 0  0 0 0.1  0.08 0.08 0.05"


def _random_model(rng: np.random.Generator, n: int, extent: float) -> mujoco.MjModel:
    """n free bodies (some with a welded child), 3 static world boxes, a floor; random contype bits."""
    parts = []
    for i in range(n):
        x, y, z = rng.uniform(0.0, extent, 3) + (0.0, 0.0, 0.3)
        kind = int(rng.integers(4))
        ct, ca = int(rng.integers(1, 4)), int(rng.integers(1, 4))
        geom = [f'type="box" size="{rng.uniform(0.02, 0.08):.3f} 0.04 0.03"',
                f'type="sphere" size="{rng.uniform(0.02, 0.08):.3f}"',
                'type="capsule" size="0.03" fromto="0 0 0 0.1 0 0"', 'type="mesh" mesh="m"'][kind]
        child = ""
        if rng.random() < 0.3:   # a welded child: same weld group, never paired with its parent
            child = f'<body name="c{i}" pos="0.05 0 0"><geom name="cg{i}" type="sphere" size="0.03"/></body>'
        parts.append(f'<body name="b{i}" pos="{x:.3f} {y:.3f} {z:.3f}"><freejoint/>'
                     f'<geom name="g{i}" {geom} contype="{ct}" conaffinity="{ca}"/>{child}</body>')
    world = "".join(f'<geom name="w{j}" type="box" size="0.1 0.1 0.1" pos="{p[0]:.3f} {p[1]:.3f} 0.3"/>'
                    for j, p in enumerate(rng.uniform(0.0, extent, (3, 2))))
    xml = (f'<mujoco><option gravity="0 0 0"/><asset><mesh name="m" vertex="{_MESH}"/></asset>'
           f'<worldbody><geom name="floor" type="plane" size="5 5 0.1"/>{world}{"".join(parts)}</worldbody>'
           f'<contact><exclude body1="b0" body2="b1"/><pair geom1="g2" geom2="g3"/></contact></mujoco>')
    return mujoco.MjModel.from_xml_string(xml)


def _plan(model: mujoco.MjModel, rng: np.random.Generator, step: float) -> monitor.Plan:
    q0 = model.qpos0.copy()
    q1 = q0.copy()
    for j in range(model.njnt):
        a = int(model.jnt_qposadr[j])
        q1[a:a + 3] += rng.normal(size=3) * step
        w = rng.normal(size=3) * 0.3
        quat = np.zeros(4)
        mujoco.mju_axisAngle2Quat(quat, w / np.linalg.norm(w), float(np.linalg.norm(w)))
        q1[a + 3:a + 7] = quat
    return monitor.Plan(np.array([0.0, 0.1]), np.stack([q0, q1]), model=model)


def _cases():
    """(scene, plan, certify kwargs) on seeded random scenes, one per pair policy."""
    rng = np.random.default_rng(20261128)
    out = []
    for c, policy in enumerate(("all", "mujoco", "list", "allowed", "subset", "all-sparse")):
        model = _random_model(rng, 24, 1.2 if c < 5 else 3.0)
        plan = _plan(model, rng, 0.08)
        kw: dict = {"epsilon": 1e-3, "margin": (0.0, 0.02)[c % 2]}
        if policy == "list":
            every = monitor.Scene.from_model(model, pairs="all").candidate_pairs
            pick = rng.choice(len(every), size=len(every) // 2, replace=False)
            scene = monitor.Scene.from_model(model, pairs=[every[i] for i in pick])
        elif policy == "allowed":
            every = monitor.Scene.from_model(model, pairs="all").candidate_pairs
            scene = monitor.Scene.from_model(model, pairs="all",
                                             allowed=[every[i] for i in rng.choice(len(every), 40)])
        else:
            scene = monitor.Scene.from_model(model, pairs="mujoco" if policy == "mujoco" else "all")
        if policy == "subset":
            every = scene.candidate_pairs
            kw["pairs"] = [every[i] for i in sorted(rng.choice(len(every), size=len(every) // 3,
                                                               replace=False))]
        out.append((policy, model, scene, plan, kw))
    # only pairs that survive (numpy swept spheres within 0.05 m): no culled pair for the smallest
    # culled gap, so the sweep widens until its threshold spans every box
    policy, model, scene, plan, kw = out[0]
    shapes = [g.shape for g in scene.geoms]
    pid = np.asarray(scene.pair_ids)
    bounded = np.array([s is not None and s.kind != "halfspace" for s in shapes])
    pid = pid[bounded[pid[:, 0]] & bounded[pid[:, 1]]]
    sph = swept_geom_spheres(plan, shapes, np.array([g.body_id for g in scene.geoms]), (0.0, 0.1), 8)
    near = pid[sphere_pair_gaps(sph, pid[:, 0], pid[:, 1]) < 0.05]
    names = [g.name for g in scene.geoms]
    scene = monitor.Scene.from_model(model, pairs=[(names[a], names[b]) for a, b in near])
    out.append(("near-only", model, scene, plan, {"epsilon": 1e-3, "margin": 0.05}))
    return out


CASES = _cases()


def _same_type_copy(x: np.ndarray) -> np.ndarray:
    """A copy with the same numba type (read-only stays read-only: another type would compile a second
    ``window_kernel`` specialisation and switch off the engine's direct call for the rest of the process)."""
    y = x.copy()
    y.flags.writeable = x.flags.writeable
    return y


def _stage0_calls(monkeypatch, scene, plan, kw) -> list[tuple]:
    """The arguments of every stage-0 ``window_kernel`` call of one certify (sweep forced)."""
    calls = []
    orig = engine._window_kernel

    def spy(*a):
        if a[7] == 0:
            calls.append(tuple(_same_type_copy(x) if isinstance(x, np.ndarray) else x for x in a))
        return orig(*a)

    monkeypatch.setattr(engine, "_window_kernel", spy)
    monkeypatch.setattr(engine, "SWEEP_MIN_GEOMS", 0)
    monitor.certify(scene, plan, **kw)
    monkeypatch.setattr(engine, "_window_kernel", orig)
    return calls


def _run_stage0(a: tuple, rows: np.ndarray) -> tuple:
    """Stage 0 alone (k1 = 0) on fresh output arrays; the sweep when ``rows`` is not empty."""
    (_KS, gp, mp, pairs, fixed, mov, route, _stage, _k0, _k1, prm, code, gap, surv, res, sc, sr, _rows,
     info) = a
    code, gap, surv = np.zeros_like(code), np.full_like(gap, -7.0), np.zeros_like(surv)
    res, sc, sr, info = np.empty_like(res), np.empty_like(sc), np.empty_like(sr), np.zeros_like(info)
    n_sig = len(KS.window_kernel.signatures)
    S = int(KS.window_kernel(gp, mp, pairs, fixed, mov, route, 0, 0, 0, prm, code, gap, surv, res, sc, sr,
                             rows, info))
    assert len(KS.window_kernel.signatures) == n_sig, "the replay compiled another specialisation"
    return S, code, gap, surv, sc, sr, info


@pytest.mark.parametrize("case", range(len(CASES)), ids=[c[0] for c in CASES])
def test_sweep_keeps_the_pair_loops_survivors_and_culls_only_far_pairs(monkeypatch, case):
    """The sweep's stage 0 == the pair loop's on the survivors (order, codes), the pad and the smallest
    culled gap; every pair it does not visit is culled by the pair loop too and is apart by more than
    the margin by the independent numpy swept spheres."""
    policy, model, scene, plan, kw = CASES[case]
    calls = _stage0_calls(monkeypatch, scene, plan, kw)
    assert calls, "no stage-0 window_kernel call"
    a = calls[0]
    pairs, rows, margin = a[3], a[17], float(a[10][KS.WP_MARGIN])
    assert rows.shape == (len(scene.geoms) + 1,), "the sweep was not taken"
    S0, code0, gap0, surv0, sc0, sr0, info0 = _run_stage0(a, engine._NONE)
    S1, code1, gap1, surv1, sc1, sr1, info1 = _run_stage0(a, rows)
    assert S1 == S0 and np.array_equal(surv1[:S1], surv0[:S0])
    assert np.array_equal(code1[surv1[:S1]], code0[surv0[:S0]])
    assert np.array_equal(sc1, sc0) and np.array_equal(sr1, sr0)
    assert np.array_equal(info1, info0, equal_nan=True), (info1, info0)
    unvisited = np.flatnonzero(code1 == KS.WK_UNVISITED)
    assert np.all(code0[unvisited] == KS.WK_CULLED)
    visited = code1 != KS.WK_UNVISITED
    assert np.array_equal(code1[visited], code0[visited])
    # the independent oracle: numpy swept spheres of the left-out pairs are apart by more than the margin
    shapes = [g.shape for g in scene.geoms]
    bodies = np.array([g.body_id for g in scene.geoms])
    used = np.unique(pairs[unvisited].ravel())
    assert all(shapes[g] is not None and shapes[g].kind != "halfspace" for g in used)
    local = np.full(len(shapes), -1)
    local[used] = np.arange(len(used))
    sph = swept_geom_spheres(plan, [shapes[g] for g in used], bodies[used], (0.0, 0.1), 8)
    gaps = sphere_pair_gaps(sph, local[pairs[unvisited, 0]], local[pairs[unvisited, 1]])
    assert np.all(gaps > margin), (policy, gaps.min(), margin)
    # and the scenes do exercise both kinds of pairs
    if policy == "near-only":
        assert len(unvisited) == 0 and S1 == len(pairs) and info1[KS.WI_BEST] == np.inf
    else:
        assert len(unvisited) > 0 and (S1 > 0 or policy == "all-sparse"), (policy, len(unvisited), S1)


def _summary(cert) -> tuple:
    w = cert.witness
    wit = None if w is None else (w.time, w.geoms, tuple(np.asarray(w.point).tolist()), w.distance)
    pairs = tuple((p.geoms, str(p.verdict), str(p.method), p.clearance) for p in cert.pairs)
    return (str(cert.verdict), cert.clearance, cert.earliest_time, wit, cert.stats["checker_mix"],
            cert.stats["pairs"], pairs)


@pytest.mark.parametrize("case", range(len(CASES)), ids=[c[0] for c in CASES])
def test_certificates_equal_with_and_without_the_sweep(monkeypatch, case):
    """The whole certificate is the same whichever stage 0 runs (fresh scenes, so no cache is shared)."""
    policy, model, _scene, plan, kw = CASES[case]
    out, rows = [], []
    orig = engine._sweep_rows
    monkeypatch.setattr(engine, "_sweep_rows", lambda *a: rows.append(orig(*a)) or rows[-1])
    for cut in (10 ** 9, 0):
        monkeypatch.setattr(engine, "SWEEP_MIN_GEOMS", cut)
        scene = monitor.Scene.from_model(model, pairs=_scene._pairs_spec, **_scene._acm_spec)
        out.append(_summary(monitor.certify(scene, plan, **kw)))
    assert out[0] == out[1], policy
    assert rows[0].size == 0 and rows[-1].size == len(_scene.geoms) + 1    # the pair loop, then the sweep


def test_unsorted_pair_rows_take_the_pair_loop():
    """The sweep finds a pair's row by binary search: rows not in strict (a, b) order get no row starts."""
    policy, model, scene, plan, kw = CASES[0]
    sp = KS.scene_pack(scene)
    pid = sp.pair_ids
    assert engine._sweep_rows(None, sp, pid).size == 0 or engine.SWEEP_MIN_GEOMS > len(scene.geoms)
    old = engine.SWEEP_MIN_GEOMS
    try:
        engine.SWEEP_MIN_GEOMS = 0
        rows = engine._sweep_rows(None, sp, pid)
        assert rows.shape == (len(scene.geoms) + 1,)
        assert np.array_equal(rows, np.searchsorted(pid[:, 0], np.arange(len(scene.geoms) + 1)))
        assert engine._sweep_rows(None, sp, np.ascontiguousarray(pid[::-1])).size == 0
        assert engine._sweep_rows(None, sp, np.ascontiguousarray(pid[:, ::-1])).size == 0
    finally:
        engine.SWEEP_MIN_GEOMS = old


def test_scene_records_sorted_pairs_and_sync_keeps_it():
    """A Scene records that its pair array is in strict (a, b) order (the sweep then skips its O(P) check);
    an in-place model edit rebuilds the scene with its new array and the record follows it."""
    from monitor.certify.packed import lex_sorted_pairs

    _policy, model, scene, _plan, _kw = CASES[1]
    assert scene._sorted_pairs is scene.pair_ids
    pid = np.asarray(scene.pair_ids)
    assert lex_sorted_pairs(pid, len(scene.geoms))
    assert not lex_sorted_pairs(pid[::-1], len(scene.geoms))
    assert not lex_sorted_pairs(pid[:, ::-1], len(scene.geoms))
    assert not lex_sorted_pairs(np.concatenate([pid[:1], pid[:1]]), len(scene.geoms))   # a repeated row
    assert not lex_sorted_pairs(pid, int(pid.max()))                                       # id out of range
    fresh = monitor.Scene.from_model(model, pairs="mujoco")
    before, size = fresh.pair_ids, float(model.geom_size[0, 0])
    model.geom_size[0, 0] = size * 1.01
    try:
        assert fresh.sync()
        assert fresh.pair_ids is not before and fresh._sorted_pairs is fresh.pair_ids
    finally:
        model.geom_size[0, 0] = size      # the shared case's model, exactly as it was


def test_small_scenes_use_a_window_kernel_without_the_sweep_and_both_take_the_direct_call(monkeypatch):
    """Below the cutover the engine passes ``rows=None``: numba prunes the sweep's branches, so a
    process that never sweeps never compiles the sweep (cold start). With both specialisations in
    the process, each kind of call still takes its own overload's entry point."""
    from numba.core import types

    policy, model, scene, plan, kw = CASES[0]
    monkeypatch.setattr(engine, "SWEEP_MIN_GEOMS", 0)
    swept = monitor.certify(scene, plan, **kw)
    monkeypatch.setattr(engine, "SWEEP_MIN_GEOMS", 10 ** 9)
    loop = monitor.certify(scene, plan, **kw)
    assert _summary(swept) == _summary(loop)
    kinds = {isinstance(sig[engine._WK_ROWS], types.NoneType) for sig in KS.window_kernel.overloads}
    assert kinds == {True, False}, list(KS.window_kernel.overloads)
    if len(KS.window_kernel.overloads) == 2:
        eps = engine._entry_points_by_rows(KS.window_kernel.overloads)
        assert eps[0] is not None and eps[1] is not None and eps[0] is not eps[1]
        for slot in (0, 1):
            d = engine._WK_DIRECT[slot]
            assert d is not None and d[2] is eps[slot]
