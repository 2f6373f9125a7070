"""Per-window cost of signing: write_window with and without a key (same process, interleaved blocks)."""
import sys, time, types, hmac, os, statistics
sys.path.insert(0, "tests")
os.makedirs("/tmp/signlog", exist_ok=True)
import numpy as np, mujoco
from monitor.log import MonitorLog
from monitor.log.digest import Digest
from monitor.log.sign import Signer
from test_log_digest import XML
from monitor.certify.certificate import Certificate, PairResult
model = mujoco.MjModel.from_xml_string(XML)
pr = PairResult(("floor", "g"), ("world", "b"), "certified", "toleranced", 1, 0, (), 0.9, None)
N = 1000
INDEX = len(sys.argv) > 1
def block(key, path):
    log = MonitorLog(path, model=model, metadata={"pairs": "mujoco"}, foxglove=False, key=key, index=INDEX)
    ts = []
    for k in range(N):
        t0 = 0.01 * k
        plan = types.SimpleNamespace(times=np.array([t0, t0 + 0.01]), qpos=np.tile(model.qpos0, (2, 1)), model=model)
        cert = Certificate("certified", (t0, t0 + 0.01), 0.0, 1e-3, "auto", None, None, 0.9, (pr,), {})
        a = time.perf_counter(); log.write_window(t0, plan, cert); ts.append(time.perf_counter() - a)
    log.close()
    return statistics.median(ts), os.path.getsize(path)
res = {"plain": [], "signed": []}
size = {}
for rep in range(6):
    for name, key in (("plain", False), ("signed", b"k" * 32)) if rep % 2 == 0 else (("signed", b"k" * 32), ("plain", False)):
        med, sz = block(key, f"/tmp/signlog/bench-{name}.mcap")
        res[name].append(med); size[name] = sz
p, s = statistics.median(res["plain"]), statistics.median(res["signed"])
print(f"write_window median per window: plain {p*1e6:.1f} us, signed {s*1e6:.1f} us, extra {(s-p)*1e6:.1f} us "
      f"(ratio {s/p:.3f}); per-block medians plain {[round(x*1e6,1) for x in res['plain']]} signed {[round(x*1e6,1) for x in res['signed']]}")
print(f"journal bytes: plain {size['plain']}, signed {size['signed']}: +{(size['signed']-size['plain'])/N:.0f} B/window")
# components
d = Digest(); d.message("/monitor/certificate", 0, 0, 0, b"x" * 500); sg = Signer(b"k" * 32)
def t(f, n=20000):
    a = time.perf_counter()
    for _ in range(n): f()
    return (time.perf_counter() - a) / n * 1e6
print(f"hmac.digest of 32 B: {t(lambda: hmac.digest(b'k'*32, b'x'*32, 'sha256')):.2f} us; "
      f"Digest.checkpoint: {t(d.checkpoint):.2f} us; Signer.checkpoint (payload bytes): {t(lambda: sg.checkpoint(d, 1)):.2f} us")
