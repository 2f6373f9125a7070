"""Helpers of the old-vs-new switch tests (test_engine_extrusion_direct.py, test_ongoing_start_bound.py,
test_extrusion_swept.py).

A module flag switches a shortcut off so that the path it replaces is the oracle; certificates
are compared in full (``to_dict()`` without the wall time).
"""

from __future__ import annotations

import numpy as np


def cert_key(cert) -> str:
    """``cert.to_dict()`` without ``stats["wall_seconds"]``, as a string (bit-exact floats)."""
    d = cert.to_dict()
    d["stats"].pop("wall_seconds")
    return repr(d)


def on_and_off(module, flag: str, run):
    """(``run()`` with ``module.flag`` True, with it False); the flag is restored afterwards."""
    old = getattr(module, flag)
    try:
        setattr(module, flag, True)
        a = run()
        setattr(module, flag, False)
        b = run()
    finally:
        setattr(module, flag, old)
    return a, b


def on_and_off_counted(module, flag: str, run, spied, name: str, counts=lambda result: True):
    """:func:`on_and_off`, counting the calls of ``spied.name`` in each run (those whose result ``counts``).

    Returns (result on, result off, calls on, calls off); ``spied.name`` is restored afterwards.
    """
    real = getattr(spied, name)
    n = [0]

    def counted(*a, **k):
        r = real(*a, **k)
        n[0] += bool(counts(r))
        return r

    per_run = []

    def run_counted():
        n[0] = 0
        out = run()
        per_run.append(n[0])
        return out

    setattr(spied, name, counted)
    try:
        a, b = on_and_off(module, flag, run_counted)
    finally:
        setattr(spied, name, real)
    return a, b, per_run[0], per_run[1]


def tunnel_gate_keys(steps: int = 60) -> list[str]:
    """:func:`cert_key` of every certificate of ``steps`` plain ``Gate.step`` windows on models/tunnel.

    The bench's controller (velocity towards +-0.3 m, switching every 15 windows; one 10 ms step
    each), ``Gate(margin=0.001)``, ball from the ``start`` keyframe: certified and violation windows.
    """
    import mujoco

    from monitor._paths import scene_path
    from monitor.gate import Gate

    m = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    gate = Gate(m, margin=0.001)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    out = []
    for k in range(steps):
        target = 0.3 if (k // 15) % 2 == 0 else -0.3
        r = gate.step(d, np.clip([12.0 * (target - d.qpos[0])], -6, 6), nstep=1)
        out.append(cert_key(r.certificate))
    out.append(d.qpos.tobytes().hex())
    return out


def agv_scene_plan(name: str, skewed: bool):
    """(scene with pairs="all", Plan) of Cameron's §5 AGV scene ``name`` (29 primitives), skewed or not."""
    import mujoco

    import monitor
    from monitor._paths import models_dir
    from monitor.bench.extrusion_scenes import schedule

    m = mujoco.MjModel.from_xml_path(str(models_dir() / "agv_trays" / ("scene_skewed.xml" if skewed
                                                                         else "scene.xml")))
    scene = monitor.Scene.from_model(m, pairs="all")
    s = schedule(name)
    return scene, monitor.Plan(s["times"], s["qpos"], model=m)
