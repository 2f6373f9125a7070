"""S-bounds of the extrusion checker (Cameron §4.3, §6.3, Appendix B).

3-D S-bounds are world-aligned boxes given at the span start and moving with the
velocity of the body that owns the subtree (a 4-D S-bound is the extrusion of a
3-D one, §4.3.2). Inside one body the tree is a union of convex leaves, so only
the aligned-box operators are needed:

* Upward rule at a union node: ``B(node) = join of B(children)`` (smallest box
  containing them), applied bottom-up.
* Downward rule: ``B(child) = B(child) meet B(parent)`` (box intersection),
  applied top-down; a leaf whose bound becomes empty is a redundant primitive
  and is removed.

At the root (the intersection of two bodies' extrusions) :func:`root_operator`
is the closed form of Appendix B: the time interval ``[t_l, t_h]`` in which two
boxes moving with velocities ``u`` and ``v`` can overlap, and the tightened boxes
(``a' = max(a, b + min((v-u) t_l, (v-u) t_h))`` and so on).

All bounds are padded outwards (callers inflate leaf boxes by the rounding pad;
the time interval is widened by a few ulp), so a bound is always a superset:
S-bounds only ever discard things that provably cannot collide.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_ULP_WIDEN = 8 * 2.0**-52


@dataclass
class RootBound:
    """Result of the Appendix-B operator on two moving boxes.

    Attributes:
        t_lo: start (s from span start) of the time interval of possible overlap.
        t_hi: end of it.
        a_lo: (3,) tightened box of A at tau = 0 (moving with u), lower corner (m).
        a_hi: (3,) upper corner.
        b_lo: (3,) tightened box of B at tau = 0 (moving with v).
        b_hi: (3,) upper corner.
    """

    t_lo: float
    t_hi: float
    a_lo: np.ndarray
    a_hi: np.ndarray
    b_lo: np.ndarray
    b_hi: np.ndarray


def root_operator(a_lo: np.ndarray, a_hi: np.ndarray, u: np.ndarray,
                  b_lo: np.ndarray, b_hi: np.ndarray, v: np.ndarray,
                  t_lo: float, t_hi: float) -> RootBound | None:
    """Appendix B: intersect two aligned boxes moving with constant velocities.

    Box A is ``{q : u tau + a_lo <= q <= u tau + a_hi}``, B likewise with ``v``,
    ``tau`` in ``[t_lo, t_hi]``. Infinite box sides (half-spaces) are allowed.

    Args:
        a_lo, a_hi: (3,) box of A at tau = 0 (m).
        u: (3,) velocity of A (m/s).
        b_lo, b_hi: (3,) box of B at tau = 0 (m).
        v: (3,) velocity of B (m/s).
        t_lo, t_hi: time interval (s) to clip to.

    Returns:
        A :class:`RootBound`, or None when the 4-D bound is provably null.
    """
    du = u - v
    with np.errstate(invalid="ignore", divide="ignore"):
        lo_num = b_lo - a_hi  # (u - v) tau >= b - alpha
        hi_num = b_hi - a_lo  # (u - v) tau <= beta - a
        # the quotients in numpy (IEEE overflow to inf, as per-axis numpy scalars gave);
        # entries with du == 0 are never read
        q_lo = (lo_num / du).tolist()
        q_hi = (hi_num / du).tolist()
    tl, th = t_lo, t_hi
    # per axis on Python floats (the same comparisons as on numpy scalars, cheaper)
    for lo_k, hi_k, du_k, x1, x2 in zip(lo_num.tolist(), hi_num.tolist(), du.tolist(), q_lo, q_hi):
        if lo_k != lo_k or hi_k != hi_k:  # NaN (inf - inf of two half-space sides)
            continue
        if du_k == 0.0:
            if lo_k > 0.0 or hi_k < 0.0:
                return None
            continue
        if du_k < 0:
            x1, x2 = x2, x1
        tl = max(tl, x1)
        th = min(th, x2)
    widen = _ULP_WIDEN * max(abs(tl), abs(th), abs(t_hi - t_lo)) if np.isfinite(tl + th) else 0.0
    tl = max(t_lo, tl - widen)
    th = min(t_hi, th + widen)
    if not tl <= th:
        return None
    e_l, e_h = -du * tl, -du * th  # (v - u) tau at both ends
    with np.errstate(invalid="ignore"):
        e_min = np.minimum(e_l, e_h)  # = np.stack([e_l, e_h]).min(axis=0), bit for bit
        e_max = np.maximum(e_l, e_h)
        na_lo = np.maximum(a_lo, b_lo + e_min)
        na_hi = np.minimum(a_hi, b_hi + e_max)
        nb_lo = np.maximum(b_lo, a_lo - e_max)
        nb_hi = np.minimum(b_hi, a_hi - e_min)
    na_lo = np.where(np.isnan(na_lo), a_lo, na_lo)
    na_hi = np.where(np.isnan(na_hi), a_hi, na_hi)
    nb_lo = np.where(np.isnan(nb_lo), b_lo, nb_lo)
    nb_hi = np.where(np.isnan(nb_hi), b_hi, nb_hi)
    return RootBound(float(tl), float(th), na_lo, na_hi, nb_lo, nb_hi)


def join(lo: np.ndarray, hi: np.ndarray, alive: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Upward rule at a union node: smallest box containing the live children (n, 3) boxes."""
    return lo[alive].min(axis=0), hi[alive].max(axis=0)


