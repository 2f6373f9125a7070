"""engine._window_kernel with a NEW motion pack of the last typed type (issue 12, helper gatepath).

A gate certifies a new Plan per window, so every window's motion pack is a new object; when it is of
the same class and its fields have numba's type fingerprint of the pack the dispatcher last typed
(``engine._pack_fingerprint``), the overload's entry point is called directly.

* Certificates: oracle = the dispatcher for every new pack (``engine._FINGERPRINT[0] = None``, the
  base's behaviour); whole certificates bit for bit (``to_dict()`` without the wall time) on seeded
  plans of one scene and on tunnel gate steps, with the entry point required to have run.
* Routing: a pack of another type (a read-only field, a field of another dtype or layout, another
  class with the same fields) and a numba without the fingerprint function go through the
  dispatcher (a stand-in dispatcher here: no compilation); a new pack of the same type does not.

Seeded, no timings.
"""

from __future__ import annotations

import collections
import sys
from pathlib import Path

import mujoco
import numpy as np

import monitor
from monitor.certify import engine

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _switch_cases import cert_key, tunnel_gate_keys  # noqa: E402

_XML = """<mujoco><worldbody>
  <geom name="wall" type="box" size="0.05 1 1" pos="0.6 0 0"/>
  <body name="a" pos="0 0 0"><joint name="x" type="slide" axis="1 0 0"/>
    <joint name="r" type="hinge" axis="0 0 1"/><geom name="ga" type="box" size="0.1 0.05 0.05"/></body>
  <body name="b" pos="0 0.5 0"><joint name="y" type="slide" axis="1 0 0"/>
    <geom name="gb" type="capsule" size="0.05 0.1"/></body>
</worldbody></mujoco>"""


