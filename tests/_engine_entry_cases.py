"""Seeded certify calls shared by ``tests/test_engine_entry.py`` and its golden-file recorder.

Run as a script to (re)record the golden file from the tree on ``PYTHONPATH``:
``PYTHONPATH=<tree> python tests/_engine_entry_cases.py tests/assets/engine_entry_golden.json``
(for one CPU family: ``engine_entry_golden.<llvmlite.binding.get_host_cpu_name()>.json``, which
the test prefers on that family). The committed default file was recorded on main 691a867 (AMD
EPYC), before the engine-entry changes of issue 12 (``docs/notes/issue-12-entry.md``); the
``rocketlake`` file on 2026-11-28 (Intel Xeon), identical from 1c16a97 and from that day's tree.
Recording, like the test, runs with the engine's compiled translating pass off (``_SWEPT_FIRST``).
A deliberate change of the kernels' search (test counts, clearances) changes the certificates;
re-record then (every CPU family's file) and say why in the commit.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np


def _summary(cert: Any) -> dict[str, Any]:
    """Everything a certificate says except its wall time, JSON-exact (floats by repr)."""
    d = cert.to_dict()
    d["stats"].pop("wall_seconds", None)
    return d


def calls() -> Iterator[tuple[str, Any]]:
    """(name, thunk) per seeded certify call; a thunk returns the Certificate."""
    yield from bench_calls()
    yield from box_calls()
    yield from pusher_calls()


def bench_calls(only: str | None = None) -> Iterator[tuple[str, Any]]:
    """Bench pair-windows (lerp / slerp groups) x method x margin; ``only``: "method/margin" suffix."""
    from monitor.certify.engine import certify

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _bench_cases import quick_cases  # the quick set, built once per process

    cases = [c for c in quick_cases() if c.group in ("translating", "rotating")]
    for c in cases:
        scene, motion = c.scene(16), c.body_motion()
        for method in ("auto", "toleranced"):
            for margin in (0.0, 0.01):
                if only is not None and only != f"{method}/{margin}":
                    continue
                yield (f"{c.name}/{method}/{margin}",
                       lambda s=scene, m=motion, me=method, ma=margin: certify(s, m, margin=ma, epsilon=1e-3,
                                                                          method=me))


_BOXES_XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <geom name="post" type="box" pos="0.3 0 0.2" size="0.05 0.05 0.2"/>
    <body name="a" pos="0 0 0.3"><freejoint/><geom name="ga" type="box" size="0.05 0.08 0.03"/></body>
    <body name="b" pos="0.2 0.2 0.3"><freejoint/><geom name="gb" type="capsule" size="0.03 0.06"/></body>
    <body name="c" pos="-0.2 0.1 0.3"><freejoint/><geom name="gc" type="sphere" size="0.06"/></body>
    <body name="d" pos="0 -0.25 0.3"><freejoint/><geom name="gd" type="cylinder" size="0.04 0.05"/></body>
  </worldbody>
</mujoco>
"""


def box_calls() -> Iterator[tuple[str, Any]]:
    """Four free bodies (box, capsule, sphere, cylinder) near a post and a floor, ``pairs="all"``:
    seeded BodyMotions, translating only (extrusion route under "auto") or also rotating."""
    import mujoco

    import monitor
    from monitor.certify.engine import certify

    model = mujoco.MjModel.from_xml_string(_BOXES_XML)
    scene = monitor.Scene.from_model(model, pairs="all")
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    rng = np.random.default_rng(7)
    for k in range(12):
        K = 4
        pos = np.repeat(data.xpos[None].copy(), K, axis=0)
        quat = np.repeat(data.xquat[None].copy(), K, axis=0)
        for b in range(1, model.nbody):
            step = rng.normal(0.0, 0.08, 3)
            pos[:, b] += np.arange(K)[:, None] * step
            if k % 2:
                ax = rng.normal(size=3)
                ax /= np.linalg.norm(ax)
                for j in range(K):
                    h = 0.3 * j
                    quat[j, b] = np.concatenate([[np.cos(h)], np.sin(h) * ax])
        motion = monitor.BodyMotion(np.linspace(0.0, 0.3, K), pos, quat)
        for method in ("auto", "toleranced"):
            yield (f"boxes/{k}/{method}",
                   lambda m=motion, me=method: certify(scene, m, margin=0.01, epsilon=1e-3, method=me))


def pusher_calls() -> Iterator[tuple[str, Any]]:
    """Pusher-v5 windows, then plans built before an in-place edit certified after it."""
    import gymnasium as gym

    import monitor
    from monitor.certify.engine import certify

    # Pusher-v5 windows: random joint paths of the arm (seeded), the gate's pair set
    env = gym.make("Pusher-v5")
    model = env.unwrapped.model
    scene = monitor.Scene.from_model(model, pairs="mujoco")
    rng = np.random.default_rng(20261124)
    q0 = model.qpos0.copy()
    plans = []
    for k in range(16):
        amp = 0.05 if k % 2 else 0.6
        qs = [q0 + rng.uniform(-amp, amp, model.nq)]
        for _ in range(4):
            qs.append(qs[-1] + rng.uniform(-amp, amp, model.nq))
        plans.append(monitor.Plan(np.linspace(0.0, 0.05, 5), np.array(qs), model))
    for k, plan in enumerate(plans):
        for ongoing in ("violation", "deepen"):
            yield (f"pusher/{k}/{ongoing}",
                   lambda p=plan, o=ongoing: certify(scene, p, margin=0.002, epsilon=1e-3, ongoing=o))
    # in-place edit: a watched field (geom size) and a structure field (a joint axis) change;
    # plans built before the edit are certified after it (the engine rebuilds them)
    def edited(k: int) -> Any:
        def run() -> Any:
            if not edited.done:
                gid = int(np.argmax(model.geom_bodyid == model.jnt_bodyid[0]))
                model.geom_size[gid] *= 1.5
                model.jnt_axis[1] = np.array([0.0, 0.6, 0.8])
                edited.done = True
            return certify(scene, plans[k], margin=0.002, epsilon=1e-3)
        return run
    edited.done = False
    for k in range(6):
        yield f"pusher-edited/{k}", edited(k)


def record(path: str) -> None:
    from monitor.certify import engine

    old, engine._SWEPT_FIRST = engine._SWEPT_FIRST, False  # as test_engine_entry._check_all compares
    try:
        out = {name: _summary(run()) for name, run in calls()}
    finally:
        engine._SWEPT_FIRST = old
    with open(path, "w") as f:   # one call per line
        f.write("{\n" + ",\n".join(f"{json.dumps(k)}: {json.dumps(v, sort_keys=True)}"
                                    for k, v in sorted(out.items())) + "\n}\n")


if __name__ == "__main__":
    record(sys.argv[1])
