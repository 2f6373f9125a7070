"""Every certify call of gated steps, in situ and re-run isolated right after (thread CPU time).

PYTHONPATH=<tree>:<tree>/docs/notes/issue-12-tail-design python calls.py WORK BLOCKS [--no-iso]

WORK as wl.py ("monitor/Arm-v0", "Pusher-v5", ...); BLOCKS blocks of wl.BLOCK steps (one
untimed warm-up block first). Per call: waypoints K, who called (joint / window / tail /
fallback), verdict, route (pack built or memo, fast path, kernel-decided / all culled /
_python_stages / extrusion / full search / deepen), gc collections during the call, thread
time in situ; then the same call re-run right after (a) on the same Plan object (the engine's
call memo and the motion-pack cache hit) and (b) on a fresh copy of the Plan (packs again).
Prints per-call JSON lines "CALL {...}" (with --dump) and a summary "SUMM {...}".
"""
import collections, gc, json, sys, time

import numpy as np

import monitor.certify.engine as E
import monitor.certify.kernels as KS
import monitor.gate as G
import wl

work, blocks = sys.argv[1], int(sys.argv[2])
iso = "--no-iso" not in sys.argv
dump = "--dump" in sys.argv
pc = time.thread_time
route = collections.Counter()
calls = []
gcn = [0]
gc.callbacks.append(lambda phase, info: gcn.__setitem__(0, gcn[0] + (phase == "start")))


def wrap(mod, name, tag):
    f = getattr(mod, name)

    def w(*a, **k):
        route[tag] += 1
        return f(*a, **k)
    setattr(mod, name, w)


for name, tag in (("_certify_fast", "fast"), ("_certify", "general"), ("_python_stages", "python_stages"),
                  ("_extrusion_decided", "extrusion_decided"), ("_full_search", "full_search"),
                  ("_kernel_decided", "kernel_decided"), ("_all_culled", "all_culled"),
                  ("deepen", "deepen")):
    wrap(E, name, tag)
_tpm = KS.trajectory_pack_memo


def tpm(traj):
    hit = KS._MOTION_PACKS.get(traj)
    route["pack_memo_hit" if hit is not None else "pack_built"] += 1
    t = pc()
    r = _tpm(traj)
    route["pack_us"] += (pc() - t) * 1e6
    return r


KS.trajectory_pack_memo = tpm

_cert = E.certify
caller_of = {"_certify_joint": "joint", "decide": None}


def who():
    f = sys._getframe(2)
    while f is not None:
        n = f.f_code.co_name
        if n == "_certify_joint":
            return "joint"
        if n == "decide":
            ln = f.f_lineno
            return ln
        f = f.f_back
    return "?"


def fresh(plan):
    from monitor.motion.plan import Plan
    return Plan._trusted(np.array(plan.times), np.array(plan._qpos), model=plan._model,
                         mocap_pos=np.array(plan._mocap_pos), mocap_quat=np.array(plan._mocap_quat))


rec = {"on": False}


def certify(scene, plan, **k):
    if not rec["on"]:
        return _cert(scene, plan, **k)
    route.clear()
    g0 = gcn[0]
    t = pc()
    c = _cert(scene, plan, **k)
    dt = pc() - t
    r = {"K": len(plan.times), "who": who(), "verdict": str(c.verdict), "ongoing_req": k["request"].ongoing,
         "npairs_req": None if k["request"].pairs is None else len(k["request"].pairs),
         "route": dict(route), "gc": gcn[0] - g0, "situ": dt * 1e6}
    if iso:
        p2 = fresh(plan)
        ts = []
        for p in (plan, p2, plan):
            t = pc(); _cert(scene, p, **k); ts.append((pc() - t) * 1e6)
        r["iso_same"] = min(ts[0], ts[2])
        r["iso_fresh"] = ts[1]
    calls.append(r)
    return c


E.certify = certify
E._OWN_CERTIFY = certify   # keep the gate's shortcuts on (Gate._certify_is_own)

from monitor.warmup import ensure_warm
ensure_warm()   # as the bench does: one-time loads out of the figures
W = wl.make(work)
n = wl.BLOCK[work]
for _ in W.steps(n, 1000):
    pass
gc.collect()
rec["on"] = True
steps = 0
t_all = pc()
step_marks = []
for rep in range(blocks):
    for _ in W.steps(n, rep):
        steps += 1
        step_marks.append(len(calls))
rec["on"] = False

# decide line numbers -> names
import inspect
src, first = inspect.getsourcelines(G.Gate.decide)
def name_of(ln):
    if not isinstance(ln, int):
        return ln
    line = src[ln - first]
    if "tail.plan" in line:
        return "tail"
    if "win.plan" in line:
        return "fallback"
    if "applied_plan" in line:
        return "fallback_other"
    if "_plan_of(plan)" in line:
        return "window"
    return line.strip()[:40]
for r in calls:
    r["who"] = name_of(r["who"])
    if dump:
        print("CALL " + json.dumps(r))
by = collections.defaultdict(list)
for r in calls:
    key = (r["who"], r["K"], r["verdict"])
    by[key].append(r)
summ = {"work": work, "steps": steps, "calls": len(calls), "groups": []}
for key, rs in sorted(by.items(), key=lambda kv: -sum(x["situ"] for x in kv[1])):
    routes = collections.Counter()
    for x in rs:
        for k2, v in x["route"].items():
            if k2 != "pack_us":
                routes[k2] += v
    g = {"who": key[0], "K": key[1], "verdict": key[2], "n": len(rs), "per_step": len(rs) / steps,
         "situ_med": float(np.median([x["situ"] for x in rs])),
         "situ_us_per_step": sum(x["situ"] for x in rs) / steps,
         "pack_us_med": float(np.median([x["route"].get("pack_us", 0) for x in rs])),
         "routes": dict(routes), "gc": sum(x["gc"] for x in rs)}
    if iso:
        g["iso_same_med"] = float(np.median([x["iso_same"] for x in rs]))
        g["iso_fresh_med"] = float(np.median([x["iso_fresh"] for x in rs]))
        g["situ_over_fresh_med"] = float(np.median([x["situ"] / x["iso_fresh"] for x in rs]))
    summ["groups"].append(g)
summ["certify_us_per_step"] = sum(x["situ"] for x in calls) / steps
print("SUMM " + json.dumps(summ, indent=1))
