"""Issue 11 acceptance: domain randomisation never gets a colliding window certified.

A gymnasium MuJoCo env (the tunnel, subclassed so no wrapper sits between the gate and
the env) whose ``reset`` scales the wall's and the ball's sizes and moves the wall at
random, IN PLACE on the env's MjModel, as domain-randomisation code does. A
``SafetyGate`` runs 50 short episodes of random velocity commands, once with the strict
contract (``allowed=None, ongoing="violation"``) and once with the stock defaults (an
allowed-contact matrix and the ongoing-contact rule), each against its own oracle.

Oracle (independent of ``monitor``): the ball is a sphere on a slide joint and the wall an
axis-aligned box, so their signed distance is closed-form from the LIVE model arrays at
any sampled slide value. The window's motion is the linear interpolation of the slide
coordinate (the gate's rollout plan for ``frame_skip=1``); the centre moves
``|dx| / (n - 1)`` between consecutive samples and the signed distance is 1-Lipschitz
in the centre, so

* "collides": some sample has distance < 0 (a proof),
* "clear": every sample has distance > |dx| / (2 (n - 1)) (Lipschitz margin), a proof too.

Every window the gate certifies (proposed or applied) must not be "collides", and the
run must contain proposed windows that collide (else the test could not fail).
"""

from __future__ import annotations

import numpy as np
import pytest

from monitor.certify.ongoing import DEFAULT_PENETRATION_TOL
from monitor.envs.tunnel_v0 import TunnelEnv
from monitor.gym_gate import SafetyGate

N_SAMPLES = 257


class RandomisedTunnel(TunnelEnv):
    """Tunnel env whose reset randomises geom sizes and the wall position in place."""

    def __init__(self, seed: int = 0, **kwargs):
        super().__init__(**kwargs)
        m = self.model
        self._wall, self._ball = m.geom("wall").id, m.geom("ball").id
        self._size0 = np.array(m.geom_size, copy=True)
        self._pos0 = np.array(m.geom_pos, copy=True)
        self._bpos0 = np.array(m.body_pos, copy=True)
        self._dr = np.random.default_rng(seed)

    def reset_model(self) -> np.ndarray:
        m, rng = self.model, self._dr
        m.geom_size[self._wall] = self._size0[self._wall] * rng.uniform(0.5, 4.0, 3)
        m.geom_size[self._ball][0] = self._size0[self._ball][0] * rng.uniform(0.5, 4.0)
        # the wall geom sits at its body's frame (geom_sameframe BODY): MuJoCo ignores this geom_pos
        # edit; the body_pos edit moves it
        m.geom_pos[self._wall] = self._pos0[self._wall] + [rng.uniform(-0.03, 0.03), 0.0, 0.0]
        wall_body = m.geom_bodyid[self._wall]
        m.body_pos[wall_body] = self._bpos0[wall_body] + [rng.uniform(-0.03, 0.03), 0.0, 0.0]
        return super().reset_model()


def _ball_wall_distance(m, x: np.ndarray) -> np.ndarray:
    """Signed distance (m) of the ball (slide value x, (n,)) to the wall box, where MuJoCo puts them.

    The geom centres come from MuJoCo's own kinematics of the live model (``mj_kinematics`` at
    slide 0: a geom at its body's frame ignores ``geom_pos``, ``geom_sameframe``).
    """
    import mujoco

    wall, ball = m.geom("wall").id, m.geom("ball").id
    half = np.asarray(m.geom_size[wall], float)
    d = mujoco.MjData(m)
    d.qpos[:] = 0.0
    mujoco.mj_kinematics(m, d)
    c_wall = np.array(d.geom_xpos[wall])
    c = np.array(d.geom_xpos[ball])[None, :] + np.outer(x, [1.0, 0.0, 0.0])  # slide axis (1, 0, 0), unrotated
    q = np.abs(c - c_wall) - half
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    return outside + inside - float(m.geom_size[ball][0])


def _classify(m, x0: float, x1: float, rule: str = "strict") -> str:
    """"collides" is a proof that the window breaks the gate's contract under ``rule``.

    ``"strict"`` (``ongoing="violation"``): any contact (d < 0) anywhere in the window.
    ``"deepen"`` (the gate's default, :mod:`monitor.certify.ongoing`): a window that starts
    clear may not make contact; one that starts in contact (d(x0) <= 0, the margin being 0)
    may not reach a penetration deeper than ``DEFAULT_PENETRATION_TOL``.
    """
    x = np.linspace(x0, x1, N_SAMPLES)
    d = _ball_wall_distance(m, x)
    lip = abs(x1 - x0) / (2 * (N_SAMPLES - 1))
    floor = 0.0
    if rule == "deepen" and d[0] <= 0.0:
        floor = -DEFAULT_PENETRATION_TOL
    if (d < floor).any():
        return "collides"
    return "clear" if (d > floor + lip).all() else "ambiguous"


def _run(episodes: int, steps: int, seed: int, rule: str = "strict") -> dict[str, int]:
    env = RandomisedTunnel(seed=seed, x0=-0.09, reset_noise=0.05)
    # "strict": the plain certify contract; "deepen": the stock defaults (ACM "auto", ongoing contacts)
    gate = SafetyGate(env, allowed=None, ongoing="violation") if rule == "strict" else SafetyGate(env)
    m = env.unwrapped.model
    rng = np.random.default_rng(seed + 1)
    counts = {"windows": 0, "proposed_collides": 0, "proposed_certified": 0, "applied_certified": 0}
    for ep in range(episodes):
        gate.reset(seed=ep)
        for _ in range(steps):
            x_before = float(env.unwrapped.data.qpos[0])
            gate.step(np.array([rng.uniform(-6.0, 6.0)]))
            rep = gate.gate.last_report
            x_after = float(env.unwrapped.data.qpos[0])
            counts["windows"] += 1
            q = np.asarray(rep.plan.qpos)[:, 0]
            assert len(q) == 2  # frame_skip=1: one MuJoCo step, lerped
            proposed = _classify(m, float(q[0]), float(q[-1]), rule)
            if rule == "deepen":  # the wall pair is never allowed away: an allowed pair is listed
                assert not rep.certificate.allowed, rep.certificate.allowed
            counts["proposed_collides"] += proposed == "collides"
            if rep.verdict == "certified":
                counts["proposed_certified"] += 1
                assert proposed != "collides", (ep, q, m.geom_size[m.geom("ball").id])
            if rep.applied_verdict == "certified":
                counts["applied_certified"] += 1
                assert _classify(m, x_before, x_after, rule) != "collides", (ep, x_before, x_after)
    gate.close()
    return counts


@pytest.mark.parametrize("rule", ["strict", "deepen"])
def test_domain_randomised_tunnel_never_certifies_a_collision(rule):
    counts = _run(episodes=50, steps=4, seed=0, rule=rule)
    assert counts["proposed_collides"] >= 10, counts  # the run exercises real collisions
    assert counts["proposed_certified"] >= 20, counts  # and certifies clear ones


@pytest.mark.slow
def test_domain_randomised_tunnel_long():
    counts = _run(episodes=300, steps=8, seed=7)
    assert counts["proposed_collides"] >= 50, counts
