"""Red team 16: re-run one onecall_fuzz.py case and compare every pair's claimed clearance with the
dense-sampling oracle (tests/redteam_oracle.py). Usage: case_oracle.py SEED I[,J...]"""
import sys, mujoco
sys.path.insert(0, "/work/wt/rt16/docs/notes/redteam-16"); sys.path.insert(0, "/work/wt/rt16/tests")
import monitor, onecall_fuzz as F, redteam_oracle as O
seed, want = int(sys.argv[1]), [int(x) for x in sys.argv[2].split(",")]
captured = {}
real = monitor.certify
cnt = [-1]
import builtins
orig_print = builtins.print
def fake(scene, plan, **kw):
    return real(scene, plan, **kw)
# track index via print of the fuzzer: wrap Plan creation to note i
calls = []
def cap(scene, plan, **kw):
    calls.append((scene, plan, kw)); return real(scene, plan, **kw)
monitor.certify = cap
import io, contextlib
with contextlib.redirect_stdout(io.StringIO()) as buf, contextlib.redirect_stderr(io.StringIO()):
    F.main(max(want) + 1, seed)
lines = buf.getvalue().splitlines()
idx = [int(l.split()[0]) for l in lines if l.split()[1].startswith("{") or "error" in l.split()[1]]
# map: calls list corresponds to lines that have a certify call (plan-error lines have no call)
call_i = [int(l.split()[0]) for l in lines if not l.split()[1].startswith("plan-error")]
for i in want:
    scene, plan, kw = calls[call_i.index(i)]
    c = real(scene, plan, **kw)
    m = scene.model if hasattr(scene, "model") else plan.model
    print("case", i, kw, c.verdict.value, "cert clearance", c.clearance)
    w0, w1 = kw.get("window") or (plan.t0, plan.t1)
    orc = O.TrajectoryOracle(plan._model if hasattr(plan, "_model") else m, plan)
    for p in c.pairs:
        ga, gb = [mujoco.mj_name2id(orc.model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in p.geoms]
        r = O.motion_min(orc, ga, gb, w0, w1, n=400, refine=3)
        flag = "  <-- CLAIM ABOVE ORACLE" if p.verdict.value == "certified" and p.clearance > r.upper + 1e-9 else ""
        print(" ", p.geoms, p.verdict.value, p.method, "clearance", p.clearance, "oracle min upper", r.upper, "at", r.time, flag)
