"""Plain-timer split of a gated step (Arm, Pusher, tunnel) into buckets and labels.

Usage (from the tree root):
    PYTHONPATH=$PWD python docs/notes/issue-12-gatechecks/split.py arm BLOCKS ROUNDS     (30 steps a block)
    PYTHONPATH=$PWD python docs/notes/issue-12-gatechecks/split.py pusher BLOCKS ROUNDS
    PYTHONPATH=$PWD python docs/notes/issue-12-gatechecks/split.py tunnel BLOCKS ROUNDS  (200 steps a block)

docs/notes/issue-12-armprof/split.py (imported: the same timers, wrapping, buckets and report) with a
``tunnel`` workload added: the bench's ``tunnel_gate`` (``Gate.step`` on models/tunnel, margin 0.001,
the README controller, nstep 1); ungated = the same controller over one ``mj_step`` per window.
"""
import os
import sys
from collections import Counter

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "issue-12-armprof"))
import split as armprof  # noqa: E402  (docs/notes/issue-12-armprof/split.py)


def tunnel_runner():
    """``run(blocks, first, env)`` of armprof's runner for the tunnel: µs per window and windows run."""
    import mujoco
    import numpy as np

    from monitor.gate import Gate
    m = mujoco.MjModel.from_xml_path("models/tunnel/scene.xml")
    gate = Gate(m, margin=0.001)
    d, du = mujoco.MjData(m), mujoco.MjData(m)
    verdicts: Counter = Counter()

    def run(blocks, first=0, env=gate):
        tot, steps = 0, 200
        for _ in range(blocks):
            dd = d if env is gate else du
            mujoco.mj_resetDataKeyframe(m, dd, 0)
            gate.reset()
            t = armprof.ns()
            for k in range(steps):
                c = np.clip([12.0 * ((0.3 if (k // 100) % 2 == 0 else -0.3) - dd.qpos[0])], -6.0, 6.0)
                if env is gate:
                    verdicts[str(gate.step(dd, c, nstep=1).verdict)] += 1
                else:
                    dd.ctrl[:] = c
                    mujoco.mj_step(m, dd)
            tot += armprof.ns() - t
        return tot / (steps * blocks) / 1e3, steps * blocks
    return run, verdicts, "ungated"


_armprof_runner = armprof.runner
armprof.runner = lambda kind: tunnel_runner() if kind == "tunnel" else _armprof_runner(kind)

if __name__ == "__main__":
    armprof.main()
