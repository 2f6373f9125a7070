"""In-kernel per-stage profile of window_kernel (issue 12, h12x): an instrumented copy of kernels.py.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-kernel-cost/instrument.py [case names...]
Copies monitor/certify/kernels.py to /tmp (module ``kprof``), inserts reads of the CPU cycle counter
(``llvm.readcyclecounter``, an intrinsic callable in nopython mode) around each stage, accumulating
cycles into extra slots of the ``info`` vector, replays each case's recorded stage-0 call N times and
prints us per window_kernel call per stage (run with the smallest total of 7; TSC calibrated against
perf_counter). Not cached: compiles the copy (~1 min).
"""
import importlib.util
import os
import sys
import time

import numpy as np

SRC = os.path.join(os.environ.get("PYTHONPATH", "."), "monitor/certify/kernels.py")
src = open(SRC).read()

TICK = '''
from numba.extending import intrinsic as _intrinsic
from numba.core import types as _types, cgutils as _cgutils
from llvmlite import ir as _ir


@_intrinsic
def _rdtsc(typingctx):
    def codegen(context, builder, signature, args):
        fnty = _ir.FunctionType(_ir.IntType(64), [])
        fn = _cgutils.get_or_insert_function(builder.module, fnty, "llvm.readcyclecounter")
        return builder.call(fn, [])
    return _types.uint64(), codegen


@njit
def _tick():
    return float(_rdtsc())
'''
P0 = 16      # first profile slot of info


def sub(old, new, count=1):
    global src
    n = src.count(old)
    assert n == count, (old, n)
    src = src.replace(old, new)


sub("from monitor.motion.kernel import", TICK + "\nfrom monitor.motion.kernel import")
# pair_window gets the info vector
sub("def pair_window(gp, mp, ga, gb, t0, t1, margin, epsilon, max_depth, max_tests, mode, rel_pad, abs_pad,\n"
    "                stack, res):",
    "def pair_window(gp, mp, ga, gb, t0, t1, margin, epsilon, max_depth, max_tests, mode, rel_pad, abs_pad,\n"
    "                stack, res, _pf):")
sub("    out = np.empty(OUT_SIZE)\n    w = np.empty(3)\n    pA = np.empty(3)\n    pB = np.empty(3)\n"
    "    RA = np.empty((3, 3))\n    RB = np.empty((3, 3))\n    stats = np.zeros(1)\n",
    "    _c = _tick()\n    out = np.empty(OUT_SIZE)\n    w = np.empty(3)\n    pA = np.empty(3)\n    pB = np.empty(3)\n"
    "    RA = np.empty((3, 3))\n    RB = np.empty((3, 3))\n    stats = np.zeros(1)\n")
sub("    while sp > 0:\n        if spent >= max_tests:",
    f"    _pf[{P0 + 6}] += _tick() - _c\n    while sp > 0:\n        if spent >= max_tests:")
sub("        bound = interval_bound(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad, pws, dref)\n",
    "        _c = _tick()\n"
    "        bound = interval_bound(gp, mp, ga, gb, a, b, pA, RA, pB, RB, levers, stats, rel_pad, pws, dref)\n"
    f"        _c2 = _tick()\n        _pf[{P0 + 7}] += _c2 - _c\n        _pf[{P0 + 11}] += 1.0\n")
sub("                lb = separated_beyond(gp, ga, RA, pA, gb, RB, pB, hi, target, rel_pad, abs_pad, VA, VB, W4,\n"
    "                                      IA, IB, lam, v, vn, X)\n",
    "                _c = _tick()\n"
    "                lb = separated_beyond(gp, ga, RA, pA, gb, RB, pB, hi, target, rel_pad, abs_pad, VA, VB, W4,\n"
    "                                      IA, IB, lam, v, vn, X)\n"
    f"                _pf[{P0 + 8}] += _tick() - _c\n                _pf[{P0 + 12}] += 1.0\n")
sub("                lb = separated_beyond(gp, ga, RA, pA, gb, RB, pB, target, floor, rel_pad, abs_pad, VA, VB, W4,\n"
    "                                      IA, IB, lam, v, vn, X)\n",
    "                _c = _tick()\n"
    "                lb = separated_beyond(gp, ga, RA, pA, gb, RB, pB, target, floor, rel_pad, abs_pad, VA, VB, W4,\n"
    "                                      IA, IB, lam, v, vn, X)\n"
    f"                _pf[{P0 + 8}] += _tick() - _c\n                _pf[{P0 + 12}] += 1.0\n")
sub("        if not no_witness:\n            lo, up = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)\n",
    "        if not no_witness:\n            _c = _tick()\n"
    "            lo, up = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)\n"
    f"            _pf[{P0 + 9}] += _tick() - _c\n            _pf[{P0 + 13}] += 1.0\n")
# window_kernel
sub("    t0, t1 = prm[WP_T0], prm[WP_T1]\n    margin, epsilon = prm[WP_MARGIN], prm[WP_EPS]\n",
    "    _w = _tick()\n    t0, t1 = prm[WP_T0], prm[WP_T1]\n    margin, epsilon = prm[WP_MARGIN], prm[WP_EPS]\n")
