"""Red team 19, part 1: does equal ``engine._pack_fingerprint`` imply equal ``numba.typeof`` of the pack?

Usage: PYTHONPATH=<tree> python docs/notes/redteam-19/fp_oracle.py [STEPS]

1. Capture the real ``_window_kernel`` calls (gp, mp, pairs, fixed, moving, rest) of: tunnel and
   hand30 plain gates, Arm-v0 / Pusher-v5 SafetyGates, seeded Plans on a small scene, a BodyMotion,
   a 1-waypoint plan and a static (all waypoints equal) plan.
2. Oracle A (all real packs, pairwise): equal fingerprint => equal numba.typeof.
3. Oracle B (each real pack x each field x each mutation): equal fingerprint => equal typeof; and
   when both are equal and the mutation keeps the values, the recorded entry point and the
   dispatcher give the same outputs (return value + every output array, bytes).
Prints counts and every mismatch.
"""
import collections
import copy
import sys
import tempfile
import warnings

import mujoco
import numba
import numpy as np

import monitor
from monitor.certify import engine

STEPS = int(sys.argv[1]) if len(sys.argv) > 1 else 20
captured = collections.defaultdict(list)
_real = engine._window_kernel
_tag = ["?"]


def spy(KS, gp, mp, pairs, fixed, moving, *rest):
    if len(captured[_tag[0]]) < 6:
        captured[_tag[0]].append((KS, gp, mp, pairs, fixed, moving, copy.deepcopy(rest)))
    return _real(KS, gp, mp, pairs, fixed, moving, *rest)


engine._window_kernel = spy


