"""Peer continuous collision checkers, run on the same :class:`PairCase` set as ours.

Every peer answers "collides during the window?" (True/False) or ``None`` when the
combination is unsupported for the case. Peers (all optional, import-guarded; the
``bench`` extra installs python-fcl and ipctk):

* python-fcl ``continuousCollide`` with each ``CCDMotionType`` x ``CCDSolverType``
  (the default ``CCDC_NAIVE`` takes 10 samples). Screw cases are run only with
  ``CCDM_SCREW`` (the same interpolation); Bézier cases are unsupported
  (:func:`peer_support`). Combinations are first probed in a
  subprocess (:func:`probe_fcl`), so a crash is recorded instead of killing the run;
  output printed by the C++ library ("Invalid continuous collision ...", "not
  supported") is captured at the file-descriptor level.
* MuJoCo sampling: ``mj_geomDistance < 0`` at N evenly spaced samples of the true
  motion (time order, stop at the first hit; lerp/slerp, screw and Bézier cases). Pose
  evaluation (poses to qpos) is precomputed outside the timed region, which favours the peer.
* ipctk Tight-Inclusion CCD: ``is_step_collision_free`` on the hull triangle meshes
  with vertices linearly interpolated between the start and end poses (exact for
  translations; for rotations the chord motion is not the true motion). Boundary CCD
  does not see a body that starts inside the other. Polytope pairs only.
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from monitor.bench.cases import PairCase, ShapeSpec

FCL_MOTIONS = ("CCDM_TRANS", "CCDM_LINEAR", "CCDM_SCREW", "CCDM_SPLINE")
FCL_SOLVERS = ("CCDC_NAIVE", "CCDC_CONSERVATIVE_ADVANCEMENT", "CCDC_RAY_SHOOTING", "CCDC_POLYNOMIAL_SOLVER")
MUJOCO_SAMPLES = (10, 100, 1000)
_UNSUPPORTED_MARKERS = ("not supported", "invalid continuous", "unsupported")


def have_fcl() -> bool:
    """True if python-fcl imports."""
    try:
        import fcl  # noqa: F401
    except ImportError:
        return False
    return True


def have_ipctk() -> bool:
    """True if ipctk imports."""
    try:
        import ipctk  # noqa: F401
    except ImportError:
        return False
    return True


@contextlib.contextmanager
def captured_fds() -> Iterator[list[str]]:
    """Capture everything written to fd 1 and 2 (C/C++ prints included).

    Yields a list that receives the captured text (one string) on exit.
    """
    out: list[str] = []
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        os.dup2(tmp.fileno(), 1)
        os.dup2(tmp.fileno(), 2)
        try:
            yield out
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            tmp.seek(0)
            out.append(tmp.read().decode(errors="replace"))


@dataclass
class PeerAnswer:
    """One peer query.

    Attributes:
        collide: True / False, or None if unsupported for this case.
        seconds: wall time of the query (s), median over repetitions.
        note: captured library output or reason for None.
    """

    collide: bool | None
    seconds: float
    note: str = ""


# ------------------------------------------------------------------------------ python-fcl
def fcl_geometry(shape: ShapeSpec):
    """The python-fcl geometry of ``shape`` (body frame, geom at the body origin)."""
    import fcl

    if shape.kind == "box":
        return fcl.Box(*(2.0 * shape.half_extents))
    if shape.kind == "sphere":
        return fcl.Sphere(shape.radius)
    if shape.kind == "capsule":
        return fcl.Capsule(shape.radius, 2.0 * shape.half_length)
    if shape.kind == "cylinder":
        return fcl.Cylinder(shape.radius, 2.0 * shape.half_length)
    if shape.kind == "ellipsoid":
        return fcl.Ellipsoid(*shape.half_extents)
    tri = shape.triangles
    faces = np.hstack([np.full((len(tri), 1), 3), tri]).ravel().astype(np.int64)
    return fcl.Convex(shape.vertices.astype(np.float64), len(tri), faces)


class FclPeer:
    """python-fcl ``continuousCollide`` with one motion type and solver."""

    def __init__(self, motion: str, solver: str):
        import fcl

        self.motion, self.solver = motion, solver
        self.name = f"fcl/{motion.removeprefix('CCDM_')}/{solver.removeprefix('CCDC_')}"
        self._req = fcl.ContinuousCollisionRequest()
        self._req.ccd_motion_type = getattr(fcl.CCDMotionType, motion)
        self._req.ccd_solver_type = getattr(fcl.CCDSolverType, solver)

    def prepare(self, case: PairCase):
        """Collision objects and start/end transforms for ``case``."""
        import fcl

        P, R = case.poses(np.array([0.0, case.duration]))
        geoms = [fcl_geometry(s) for s in case.shapes]
        tf = [[fcl.Transform(R[k, b], P[k, b]) for b in range(2)] for k in range(2)]
        objs = [fcl.CollisionObject(geoms[b], tf[0][b]) for b in range(2)]
        return objs, tf

    def query(self, prepared) -> tuple[bool | None, float]:
        """(collide or None if the library returned -1, time of contact)."""
        import fcl

        objs, tf = prepared
        objs[0].setTransform(tf[0][0])
        objs[1].setTransform(tf[0][1])
        res = fcl.ContinuousCollisionResult()
        toc = fcl.continuousCollide(objs[0], tf[1][0], objs[1], tf[1][1], self._req, res)
        if toc < 0:
            return None, toc
        return bool(res.is_collide), float(res.time_of_contact)


_PROBE_SCRIPT = r"""
import json, sys
import numpy as np
from monitor.bench.cases import PairCase, ShapeSpec
from monitor.bench.peers import FclPeer, captured_fds
skip = set(json.loads(sys.argv[1]))
specs = {"box": ShapeSpec.box([0.1, 0.15, 0.2]), "sphere": ShapeSpec("sphere", radius=0.12),
         "capsule": ShapeSpec("capsule", radius=0.05, half_length=0.1),
         "hull": ShapeSpec.hull(np.array([[0.1, 0, 0], [-0.1, 0, 0], [0, 0.12, 0], [0, -0.1, 0],
                                          [0, 0, 0.1], [0, 0, -0.13], [0.05, 0.05, 0.05]]))}
