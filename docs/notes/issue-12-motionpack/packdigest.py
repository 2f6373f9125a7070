"""Digest of every motion pack built on gate windows and bench pair cases (for a byte A/B of two trees).

usage: PYTHONPATH=<tree> python packdigest.py OUT.txt [STEPS]
Wraps monitor.motion.pack.pack_trajectory and runs STEPS gated steps of tunnel, Pusher-v5 and
monitor/Arm-v0 (seeded), then packs every bench pair case of make_cases(7, quick=True): its
BodyMotion (lerp_slerp cases) and a 5-waypoint Plan of its model. One line per pack: the workload,
the call index and the sha256 of every field's dtype, shape and bytes, in field order.
`diff` two trees' outputs: equal lines <=> byte-equal packs.
"""
import hashlib
import sys
import warnings

import numpy as np

warnings.simplefilter("ignore")
import monitor.motion.pack as MP  # noqa: E402
from monitor.bench.cases import make_cases  # noqa: E402
from monitor.errors import MonitorError  # noqa: E402
from monitor.motion.plan import Plan  # noqa: E402
from monitor.warmup import ensure_warm  # noqa: E402

sys.path.insert(0, __file__.rsplit("/", 2)[0] + "/issue-12-gate-5")  # its runners.py
from runners import runner  # noqa: E402

out_path, steps = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 200
ensure_warm()
lines = []
where = ["?"]


def digest(mp):
    """sha256 over (dtype, shape, bytes) of every field, in field order."""
    h = hashlib.sha256()
    for name, a in zip(mp._fields, mp, strict=True):
        h.update(f"{name}|{a.dtype.str}|{a.shape}|".encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


_orig = MP.pack_trajectory


def wrapped(traj):
    """pack_trajectory, recording the pack's digest."""
    mp = _orig(traj)
    lines.append(f"{where[0]} {len(lines)} {type(traj).__name__} {digest(mp)}")
    return mp


MP.pack_trajectory = wrapped
for work in ("tunnel", "Pusher-v5", "monitor/Arm-v0"):
    where[0] = work
    runner(work)(steps)
where[0] = "bench"
for case in make_cases(7, quick=True):
    if case.interpolation == "lerp_slerp":
        wrapped(case.body_motion())
    t = np.linspace(0.0, case.duration, 5)
    try:
        wrapped(Plan(t, case.qpos(t), case.model))
    except MonitorError as exc:
        lines.append(f"bench {len(lines)} Plan error {type(exc).__name__}")
with open(out_path, "w") as f:
    f.write("\n".join(lines) + "\n")
print(f"{len(lines)} packs -> {out_path}")
