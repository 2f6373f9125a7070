"""Red team 18: end-to-end audit of `certified` on the envs a user runs (docs/notes/redteam-18.md).

For every gated step whose APPLIED window the gate reports `certified`, and for every accepted
step's braking tail it reports `certified`, this script re-simulates the motion MuJoCo applied from
the state before the step (``mj_getState`` / ``mj_setState`` on its own ``MjData``, the control the
env actually wrote to ``data.ctrl``, ``mj_step`` one substep at a time), checks that replay against
the env's state after the step bit for bit, and audits the continuous joint-space path through the
substep rows for every monitored pair with ``oracle18.PathOracle`` (own distances, Lipschitz bound
between samples; shares no code with ``monitor``). A certified motion with a monitored pair closer
than its threshold (margin, or ``-penetration_tol`` for a pair that could be an ongoing contact at
the window's start) by more than the oracle's error is a FINDING.

Also counted: replays that differ from the applied state, certified rows that differ from the
replay, controls that differ from what the env received (``ClipAction`` / ``RescaleAction``
composed by hand), NaN / inf actions that were not refused with ``InvalidInputError``, MuJoCo
contacts during the run on pairs the gate does not monitor (by reason).

Run (from a checkout; quick mode < 3 min on the 2 shared cores):
    PYTHONPATH=. python docs/notes/redteam-18/audit.py --quick
    PYTHONPATH=. python docs/notes/redteam-18/audit.py            # full: more steps per workload
    PYTHONPATH=. python docs/notes/redteam-18/audit.py --only Ant  # workloads whose name contains "Ant"
    PYTHONPATH=. python docs/notes/redteam-18/audit.py --seed-offset 100   # other seeds, same workloads
Prints one line per workload: steps, certified windows / tails audited, findings, and the other counts.
Exit code 1 if any finding (or replay / rows / control mismatch, or an unrefused NaN) was seen.
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import sys
import tempfile
import time
import warnings
from pathlib import Path

import gymnasium as gym
import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from oracle18 import PathOracle  # noqa: E402

import monitor  # noqa: E402
import monitor.envs  # noqa: E402,F401
from monitor.errors import InvalidInputError  # noqa: E402
from monitor.gym_gate import SafetyGate  # noqa: E402

ONGOING_BAND = 1e-5  # m: a pair within margin + this at a window's start may be an ongoing contact
_STATE = mujoco.mjtState.mjSTATE_INTEGRATION


class Counts:
    """Per-workload tallies and the first few details of anything irregular."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.c = collections.Counter()
        self.details: list[dict] = []
        self.unmonitored_contacts = collections.Counter()
        self.min_margin = math.inf  # smallest (oracle upper - threshold) over audited certified motions

    def add_detail(self, kind: str, **kw) -> None:
        """Count ``kind`` and keep its first five details."""
        self.c[kind] += 1
        if len([d for d in self.details if d["kind"] == kind]) < 5:
            self.details.append({"kind": kind, **kw})

    def line(self) -> str:
        """One summary line."""
        c = self.c
        return (f"{self.name:44s} steps={c['steps']:4d} certified_windows_audited={c['win_audited']:4d} "
                f"tails_audited={c['tail_audited']:4d} findings={c['finding']} unresolved={c['unresolved']} "
                f"replay_mismatch={c['replay_mismatch']} rows_mismatch={c['rows_mismatch']} "
                f"tail_rows_mismatch={c['tail_rows_mismatch']} ctrl_mismatch={c['ctrl_mismatch']} "
                f"nan_not_refused={c['nan_not_refused']} log_mismatch={c['log_mismatch']} "
                f"replaced={c['replaced']} "
                f"applied_not_certified={c['applied_not_certified']} "
                f"violations_confirmed={c['violation_confirmed_by_oracle']}/{c['violation_proposals']} "
                f"min_slack_m={self.min_margin:.3g}")

    def bad(self) -> int:
        """Irregular outcomes (findings and mismatches)."""
        c = self.c
        return (c["finding"] + c["replay_mismatch"] + c["log_mismatch"] + c["rows_mismatch"]
                + c["ctrl_mismatch"]
                + c["nan_not_refused"] + c["tail_rows_mismatch"])


