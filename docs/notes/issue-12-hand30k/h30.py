"""Shared set-up of these scripts: the captured joint plans, the hand30 gate, a spy on the kernel calls."""
import pickle
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "issue-12-tail-design"))
import wl  # noqa: E402
import monitor.certify.engine as E  # noqa: E402
from monitor.motion.plan import Plan  # noqa: E402


def setup(pkl):
    """(captured rows of capture.py, the hand30 workload W, its scene, the gate's plain request)."""
    kept = pickle.load(open(pkl, "rb"))
    W = wl.make("hand30")
    for _ in W.steps(2, 0):
        pass
    return kept, W, W.gate.scene, W.gate._plain_request()


def joint_plan(W, rows):
    """The gate's joint plan (window rows, then the tail's rows after its first) of one capture."""
    wr, tr, mp, mq = rows
    return Plan._trusted(np.concatenate((wr[:, 0], tr[1:, 0])), np.concatenate((wr[:, 1:], tr[1:, 1:])),
                         model=W.model, mocap_pos=mp.copy(), mocap_quat=mq.copy())


def spy_kernel_calls():
    """Record every engine._window_kernel call: (gp, mp, pairs, fixed, moving, copies of the other
    arguments as passed, the live other arguments); returns (records, the original function)."""
    rec = []
    orig = E._window_kernel

    def wk(KS_, gp, mp, pairs, fixed, moving, *rest):
        rec.append((gp, mp, pairs, fixed, moving, [x.copy() if isinstance(x, np.ndarray) else x for x in rest],
                    rest))
        return orig(KS_, gp, mp, pairs, fixed, moving, *rest)
    E._window_kernel = wk
    return rec, orig
