"""Shared test fixtures and the suite's scheduling on several processes (keep small).

The fast suite runs on pytest-xdist workers (``scripts/test.sh`` passes ``-n``; plain
``pytest`` still runs in one process). Three things here make that safe and short:

* every test that uses a module-scoped fixture of its own module is put in one
  ``xdist_group`` per module (``--dist loadgroup``), so an expensive module fixture (a Ray
  instance, a wheel build, a set of logs) is built once, not once per worker;
* the longest single tests are collected first, so that no worker starts one of them while
  the other has already run out of work;
* each process compiles (or loads) the numba kernels once under a file lock before its first
  test (:func:`monitor.warmup.ensure_warm`), so two workers never write the same cache entries
  at the same time, and compilation is never inside a test's own budget; a wait for
  ``scripts/test.sh``'s background warm-up is not counted in any test's duration.
"""

from __future__ import annotations

import os
from pathlib import Path

# One BLAS thread per test process (before numpy loads; scripts/test.sh exports the same). With
# OpenBLAS's default threads, a 4x4 scipy expm in the screw oracle took 7-11 ms instead of 40 us
# on the 2-core machine once the threads had been woken (docs/notes/issue-12-tests.md).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import pytest  # noqa: E402

ASSETS = Path(__file__).resolve().parent / "assets"
"""Folder of the test MJCF scenes (tests/assets/*.xml)."""

LONG_FIRST = (
    "tests/test_accuracy.py::test_accuracy_1000_seeded_cases",
    "tests/test_screw.py::test_screw_certify_no_false_negatives_quick",
    "tests/test_envs.py::test_gate_keeps_arm_off_the_post_500_steps",
    "tests/test_plain_mujoco.py::test_example_gates_500_steps",
    "tests/test_extrusion_exact.py::test_verdicts_and_earliest_match_oracle",
    "tests/test_bezier_motion.py::test_bezier_certify_no_false_negatives_quick",
    "tests/test_window_kernel.py::test_same_pairs_as_the_python_pipeline_on_the_peers_cases",
    "tests/test_window_kernel.py::test_lazy_pairs_read_like_a_tuple",
    "tests/test_motion_bounds.py::test_random_chains_never_exceed_bound",
    "tests/test_extrusion_pipeline.py::test_null_set_path_issues_most_certificates_on_bench_cases",
    "tests/test_kernels.py::test_random_pairs_never_certify_a_collision",
)
"""Node ids (without parameters) of the longest fast tests, measured with ``--durations``
(docs/notes/issue-12-tests.md; the last five by CPU seconds per test, issue-12-suite-time.md):
they are scheduled first. An id that no longer exists is ignored; the order only changes which
worker runs what, never what runs."""


@pytest.fixture
def load_asset():
    """Return a loader ``name -> mujoco.MjModel`` for tests/assets/<name> (a fresh model per call)."""
    import mujoco

    def _load(name: str):
        return mujoco.MjModel.from_xml_path(str(ASSETS / name))

    return _load


def _warm_kernels_once() -> None:
    """Compile or load the certification kernels once per process, one process at a time.

    numba's cache writes each file atomically, but two processes compiling different
    signatures of one function at once can both claim the same data-file number; the
    exclusive lock makes the second worker wait and then load what the first one wrote.
    """
    import fcntl

    import monitor
    from monitor.warmup import ensure_warm

    # the lock file sits next to numba's cache; scripts/test.sh holds it while `monitor warmup` runs
    cache_dir = os.environ.get("NUMBA_CACHE_DIR") or Path(monitor.__file__).parent / "__pycache__"
    lock_path = Path(cache_dir) / "monitor-warmup.lock"
    lock_path.parent.mkdir(parents=True, exist_ok=True)
    with open(lock_path, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            ensure_warm()
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtestloop(session):
    """Warm the kernels in each test process after collection and before its first test.

    Here rather than in a fixture only, so that a wait for ``scripts/test.sh``'s warm-up (which
    runs beside pytest's start-up and collection) is not reported as the first test's setup.
    Not in the pytest-xdist controller (it runs no test) nor for ``--collect-only``.
    """
    controller = session.config.pluginmanager.has_plugin("dsession")
    if session.items and not controller and not session.config.option.collectonly:
        _warm_kernels_once()
    yield


@pytest.fixture(scope="session", autouse=True)
def _numba_kernels_warm():
    """The same, for a run that does not go through :func:`pytest_runtestloop` (cheap when warm)."""
    _warm_kernels_once()
    yield


def _uses_own_module_fixture(item: pytest.Item) -> bool:
    """True when ``item`` uses a module-scoped fixture defined in its own test module."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None or item.module is None:
        return False
    for defs in info.name2fixturedefs.values():
        for fdef in defs:
            if fdef.scope == "module" and getattr(fdef.func, "__module__", None) == item.module.__name__:
                return True
    return False


@pytest.hookimpl(tryfirst=True)  # before xdist reads the xdist_group marks
def pytest_collection_modifyitems(config, items):
    """Group module-fixture tests per module, put the longest tests first, skip ``slow``.

    ``@pytest.mark.slow`` tests are skipped unless a ``-m`` expression selects markers
    explicitly: ``pytest tests`` then stays CI-sized; ``pytest -m slow`` runs the sweeps.
    """
    rank = {nodeid: i for i, nodeid in enumerate(LONG_FIRST)}
    group_rank: dict[str, int] = {}
    group_of: dict[str, str] = {}
    for item in items:
        if _uses_own_module_fixture(item):
            group = group_of[item.nodeid] = item.module.__name__
            item.add_marker(pytest.mark.xdist_group(group))
            r = rank.get(item.nodeid.split("[")[0], len(rank))
            group_rank[group] = min(group_rank.get(group, len(rank)), r)

    def order(item: pytest.Item) -> int:
        """Long tests (with their module group) first, then the other groups, then the rest."""
        group = group_of.get(item.nodeid)
        if group is not None:
            return group_rank[group]
        return rank.get(item.nodeid.split("[")[0], len(rank) + 1)

    items.sort(key=order)  # stable: tests of equal rank keep their collection order
    if config.getoption("-m"):
        return
    skip = pytest.mark.skip(reason="slow sweep: run with -m slow (or python -m monitor bench)")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