# ----------------------------------------------------------------------------- the per-motion audit
def thresholds(oracle: PathOracle, q0: np.ndarray, pairs, margin: float, tol: float) -> np.ndarray:
    """Per pair: the weakest clearance the gate's certificate can mean for a window starting at q0."""
    b = oracle.start_distance(q0, pairs)
    thr = np.where(b[:, 0] > margin + ONGOING_BAND, margin, -tol)
    ONGOING_COUNT[0] += int(np.sum(thr < margin))
    return thr


SEED_OFFSET = [0]  # added to every workload's seed (--seed-offset)
ONGOING_COUNT = [0]  # (motion, pair) audits that used the ongoing-contact threshold -penetration_tol


def audit_motion(cnt: Counts, oracle: PathOracle, rows: np.ndarray, pairs, thr: np.ndarray,
                 what: str, where: dict) -> None:
    """Audit one certified motion (rows (K, nq)); count findings / unresolved pairs."""
    res = oracle.audit(rows, pairs, thr)
    m = oracle.model
    for (a, b), r in zip(pairs, res):
        if math.isfinite(r.min_upper):
            cnt.min_margin = min(cnt.min_margin, r.min_upper - r.threshold)
        if r.status == "finding":
            cnt.add_detail("finding", what=what, pair=(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, a),
                                                      mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, b)),
                           upper=r.min_upper, threshold=r.threshold, at_row=r.time_param,
                           mj_geomDistance=r.mj_distance, **where)
        elif r.status == "unresolved":
            cnt.add_detail("unresolved", what=what, pair=(a, b), upper=r.min_upper, threshold=r.threshold,
                           **where)


def replay(model: mujoco.MjModel, scratch: mujoco.MjData, state: np.ndarray, ctrl: np.ndarray,
           nstep: int) -> np.ndarray:
    """(nstep + 1, nq) qpos rows of ``nstep`` mj_step calls from ``state`` under ``ctrl``."""
    mujoco.mj_setState(model, scratch, state, _STATE)
    scratch.ctrl[:] = ctrl
    rows = [scratch.qpos.copy()]
    for _ in range(nstep):
        mujoco.mj_step(model, scratch)
        rows.append(scratch.qpos.copy())
    return np.array(rows)


def tail_rows(model, scratch, state, brake, nmax: int, vel_tol: float) -> np.ndarray:
    """Braking tail: hold ``brake`` from ``state`` until every |qvel| <= vel_tol or nmax substeps."""
    mujoco.mj_setState(model, scratch, state, _STATE)
    scratch.ctrl[:] = brake
    rows = [scratch.qpos.copy()]
    for _ in range(max(nmax, 1)):  # at least one substep (the gate's rule: the first substep at rest ends it)
        mujoco.mj_step(model, scratch)
        rows.append(scratch.qpos.copy())
        if np.all(np.abs(scratch.qvel) <= vel_tol):
            break
    return np.array(rows)


def rows_t0(data: mujoco.MjData, model: mujoco.MjModel, nstep: int) -> float:
    """Start time of the window that just ran (``data.time`` minus its substeps)."""
    return float(data.time) - nstep * float(model.opt.timestep) + 1e-12


def get_state(model, data) -> np.ndarray:
    """(S,) integration state of ``data``."""
    s = np.empty(mujoco.mj_stateSize(model, _STATE))
    mujoco.mj_getState(model, data, s, _STATE)
    return s


