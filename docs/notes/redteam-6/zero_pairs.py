import mujoco, numpy as np, warnings, math
warnings.simplefilter("ignore")
from monitor.gate import Gate
import monitor.gate as G
BASE = """<mujoco><option timestep="0.01" gravity="0 0 0"/><worldbody>
<body name="a"><joint name="h" type="hinge" axis="0 0 1"/><geom name="ga" type="capsule" fromto="0 0 0 .2 0 0" size=".02" contype="0" conaffinity="0"/>
 <body name="b" pos=".2 0 0"><joint name="h2" type="slide" axis="1 0 0"/><geom name="gb" type="sphere" size=".02" contype="0" conaffinity="0"/></body></body>
<body name="wall" pos=".3 0 0"><geom name="wall" type="box" size=".01 .2 .2" contype="0" conaffinity="0"/></body>
%s</worldbody><actuator><motor joint="h"/></actuator></mujoco>"""
FREE = '<body name="f" pos="0 1 0"><freejoint/><geom type="sphere" size=".02" contype="0" conaffinity="0"/></body>'
MOC = '<body name="mc" mocap="true" pos="0 -1 0"><geom type="sphere" size=".02" contype="0" conaffinity="0"/></body>'
def key(c):
    dd = c.to_dict(); dd["stats"] = {k: v for k, v in dd["stats"].items() if k != "wall_seconds"}; return repr(dd)
def run(general, extra="", qpos=None, time=None, ctrl=0.0, gate_kw={}, steps=3, sub=None):
    m = mujoco.MjModel.from_xml_string(BASE % extra); d = mujoco.MjData(m)
    if qpos is not None: d.qpos[:len(qpos)] = qpos
    if time is not None: d.time = time
    cls = sub or Gate
    g = cls(m, **gate_kw)
    if general: own = g._certify; g._certify = lambda p: own(p)
    out = []
    for k in range(steps):
        try:
            r = g.step(d, np.array([ctrl]))
            out.append((str(r.verdict), key(r.certificate), str(r.brake_verdict)))
        except Exception as e:
            out.append((type(e).__name__, str(e)[:200])); break
    return out, g.stats.get("static_reused")
class Sub(Gate):
    def _certify(self, plan):
        c, us = super()._certify(plan); return c, us
cases = {
 "plain": {}, "nan_qpos": dict(qpos=[np.nan]), "inf_qpos": dict(qpos=[np.inf]), "huge_qpos": dict(qpos=[1e300, 1e300]),
 "overflow_sum": dict(qpos=[1.7e308, 1.7e308]), "nan_time": dict(time=np.nan), "huge_time": dict(time=1e300),
 "neg_zero": dict(qpos=[-0.0, -0.0]), "free": dict(extra=FREE), "mocap": dict(extra=MOC),
 "subclass": dict(sub=Sub), "explicit_empty_pairs": dict(gate_kw=dict(pairs=[])),
 "allowed_all": dict(gate_kw=dict(pairs="all", allow=["*"])), "hazards_none": dict(gate_kw=dict(pairs="all", hazards=["nothing:*"])),
 "brake_off": dict(gate_kw=dict(brake=False)), "ctrl_big": dict(ctrl=1e6), "reuse_off": dict(gate_kw=dict(reuse=False)),
 "frame_skip5": dict(gate_kw=dict(frame_skip=5)), "ongoing_violation": dict(gate_kw=dict(ongoing="violation")),
}
n_same = 0
for name, kw in cases.items():
    try:
        a, _ = run(False, **kw); b, _ = run(True, **kw)
    except Exception as e:
        print(name, "CONSTRUCT", type(e).__name__, str(e)[:100]); continue
    same = a == b; n_same += same
    print(f"{name:22s} same={same} {a[-1][0]} {a[-1][1][:90] if len(a[-1])>1 and a[-1][0] not in ('certified',) else ''}")
print(n_same, "/", len(cases))
