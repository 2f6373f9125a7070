"""Benchmarks: run time against error, peers, seed reproductions, gate overhead, scaling, review cost.

Run with ``python -m monitor bench [--quick] [--out DIR] [--suite NAME ...]``.

Modules:

* :mod:`monitor.bench.cases`: the fixed, seeded pair-window case set (two convex
  bodies, one lerp/slerp segment each), its MJCF scenes and exact motions.
* :mod:`monitor.bench.oracle`: the independent oracle (adaptive dense time sampling
  of the static distance with an analytic Lipschitz margin; exact LP for translations).
* :mod:`monitor.bench.peers`: python-fcl ``continuousCollide``, MuJoCo sampling with
  ``mj_geomDistance`` and ipctk Tight-Inclusion CCD, each import-guarded.
* :mod:`monitor.bench.suites`: the six suites; each returns a JSON-serialisable dict.
* :mod:`monitor.bench.report`: machine info, ``results.json``, ``results.md`` and the plots.

Timing rules: medians of interleaved repetitions, ratios measured in the same run,
never one absolute time.
"""

from __future__ import annotations

SUITES = ("accuracy", "peers", "seeds", "gate", "scaling", "review", "targets")
"""Suite names accepted by ``--suite`` (in run order)."""

__all__ = ["SUITES"]