class StepAuditor:
    """Wraps one gated stepping loop (SafetyGate or Gate.step) with the audit."""

    def __init__(self, cnt: Counts, gate: monitor.Gate, model: mujoco.MjModel) -> None:
        self.cnt, self.gate, self.model = cnt, gate, model
        self.oracle = PathOracle(model)
        self.scratch = mujoco.MjData(model)
        self.pairs = None
        self.applied_log: list[tuple[np.ndarray, bool]] = []  # (data.ctrl after the step, replaced)

    def _pairs(self):
        if self.pairs is None:
            sc = self.gate.scene
            self.pairs = [tuple(int(x) for x in p) for p in sc.pair_ids]
            self.monitored = {tuple(sorted(p)) for p in self.pairs}
        return self.pairs

    def _unit_quats(self, rows: np.ndarray) -> np.ndarray:
        out = np.array(rows, float)
        for sl in self.oracle.interp.quat_slices:
            out[:, sl] /= np.linalg.norm(out[:, sl], axis=1, keepdims=True)
        return out

    def after_step(self, data: mujoco.MjData, state0: np.ndarray, nstep: int, report,
                   expected_ctrl: np.ndarray | None, step_no: int) -> None:
        """Audit one gated step that just ran (``state0``: the integration state before it)."""
        cnt, m, g = self.cnt, self.model, self.gate
        cnt.c["steps"] += 1
        pairs = self._pairs()
        ctrl = np.array(data.ctrl)
        self.applied_log.append((ctrl.copy(), bool(report.replaced)))
        where = {"step": step_no, "time": float(data.time)}
        if (expected_ctrl is not None and not report.replaced
                and not np.allclose(expected_ctrl, ctrl, rtol=1e-5, atol=1e-6)):  # float32 rescaling
            cnt.add_detail("ctrl_mismatch", expected=expected_ctrl.tolist(), got=ctrl.tolist(), **where)
        if not np.array_equal(np.asarray(report.applied_ctrl, float), ctrl):
            cnt.add_detail("ctrl_mismatch", certified=np.asarray(report.applied_ctrl).tolist(),
                           got=ctrl.tolist(), **where)
        rows = replay(m, self.scratch, state0, ctrl, nstep)
        s = self.scratch
        if not (np.array_equal(s.qpos, data.qpos) and np.array_equal(s.qvel, data.qvel)):
            cnt.add_detail("replay_mismatch", **where)
        if report.replaced:
            cnt.c["replaced"] += 1
        elif report.verdict == "certified":
            # the certificate's rows are the applied rows (not built for a replaced step)
            pq = np.asarray(report.plan.qpos)
            if pq.shape != rows.shape or not np.array_equal(pq, rows):
                pq, rows_n = self._unit_quats(pq), self._unit_quats(rows)
                if pq.shape == rows.shape and np.abs(pq - rows_n).max() <= 1e-12:
                    # Plan normalises free / ball quaternions (docs/design.md), as MuJoCo's kinematics
                    # do: the same poses (Ant / Humanoid reset noise leaves |q| != 1 in the first row)
                    cnt.c["rows_quat_normalised"] += 1
                    pq = rows
                if pq is not rows:
                    diff = float(np.abs(pq - rows).max()) if pq.shape == rows.shape else math.inf
                    cnt.add_detail("rows_mismatch", max_abs_diff=diff, **where)
        for c in data.contact[: data.ncon] if data.ncon else ():
            p = tuple(sorted((int(c.geom1), int(c.geom2))))
            if p not in self.monitored:
                n1 = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, p[0]) or f"geom{p[0]}"
                n2 = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, p[1]) or f"geom{p[1]}"
                cnt.unmonitored_contacts[f"{n1}|{n2}"] += 1
        if report.replaced and report.verdict == "violation" and pairs:
            # positive control: the oracle should confirm the gate's violation on the proposal's rows
            prow = np.asarray(report.plan.qpos)
            thr_p = thresholds(self.oracle, prow[0], pairs, g.margin, g.penetration_tol)
            res = self.oracle.audit(prow, pairs, thr_p, cross_check=False, max_samples=300)
            cnt.c["violation_proposals"] += 1
            cnt.c["violation_confirmed_by_oracle"] += any(r.status == "finding" for r in res)
        if not pairs:
            cnt.c["win_nothing_monitored"] += 1
            return
        thr = thresholds(self.oracle, rows[0], pairs, g.margin, g.penetration_tol)
        if report.applied_verdict != "certified":
            # applied although not certified (fallback after a long rejection streak, or "warn"):
            # not a claim; the oracle's view is tallied as a control of the oracle itself
            cnt.c["applied_not_certified"] += 1
            res = self.oracle.audit(rows, pairs, thr, cross_check=False, max_samples=300)
            hit = any(r.status == "finding" for r in res)
            cnt.c[f"applied_{report.applied_verdict}_oracle_{'violation' if hit else 'clear'}"] += 1
            if report.replaced and report.verdict == "uncertain":
                # the gate applied an uncertified fallback instead of an uncertain proposal: what would
                # the proposal have done? (a policy question for the lead, not a certificate)
                prow = np.asarray(report.plan.qpos)
                thr_p = thresholds(self.oracle, prow[0], pairs, g.margin, g.penetration_tol)
                res_p = self.oracle.audit(prow, pairs, thr_p, cross_check=False, max_samples=300)
                hit_p = any(r.status == "finding" for r in res_p)
                cnt.c[f"uncertain_proposal_oracle_{'violation' if hit_p else 'clear'}_replaced_by_"
                      f"{report.applied_verdict}"] += 1
                if report.applied_verdict == "violation":
                    worst = min(res_p, key=lambda r: r.min_upper - r.threshold)
                    cnt.add_detail("uncertain_replaced_by_violation", proposal_oracle=worst.status,
                                   proposal_min_slack=worst.min_upper - worst.threshold,
                                   applied_oracle="violation" if hit else "clear",
                                   unresolved_pairs=sum(r.status == "unresolved" for r in res_p),
                                   block_reason=report.block_reason, **where)
            return
        fb = report.fallback_certificate if report.replaced else None
        tail = g._tail[0] if g._tail is not None else None
        if (fb is not None and tail is not None and float(fb.window[0]) < float(rows_t0(data, m, nstep))
                and float(fb.window[0]) == float(tail.rows[0, 0])):
            # the applied window is part of the committed braking tail, certified as ONE window from the
            # tail's start: the ongoing-contact rule's baseline is there (docs/design.md: "the bound is per
            # window"). A pair in contact at the tail's start may lift off and touch again within it.
            thr_base = np.minimum(thr, thresholds(self.oracle, np.asarray(tail.rows[0, 1:]), pairs, g.margin,
                                                  g.penetration_tol))
            if np.any(thr_base < thr):
                res = self.oracle.audit(rows, pairs, thr, cross_check=False)
                for (a, b), r, tb in zip(pairs, res, thr_base):
                    if r.status == "finding" and r.min_upper >= tb - 1e-9:
                        cnt.add_detail("recontact_in_committed_tail", pair=(a, b), upper=r.min_upper,
                                       window_threshold=r.threshold, tail_threshold=float(tb),
                                       tail_start=float(tail.rows[0, 0]), **where)
                thr = thr_base
        audit_motion(cnt, self.oracle, rows, pairs, thr, "window", where)
        cnt.c["win_audited"] += 1
        if report.replaced or report.brake_verdict != "certified" or g._tail is None:
            return
        tail = g._tail[0]
        brake = np.asarray(tail.key[1], float)
        state1 = get_state(m, data)
        trows = tail_rows(m, self.scratch, state1, brake, g.brake_steps, g.brake_vel_tol)
        grows = np.asarray(tail.rows[:, 1:])
        if grows.shape != trows.shape or not np.array_equal(grows, trows):
            cnt.add_detail("tail_rows_mismatch", gate_len=len(grows), oracle_len=len(trows), **where)
            n = min(len(grows), len(trows))
            trows = trows[:n]
        thr_t = np.minimum(thr, thresholds(self.oracle, trows[0], pairs, g.margin, g.penetration_tol))
        audit_motion(cnt, self.oracle, trows, pairs, thr_t, "tail", where)
        cnt.c["tail_audited"] += 1