@dataclass
class PairSBounds:
    """Converged S-bounds of one body pair over one span.

    Attributes:
        t_lo: (s from span start) start of the possible-overlap interval.
        t_hi: end of it.
        a_lo: (nA, 3) leaf boxes of body A at tau = 0 (moving with A), empty where dead.
        a_hi: (nA, 3).
        a_alive: (nA,) bool: leaf survives.
        b_lo: (nB, 3), b_hi: (nB, 3), b_alive: (nB,) likewise for B.
        passes: Up/Down passes performed.
    """

    t_lo: float
    t_hi: float
    a_lo: np.ndarray
    a_hi: np.ndarray
    a_alive: np.ndarray
    b_lo: np.ndarray
    b_hi: np.ndarray
    b_alive: np.ndarray
    passes: int


def pair_sbounds(a_lo: np.ndarray, a_hi: np.ndarray, a_alive: np.ndarray, u: np.ndarray,
                 b_lo: np.ndarray, b_hi: np.ndarray, b_alive: np.ndarray, v: np.ndarray,
                 t_lo: float, t_hi: float, max_passes: int = 8) -> PairSBounds | None:
    """Iterate Upward / root / Downward passes for the tree ``(U A_i) meet (U B_j)``.

    Args:
        a_lo, a_hi: (nA, 3) leaf boxes of A at tau = 0 (m); a_alive (nA,) initial mask
            (False = disabled by the pair policy: an empty S-bound, §6.3).
        u: (3,) velocity of A.
        b_lo, b_hi, b_alive, v: same for B.
        t_lo, t_hi: span (s from span start).
        max_passes: cap on Up/Down passes (they converge in a linear number, §5 fn. 7;
            we stop as soon as a pass changes no leaf and shrinks no bound by > 1e-9).

    Returns:
        :class:`PairSBounds`, or None when the pair is provably clear in the span.
    """
    if len(a_lo) == 1 and len(b_lo) == 1 and max_passes >= 1 and a_alive[0] and b_alive[0]:
        return _pair_sbounds_1x1(a_lo[0], a_hi[0], u, b_lo[0], b_hi[0], v, t_lo, t_hi, max_passes)
    a_lo, a_hi, b_lo, b_hi = a_lo.copy(), a_hi.copy(), b_lo.copy(), b_hi.copy()
    a_alive, b_alive = a_alive.copy(), b_alive.copy()
    tl, th = t_lo, t_hi
    passes = 0
    while passes < max_passes:
        if not a_alive.any() or not b_alive.any():
            return None
        passes += 1
        ua_lo, ua_hi = join(a_lo, a_hi, a_alive)
        ub_lo, ub_hi = join(b_lo, b_hi, b_alive)
        rb = root_operator(ua_lo, ua_hi, u, ub_lo, ub_hi, v, tl, th)
        if rb is None:
            return None
        old = (a_lo, a_hi, b_lo, b_hi, tl, th)  # rebound below, never written in place
        tl, th = rb.t_lo, rb.t_hi
        a_lo = np.maximum(a_lo, rb.a_lo)
        a_hi = np.minimum(a_hi, rb.a_hi)
        b_lo = np.maximum(b_lo, rb.b_lo)
        b_hi = np.minimum(b_hi, rb.b_hi)
        na = a_alive & np.all(a_lo <= a_hi, axis=1)
        nb = b_alive & np.all(b_lo <= b_hi, axis=1)
        died = (na != a_alive).any() or (nb != b_alive).any()
        a_alive, b_alive = na, nb
        with np.errstate(invalid="ignore"):
            shrink = max(_max_change(old[0], a_lo, a_alive), _max_change(old[1], a_hi, a_alive),
                         _max_change(old[2], b_lo, b_alive), _max_change(old[3], b_hi, b_alive),
                         abs(old[4] - tl), abs(old[5] - th))
        if not died and shrink <= 1e-9:
            break
    if not a_alive.any() or not b_alive.any():
        return None
    return PairSBounds(tl, th, a_lo, a_hi, a_alive, b_lo, b_hi, b_alive, passes)


