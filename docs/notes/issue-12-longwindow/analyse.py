"""Replay recorded windows (record.py): tests per pair, sub-intervals per segment, cull shares, times.

Usage: PYTHONPATH=$PWD python docs/notes/issue-12-longwindow/analyse.py REC.pkl [trace]

Times: stage 0 only (broad phase) vs the full kernel call, median of 5 per window.
``trace``: every survivor is stepped one test at a time (max_tests=1) and the tested
sub-intervals are read off the stack (as tests/test_adaptive.py does).
"""
import collections
import pickle
import sys
import time

import numpy as np

from monitor.certify import kernels as K

calls = pickle.load(open(sys.argv[1], "rb"))
trace = len(sys.argv) > 2 and sys.argv[2] == "trace"
dump = sys.argv[3] if len(sys.argv) > 3 and sys.argv[2] == "dump" else None


def run(c, stage1=True):
    P = c["pairs"].shape[0]
    G = c["gp"].kind.shape[0]
    code = np.empty(P, np.int64)
    gap = np.empty(P)
    surv = np.empty(P, np.int64)
    res = np.empty((P, K.R_SIZE))
    sc = np.empty((c["T"], G, 3))
    sr = np.empty((c["T"], G))
    info = np.zeros(K.WI_SIZE)
    S = K.window_kernel(c["gp"], c["mp"], c["pairs"], c["fixed"], c["moving"], np.zeros(0, np.int64), 0, 0,
                        P if stage1 else 0, c["prm"], code, gap, surv, res, sc, sr, info)
    return S, code, surv, res, info


def steps(c, ga, gb):
    """Tested sub-intervals (a, b) of the whole-shape search of one pair, in order, and the verdict."""
    prm = c["prm"]
    t0, t1 = prm[K.WP_T0], prm[K.WP_T1]
    md = int(prm[K.WP_MAX_DEPTH])
    stack = np.empty((md + 2, 3))
    res = K.new_result()
    res[K.R_STARTED] = 2.0
    out = [(t0, t1, True)]      # the first test: the whole window (the sweep's first step is W)
    for _ in range(5000):
        sp = int(res[K.R_SP])
        if res[K.R_STARTED] == 1.0 and sp > 0:
            a, b, d = (float(x) for x in stack[sp - 1])
            if d < 0.0:
                b = b if not a - d < b + 0.05 * d else a - d
            out.append((a, b, d < 0.0))
        v = K.pair_window(c["gp"], c["mp"], ga, gb, t0, t1, prm[K.WP_MARGIN], prm[K.WP_EPS], md, 1,
                          K.MODE_CERTIFY_ONLY, prm[K.WP_REL], prm[K.WP_ABS], stack, res)
        if v != K.PAUSED:
            return out, v, int(res[K.R_TESTS])
    raise RuntimeError


t_s0, t_all, tests_w, surv_n, P_n, codes = [], [], [], [], [], collections.Counter()
for c in calls:
    run(c)
    a = []
    b = []
    for _ in range(5):
        t = time.perf_counter()
        run(c, False)
        a.append(time.perf_counter() - t)
        t = time.perf_counter()
        S, code, surv, res, info = run(c)
        b.append(time.perf_counter() - t)
    t_s0.append(np.median(a))
    t_all.append(np.median(b))
    tests_w.append(info[K.WI_TESTS])
    surv_n.append(S)
    P_n.append(len(code))
    codes.update(code.tolist())
if dump:   # verdict codes and result rows of every window (compare two trees bit for bit)
    rows = [run(c) for c in calls]
    np.savez(dump, **{f"code{i}": r[1] for i, r in enumerate(rows)},
             **{f"res{i}": r[3][:r[0]] for i, r in enumerate(rows)})
names = {v: k for k, v in vars(K).items() if k.startswith("WK_") and isinstance(v, int)}
print(f"windows {len(calls)}  pairs/window {np.median(P_n):.0f}  survivors/window median {np.median(surv_n):.0f}"
      f" mean {np.mean(surv_n):.1f}")
print("pair outcomes:", {names[k]: v for k, v in sorted(codes.items())})
print(f"kernel ms/window median {1e3 * np.median(t_all):.3f} mean {1e3 * np.mean(t_all):.3f};"
      f" stage 0 median {1e3 * np.median(t_s0):.3f} mean {1e3 * np.mean(t_s0):.3f}")
print(f"tests/window median {np.median(tests_w):.0f} mean {np.mean(tests_w):.1f};"
      f" us/test (stage1 time / tests) {1e6 * (np.sum(t_all) - np.sum(t_s0)) / max(1, np.sum(tests_w)):.2f}")
c0 = calls[0]
times = c0["mp"].times
print(f"first window: span {c0['prm'][0]:.4f}..{c0['prm'][1]:.4f}, K={len(times)} waypoints,"
      f" dt {np.median(np.diff(times)):.4g}")
if trace:
    per_pair, per_len, seg_span, verdicts, first_len = [], collections.Counter(), [], collections.Counter(), []
    excl_tail = collections.Counter()
    for c in calls:
        S, code, surv, res, info = run(c)
        times = c["mp"].times
        dt = float(np.median(np.diff(times)))
        for s in range(S):
            k = surv[s]
            if code[k] not in (K.WK_CERT, K.WK_VIOL, K.WK_UNRES):
                continue
            iv, v, nt = steps(c, int(c["pairs"][k, 0]), int(c["pairs"][k, 1]))
            verdicts[K._NAMES[int(v)]] += 1
            per_pair.append(nt)
            for (a, b, sw) in iv:
                nseg = int(np.searchsorted(times, b, "left") - np.searchsorted(times, a, "right")) + 1
                seg_span.append(nseg)
                per_len[min(int(round((b - a) / dt)), 200) if b - a >= dt else 0] += 1
    print("verdicts of stage-1 pairs:", dict(verdicts))
    print(f"tests per pair: median {np.median(per_pair):.0f} mean {np.mean(per_pair):.1f}"
          f" p90 {np.percentile(per_pair, 90):.0f} max {np.max(per_pair)} (n={len(per_pair)})")
    print(f"segments spanned per tested sub-interval: median {np.median(seg_span):.0f} mean {np.mean(seg_span):.1f};"
          f" share within one segment {np.mean(np.array(seg_span) == 1):.2f}")
    tot = sum(per_len.values())
    print("tested sub-interval length in substeps (0 = < 1 substep):",
          ", ".join(f"{k}:{v}" for k, v in sorted(per_len.items())[:25]), f"(n={tot})")