# ----------------------------------------------------------------------------- action schedules
def schedule(kind: str, low: np.ndarray, high: np.ndarray, n: int, rng: np.random.Generator,
             over: float = 1.0) -> list[np.ndarray]:
    """Seeded action schedule of one kind.

    Kinds: random (uniform), hold (extreme sign patterns held 15 steps: limits, floor, each other),
    bang (max magnitude, sign flipped every 2 steps). ``over`` > 1 leaves the box (wrapped envs clip).
    """
    mid, half = 0.5 * (low + high), 0.5 * (high - low)
    out = []
    if kind == "random":
        return [rng.uniform(low, high) for _ in range(n)]
    if kind == "huge":  # finite but far outside the box (1e30): clamped by ctrlrange / ClipAction
        return [mid + 1e30 * rng.choice([-1.0, 1.0], size=len(low)) for _ in range(n)]
    signs = rng.choice([-1.0, 1.0], size=len(low))
    for k in range(n):
        if kind == "hold" and k % 15 == 0:
            signs = rng.choice([-1.0, 1.0], size=len(low))
        if kind == "bang" and k % 2 == 0:
            signs = -signs
        out.append(mid + over * signs * half)
    return out


# ----------------------------------------------------------------------------- workloads
def _expected_ctrl_fn(env):
    """The control the env should receive for an outer action, composed by hand (Clip / Rescale)."""
    chain = []
    e = env
    while isinstance(e, gym.Wrapper):
        if isinstance(e, gym.wrappers.ClipAction):
            chain.append(("clip", e.env.action_space.low, e.env.action_space.high))
        elif isinstance(e, gym.wrappers.RescaleAction):
            chain.append(("rescale", e.action_space.low, e.action_space.high,
                          e.env.action_space.low, e.env.action_space.high))
        e = e.env

    def f(a):
        a = np.asarray(a, float)
        for item in chain:
            if item[0] == "clip":
                a = np.clip(a, item[1], item[2])
            else:
                _, lo, hi, LO, HI = item
                a = LO + (HI - LO) * ((a - lo) / (hi - lo))
        return a
    return f