def _pair_sbounds_1x1(a_lo: np.ndarray, a_hi: np.ndarray, u: np.ndarray, b_lo: np.ndarray,
                      b_hi: np.ndarray, v: np.ndarray, t_lo: float, t_hi: float,
                      max_passes: int) -> PairSBounds | None:
    """:func:`pair_sbounds` for one live leaf per side, (3,) boxes: the same passes and values.

    With one leaf the Upward join is the leaf itself, a dead leaf ends the pair (None),
    and the four per-side changes are one maximum over the concatenated coordinates.
    """
    tl, th = t_lo, t_hi
    passes = 0
    while passes < max_passes:
        passes += 1
        rb = root_operator(a_lo, a_hi, u, b_lo, b_hi, v, tl, th)
        if rb is None:
            return None
        old = np.concatenate([a_lo, a_hi, b_lo, b_hi])
        old_tl, old_th = tl, th
        tl, th = rb.t_lo, rb.t_hi
        a_lo = np.maximum(a_lo, rb.a_lo)
        a_hi = np.minimum(a_hi, rb.a_hi)
        b_lo = np.maximum(b_lo, rb.b_lo)
        b_hi = np.minimum(b_hi, rb.b_hi)
        if not ((a_lo <= a_hi).all() and (b_lo <= b_hi).all()):
            return None
        with np.errstate(invalid="ignore"):
            d = np.abs(old - np.concatenate([a_lo, a_hi, b_lo, b_hi]))
        d = d[np.isfinite(d)]
        shrink = max(float(d.max()) if d.size else 0.0, abs(old_tl - tl), abs(old_th - th))
        if shrink <= 1e-9:
            break
    one = np.ones(1, bool)
    return PairSBounds(tl, th, a_lo[None], a_hi[None], one, b_lo[None], b_hi[None], one.copy(), passes)


def _max_change(old: np.ndarray, new: np.ndarray, alive: np.ndarray) -> float:
    """Largest finite change of live box coordinates (m)."""
    if not alive.any():
        return 0.0
    d = np.abs(old[alive] - new[alive])
    d = d[np.isfinite(d)]
    return float(d.max()) if d.size else 0.0


def swept_box(lo: np.ndarray, hi: np.ndarray, v: np.ndarray, ta: float, tb: float
              ) -> tuple[np.ndarray, np.ndarray]:
    """Static AABB of a box (at tau = 0, moving with v) over ``tau in [ta, tb]``."""
    ea, eb = v * ta, v * tb
    return lo + np.minimum(ea, eb), hi + np.maximum(ea, eb)


__all__ = ["RootBound", "root_operator", "join", "PairSBounds", "pair_sbounds", "swept_box"]