sub("        mag = 0.0\n", f"        _n = _tick()\n        info[{P0 + 0}] += _n - _w\n        _w = _n\n        mag = 0.0\n")
sub("        info[WI_PAD] = pad\n", f"        _n = _tick()\n        info[{P0 + 1}] += _n - _w\n        _w = _n\n"
    "        info[WI_PAD] = pad\n")
sub("        info[WI_BEST] = best\n", f"        _n = _tick()\n        info[{P0 + 2}] += _n - _w\n        _w = _n\n"
    "        info[WI_BEST] = best\n")
sub("    for s in range(k0, k1):\n        k = surv[s]\n        if code[k] != WK_OPEN:",
    f"    _n = _tick()\n    info[{P0 + 3}] += _n - _w\n    _w = _n\n"
    "    for s in range(k0, k1):\n        k = surv[s]\n        if code[k] != WK_OPEN:")
sub("        body_pose(mp, ba, t0, pA, RA)\n        body_pose(mp, bb, t0, pB, RB)\n"
    "        lo_d, up_d = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)\n",
    "        _w = _tick()\n        body_pose(mp, ba, t0, pA, RA)\n        body_pose(mp, bb, t0, pB, RB)\n"
    "        lo_d, up_d = posed_distance(gp, ga, RA, pA, gb, RB, pB, rel_pad, abs_pad, out, w)\n"
    f"        info[{P0 + 4}] += _tick() - _w\n")
sub("        v = pair_window(gp, mp, ga, gb, ta_s, tb_s, margin, epsilon, max_depth, max_tests, MODE_CERTIFY_ONLY,\n"
    "                        rel_pad, abs_pad, stack, row)\n",
    "        _w = _tick()\n"
    "        v = pair_window(gp, mp, ga, gb, ta_s, tb_s, margin, epsilon, max_depth, max_tests, MODE_CERTIFY_ONLY,\n"
    "                        rel_pad, abs_pad, stack, row, info)\n"
    f"        info[{P0 + 5}] += _tick() - _w\n")
sub("    if stage == 0:\n        return S\n    return k1 - k0\n",
    f"    info[{P0 + 14}] += _tick() - _w\n    if stage == 0:\n        return S\n    return k1 - k0\n")
# the Python callers of pair_window (not used here) need an extra argument
src = src.replace("cache=True", "cache=False")
src = src.replace("stack, new_result())", "stack, new_result(), np.zeros(64))")
open("/tmp/h12x_kprof.py", "w").write(src)
spec = importlib.util.spec_from_file_location("kprof", "/tmp/h12x_kprof.py")
KP = importlib.util.module_from_spec(spec)
spec.loader.exec_module(KP)

import monitor.certify.kernels as K  # noqa: E402
from monitor.bench.cases import make_cases  # noqa: E402
from monitor.certify.engine import certify  # noqa: E402
from numba import njit  # noqa: E402

rec = []
orig = K.window_kernel


class W:
    def __getattr__(self, a):
        return getattr(orig, a)

    def __call__(self, *a):
        if a[6] == 0:
            rec.append([x.copy() if isinstance(x, np.ndarray) else x for x in a])
        return orig(*a)


K.window_kernel = W()
wk = KP.window_kernel


@njit
def drive(n, gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info):
    for _ in range(n):
        wk(gp, mp, pairs, fixed, moving, route, stage, k0, k1, prm, code, gap, surv, res, sc, sr, info)


KP._tick()
t = time.perf_counter()
c0 = KP._tick()
time.sleep(0.2)
hz = (KP._tick() - c0) / (time.perf_counter() - t)
names = sys.argv[1:] or ["tra-box-box-clear", "tra-capsule-box-clear", "tra-box-box-near-1e-02",
                         "rot-hull-box-collide", "tra-box-box-graze-1e-03"]
cases = {c.name: c for c in make_cases(seed=7, quick=True)}
LAB = ["tree_bounds xT", "geom spheres", "pair loop", "s1 setup", "start pose", "pair_window",
       "pw setup", "interval_bound", "separated_beyond", "posed_distance", "pw rest", "tests", "sb calls",
       "pd calls", "s1 loop rest"]
print("us per window_kernel call; tests / calls are counts per call")
print(f"{'case':26s} " + " ".join(f"{x[:10]:>10s}" for x in LAB) + f" {'total':>8s}")
for nm in names:
    c = cases[nm]
    rec.clear()
    certify(c.scene(16), c.body_motion(), margin=0.0, epsilon=1e-3, method="toleranced")
    a = list(rec[0])
    best = None
    n = 300
    for rep in range(12):
        a[16] = np.zeros(64)
        t = time.perf_counter()
        drive(n, *a)
        tot = (time.perf_counter() - t) / n
        if rep and (best is None or tot < best[0]):
            best = (tot, a[16][16:32].copy() / n)
    tot, p = best
    us = p / hz * 1e6
    us[10] = us[5] - us[6] - us[7] - us[8] - us[9]
    for j in (11, 12, 13):
        us[j] = p[j]
    print(f"{nm:26s} " + " ".join(f"{x:10.2f}" for x in us[:15]) + f" {tot * 1e6:8.1f}", flush=True)