def run_gym(name: str, make, steps: dict, seed: int, *, frame_skip_change: int | None = None,
            over: float = 1.0) -> Counts:
    """Audit a gymnasium workload (``make()`` builds the gated env)."""
    cnt = Counts(name)
    seed += SEED_OFFSET[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = make()
    u = env.unwrapped
    env.reset(seed=seed)
    aud = StepAuditor(cnt, env.gate, u.model)
    expect = _expected_ctrl_fn(env.env)
    rng = np.random.default_rng(seed)
    space = env.action_space
    e = env.env
    while not (np.isfinite(space.low).all() and np.isfinite(space.high).all()):  # ClipAction: inf box
        space = e.action_space
        e = e.env
    acts = []
    for kind, n in steps.items():
        acts += schedule(kind, space.low.astype(float), space.high.astype(float), n, rng,
                         over=over if kind != "random" else 1.0)
    # NaN / inf once: a typed refusal, nothing stepped
    for bad in (np.nan, np.inf):
        a = np.array(acts[0], float)
        a[0] = bad
        t0 = float(u.data.time)
        try:
            env.step(a)
            cnt.add_detail("nan_not_refused", value=str(bad))
        except InvalidInputError:
            cnt.c["nan_refused"] += 1
            if float(u.data.time) != t0:
                cnt.add_detail("nan_not_refused", value=str(bad), note="refused but time advanced")
    for k, a in enumerate(acts):
        if frame_skip_change is not None and k == len(acts) // 2:
            u.frame_skip = frame_skip_change
        state0 = get_state(u.model, u.data)
        nstep = int(u.frame_skip)
        a = np.asarray(a, dtype=env.action_space.dtype)
        _, _, term, trunc, info = env.step(a)
        aud.after_step(u.data, state0, nstep, env.gate.last_report, expect(a), k)
        if term or trunc:
            env.reset()
    cnt.pairs_info = pair_info(env.gate, u.model)
    path = env.gate.log_path
    env.close()
    if path is not None:
        compare_log(cnt, path, aud.applied_log)
    return cnt


def compare_log(cnt: Counts, path, applied: list) -> None:
    """The log's action records against what the env received (``data.ctrl``), step by step."""
    from monitor.log.reader import read_log

    acts = read_log(path).messages.get("/monitor/action", [])
    cnt.c["log_actions"] = len(acts)
    if len(acts) != len(applied):
        cnt.add_detail("log_mismatch", note=f"{len(acts)} action records for {len(applied)} steps")
    for k, (rec, (ctrl, replaced)) in enumerate(zip(acts, applied)):
        if np.asarray(rec["applied"], float).tobytes() != ctrl.tobytes() or bool(rec["replaced"]) != replaced:
            cnt.add_detail("log_mismatch", step=k, logged=rec["applied"], got=ctrl.tolist())


def run_plain(name: str, scene: str, steps: dict, seed: int, nstep: int, reset, **gate_kw) -> Counts:
    """Audit ``Gate.step`` on ``models/<scene>``."""
    cnt = Counts(name)
    seed += SEED_OFFSET[0]
    model = mujoco.MjModel.from_xml_path(str(Path(monitor.__file__).resolve().parents[1] / "models" / scene
                                             / "scene.xml"))
    data = mujoco.MjData(model)
    reset(model, data)
    gate = monitor.Gate(model, **gate_kw)
    aud = StepAuditor(cnt, gate, model)
    rng = np.random.default_rng(seed)
    lo, hi = model.actuator_ctrlrange[:, 0].astype(float), model.actuator_ctrlrange[:, 1].astype(float)
    acts = []
    for kind, n in steps.items():
        if kind == "random":  # hold each random target 5 windows (joint targets need time to act)
            for _ in range(n // 5 + 1):
                acts += [rng.uniform(lo, hi)] * 5
            acts = acts[: sum(v for kk, v in steps.items() if kk == "random")]
        else:
            acts += schedule(kind, lo, hi, n, rng)
    for bad in (np.nan, np.inf):
        c = np.array(acts[0], float)
        c[0] = bad
        t0 = float(data.time)
        try:
            gate.step(data, c, nstep=nstep)
            cnt.add_detail("nan_not_refused", value=str(bad))
        except InvalidInputError:
            cnt.c["nan_refused"] += 1
            if float(data.time) != t0:
                cnt.add_detail("nan_not_refused", value=str(bad), note="refused but time advanced")
    for k, c in enumerate(acts):
        state0 = get_state(model, data)
        rep = gate.step(data, c, nstep=nstep)
        aud.after_step(data, state0, nstep, rep, np.asarray(c, float) if not rep.replaced else None, k)
    cnt.pairs_info = pair_info(gate, model)
    gate.close()
    return cnt


def pair_info(gate, model) -> dict:
    """What the gate monitors vs what pairs='all' / MuJoCo's own filter would give."""
    sc = gate.scene
    out = {"monitored": len(sc.candidate_pairs),
           "allowed": [[a, b, str(r)] for a, b, r in sc.allowed_pairs]}
    try:
        allsc = monitor.Scene.from_model(model, pairs="all")
        mon = set(sc.candidate_pairs) | {(a, b) for a, b, _ in sc.allowed_pairs}
        out["in_pairs_all_not_candidates"] = len([p for p in allsc.candidate_pairs if p not in mon])
    except Exception as e:  # noqa: BLE001  (a report, not a verdict)
        out["pairs_all_error"] = f"{type(e).__name__}: {e}"
    return out


def workloads(quick: bool):
    """(name, runner) of every workload."""
    def n(r: int, h: int, b: int, huge: int = 2) -> dict:
        return {"random": r, "hold": h, "bang": b, "huge": huge}

    S = n(12, 12, 6) if quick else n(120, 60, 30)
    Sh = n(6, 6, 4) if quick else n(60, 45, 15)   # humanoids: expensive steps
    out = []
    for env_id in ["Reacher-v5", "Pusher-v5", "Ant-v5", "HalfCheetah-v5", "Hopper-v5", "Walker2d-v5",
                   "Swimmer-v5", "InvertedPendulum-v5", "InvertedDoublePendulum-v5", "Humanoid-v5",
                   "HumanoidStandup-v5"]:
        sched = Sh if env_id.startswith("Humanoid") else S
        out.append((env_id, lambda e=env_id, s=sched: run_gym(e, lambda: SafetyGate(gym.make(e)), s, 0)))
    logdir = Path(tempfile.mkdtemp(prefix="rt18-"))
    out.append(("monitor/Arm-v0 (logged)", lambda: run_gym(
        "monitor/Arm-v0 (logged)",
        lambda: SafetyGate(gym.make("monitor/Arm-v0"), log=str(logdir / "arm.mcap")),
        S, 1)))
    out.append(("monitor/Arm-v0 margin=5 mm (README example)", lambda: run_gym(
        "monitor/Arm-v0 margin=5 mm (README example)",
        lambda: SafetyGate(gym.make("monitor/Arm-v0"), on_violation="block", margin=0.005), S, 9)))
    out.append(("Pusher-v5 margin=1 cm", lambda: run_gym(
        "Pusher-v5 margin=1 cm", lambda: SafetyGate(gym.make("Pusher-v5"), margin=0.01), S, 10)))
    out.append(("Arm-v0 on_violation=warn (oracle control)", lambda: run_gym(
        "Arm-v0 on_violation=warn (oracle control)",
        lambda: SafetyGate(gym.make("monitor/Arm-v0"), on_violation="warn"), n(0, 8, 2) if quick
        else n(0, 60, 15), 8)))
    out.append(("Pusher-v5 pairs=mujoco", lambda: run_gym(
        "Pusher-v5 pairs=mujoco", lambda: SafetyGate(gym.make("Pusher-v5"), pairs="mujoco"), S, 2)))
    out.append(("Ant-v5 Clip(Rescale)+NormObs, over-range", lambda: run_gym(
        "Ant-v5 Clip(Rescale)+NormObs, over-range",
        lambda: SafetyGate(gym.wrappers.NormalizeObservation(gym.wrappers.ClipAction(
            gym.wrappers.RescaleAction(gym.make("Ant-v5"), -0.5, 0.5)))), S, 3, over=3.0)))
    out.append(("Arm-v0 Clip(Rescale(-1,1)), over-range", lambda: run_gym(
        "Arm-v0 Clip(Rescale(-1,1)), over-range",
        lambda: SafetyGate(gym.wrappers.ClipAction(gym.wrappers.RescaleAction(gym.make("monitor/Arm-v0"),
                                                                             -1.0, 1.0))), S, 4, over=2.0)))
    out.append(("Hopper-v5 frame_skip=2 then 7", lambda: run_gym(
        "Hopper-v5 frame_skip=2 then 7", lambda: SafetyGate(gym.make("Hopper-v5", frame_skip=2)), S, 5,
        frame_skip_change=7)))

    def tunnel_reset(m, d):
        mujoco.mj_resetDataKeyframe(m, d, 0)

    out.append(("Gate.step models/tunnel (margin 1 mm)", lambda: run_plain(
        "Gate.step models/tunnel (margin 1 mm)", "tunnel", n(40, 30, 10) if quick else n(300, 150, 50), 6,
        1, tunnel_reset, margin=0.001)))
    out.append(("Gate.step models/hand30", lambda: run_plain(
        "Gate.step models/hand30", "hand30", n(6, 4, 2) if quick else n(40, 30, 10), 7, 5,
        lambda m, d: mujoco.mj_resetData(m, d))))
    return out


def main(argv=None) -> int:
    """Run the workloads; print one line each."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps (< 3 min on this machine)")
    ap.add_argument("--only", default=None, help="run workloads whose name contains this")
    ap.add_argument("--json", default=None, help="write per-workload counts and details here")
    ap.add_argument("--seed-offset", type=int, default=0, help="added to every workload's seed")
    args = ap.parse_args(argv)
    SEED_OFFSET[0] = args.seed_offset
    from monitor.warmup import ensure_warm
    ensure_warm()
    t0 = time.perf_counter()
    allc = []
    for name, fn in workloads(args.quick):
        if args.only and args.only not in name:
            continue
        t = time.perf_counter()
        before = ONGOING_COUNT[0]
        cnt = fn()
        cnt.c["ongoing_threshold_audits"] = ONGOING_COUNT[0] - before
        allc.append(cnt)
        print(cnt.line() + f" ({time.perf_counter() - t:.1f} s)", flush=True)
        ctrl_ = {k: v for k, v in cnt.c.items() if "_oracle_" in k and "confirmed" not in k}
        if ctrl_:
            print("    oracle on applied windows that were not certified:", dict(sorted(ctrl_.items())))
        for d in cnt.details:
            if d["kind"] not in ("unresolved", "rows_quat_normalised"):
                print("   ", json.dumps(d, default=str))
    tot = sum(c.bad() for c in allc)
    print(f"(motion, pair) audits at the ongoing-contact threshold -penetration_tol: {ONGOING_COUNT[0]}")
    agg = collections.Counter()
    for c in allc:
        agg.update(c.c)
    print(f"TOTAL workloads={len(allc)} steps={agg['steps']} windows_audited={agg['win_audited']} "
          f"tails_audited={agg['tail_audited']} findings={agg['finding']} unresolved={agg['unresolved']} "
          f"irregular={tot} wall={time.perf_counter() - t0:.0f} s")
    if args.json:
        Path(args.json).write_text(json.dumps(
            [{"name": c.name, "counts": dict(c.c), "details": c.details,
              "pairs": getattr(c, "pairs_info", {}),
              "unmonitored_contacts": dict(c.unmonitored_contacts.most_common(20)),
              "min_slack_m": c.min_margin} for c in allc], indent=1, default=str))
    return 1 if tot else 0


if __name__ == "__main__":
    sys.exit(main())
