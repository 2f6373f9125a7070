import time, numpy as np, mujoco
from monitor.certify.extrusion_null import warm_small_lp; warm_small_lp()  # what monitor.warmup should do
import monitor.certify.extrusion as ex
from monitor._paths import models_dir
from monitor.certify.engine import certify
from monitor.motion.plan import Plan
from monitor.scene import Scene
from monitor.bench.extrusion_scenes import schedule
orig = ex.check_pairs
calls = []
def rec(pairs, window, margin=0.0, *a, **k):
    calls.append((list(pairs), window, margin)); return orig(pairs, window, margin, *a, **k)
for f in ("scene.xml", "scene_skewed.xml"):
    m = mujoco.MjModel.from_xml_path(str(models_dir() / "agv_trays" / f))
    scene = Scene.from_model(m, pairs="all")
    for name in ("straight", "weaving"):
        s = schedule(name); calls.clear()
        ex.check_pairs = rec
        certify(scene, Plan(s["times"], s["qpos"], model=m), method="auto")
        ex.check_pairs = orig
        print([len(c[0]) for c in calls]); pairs, w, mg = max(calls, key=lambda c: len(c[0]))
        out = {}
        for label, kw in (("old", dict(nary=False, offset=False)), ("new", dict(nary=True, offset=True))):
            ts = []
            for _ in range(3):
                t = time.perf_counter(); o = orig(pairs, w, mg, **kw); ts.append(time.perf_counter() - t)
            out[label] = (min(ts), o)
        agree = all(a.verdict == b.verdict for a, b in zip(out["old"][1], out["new"][1]))
        n = len(pairs)
        print(f"{f:17s} {name:8s} pairs {n:3d}: first pass old {out['old'][0]*1e3:7.1f} ms ({out['old'][0]/n*1e3:.2f} ms/pair), new {out['new'][0]*1e3:7.1f} ms ({out['new'][0]/n*1e3:.2f} ms/pair), ratio new/old {out['new'][0]/out['old'][0]:.2f}, verdicts agree {agree}")