def _plans(m, n: int, seed: int) -> list:
    """``n`` seeded 3-waypoint plans of ``m`` (clear, grazing and colliding with the wall)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = np.zeros((3, m.nq))
        q[:, 0] = np.sort(rng.uniform(-0.2, 0.6, 3))
        q[:, 1] = rng.uniform(-0.5, 0.5, 3) * (rng.random() < 0.5)   # half of them only translate
        q[:, 2] = rng.uniform(-0.3, 0.6, 3)
        out.append(monitor.Plan([0.0, 0.05, 0.1], q, m))
    return out


class _Counted:
    """Wraps the entry point recorded in ``engine._WK_DIRECT[0]``, counting its calls with another pack."""

    def __init__(self, slot: int = 0):
        self.n = 0
        d = engine._WK_DIRECT[slot]
        real = d[2]

        def ep(*a):
            self.n += a[1] is not d[4]
            return real(*a)

        engine._WK_DIRECT[slot] = d[:2] + (ep,) + d[3:]


def _fresh(plan):
    """A new Plan object with the same waypoints (a new motion pack, as the gate makes per window)."""
    return monitor.Plan(np.array(plan.times), np.array(plan.qpos), plan.model)


def test_new_packs_take_the_entry_point_with_the_dispatchers_certificates(monkeypatch):
    m = mujoco.MjModel.from_xml_string(_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    plans = _plans(m, 24, seed=7)
    kw = dict(margin=0.01, epsilon=1e-3)
    monitor.certify(scene, plans[0], **kw)                 # types the pack through the dispatcher
    assert engine._WK_DIRECT[0] is not None
    fp = engine._FINGERPRINT[0]
    assert fp is not None                                   # this numba has it (else nothing to test)
    monkeypatch.setattr(engine, "_FINGERPRINT", [None])    # the base: the dispatcher for every new pack
    ref = [cert_key(monitor.certify(scene, p, **kw)) for p in plans]
    monkeypatch.setattr(engine, "_FINGERPRINT", [fp])
    monitor.certify(scene, _fresh(plans[0]), **kw)          # (re)record the slot through the dispatcher
    count = _Counted()
    new = [cert_key(monitor.certify(scene, _fresh(p), **kw)) for p in plans]
    assert new == ref
    assert count.n >= len(plans)                            # every new pack took the entry point
    verdicts = collections.Counter(k.split("'verdict': ")[1].split(",")[0] for k in ref)
    assert verdicts["'certified'"] >= 3 and verdicts["'violation'"] >= 3, verdicts


def test_tunnel_gate_same_certificates_with_and_without_the_shortcut(monkeypatch):
    """60 tunnel gate steps: identical certificates and end state; the entry point ran on new packs."""
    n = [0, 0]
    real = engine._window_kernel

    def spy(KS, gp, mp, *a):
        d = engine._WK_DIRECT[0 if a[-2] is None else 1]
        n[0] += 1
        n[1] += d is not None and d[4] is not mp and d[0] is KS.window_kernel
        return real(KS, gp, mp, *a)

    monkeypatch.setattr(engine, "_window_kernel", spy)
    on = tunnel_gate_keys(60)
    fresh_on = n[1]
    fp = engine._FINGERPRINT[0]
    monkeypatch.setattr(engine, "_FINGERPRINT", [None])
    off = tunnel_gate_keys(60)
    monkeypatch.setattr(engine, "_FINGERPRINT", [fp])
    assert on == off
    assert fresh_on >= 40, n          # most windows: a new pack met a recorded slot


class _StandIn:
    """A stand-in ``window_kernel`` dispatcher: records that it ran (no typing, no compilation)."""

    def __init__(self, overloads: int):
        self.overloads = dict.fromkeys(range(overloads))
        self.ran = 0

    def __call__(self, *a):
        self.ran += 1
        return 0


def test_only_a_pack_of_the_recorded_type_skips_the_dispatcher(monkeypatch):
    from monitor.certify import kernels as KS

    m = mujoco.MjModel.from_xml_string(_XML)
    scene = monitor.Scene.from_model(m, pairs="all")
    plan = _plans(m, 1, seed=3)[0]
    seen = []
    real = engine._window_kernel

    def spy(KS_, gp, mp, pairs, fixed, moving, *rest):
        seen.append((gp, mp, pairs, fixed, moving, rest))
        return real(KS_, gp, mp, pairs, fixed, moving, *rest)

    monkeypatch.setattr(engine, "_window_kernel", spy)
    monitor.certify(scene, plan, margin=0.01)
    monkeypatch.setattr(engine, "_window_kernel", real)
    gp, mp, pairs, fixed, moving, rest = seen[0]
    slot = 0 if rest[-2] is None else 1
    d = engine._WK_DIRECT[slot]
    assert d is not None and d[4] is mp and d[8] is type(mp) and d[9] is not None
    stand_in = _StandIn(d[1])
    direct = []
    monkeypatch.setattr(KS, "window_kernel", stand_in)
    recorded = (stand_in,) + d[1:2] + (lambda *a: direct.append(a[1]) or 0,) + d[3:]

    def route(pack) -> str:
        engine._WK_DIRECT[slot] = recorded
        direct.clear()
        stand_in.ran = 0
        engine._window_kernel(KS, gp, pack, pairs, fixed, moving, *rest)
        assert len(direct) + stand_in.ran == 1
        return "direct" if direct else "dispatcher"

    fresh_mp, _ = KS.trajectory_pack_memo(_fresh(plan))
    assert fresh_mp is not mp and engine._pack_fingerprint(fresh_mp) == d[9]
    assert route(mp) == "direct"                        # the recorded pack itself (as before)
    assert route(fresh_mp) == "direct"                  # a new pack of the same type
    ro = mp.times.copy()
    ro.flags.writeable = False
    assert route(mp._replace(times=ro)) == "dispatcher"                                   # read-only field
    assert route(mp._replace(tol=mp.tol.astype(np.float32))) == "dispatcher"              # another dtype
    assert route(mp._replace(qpos=np.asfortranarray(np.tile(mp.qpos, (1, 2))))) == "dispatcher"  # layout F
    assert route(mp._replace(qpos=mp.qpos[:, None, :])) == "dispatcher"                   # another ndim
    other = collections.namedtuple("MotionPack", type(mp)._fields)
    assert route(other(*mp)) == "dispatcher"                                              # another class
    assert route(tuple(mp)) == "dispatcher"
    assert route(mp._replace(times=np.zeros(3, object))) == "dispatcher"                  # no fingerprint
    # another scene pack, pair or flag array: the dispatcher, as before
    engine._WK_DIRECT[slot] = recorded
    direct.clear()
    stand_in.ran = 0
    engine._window_kernel(KS, gp, fresh_mp, pairs.copy(), fixed, moving, *rest)
    assert stand_in.ran == 1 and not direct
    # a numba without compute_fingerprint: only the recorded pack itself
    monkeypatch.setattr(engine, "_FINGERPRINT", [None])
    assert engine._pack_fingerprint(fresh_mp) is None
    assert route(mp) == "direct"
    assert route(fresh_mp) == "dispatcher"


def test_motion_pack_fields_are_native_plain_arrays_for_odd_plan_inputs():
    """The shortcut's premise (red team 19): numba's fingerprint encodes neither byte order nor an
    ndarray subclass, so every motion pack field must be a plain, aligned, native-order ndarray (or a
    Python / numpy scalar) whatever the Plan was built from: big-endian, masked, float32, F-order and
    non-contiguous waypoints and times give such packs, with the same fingerprint as the plain plan's."""
    m = mujoco.MjModel.from_xml_string(_XML)
    base = _plans(m, 1, 19)[0]
    times, qpos = np.array(base.times), np.array(base.qpos)
    odd = {
        "big-endian": (times.astype(">f8"), qpos.astype(">f8")),
        "masked": (np.ma.masked_array(times), np.ma.masked_array(qpos)),
        "float32": (times.astype(np.float32), qpos.astype(np.float32)),
        "F-order": (times, np.asfortranarray(qpos)),
        "non-contiguous": (np.repeat(times, 2)[::2], np.repeat(qpos, 2, axis=1)[:, ::2]),
    }
    KS = engine._kernels()
    ref, _ = KS.trajectory_pack_memo(monitor.Plan(times, qpos, m))
    fp_ref = engine._pack_fingerprint(ref)
    for name, (t, q) in odd.items():
        mp, _ = KS.trajectory_pack_memo(monitor.Plan(t, q, m))
        assert mp is not None, name
        for field, x in zip(type(mp)._fields, mp):
            if isinstance(x, np.ndarray):
                assert type(x) is np.ndarray, (name, field, type(x))
                assert x.dtype.isnative and x.flags.aligned, (name, field, x.dtype)
            else:
                assert isinstance(x, (int, float, bool, np.generic)), (name, field, type(x))
        if fp_ref is not None:
            assert engine._pack_fingerprint(mp) == fp_ref, name
