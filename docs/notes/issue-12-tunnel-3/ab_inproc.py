"""In-process A/B of this branch's tunnel shortcuts, interleaved rounds; certificates compared in full.

PYTHONPATH=<this tree> python docs/notes/issue-12-tunnel-3/ab_inproc.py [rounds] [steps] [switch...]
switch: "direct" (engine._EXTRUSION_DIRECT), "start" (ongoing._START_BOUND), "pose" (distance._check_pose:
old = the numpy checks alone, as on main); default all three. "old" = the switches off, "new" = on. Workload: the
bench's tunnel_gate (models/tunnel, Gate(margin=0.001), target +-0.3 m switching every 100 windows,
one 10 ms step per window). Every step's certificate (to_dict without wall_seconds, pairs
included) and the final state must be identical between the two; medians of per-round means.
"""
import hashlib
import math
import sys
import time

import mujoco
import numpy as np

from monitor.certify import engine, ongoing
from monitor.errors import InvalidInputError
from monitor.gate import Gate
from monitor.geometry import distance

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 4
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 600
switches = sys.argv[3:] or ["direct", "start", "pose"]
NEW_POSE = distance._check_pose


def old_check_pose(X, name):
    """main's _check_pose (numpy reductions only)."""
    R, p = X
    R = np.ascontiguousarray(R, dtype=np.float64)
    p = np.ascontiguousarray(p, dtype=np.float64)
    if R.shape != (3, 3) or p.shape != (3,):
        raise InvalidInputError(f"{name}: expected R (3, 3) and p (3,), got {R.shape} and {p.shape}")
    if not math.isfinite(R.sum() + p.sum()):
        raise InvalidInputError(f"{name}: pose is not finite")
    if max(p.max(), -p.min()) > distance._MAX_COORD or max(R.max(), -R.min()) > distance._MAX_ROT:
        raise InvalidInputError(f"{name}: out of bounds")
    return R, p

m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
gate = Gate(m, margin=0.001)
d = mujoco.MjData(m)


def use(on):
    if "direct" in switches:
        engine._EXTRUSION_DIRECT = on
    if "start" in switches:
        ongoing._START_BOUND = on
    if "pose" in switches:
        distance._check_pose = NEW_POSE if on else old_check_pose


def key(c):
    out = c.to_dict()
    out["stats"].pop("wall_seconds", None)
    return repr(out)


def run(n, record):
    mujoco.mj_resetDataKeyframe(m, d, 0)
    gate.reset()
    out = []
    tot = 0.0
    for k in range(n):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        t = time.perf_counter()
        r = gate.step(d, ctrl, nstep=1)
        tot += time.perf_counter() - t
        if record:
            out.append(key(r.certificate))
    return tot / n, out, d.qpos.tobytes()


res = {"old": [], "new": []}
ref = {}
for name, on in (("old", False), ("new", True)):
    use(on)
    _, out, q = run(steps, True)
    ref[name] = (out, q)
same = ref["old"] == ref["new"]
verd = [o.split("'verdict': ")[1][:12] for o in ref["new"][0]]
print(f"{steps} steps, certificates identical: {same}; new verdicts: "
      f"certified {sum('certified' in v for v in verd)}, violation {sum('violation' in v for v in verd)}; "
      f"final qpos md5 {hashlib.md5(ref['new'][1]).hexdigest()[:12]}")
if not same:
    bad = [k for k, (a, b) in enumerate(zip(*(ref[n][0] for n in ("old", "new")))) if a != b]
    print("differ at steps", bad[:10], "\nold", ref["old"][0][bad[0]], "\nnew", ref["new"][0][bad[0]])
for _ in range(rounds):
    for name, on in (("old", False), ("new", True)):
        use(on)
        res[name].append(run(steps, False)[0])
o, n = np.median(res["old"]) * 1e6, np.median(res["new"]) * 1e6
print(f"switches {switches}: old {o:.0f} us  new {n:.0f} us per step  old/new {o / n:.3f}  (per-round ratios "
      f"{[round(a / b, 3) for a, b in zip(res['old'], res['new'])]})")
