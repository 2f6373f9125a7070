import sys, json, io, contextlib
sys.path.insert(0, "tests")
from pathlib import Path
import test_log_sign as T
from monitor.cli import main
import mujoco, numpy as np
from monitor.gate import Gate
out = Path("/tmp/signlog/rt11"); out.mkdir(parents=True, exist_ok=True)
path = out / "bounce.mcap"
model = mujoco.MjModel.from_xml_string(T.BOUNCE); d = mujoco.MjData(model); d.qpos[0], d.qvel[0] = -0.25, 1.0
with Gate(model, log=path, frame_skip=50, allowed=None, on_violation="warn", log_options={"key": T.KEY}) as g:
    for _ in range(6): g.step(d, np.zeros(1))
(out / "k.key").write_bytes(T.KEY)
for name, f in (("A", T._episode_split), ("B", T._predictor_relabel)):
    f(path, model, out / f"{name}.mcap")
    for args in ([], ["--key-file", str(out / "k.key")]):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            code = main(["review", "--verify", *args, str(out / f"{name}.mcap")])
        sig = [l for l in buf.getvalue().splitlines() if "signature" in l]
        print(name, "key" if args else "no key", "exit", code); print("  " + "\n  ".join(sig))
