"""Red team 17, part 2: fuzz armprof's two cuts against their old forms (2b1221d).

1. gate._first_at_rest(qvel, vel_tol) vs the old stop rule
   ``stop = np.abs(q).max(axis=1) <= vel_tol; stop.argmax() if stop.any() else None``
   on rows with NaN / +-inf / +-0.0 / subnormals / values at, just above and just below the
   tolerance, tolerances NaN / +-inf / +-0.0 / negative / numpy scalars, empty arrays, nv = 1..7,
   float32 and non-contiguous views. Exceptions must match in type too.
2. engine._WindowPairs.methods: the old fill (``np.full(n, "culled", dtype=object)``, plain str
   assignments) vs the new one (0-d object arrays) on random sel / surv / code / results / unfin,
   including empty arrays, single-element fancy indices and odd method names (results' str).
   Compared: dtype, shape, element types (exactly str), values, and pickle round trip equality.

Run: PYTHONPATH=<tree> /work/main/.venv/bin/python docs/notes/redteam-17/fuzz_armprof_cuts.py [N]
"""
from __future__ import annotations

import pickle
import sys
from types import SimpleNamespace

import numpy as np

from monitor.certify import engine
from monitor.gate import _first_at_rest


def old_first(q, tol):
    stop = np.abs(q).max(axis=1) <= tol
    return int(stop.argmax()) if stop.any() else None


def outcome(fn, *a):
    try:
        return ("ok", fn(*a))
    except Exception as exc:  # noqa: BLE001
        return ("exc", type(exc).__name__)


SPECIAL = [np.nan, np.inf, -np.inf, 0.0, -0.0, 5e-324, -5e-324, 1e-300, 1e300]


def fuzz_first(rng, n):
    cases = diffs = 0
    for _ in range(n):
        K = int(rng.integers(0, 9))
        nv = int(rng.integers(1, 8))
        tol = float(rng.choice([1e-3, 0.0, -0.0, 1.0, np.inf, -np.inf, np.nan, -1e-3, 5e-324]))
        q = rng.normal(scale=10 ** rng.uniform(-5, 1), size=(K, nv))
        mask = rng.random(q.shape)
        q[mask < 0.15] = rng.choice(SPECIAL, size=int((mask < 0.15).sum())) if K else q[mask < 0.15]
        edge = (mask >= 0.15) & (mask < 0.35)
        if np.isfinite(tol):
            near = np.array([tol, -tol, np.nextafter(tol, np.inf), np.nextafter(tol, -np.inf),
                             -np.nextafter(tol, np.inf)])
            q[edge] = rng.choice(near, size=int(edge.sum())) if edge.any() else q[edge]
        if rng.random() < 0.2:  # rows mostly at rest
            q[rng.random(K) < 0.5] *= 0.0
        variants = [q, np.asfortranarray(q), q.astype(np.float32)]
        if nv > 1:
            wide = np.concatenate([q, q], axis=1)
            variants.append(wide[:, ::2])  # non-contiguous view equal to q
        for v in variants:
            for t in (tol, np.float64(tol), np.float32(tol)):
                cases += 1
                a, b = outcome(old_first, v, t), outcome(_first_at_rest, v, t)
                if a != b:
                    diffs += 1
                    if diffs <= 5:
                        print("DIFF first_at_rest", a, b, v.dtype, t, v.tolist())
    # nv = 0 (the callers never pass it: _tail_by_loop breaks on m.nv == 0 and _tail_by_rollout's
    # substep-1 test raises first): both raise, the type differs
    z = np.empty((3, 0))
    print("nv=0:", outcome(old_first, z, 1e-3), outcome(_first_at_rest, z, 1e-3))
    return cases, diffs


def old_methods(self):
    KS = engine._kernels()
    code = self.code
    out = np.full(len(self.sel), "culled", dtype=object)
    if self.results:
        pos = np.searchsorted(self.sel, np.fromiter(self.results, np.int64, len(self.results)))
        for k, r in zip(pos.tolist(), self.results.values()):
            out[k] = str(r.method)
    if self.surv.size:
        c = code[self.surv]
        st = self.surv[(c == KS.WK_STATIC_VIOL) | (c == KS.WK_STATIC_CERT)]
        tl = self.surv[(c == KS.WK_CERT) | (c == KS.WK_VIOL)]
        out[st] = "static"
        out[tl] = "toleranced"
    if self.unfin.any():
        out[self.unfin] = "budget"
    return out


ODD = ["", "culled", "static", "budget", "toleranced", "é", "x" * 300, "0", "nan", "\x00", "None"]


def fuzz_methods(rng, n):
    KS = engine._kernels()
    codes = [KS.WK_CULLED, KS.WK_SS, KS.WK_STATIC_VIOL, KS.WK_STATIC_CERT, KS.WK_CERT, KS.WK_VIOL]
    codes += [c for c in (getattr(KS, x) for x in dir(KS) if x.startswith("WK_")) if c not in codes]
    cases = diffs = 0
    for _ in range(n):
        P = int(rng.integers(0, 12))
        sel = np.sort(rng.choice(1000, size=P, replace=False)).astype(np.int64)
        code = rng.choice(codes, size=P).astype(np.int64) if P else np.empty(0, np.int64)
        surv = np.flatnonzero(rng.random(P) < 0.6).astype(np.int64) if P else np.empty(0, np.int64)
        unfin = rng.random(P) < 0.2
        results = {}
        for i in (rng.choice(P, size=int(rng.integers(0, P + 1)), replace=False) if P else []):
            results[int(sel[i])] = SimpleNamespace(method=str(rng.choice(ODD)))
        fake = SimpleNamespace(sel=sel, code=code, surv=surv, unfin=unfin, results=results)
        cases += 1
        a = old_methods(fake)
        b = engine._WindowPairs.methods(fake)
        same = (a.dtype == b.dtype and a.shape == b.shape and all(type(x) is str for x in b)
                and a.tolist() == b.tolist() and pickle.loads(pickle.dumps(b)).tolist() == a.tolist())
        if not same:
            diffs += 1
            if diffs <= 5:
                print("DIFF methods", a.tolist(), b.tolist(), [type(x) for x in b])
    # the constants must stay unchanged (a caller writing into them would change every later call)
    consts = (engine._M_CULLED, engine._M_STATIC, engine._M_TOLERANCED, engine._M_BUDGET)
    assert [str(m[()]) for m in consts] == ["culled", "static", "toleranced", "budget"]
    return cases, diffs


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
    rng = np.random.default_rng(17)
    print("first_at_rest cases, diffs:", fuzz_first(rng, n))
    print("methods cases, diffs:", fuzz_methods(rng, n))
