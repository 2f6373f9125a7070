p = "/work/wt/certpy/monitor/certify/engine.py"
s = open(p).read()


def ins_before(anchor, tag):
    global s
    assert s.count(anchor) == 1, anchor
    i = s.index(anchor)
    ind = len(anchor) - len(anchor.lstrip(" "))
    s = s[:i] + " " * ind + f"_MK.append(({tag!r}, time.perf_counter()))\n" + s[i:]


s = s.replace("_KS: list = []", "_KS: list = []\n_MK: list = []", 1)
s = s.replace(
    "    wall0 = time.perf_counter()\n", '    wall0 = time.perf_counter()\n    _MK.append(("c0", wall0))\n', 1
)
ins_before("    lim = req.budget\n", "req")
ins_before(
    '    sync = getattr(scene, "sync", None)\n    if sync is not None:\n        sync()      # every', "budget"
)
ins_before(
    '    allowed = getattr(scene, "allowed_pairs", ())\n    if type(allowed) is not tuple:\n        allowed = tuple(allowed)\n    hit =',
    "sync",
)
ins_before("    hit = _call_memo(scene, plan, req)\n", "allowed")
ins_before(
    "    # the compiled path builds no PairResult objects (cert.pairs is built on first read)\n    stage =",
    "memo",
)
ins_before(
    "    with active_budget(stage):\n        if fast is not None and not stage.exhausted:\n            cert = _certify_fast(",
    "stage",
)
ins_before("    P = len(sel)\n    pid, moving, fixed, mov, prm, narrow = prep\n", "enter_fast")
ins_before(
    "    S = int(_window_kernel(KS, sp.geoms, mp, pid, fixed, mov, none, 0, 0, first, prm, code, gap, surv, res,",
    "arrays",
)
ins_before("    done_to = min(first, S)\n", "kernel")
ins_before("    if S == 0:   # every selected pair culled", "charge")
ins_before("    P = len(sel)\n    rows = res[:S].tolist()\n    mix: dict[str, int] = {}\n", "kd_head")
ins_before('    if n_static:\n        mix["static"] = n_static\n    if S - n_static:', "kd_loop")
ins_before("    witness = earliest = None\n    if best_v is not None:", "kd_lazy")
ins_before(
    "    verdict = Verdict.VIOLATION if best_v is not None else Verdict.CERTIFIED\n    return _window_certificate",
    "kd_witness",
)
ins_before('    stats = {"pairs": P, "pairs_culled": P - S, "tests": tests, "max_depth": depth,', "wc_clear")
ins_before(
    "    return Certificate._trusted(verdict, (t0, t1), margin, epsilon, _METHOD_OF[method], witness, earliest,\n                                clearance, lazy, stats, allowed)",
    "wc_stats",
)
ins_before("    # issue 13: contacts present at t0", "ret_with")
ins_before('    cert.__dict__["request"] = req  # not a compared field', "deepen")
open(p, "w").write(s)
