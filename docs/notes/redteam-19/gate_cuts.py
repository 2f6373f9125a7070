"""Red team 19, part 2: the gate's per-step cuts (c935623) against their old forms (fa269d6).

Usage: PYTHONPATH=<tree> python docs/notes/redteam-19/gate_cuts.py [N]

Function level (seeded random rows / controls with NaN, +-inf, -0.0, subnormals, huge values; nv = 0;
vel_tol NaN / 0 / -0.0 / negative / inf / numpy scalars), each new form against the old expression:
  _row_at_rest(row.tolist(), tol)        vs np.abs(row).max() <= tol (old raised on nv = 0)
  _first_at_rest(q, tol)                 vs the old three-line form
  ndarray.clip (hold_ctrl, _as_inner)    vs np.clip (bytes of the result, dtype, type)
  ctrl.tolist() != expected.tolist()     vs not (ctrl == expected).all()  (equal shapes)
  counters.tobytes() != zeros' bytes     vs counters.any()  (int32 counters)
Gate level: Gate._pairs_moving's memo against a recomputation on every call, over a Gate run with
fixed pairs through scene rebuilds, in-place model edits and a new Gate (certificates compared).
"""
import sys
from collections import Counter

import mujoco
import numpy as np

from monitor import gate as G

N = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
rng = np.random.default_rng(19)
SPECIAL = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, 5e-324, -5e-324, 1e308, -1e308, 1e-3, -1e-3,
                    1e-3 + 1e-19, np.nextafter(1e-3, 1), np.nextafter(1e-3, 0)])
TOLS = [1e-3, 0.0, -0.0, -1.0, np.inf, -np.inf, np.nan, np.float64(1e-3), np.float32(1e-3), 5e-324, 1e308]
stats, bad = Counter(), Counter()


def row(n):
    r = rng.normal(scale=10.0 ** rng.integers(-5, 3), size=n)
    mask = rng.random(n) < 0.3
    r[mask] = rng.choice(SPECIAL, mask.sum())
    return r


def old_row(r, tol):
    try:
        return bool(np.abs(r).max() <= tol)
    except ValueError as exc:
        return f"RAISE {type(exc).__name__}"


def old_first(q, tol):
    ok = np.abs(q) <= tol
    cand = np.flatnonzero(ok[:, 0])
    if cand.size:
        cand = cand[ok[cand].all(axis=1)]
    return int(cand[0]) if cand.size else None


def same_array(a, b):
    return type(a) is type(b) and np.asarray(a).dtype == np.asarray(b).dtype and \
        np.asarray(a).shape == np.asarray(b).shape and np.asarray(a).tobytes() == np.asarray(b).tobytes()


for _ in range(N):
    nv = int(rng.integers(0, 6))
    tol = TOLS[int(rng.integers(len(TOLS)))] if rng.random() < 0.5 else float(abs(rng.normal()) * 1e-2)
    r = row(nv)
    new = G._row_at_rest(r.tolist(), tol)
    old = old_row(r, tol)
    stats["_row_at_rest"] += 1
    if new != old:
        bad[f"_row_at_rest nv={nv}: new {new} old {old}"] += 1
    if nv:
        q = np.stack([row(nv) for _ in range(int(rng.integers(1, 6)))]) if rng.random() < 0.9 \
            else np.zeros((0, nv))
        if q.size and rng.random() < 0.3:
            q[int(rng.integers(len(q)))] = rng.uniform(-tol if np.isfinite(tol) and tol > 0 else 0, 1e-4, nv)
        stats["_first_at_rest"] += 1
        if G._first_at_rest(q, tol) != old_first(q, tol):
            bad["_first_at_rest"] += 1
    # clip: ctrl (nu,) or odd shapes / dtypes against bounds (lo may exceed hi, NaN bounds)
    nu = int(rng.integers(0, 5))
    c = row(nu)
    lo, hi = row(nu), row(nu)
    for x in (c, c.astype(np.float32), c.reshape(1, -1), np.asarray(c[0]) if nu else np.asarray(0.0),
              np.nan_to_num(c).astype(np.int64)):
        with np.errstate(all="ignore"):
            try:
                a = np.clip(x, lo, hi)
            except Exception as exc:  # noqa: BLE001
                a = f"RAISE {type(exc).__name__}"
            try:
                b = x.clip(lo, hi)
            except Exception as exc:  # noqa: BLE001
                b = f"RAISE {type(exc).__name__}"
        stats["clip"] += 1
        if (a != b) if isinstance(a, str) or isinstance(b, str) else not same_array(a, b):
            bad[f"clip {x.dtype} {x.shape}"] += 1
    # _check_applied_ctrl's compare (equal shapes; data.ctrl is (nu,) float64)
    e = c.copy()
    k = rng.random()
    if nu and k < 0.4:
        e[int(rng.integers(nu))] = rng.choice(SPECIAL)
    elif nu and k < 0.5:
        e = np.where(e == 0, -0.0, e)
    stats["ctrl compare"] += 1
    if (c.tolist() != e.tolist()) != (not (c == e).all()):
        bad["ctrl compare"] += 1
    cnt = np.zeros(8, np.int32)
    if rng.random() < 0.5:
        cnt[int(rng.integers(8))] = rng.choice([1, -1, 2 ** 31 - 1, -2 ** 31])
    stats["counters"] += 1
    if (cnt.tobytes() != bytes(cnt.nbytes)) != bool(cnt.any()):
        bad["counters"] += 1