for motion in sys.argv[2].split(","):
    for solver in sys.argv[3].split(","):
        for kind in specs:
            key = f"{motion}|{solver}|{kind}"
            if key in skip:
                continue
            print(json.dumps({"start": key}), flush=True)
            peer = FclPeer(motion, solver)
            pos = np.array([[[-1.0, 0.02, 0], [1.0, 0.02, 0]], [[0, 0, 0], [0, 0, 0]]])
            quat = np.array([[[1.0, 0, 0, 0], [0.9, 0.43589, 0, 0]], [[1.0, 0, 0, 0], [1.0, 0, 0, 0]]])
            shapes = (specs[kind], ShapeSpec.box([0.2, 0.2, 0.2]))
            case = PairCase("probe", "rotating", "collide", -1.0, shapes, pos, quat, (True, False))
            with captured_fds() as cap:
                col, toc = peer.query(peer.prepare(case))
            print(json.dumps({"done": key, "collide": col, "toc": toc, "output": cap[0][-300:]}), flush=True)
"""


def probe_fcl(motions=FCL_MOTIONS, solvers=FCL_SOLVERS, timeout: float = 120.0) -> dict[str, dict]:
    """Run every motion x solver x shape kind once in a subprocess on a colliding probe case.

    Returns:
        {"MOTION|SOLVER|kind": {"status": "ok" | "unsupported" | "crash" | "timeout",
        "collide": bool | None, "output": captured text}}. A crash (the subprocess
        dies) is recorded and the probe resumes after the crashing combination.
    """
    results: dict[str, dict] = {}
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([os.getcwd(), env.get("PYTHONPATH", "")])
    for _ in range(64):
        skip = list(results)
        try:
            proc = subprocess.run(
                [sys.executable, "-c", _PROBE_SCRIPT, json.dumps(skip), ",".join(motions), ",".join(solvers)],
                capture_output=True,
                text=True,
                timeout=timeout,
                env=env,
                cwd=os.path.dirname(os.path.dirname(os.path.dirname(__file__))),
            )
            lines, rc, err = proc.stdout.splitlines(), proc.returncode, proc.stderr
        except subprocess.TimeoutExpired as exc:
            out = exc.stdout or b""
            lines = (out.decode() if isinstance(out, bytes) else out).splitlines()
            rc, err = "timeout", ""
        started = None
        for line in lines:
            try:
                msg = json.loads(line)
            except json.JSONDecodeError:
                continue
            if "start" in msg:
                started = msg["start"]
            else:
                text = msg["output"]
                unsupported = msg["collide"] is None or any(k in text.lower() for k in _UNSUPPORTED_MARKERS)
                results[msg["done"]] = {
                    "status": "unsupported" if unsupported else "ok",
                    "collide": msg["collide"],
                    "output": text.strip(),
                }
                started = None
        if started is not None:  # died inside this combination
            results[started] = {
                "status": "timeout" if rc == "timeout" else "crash",
                "collide": None,
                "output": f"returncode {rc}: {err[-300:]}",
            }
            continue
        break
    return results


# ------------------------------------------------------------------------------ MuJoCo sampling
class MujocoSampler:
    """``mj_geomDistance < 0`` at N evenly spaced samples (time order, early exit)."""

    def __init__(self, n: int):
        self.n = int(n)
        self.name = f"mujoco/N={self.n}"

    def prepare(self, case: PairCase):
        """Model, scratch data and the (N, nq) sample coordinates (untimed)."""
        import mujoco

        m = case.model
        return m, mujoco.MjData(m), case.qpos(np.linspace(0.0, case.duration, self.n))

    def query(self, prepared) -> tuple[bool, float | None]:
        """(collide, first sample time fraction or None)."""
        import mujoco

        m, d, Q = prepared
        for k in range(len(Q)):
            d.qpos[:] = Q[k]
            mujoco.mj_kinematics(m, d)
            if mujoco.mj_geomDistance(m, d, 0, 1, 1e-3, None) < 0.0:
                return True, k / max(1, len(Q) - 1)
        return False, None


# ------------------------------------------------------------------------------ ipctk
class IpctkPeer:
    """ipctk ``is_step_collision_free`` (Tight-Inclusion CCD) on linearly interpolated hull vertices."""

    name = "ipctk/TightInclusion"

    def applies(self, case: PairCase) -> bool:
        """Polytope pairs only (triangle meshes)."""
        return all(s.is_polytope for s in case.shapes)

    def prepare(self, case: PairCase):
        """Collision mesh of both hulls and (V0, V1) world vertices at t=0 and t=T."""
        import ipctk

        va, vb = (s.vertices for s in case.shapes)
        ta, tb = (s.triangles for s in case.shapes)
        F = np.vstack([ta, tb + len(va)]).astype(np.int32)
        E = ipctk.edges(F)
        mesh = ipctk.CollisionMesh(np.vstack([va, vb]), E, F)
        P, R = case.poses(np.array([0.0, case.duration]))
        V = [
            np.asfortranarray(np.vstack([va @ R[k, 0].T + P[k, 0], vb @ R[k, 1].T + P[k, 1]]))
            for k in range(2)
        ]
        return mesh, V[0], V[1]

    def query(self, prepared) -> tuple[bool, None]:
        """(collide, None)."""
        import ipctk

        mesh, V0, V1 = prepared
        return (not ipctk.is_step_collision_free(mesh, V0, V1)), None


def peer_support(peer: object, case: PairCase, probe: dict[str, dict] | None = None) -> str | None:
    """None if ``peer`` answers about the case's true motion, else why it is unsupported.

    * python-fcl: lerp/slerp cases as before (every motion type is run; the probe decides
      which combinations work per shape kind). Screw cases: only ``CCDM_SCREW``, whose
      ``ScrewMotion`` is the same constant twist between the two poses (the SE(3)
      geodesic); the other motion types interpolate differently. Bézier cases: none
      (fcl has no rational Bézier motion; ``CCDM_SPLINE`` is a B-spline of its own).
    * MuJoCo sampling: every case (samples of :meth:`PairCase.poses`).
    * ipctk: lerp/slerp cases only (it interpolates vertices linearly).
    """
    interp = getattr(case, "interpolation", "lerp_slerp")
    if isinstance(peer, FclPeer):
        if interp == "bezier":
            return "fcl has no rational Bézier motion"
        if interp == "screw" and peer.motion != "CCDM_SCREW":
            return f"fcl {peer.motion} is not the screw motion"
        kinds = {s.kind for s in case.shapes}
        bad = [k for k in sorted(kinds) if (probe or {}).get(f"{peer.motion}|{peer.solver}|{k}", {}).get(
            "status") != "ok"]
        if bad:
            return f"probe failed for {', '.join(bad)}"
        return None
    if isinstance(peer, IpctkPeer) and interp != "lerp_slerp":
        return f"ipctk interpolates vertices linearly, not the {interp} motion"
    return None


def timed(fn: Callable[[], object], reps: int) -> tuple[object, float]:
    """(last result, median seconds) of ``reps`` calls of ``fn``."""
    ts, out = [], None
    for _ in range(max(1, reps)):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return out, float(np.median(ts))


__all__ = [
    "FclPeer",
    "MujocoSampler",
    "IpctkPeer",
    "probe_fcl",
    "captured_fds",
    "have_fcl",
    "have_ipctk",
    "fcl_geometry",
    "timed",
    "peer_support",
    "PeerAnswer",
    "FCL_MOTIONS",
    "FCL_SOLVERS",
    "MUJOCO_SAMPLES",
]
