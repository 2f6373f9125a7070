"""Red team 19, part 1b: stale entry points. Each scenario runs twice in this process: with
``engine._window_kernel`` as merged (identity + fingerprint shortcut) and with every call through
numba's dispatcher (``KS.window_kernel(...)``, the oracle); whole certificates (``to_dict()`` minus the
wall time) and end states are compared.

Usage: PYTHONPATH=<tree> python docs/notes/redteam-19/stale.py [STEPS] [--overload]

Scenarios (tunnel plain gate as the driver, ``margin=0.001``):
  interleave: a ``monitor.certify`` on another scene (and another model) between every two gate steps;
  two-gates: two gates on two models (tunnel, hand30) stepped alternately;
  edit: the tunnel model edited in place mid-run (a geom size, a body offset, the joint range);
  rebuild: a new Gate on the same model mid-run;
  --overload: a new overload of window_kernel compiled mid-run (a read-only field: ~1 min compile).
"""
import sys

import mujoco
import numpy as np

import monitor
from monitor._paths import scene_path
from monitor.bench.targets import _scene_file
from monitor.certify import engine
from monitor.gate import Gate

STEPS = int(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1].isdigit() else 40
_REAL = engine._window_kernel


HITS = [0, 0]


def counted(KS, gp, mp, pairs, fixed, moving, *rest):
    """The merged function, counting calls that met a recorded slot with a NEW pack (fingerprint route)."""
    d = engine._WK_DIRECT[0 if rest[-2] is None else 1]
    HITS[0] += 1
    HITS[1] += (d is not None and d[0] is KS.window_kernel and d[3] is gp and d[5] is pairs and d[6] is fixed
                and d[7] is moving and d[4] is not mp and type(mp) is d[8]
                and engine._pack_fingerprint(mp) == d[9] and len(KS.window_kernel.overloads) == d[1])
    return _REAL(KS, gp, mp, pairs, fixed, moving, *rest)


def dispatcher_only(KS, gp, mp, pairs, fixed, moving, *rest):
    return KS.window_kernel(gp, mp, pairs, fixed, moving, *rest)


def key(c):
    d = c.to_dict()
    d["stats"].pop("wall_seconds", None)
    return repr(d)


_XML = """<mujoco><worldbody><geom name="wall" type="box" size="0.05 1 1" pos="0.6 0 0"/>
  <body name="a"><joint name="x" type="slide" axis="1 0 0"/><joint name="r" type="hinge" axis="0 0 1"/>
  <geom name="ga" type="box" size="0.1 0.05 0.05"/></body></worldbody></mujoco>"""


def tunnel():
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    return m, d


def ctrl(k, d):
    return np.clip([12.0 * ((0.3 if (k // 15) % 2 == 0 else -0.3) - d.qpos[0])], -6, 6)


def scenario(name, out, overload=False):
    m, d = tunnel()
    gate = Gate(m, margin=0.001)
    m2 = mujoco.MjModel.from_xml_string(_XML)
    sc2 = monitor.Scene.from_model(m2, pairs="all")
    rng = np.random.default_rng(5)
    if name == "two-gates":
        mh = mujoco.MjModel.from_xml_path(str(_scene_file("hand30")))
        dh = mujoco.MjData(mh)
        gh = Gate(mh)
        tg = rng.uniform(mh.actuator_ctrlrange[:, 0], mh.actuator_ctrlrange[:, 1], (8, mh.nu))
    for k in range(STEPS):
        r = gate.step(d, ctrl(k, d), nstep=1)
        out.append(key(r.certificate))
        if name == "interleave":
            q = np.zeros((3, m2.nq))
            q[:, 0] = np.sort(rng.uniform(-0.2, 0.6, 3))
            q[:, 1] = rng.uniform(-0.5, 0.5, 3)
            out.append(key(monitor.certify(sc2, monitor.Plan([0.0, 0.05, 0.1], q, m2), margin=0.01)))
        elif name == "two-gates" and k % 4 == 0:
            out.append(key(gh.step(dh, tg[(k // 4) % 8], nstep=5).certificate))
        elif name == "edit" and k == STEPS // 3:
            m.geom_size[:] *= 1.3
            m.body_pos[1:] += 0.01
        elif name == "edit" and k == 2 * STEPS // 3:
            m.geom_size[:] /= 1.3
            m.jnt_range[:] *= 0.5
        elif name == "rebuild" and k == STEPS // 2:
            gate = Gate(m, margin=0.001)
        elif overload and k == STEPS // 2:
            KS = engine._kernels()
            n0 = len(KS.window_kernel.overloads)
            spy_once[0] = True
            out.append(f"overloads {n0}")
    out.append(d.qpos.tobytes().hex() + d.qvel.tobytes().hex())


spy_once = [False]


def readonly_spy(KS, gp, mp, pairs, fixed, moving, *rest):
    """Once: pass a pack with one read-only field through the dispatcher (compiles a new overload)."""
    if spy_once[0]:
        spy_once[0] = False
        f = mp.times.copy()
        f.flags.writeable = False
        mp = type(mp)(f, *mp[1:])
        return KS.window_kernel(gp, mp, pairs, fixed, moving, *rest)
    return counted(KS, gp, mp, pairs, fixed, moving, *rest)


overload = "--overload" in sys.argv
names = ["interleave", "two-gates", "edit", "rebuild"] + (["overload"] if overload else [])
bad = 0
for name in names:
    res = []
    HITS[:] = [0, 0]
    for impl in (readonly_spy if name == "overload" else counted, dispatcher_only):
        engine._window_kernel = impl
        out = []
        try:
            scenario(name, out, overload=(name == "overload" and impl is readonly_spy))
        except Exception as exc:  # noqa: BLE001
            out.append(f"RAISE {type(exc).__name__}: {exc}")
        res.append([x for x in out if not x.startswith("overloads")])
        print("  ", name, impl.__name__, [x for x in out if x.startswith("overloads")],
              "overloads after:", len(engine._kernels().window_kernel.overloads))
    engine._window_kernel = _REAL
    same = res[0] == res[1]
    bad += not same
    n_cert = sum(1 for x in res[0] if x.startswith("{"))
    print(f"{name}: {n_cert} certificates, {HITS[0]} window_kernel calls, {HITS[1]} by fingerprint,"
          f" shortcut == dispatcher: {same}")
    if not same:
        for i, (a, b) in enumerate(zip(res[0], res[1])):
            if a != b:
                print("   first difference at", i, a[:200], "|", b[:200])
                break
if overload:
    KS = engine._kernels()
    print("window_kernel overloads now:", len(KS.window_kernel.overloads))
print("scenarios differing:", bad)