# targeted: a float64 entry just above a float32 vel_tol (numpy 2 compares a Python float with a
# numpy float32 in float32, NEP 50; the old numpy form compares in float64)
for tol in (np.float32(1e-3), np.float32(0.1), np.float16(1e-3), np.float64(1e-3), 1e-3):
    v = float(np.nextafter(np.float64(tol), np.inf))
    r = np.array([v, 0.0])
    stats["_row_at_rest targeted"] += 1
    new, old = G._row_at_rest(r.tolist(), tol), old_row(r, tol)
    if new != old:
        bad[f"_row_at_rest vel_tol {type(tol).__name__}: new {new} old {old}"] += 1
print("function level:", dict(stats))
print("function level mismatches:", dict(bad) or "none")

# Gate level: the moving memo against recomputation, across rebuilds and edits.
_XML = """<mujoco><option timestep="0.01"/><worldbody>
  <geom name="floor" type="plane" size="2 2 0.1"/>
  <geom name="wall" type="box" size="0.05 1 0.3" pos="0.6 0 0.3"/>
  <body name="a" pos="0 0 0.3"><joint name="x" type="slide" axis="1 0 0" damping="1"/>
    <geom name="ga" type="box" size="0.1 0.05 0.05"/></body>
  <body name="b" pos="0 0.5 0.3"><joint name="y" type="slide" axis="1 0 0" damping="1"/>
    <geom name="gb" type="sphere" size="0.05"/></body>
  <body name="c" pos="0.3 -0.5 0.3"><geom name="gc" type="box" size="0.05 0.05 0.05"/></body>
</worldbody><actuator><motor joint="x" ctrlrange="-1 1"/><motor joint="y" ctrlrange="-1 1"/></actuator>
</mujoco>"""


def key(c):
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    return repr(d)


def gate_run(memo_on, steps=60):
    m = mujoco.MjModel.from_xml_string(_XML)
    d = mujoco.MjData(m)
    g = G.Gate(m, margin=0.01)
    if not memo_on:
        def fresh(self, moving, body_a, body_b):
            either = moving[body_a] | moving[body_b]
            return either, bool(either.all())
        g._pairs_moving = fresh.__get__(g)
    out, r2 = [], np.random.default_rng(3)
    for k in range(steps):
        u = np.array([r2.uniform(-1, 1) * (r2.random() < 0.7), 0.0])  # b at rest: its pairs are fixed
        if k in (20, 40):
            d.qvel[:] = 0.0                          # a at rest too for a window: every pair fixed
        if k == 15:
            m.geom_size[1] *= 1.5                  # in-place edit: a fixed geom grows
        if k == 25:
            m.body_pos[3, 1] = -0.4                 # a fixed body moves (edit)
        if k == 35:
            m.geom_bodyid[4]                        # (read) then a rebuild by a new gate on the same data
            g2 = G.Gate(m, margin=0.01)
            if not memo_on:
                g2._pairs_moving = g._pairs_moving.__func__.__get__(g2)
            g = g2
        if k == 45:
            m.dof_damping[:] = 0.0
        rep = g.step(d, u, nstep=2)
        out.append(f"{rep.verdict} {rep.replaced} {key(rep.certificate)} {g.stats.get('reused_pairs', '')}")
    out.append(d.qpos.tobytes().hex())
    return out, dict(g.stats)


a, sa = gate_run(True)
b, sb = gate_run(False)
print("gate level: 60 steps, memo == recompute:", a == b, "| stats", {k: v for k, v in sa.items()
                                                                       if "reuse" in k or "pairs" in k})
