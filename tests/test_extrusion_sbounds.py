"""pair_sbounds: the one-leaf-per-side fast path against the general Up/Down loop.

Oracle: the general loop on each side's box given twice (two identical leaves join to the
same box, shrink and die together), which never takes the fast path; every returned value
must agree bit for bit, including infinite (half-space) sides and zero relative speed.
"""
import numpy as np
import pytest

from monitor.certify.extrusion_sbounds import pair_sbounds


def _boxes(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    c = rng.uniform(-1.0, 1.0, 3)
    e = rng.uniform(0.01, 0.5, 3)
    lo, hi = c - e, c + e
    if rng.random() < 0.2:  # a half-space-like side: one unbounded face
        k = int(rng.integers(3))
        if rng.random() < 0.5:
            lo[k] = -np.inf
        else:
            hi[k] = np.inf
    return lo, hi


def _vel(rng: np.random.Generator) -> np.ndarray:
    v = rng.uniform(-3.0, 3.0, 3)
    v[rng.random(3) < 0.3] = 0.0
    return v


@pytest.mark.parametrize("seed", range(4))
def test_one_leaf_fast_path_matches_general_loop(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n_some = 0
    for _ in range(300):
        a_lo, a_hi = _boxes(rng)
        b_lo, b_hi = _boxes(rng)
        u, v = _vel(rng), _vel(rng)
        if rng.random() < 0.3:
            v = u.copy()  # zero relative speed
        one, two = np.ones(1, bool), np.ones(2, bool)
        fast = pair_sbounds(a_lo[None], a_hi[None], one, u, b_lo[None], b_hi[None], one, v, 0.0, 0.5)
        ref = pair_sbounds(np.stack([a_lo, a_lo]), np.stack([a_hi, a_hi]), two, u,
                           np.stack([b_lo, b_lo]), np.stack([b_hi, b_hi]), two, v, 0.0, 0.5)
        assert (fast is None) == (ref is None)
        if fast is None:
            continue
        n_some += 1
        assert (fast.t_lo, fast.t_hi, fast.passes) == (ref.t_lo, ref.t_hi, ref.passes)
        for f, r in ((fast.a_lo, ref.a_lo), (fast.a_hi, ref.a_hi), (fast.b_lo, ref.b_lo),
                     (fast.b_hi, ref.b_hi)):
            assert f.shape == (1, 3)
            assert f[0].tobytes() == r[0].tobytes() == r[1].tobytes()
        assert fast.a_alive.tolist() == [True] and fast.b_alive.tolist() == [True]
    assert n_some > 20  # the comparison ran on surviving pairs, not only on culled ones


def _frame_axis_by_axis(rb, va: np.ndarray, vb: np.ndarray) -> np.ndarray:  # noqa: ANN001
    """The per-axis rule as first written: one overlap box per axis and candidate."""
    from monitor.certify.extrusion import _pair_box

    w = np.zeros(3)
    for k in range(3):
        widths = []
        for c in (va[k], vb[k]):
            dv = np.zeros(3)
            dv[k] = c
            lo, hi = _pair_box(rb, va - dv, vb - dv)
            widths.append(hi[k] - lo[k])
        w[k] = va[k] if widths[0] <= widths[1] else vb[k]
    return w


@pytest.mark.parametrize("seed", range(3))
def test_own_frame_velocity_matches_axis_by_axis(seed: int) -> None:
    from monitor.certify.extrusion import _own_frame_velocity
    from monitor.certify.extrusion_sbounds import RootBound

    rng = np.random.default_rng(100 + seed)
    picked_b = 0
    for _ in range(300):
        a_lo, a_hi = _boxes(rng)
        b_lo, b_hi = _boxes(rng)
        t_lo = float(rng.uniform(0.0, 0.2))
        rb = RootBound(t_lo, t_lo + float(rng.uniform(0.0, 0.3)), a_lo, a_hi, b_lo, b_hi)
        va, vb = _vel(rng), _vel(rng)
        got, ref = _own_frame_velocity(rb, va, vb), _frame_axis_by_axis(rb, va, vb)
        assert got.tobytes() == ref.tobytes()
        picked_b += int(np.sum((ref == vb) & (ref != va)))
    assert picked_b > 20  # both candidates win on some axes
