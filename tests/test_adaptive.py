"""Adaptive sub-intervals of the compiled pair window (issue 12, item 2): coverage and soundness.

The kernel (:func:`monitor.certify.kernels.pair_window`) is stepped one test at a time
(``max_tests=1``: it pauses with its pending work on the stack), so the sub-intervals it
excludes are read off the stack between steps: what leaves the pending set in a step that
neither confirmed a witness nor left an interval unresolved was excluded. Checked:

* the excluded intervals tile the window exactly when the verdict is ``certified``
  (disjoint, no gap, from t0 to t1), and all lie before the witness otherwise
  (earliest first);
* no excluded interval contains a time the independent oracle proves colliding: static
  distances of the bench oracle (MuJoCo / the oracle backend, not the kernel's GJK) at
  dense samples, refined with the analytic Lipschitz margin of the case (its speed bound);
* that oracle has teeth: a sweep whose step length ignores the rotation term (translation
  only bound) excludes a rotating stick's whole window in a few steps, and the oracle flags
  it; the kernel on the same case reports the violation.

Seeded; no timings.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from monitor.bench import oracle
from monitor.bench.cases import PairCase, ShapeSpec, _place, _random_shape
from monitor.certify import kernels as K
from monitor.certify.packed import pack_shapes
from monitor.motion.pack import pack_trajectory

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _intervals import minus  # noqa: E402

REL, ABS = 64 * 2.0**-52, 1e-12


def _unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _case(rng, ka, kb, rotating, name):
    """Body A travels past B (fixed or slightly moving), optionally spinning; placed near B."""
    shapes = (_random_shape(rng, ka), _random_shape(rng, kb))
    u = _unit(rng)
    travel = rng.uniform(0.4, 0.9)
    pos = np.zeros((2, 2, 3))
    pos[0, 0] = -travel * u
    pos[0, 1] = travel * u
    pos[1, 1] = 0.1 * _unit(rng)
    quat = np.zeros((2, 2, 4))
    qa, qb = Rotation.random(random_state=rng), Rotation.random(random_state=rng)
    quat[0, :] = qa.as_quat(scalar_first=True)
    quat[1, :] = qb.as_quat(scalar_first=True)
    if rotating:
        spin = Rotation.from_rotvec(rng.uniform(0.5, 2.0) * _unit(rng))
        quat[0, 1] = (spin * qa).as_quat(scalar_first=True)
    for b in range(2):
        if quat[b, 0] @ quat[b, 1] < 0:
            quat[b, 1] *= -1
    c = PairCase(name, "rotating" if rotating else "translating", "x", 0.0, shapes, pos, quat, (True, True))
    w = np.cross(pos[0, 1] - pos[0, 0], _unit(rng))
    return c, w / np.linalg.norm(w)


def _cases():
    rng = np.random.default_rng(20261124)
    out = []
    kinds = [("box", "box"), ("hull", "box"), ("capsule", "box"), ("sphere", "hull")]
    targets = [2e-2, 4e-3, -5e-3, 1e-1, 8e-3, -2e-2, 3e-2, 2e-3]
    for i, tgt in enumerate(targets):
        ka, kb = kinds[i % len(kinds)]
        c, w = _case(rng, ka, kb, rotating=bool(i % 2), name=f"{ka}-{kb}-{i}")
        out.append(_place(c, w, tgt, oracle.mujoco_distance))
    return out


def _pack(case):
    shapes = [s.convex_shape() for s in case.shapes]
    return pack_shapes([None, *shapes], [0, 1, 2]), pack_trajectory(case.body_motion())


def _pending(stack, sp):
    """Union (sorted, merged) of the intervals on the first ``sp`` stack rows (sweep rows: [a, e])."""
    rows = sorted((float(stack[i, 0]), float(stack[i, 1])) for i in range(sp))
    out = []
    for a, b in rows:
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return out


def _trace(gp, mp, window, margin=0.0, eps=1e-3, max_depth=40, mode=K.MODE_FULL, max_steps=5000):
    """Step pair_window one test at a time; returns (verdict code, excluded pieces, result row)."""
    stack = np.empty((max_depth + 2, 3))
    res = K.new_result()
    t0, t1 = window
    excluded = []
    before = None
    for _ in range(max_steps):
        state = (res[K.R_WTIME], res[K.R_UNRES], res[K.R_FIRST_UNRES])
        tested = None
        if before is not None and before:
            # the interval the next test covers: the top stack entry (a sweep entry: its prefix
            # [a, a + L], extended to e when less than 5 % of L would be left, as the kernel does)
            a, b, d = (float(x) for x in stack[int(res[K.R_SP]) - 1])
            if d < 0.0:
                b = b if not a - d < b + 0.05 * d else a - d
            tested = (a, b)
        wt_prev = state[0]
        v = K.pair_window(gp, mp, 1, 2, t0, t1, margin, eps, max_depth, 1, mode, REL, ABS, stack, res)
        after = _pending(stack, int(res[K.R_SP])) if v == K.PAUSED else []
        now = (res[K.R_WTIME], res[K.R_UNRES], res[K.R_FIRST_UNRES])
        changed = [x for x, y in zip(state, now, strict=True) if not (x == y or (x != x and y != y))]
        if before is not None and not changed:
            # while refining a witness, an unresolved interval at or after the first unresolved
            # time changes no state: such pieces are not counted (they may not be excluded)
            fu = state[2]
            removed = minus(before, after)
            # coverage: a step drops nothing (split, retry) or exactly the interval it tested
            assert removed == [] or (state[0] == state[0] and tested[0] >= wt_prev) or removed == [tested], \
                (removed, tested)
            excluded += [p for p in removed if not (state[0] == state[0] and p[0] >= fu)]
        before = after
        if v != K.PAUSED:
            return v, sorted(excluded), res
    raise AssertionError("pair_window did not finish")


def _oracle_collides_in(case, a, b, margin=0.0, n=24, max_evals=400):
    """A time in [a, b] where the oracle's static distance upper bound is < margin, else None.

    Dense samples first, then refinement of the sub-intervals the Lipschitz margin
    (case speed bound x half length) does not clear, earliest first, up to ``max_evals``.
    """
    L = float(case.speed_bounds().sum())
    todo = [(a + (b - a) * k / n, a + (b - a) * (k + 1) / n) for k in range(n)]
    evals = 0
    while todo and evals < max_evals:
        u, w = todo.pop(0)
        m = 0.5 * (u + w)
        lo, up = oracle.distance_bounds(case, m)
        evals += 1
        if up < margin:
            return m
        if lo - L * 0.5 * (w - u) > margin or w - u < 1e-9:
            continue
        todo[:0] = [(u, m), (m, w)]
    return None


@pytest.fixture(scope="module")
def cases():
    return _cases()


def test_excluded_intervals_tile_the_window_and_are_clear(cases):
    seen = {K.CERTIFIED: 0, K.VIOLATION: 0}
    for case in cases:
        gp, mp = _pack(case)
        v, pieces, res = _trace(gp, mp, (0.0, case.duration))
        assert v in (K.CERTIFIED, K.VIOLATION, K.UNRESOLVED), case.name
        seen[v] = seen.get(v, 0) + 1
        for (a, b), (c, d) in zip(pieces, pieces[1:], strict=False):
            assert a < b and b <= c, (case.name, "overlap", (a, b), (c, d))
        if v == K.CERTIFIED:
            assert pieces[0][0] == 0.0 and pieces[-1][1] == case.duration, case.name
            assert all(b == c for (_, b), (c, _) in zip(pieces, pieces[1:], strict=False)), (case.name, "gap")
        if v == K.VIOLATION:
            assert not pieces or pieces[-1][1] <= res[K.R_WTIME], (case.name, "excluded after the witness")
            assert oracle.distance_bounds(case, float(res[K.R_WTIME]))[0] < 1e-6, case.name
        # same verdict and test count as one uninterrupted call (stepping does not change the search)
        one = K.check_pair_window(gp, mp, 1, 2, (0.0, case.duration), 0.0, 1e-3)
        assert one["verdict"] == K._NAMES[int(v)] and one["tests"] == int(res[K.R_TESTS]), case.name
        for a, b in pieces:
            t = _oracle_collides_in(case, a, b, n=6, max_evals=60)
            assert t is None, (case.name, "excluded interval collides", (a, b), t)
    assert seen[K.CERTIFIED] >= 3 and seen[K.VIOLATION] >= 2, seen


def _stick_case():
    """A 1 m stick spinning a quarter turn about z next to a box: collides only through rotation."""
    stick = ShapeSpec.box(np.array([0.5, 0.02, 0.02]))
    box = ShapeSpec.box(np.array([0.05, 0.05, 0.05]))
    pos = np.zeros((2, 2, 3))
    pos[1, :] = [0.3, 0.3, 0.0]
    quat = np.zeros((2, 2, 4))
    quat[:, :, 0] = 1.0
    quat[0, 1] = Rotation.from_rotvec([0.0, 0.0, 0.5 * np.pi]).as_quat(scalar_first=True)
    return PairCase("stick", "rotating", "collide", -0.1, (stick, box), pos, quat, (True, False))


def _unsound_sweep(case, margin=0.0):
    """Conservative advancement whose bound ignores the rotation term: returns the excluded pieces."""
    v = np.linalg.norm(case.pos[:, 1] - case.pos[:, 0], axis=1).sum() / case.duration
    t, T, pieces = 0.0, case.duration, []
    while t < T:
        L = T - t
        while True:
            m = t + 0.5 * L
            lo, _ = oracle.distance_bounds(case, m)
            if lo - v * 0.5 * L > margin:        # translation-only bound: UNSOUND for a rotating body
                pieces.append((t, t + L))
                t += L
                break
            L *= 0.5
            if L < 1e-6:
                return pieces
    return pieces


def test_an_unsound_step_length_is_caught_by_the_oracle():
    case = _stick_case()
    pieces = _unsound_sweep(case)
    # the unsound sweep "certifies" the whole window in a few long steps (rotation ignored) ...
    assert pieces[0][0] == 0.0 and pieces[-1][1] == case.duration and len(pieces) <= 4
    # ... and the oracle finds a colliding time inside one of them
    assert any(_oracle_collides_in(case, a, b) is not None for a, b in pieces)
    gp, mp = _pack(case)
    v, mine, res = _trace(gp, mp, (0.0, case.duration))
    assert v == K.VIOLATION
    assert all(_oracle_collides_in(case, a, b) is None for a, b in mine)
    assert oracle.distance_bounds(case, float(res[K.R_WTIME]))[0] < 1e-6
