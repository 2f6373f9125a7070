"""Record every engine.certify certificate (to_dict minus wall_seconds) of seeded gate runs and the golden calls.

PYTHONPATH=<tree> python dump_all.py out.txt [tunnel_steps]
"""
import hashlib
import os
import sys

import mujoco
import numpy as np

tree = os.environ["PYTHONPATH"].split(":")[0]
sys.path.insert(0, os.path.join(tree, "tests"))
import monitor  # noqa: E402
from monitor.certify import engine  # noqa: E402

assert monitor.__file__.startswith(tree), monitor.__file__
out = sys.argv[1]
N = int(sys.argv[2]) if len(sys.argv) > 2 else 600
lines = []
_orig = engine.certify


def rec(*a, **k):
    c = _orig(*a, **k)
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    lines.append(f"  {c.verdict} {d!r}")
    return c


engine.certify = rec
engine._OWN_CERTIFY = rec
from monitor.gate import Gate  # noqa: E402

for margin, amp, half, ongoing in ((0.001, 0.3, 100, None), (0.0, 0.35, 37, None), (0.002, 0.28, 50, "violation")):
    m = mujoco.MjModel.from_xml_path(os.path.join(tree, "models/tunnel/scene.xml"))
    kw = {} if ongoing is None else {"ongoing": ongoing}
    try:
        gate = Gate(m, margin=margin, **kw)
    except TypeError:
        gate = Gate(m, margin=margin)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    for k in range(N if ongoing is None else N // 3):
        target = amp if (k // half) % 2 == 0 else -amp
        ctrl = np.clip([12.0 * (target - d.qpos[0])], -6.0, 6.0)
        r = gate.step(d, ctrl, nstep=1 + (k % 3 == 2))
        lines.append(f"step {margin} {k} {r.verdict} {r.replaced}")
    lines.append("qpos " + d.qpos.tobytes().hex() + " qvel " + d.qvel.tobytes().hex())
    gate.close()
engine.certify = _orig
engine._OWN_CERTIFY = _orig
from _engine_entry_cases import _summary, box_calls, pusher_calls  # noqa: E402

for name, thunk in list(box_calls()) + list(pusher_calls()):
    for _ in range(2):
        lines.append(f"{name} {_summary(thunk())!r}")
text = "\n".join(lines) + "\n"
open(out, "w").write(text)
ncert = sum(1 for ln in lines if ln.startswith("  "))
print(hashlib.md5(text.encode()).hexdigest(), len(lines), "lines", ncert, "certificates")