def run_tunnel():
    from monitor._paths import scene_path
    from monitor.gate import Gate
    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    gate, d = Gate(m, margin=0.001), mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    for k in range(STEPS):
        gate.step(d, np.clip([12.0 * ((0.3 if (k // 15) % 2 == 0 else -0.3) - d.qpos[0])], -6, 6), nstep=1)


def run_hand30():
    from monitor.bench.targets import _scene_file
    from monitor.gate import Gate
    m = mujoco.MjModel.from_xml_path(str(_scene_file("hand30")))
    gate, d = Gate(m), mujoco.MjData(m)
    tg = np.random.default_rng(0).uniform(m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1], (8, m.nu))
    for k in range(max(STEPS // 4, 2)):
        gate.step(d, tg[k % 8], nstep=5)


def run_gym(env_id):
    import gymnasium as gym

    import monitor.envs  # noqa: F401
    env = monitor.SafetyGate(gym.make(env_id), pairs="mujoco")
    env.reset(seed=5)
    env.action_space.seed(3)
    for _ in range(STEPS):
        env.step(env.action_space.sample())
    env.close()


_XML = """<mujoco><worldbody>
  <geom name="wall" type="box" size="0.05 1 1" pos="0.6 0 0"/>
  <body name="a" pos="0 0 0"><joint name="x" type="slide" axis="1 0 0"/>
    <joint name="r" type="hinge" axis="0 0 1"/><geom name="ga" type="box" size="0.1 0.05 0.05"/></body>
  <body name="b" pos="0 0.5 0"><joint name="y" type="slide" axis="1 0 0"/>
    <geom name="gb" type="capsule" size="0.05 0.1"/></body>
  <body name="f" pos="0 -0.5 0"><freejoint/><geom name="gf" type="sphere" size="0.05"/></body>
</worldbody></mujoco>"""


def small_scene():
    m = mujoco.MjModel.from_xml_string(_XML)
    return m, monitor.Scene.from_model(m, pairs="all")


def run_plans():
    m, scene = small_scene()
    rng = np.random.default_rng(19)
    for _ in range(6):
        q = np.tile(m.qpos0, (3, 1))
        q[:, 0] = np.sort(rng.uniform(-0.2, 0.6, 3))
        q[:, 2] = rng.uniform(-0.3, 0.6, 3)
        monitor.certify(scene, monitor.Plan([0.0, 0.05, 0.1], q, m), margin=0.01)


def run_one_waypoint():
    m, scene = small_scene()
    monitor.certify(scene, monitor.Plan([0.0], m.qpos0[None, :], m), margin=0.01)


def run_static():
    m, scene = small_scene()
    monitor.certify(scene, monitor.Plan([0.0, 0.1], np.tile(m.qpos0, (2, 1)), m), margin=0.01)


def run_bodymotion():
    m, scene = small_scene()
    pos = np.zeros((3, m.nbody, 3))
    quat = np.zeros((3, m.nbody, 4))
    quat[..., 0] = 1.0
    pos[:, 2, 1] = 0.5
    pos[:, 3, 1] = -0.5
    pos[:, 1, 0] = [0.0, 0.2, 0.45]
    monitor.certify(scene, monitor.BodyMotion([0.0, 0.05, 0.1], pos, quat), margin=0.01)


WORKLOADS = {"tunnel": run_tunnel, "hand30": run_hand30, "Arm-v0": lambda: run_gym("monitor/Arm-v0"),
             "Pusher-v5": lambda: run_gym("Pusher-v5"), "plans": run_plans, "one-waypoint": run_one_waypoint,
             "static": run_static, "bodymotion": run_bodymotion}
for name, fn in WORKLOADS.items():
    _tag[0] = name
    try:
        fn()
    except Exception as exc:  # noqa: BLE001
        print("workload", name, "failed:", type(exc).__name__, exc)
engine._window_kernel = _real
print("captured calls:", {k: len(v) for k, v in captured.items()})

fpf = engine._pack_fingerprint


def ty(x):
    try:
        return numba.typeof(x)
    except Exception as exc:  # noqa: BLE001
        return f"RAISE {type(exc).__name__}"


# Oracle A: every pair of real packs
packs = [(k, c[2]) for k, v in captured.items() for c in v]
n_pairs = n_eq = bad_a = 0
for i in range(len(packs)):
    for j in range(i, len(packs)):
        a, b = packs[i][1], packs[j][1]
        n_pairs += 1
        if type(a) is type(b) and fpf(a) is not None and fpf(a) == fpf(b):
            n_eq += 1
            if ty(a) != ty(b):
                bad_a += 1
                print("A MISMATCH", packs[i][0], packs[j][0])
print(f"A: {n_pairs} pairs of real packs, {n_eq} with equal fingerprints, {bad_a} typeof mismatches")
print("   real pack types:", len({str(ty(p)) for _, p in packs}), "distinct;",
      "namedtuple fingerprint of the pack itself:", end=" ")
try:
    numba._dispatcher.compute_fingerprint(packs[0][1])
    print("encodable (the dispatcher uses its fingerprint cache for the pack)")
except Exception as exc:  # noqa: BLE001
    print(f"raises {type(exc).__name__} (the dispatcher types the pack with typeof every call)")


class Sub(np.ndarray):
    pass


def unaligned(a):
    buf = bytearray(a.nbytes + 1)
    u = np.frombuffer(buf, dtype=a.dtype, count=a.size, offset=1).reshape(a.shape)
    u[...] = a
    return u


def memmap(a):
    if a.size == 0:
        return a.copy()
    mm = np.memmap(tempfile.mktemp(dir="/tmp/rt19"), dtype=a.dtype, mode="w+", shape=a.shape)
    mm[...] = a
    return mm


def ro(a):
    b = a.copy()
    b.flags.writeable = False
    return b


def noncontig(a):
    b = np.repeat(a, 2, axis=-1) if a.ndim else a.copy()
    return b[..., ::2] if a.ndim else b


def nan(a):
    b = a.copy()
    if b.size and b.dtype.kind == "f":
        b.flat[0] = np.nan
    return b


# (name, function, keeps values: run both paths)
MUTATIONS = [
    ("writable copy", lambda a: a.copy(), True),
    ("read-only copy", ro, False),
    ("F-order", lambda a: np.asfortranarray(a), True),
    ("non-contiguous", noncontig, True),
    ("int32", lambda a: a.astype(np.int32), False),
    ("float32", lambda a: a.astype(np.float32), False),
    ("float64", lambda a: a.astype(np.float64), False),
    ("int64", lambda a: a.astype(np.int64), False),
    ("bool", lambda a: a.astype(bool), False),
    ("object", lambda a: a.astype(object), False),
    ("0-d", lambda a: np.array(a.flat[0] if a.size else 0, a.dtype), False),
    ("numpy scalar", lambda a: a.dtype.type(a.flat[0] if a.size else 0), False),
    ("python scalar", lambda a: (a.flat[0] if a.size else a.dtype.type(0)).item(), False),
    ("unaligned", unaligned, True),
    ("subclass", lambda a: a.view(Sub), True),
    ("memmap", memmap, True),
    ("large", lambda a: np.zeros((100000,) + a.shape[1:], a.dtype) if a.ndim else a.copy(), False),
    ("empty", lambda a: np.zeros((0,) + a.shape[1:], a.dtype) if a.ndim else a.copy(), False),
    ("NaN", nan, True),
    ("big-endian", lambda a: a.astype(a.dtype.newbyteorder(">")), True),
    ("masked", lambda a: np.ma.masked_array(a.copy()), True),
    ("ndim+1", lambda a: a[None], False),
]

stats = collections.Counter()
findings = collections.Counter()
examples = {}
for name, calls in captured.items():
    for (KS, gp, mp, pairs, fixed, moving, rest) in calls[:2]:
        wk = KS.window_kernel
        slot = 0 if rest[-2] is None else 1
        ep = engine._entry_points_by_rows(wk.overloads)[slot]
        base_fp, base_ty = fpf(mp), ty(mp)
        for i, field in enumerate(mp._fields):
            a = mp[i]
            for mname, fn, keeps in MUTATIONS:
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        v = fn(a)
                except Exception:  # noqa: BLE001
                    stats["mutation not applicable"] += 1
                    continue
                mut = type(mp)(*(v if k == i else x for k, x in enumerate(mp)))
                stats["mutants"] += 1
                f = fpf(mut)
                if f is None or f != base_fp:
                    stats["fingerprint differs (dispatcher)"] += 1
                    continue
                stats["fingerprint equal (shortcut)"] += 1
                if ty(mut) != base_ty:
                    findings[mname] += 1
                    examples.setdefault(mname, (name, field, str(ty(mut))[:80]))
                    continue
                if not keeps:
                    continue
                outs = []
                for call in (ep, wk):
                    r = copy.deepcopy(rest)
                    try:
                        ret = call(gp, mut, pairs, fixed, moving, *r)
                        outs.append((repr(ret), [x.tobytes() for x in r if isinstance(x, np.ndarray)]))
                    except Exception as exc:  # noqa: BLE001
                        outs.append(f"RAISE {type(exc).__name__}")
                stats["ran both paths"] += 1
                if outs[0] != outs[1]:
                    findings[mname + " (outputs differ)"] += 1
                    examples.setdefault(mname + " (outputs differ)", (name, field, ""))
print("B:", dict(stats))
print("B findings (fingerprint equal, typeof differs / outputs differ):", dict(findings))
for k, v in examples.items():
    print("   e.g.", k, v)

# C. The builders: Plans / BodyMotions built from odd inputs (non-native byte order, masked, array
# subclass, F-order, read-only, float32, int, unaligned) -- does any field of their pack carry one of the
# two fingerprint collisions above (non-native byte order, a masked or other ndarray subclass)?
from monitor.certify import kernels as KS_  # noqa: E402

m, scene = small_scene()
rng = np.random.default_rng(7)
q = np.tile(m.qpos0, (3, 1))
q[:, 0] = [0.0, 0.2, 0.45]
pos = np.zeros((3, m.nbody, 3))
quat = np.zeros((3, m.nbody, 4))
quat[..., 0] = 1.0
pos[:, 1, 0] = [0.0, 0.2, 0.45]
ODD = {"big-endian": lambda a: a.astype(a.dtype.newbyteorder(">")), "masked": lambda a: np.ma.masked_array(a),
       "subclass": lambda a: a.view(Sub), "F-order": np.asfortranarray, "read-only": ro,
       "float32": lambda a: a.astype(np.float32), "unaligned": unaligned, "memmap": memmap}
n_built = n_bad = 0
ref_plan_fp = fpf(KS_.trajectory_pack(monitor.Plan([0.0, 0.05, 0.1], q, m)))
ref_bm_fp = fpf(KS_.trajectory_pack(monitor.BodyMotion([0.0, 0.05, 0.1], pos, quat)))
for oname, fn in ODD.items():
    for kind in ("Plan times", "Plan qpos", "BodyMotion pos", "BodyMotion quat", "BodyMotion times"):
        try:
            t = fn(np.array([0.0, 0.05, 0.1]))
            if kind.startswith("Plan"):
                traj = monitor.Plan(t if kind == "Plan times" else [0.0, 0.05, 0.1],
                                    fn(q) if kind == "Plan qpos" else q, m)
                ref = ref_plan_fp
            else:
                traj = monitor.BodyMotion(t if kind == "BodyMotion times" else [0.0, 0.05, 0.1],
                                          fn(pos) if kind == "BodyMotion pos" else pos,
                                          fn(quat) if kind == "BodyMotion quat" else quat)
                ref = ref_bm_fp
            mp = KS_.trajectory_pack(traj)
        except Exception as exc:  # noqa: BLE001
            print(f"C: {kind} {oname}: refused ({type(exc).__name__})")
            continue
        n_built += 1
        odd = [f for f, a in zip(mp._fields, mp) if type(a) is not np.ndarray or not a.dtype.isnative]
        if odd or fpf(mp) != ref or ty(mp) != ty(packs[0][1]):
            n_bad += 1
            print(f"C: {kind} {oname}: odd fields {odd}, fingerprint equal {fpf(mp) == ref}")
print(f"C: {n_built} packs built from odd inputs, {n_bad} with a field that is not a native plain ndarray"
      " or another type")

# D. End to end: a mutated pack (values and numba type kept: unaligned / subclass / memmap / NaN /
# writable copy) injected as a new Plan's cached pack; certify with the shortcut and with the
# dispatcher for every pack (engine._FINGERPRINT = [None]); whole certificates compared.
m, scene = small_scene()
plans = []
for _ in range(4):
    q = np.tile(m.qpos0, (3, 1))
    q[:, 0] = np.sort(rng.uniform(-0.2, 0.6, 3))
    q[:, 2] = rng.uniform(-0.3, 0.6, 3)
    plans.append(q)
fp0 = engine._FINGERPRINT[0]
n_cert = n_diff = n_hit = 0
for mname, fn, keeps in MUTATIONS:
    if not keeps or mname in ("big-endian", "masked", "F-order", "non-contiguous"):
        continue
    for q in plans:
        base = monitor.Plan([0.0, 0.05, 0.1], q, m)
        monitor.certify(scene, base, margin=0.01)          # records the slot with this plan's pack
        mp0 = KS_.trajectory_pack(base)
        for i in range(len(mp0)):
            mut = type(mp0)(*(fn(x) if k == i else x for k, x in enumerate(mp0)))
            if ty(mut) != ty(mp0):
                continue
            keys = []
            for fpv in (fp0, None):
                engine._FINGERPRINT[0] = fpv
                p = monitor.Plan([0.0, 0.05, 0.1], q, m)
                KS_._MOTION_PACKS[p] = (mut, {})
                d = engine._WK_DIRECT[0]
                n_hit += fpv is not None and d is not None and d[4] is not mut and fpf(mut) == d[9]
                keys.append(repr({k: v for k, v in monitor.certify(scene, p, margin=0.01).to_dict().items()
                                  if k != "stats"}))  # (stats: wall time)
            engine._FINGERPRINT[0] = fp0
            n_cert += 1
            n_diff += keys[0] != keys[1]
print(f"D: {n_cert} mutated packs certified both ways, {n_hit} met the slot by fingerprint, "
      f"{n_diff} certificates differ")
