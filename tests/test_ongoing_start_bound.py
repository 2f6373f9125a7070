"""``deepen`` taking the window kernel's start-pose bound (``ongoing._START_BOUND``, issue 12 tunnel).

Oracles: the bound against the exact distance at t0 (closed form on the tunnel: a sphere on a
slide joint in front of a box face; ``shape_distance_batch`` bounds on the seeded translating
cases), and ``deepen`` measuring every pair with ``shape_distance`` (``_START_BOUND = False``) on
the same inputs: the same certificates (``to_dict()`` without ``wall_seconds``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from monitor.certify import ongoing
from monitor.certify.engine import certify

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _switch_cases import cert_key as _key  # noqa: E402
from _switch_cases import on_and_off, tunnel_gate_keys  # noqa: E402


def _both(run):
    return on_and_off(ongoing, "_START_BOUND", run)


def _bounds(cert) -> dict | None:
    return ongoing._start_lower(cert)


def test_start_bound_is_a_lower_bound_of_the_start_distance():
    """Seeded translating cases (incl. start-inside and grazing): shape_distance's lower - 1e-9 m <=
    kernel bound <= shape_distance's upper at t0, for every pair the kernel did not cull."""
    from monitor.bench.cases import make_translating_cases

    n = 0
    for case in make_translating_cases(80, seed0=300):
        cert = certify(case.scene(), case.body_motion(), margin=case.margin, method="auto")
        known = _bounds(cert)
        if not known:
            continue
        lo_sd, up_sd = case.distance_bounds(np.array([case.times[0]]))
        for lo in known.values():
            if np.isnan(lo):
                continue
            assert lo <= up_sd[0] + 1e-12, case.name
            assert lo >= lo_sd[0] - 1e-9, case.name
            n += 1
    assert n > 40


def test_same_certificates_on_translating_cases():
    """60 seeded cases (start-inside, within margin, new contacts), ongoing="deepen", auto and extrusion,
    two penetration tolerances: identical certificates with and without the kernel's bound."""
    from monitor.bench.cases import make_translating_cases

    ongoing_seen = 0
    for case in make_translating_cases(60, seed0=400):
        scene, motion = case.scene(), case.body_motion()
        for method in ("auto", "extrusion"):
            for tol in (0.005, 0.05):
                def run(scene=scene, motion=motion, margin=case.margin + 0.01, method=method, tol=tol):
                    return certify(scene, motion, margin=margin, method=method, ongoing="deepen",
                                   penetration_tol=tol)

                a, b = _both(run)
                assert _key(a) == _key(b), (case.name, method, tol)
                ongoing_seen += a.stats.get("ongoing", 0)
    assert ongoing_seen > 10


def test_tunnel_gate_same_certificates_and_closed_form_bound():
    """models/tunnel, plain Gate.step (ongoing "deepen"): the same certificate at every step; every
    start bound within 1e-9 m below the closed-form start distance |x0| - 0.005 - 0.01."""
    pytest.importorskip("mujoco")
    from monitor.certify import engine

    seen: list = []
    real = engine.deepen

    def spy(certify_fn, scene, plan, cert, **kw):
        known = ongoing._start_lower(cert)
        if known:
            x0 = float(plan.body_poses(np.array([cert.window[0]]))[0][0, scene.geom("ball").body_id, 0])
            seen.append((x0, list(known.values())))
        return real(certify_fn, scene, plan, cert, **kw)

    engine.deepen = spy
    try:
        a, b = _both(tunnel_gate_keys)
    finally:
        engine.deepen = real
    assert a == b
    assert len(seen) > 10
    for x0, los in seen:
        exact = abs(x0) - 0.005 - 0.01
        for lo in los:
            assert exact - 1e-9 <= lo <= exact
