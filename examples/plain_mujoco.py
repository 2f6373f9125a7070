"""Gate a plain MuJoCo simulation (no gymnasium): certify every step before it runs.

A small ball on a slide joint is driven by a proportional velocity controller
towards targets on alternating sides of a 1 cm thick wall, at up to 6 m/s. At
10 ms per step the ball moves up to 6 cm per step: MuJoCo's discrete contacts
miss the wall and the ball tunnels through it. :meth:`monitor.Gate.step`
certifies the continuous motion of each step before stepping, and replaces an
unsafe control by a braking one, so the gated ball never crosses.

Run from the repository root::

    python examples/plain_mujoco.py [--steps 500]
"""

from __future__ import annotations

import argparse

import mujoco
import numpy as np

import monitor
from monitor._paths import scene_path


def controller(data: mujoco.MjData, target: float) -> np.ndarray:
    """Velocity command (m/s) towards ``target`` (m), saturated at the actuator's 6 m/s."""
    return np.clip([12.0 * (target - data.qpos[0])], -6.0, 6.0)


def run(steps: int = 500, gated: bool = True) -> dict:
    """Drive the ball for ``steps`` steps (target switches side every 100 steps).

    Returns:
        the gate's summary (``None`` when not gated) and the ball's x per step.
    """
    model = mujoco.MjModel.from_xml_path(str(scene_path("tunnel")))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)  # ball at x = -0.32 m
    gate = monitor.Gate(model, margin=0.001, on_violation="block") if gated else None
    xs = []
    for k in range(steps):
        target = 0.3 if (k // 100) % 2 == 0 else -0.3
        ctrl = controller(data, target)
        if gate is not None:
            gate.step(data, ctrl)          # certify the step's motion, then step (or block)
        else:
            data.ctrl[:] = ctrl
            mujoco.mj_step(model, data)
        xs.append(float(data.qpos[0]))
    return {"summary": gate.summary() if gate else None, "x": np.array(xs)}


def crossings(x: np.ndarray, start: float = -0.32) -> int:
    """How often the ball changed side of the wall between consecutive steps."""
    side = np.sign(np.concatenate([[start], x]))
    return int(np.count_nonzero(side[1:] != side[:-1]))


def main(steps: int = 500) -> dict:
    """Run gated and ungated and print the summary; returns both results."""
    gated, free = run(steps, gated=True), run(steps, gated=False)
    s = gated["summary"]
    print(f"{s['windows']} gated steps: certified {s['certified']}, violation {s['violation']}, "
          f"uncertain {s['uncertain']}; blocked {s['replaced']}; "
          f"{s['mean_certify_us']:.0f} us per step")
    print(f"wall crossings: gated {crossings(gated['x'])}, ungated MuJoCo {crossings(free['x'])}")
    return {"gated": gated, "ungated": free}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=500)
    main(parser.parse_args().steps)
