#!/usr/bin/env bash
# Set up a venv and run the fast test suite (the README's second quick-start command).
# pytest exit code 5 (no tests collected) is a failure, not a pass.
#
# The suite runs on every core (pytest-xdist, TEST_WORKERS=auto; TEST_WORKERS=0 runs it in one
# process). The numba kernels compile once (`monitor warmup`, about a minute of one core with
# an empty cache) in the background while pip installs the test tools and pytest collects;
# tests/conftest.py makes each worker wait on the same lock file and then load the cached code.
set -uo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
VENV=${VENV:-.venv}
WORKERS=${TEST_WORKERS:-auto}
# one BLAS thread per process: the workers already use every core (tests/conftest.py does the same)
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} \
    MKL_NUM_THREADS=${MKL_NUM_THREADS:-1}
[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV" || exit 1
"$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null 2>&1
# --no-compile: byte-code is written on first import instead (only what the tests import; 40 -> 22 s)
"$VENV/bin/python" -m pip install -q --no-compile -e . || exit 1

# Same lock file as tests/conftest.py: next to numba's cache.
LOCK_DIR=${NUMBA_CACHE_DIR:-monitor/__pycache__}
mkdir -p "$LOCK_DIR" || exit 1
WARM_LOG=$(mktemp)
"$VENV/bin/python" -c 'import fcntl, sys; lock = open(sys.argv[1], "a"); fcntl.flock(lock, fcntl.LOCK_EX)
from monitor.cli import main; sys.exit(main(["warmup"]))' "$LOCK_DIR/monitor-warmup.lock" >"$WARM_LOG" 2>&1 &
warm_pid=$!
finish() {  # never leave the background compile running; show its output if it failed
    kill "$warm_pid" 2>/dev/null
    wait "$warm_pid"; local warm_rc=$?
    [ "$warm_rc" -eq 0 ] || [ "$warm_rc" -eq 143 ] || { echo "monitor warmup failed ($warm_rc):"; cat "$WARM_LOG"; }
    rm -f "$WARM_LOG"
}
trap finish EXIT

# The test extra's own requirements (not `-e .[test]`: that would reinstall the package under the compile).
"$VENV/bin/python" -c 'import tomllib; print("\n".join(tomllib.load(open("pyproject.toml", "rb"))
    ["project"]["optional-dependencies"]["test"]))' >"$WARM_LOG.req" || exit 1
"$VENV/bin/python" -m pip install -q --no-compile -r "$WARM_LOG.req" || { rm -f "$WARM_LOG.req"; exit 1; }
rm -f "$WARM_LOG.req"
"$VENV/bin/python" -m ruff check monitor envs tests || exit 1
if [ "$WORKERS" = 0 ]; then
    "$VENV/bin/python" -m pytest -q -m "not slow" --durations=15 "$@"
else
    "$VENV/bin/python" -m pytest -q -m "not slow" --durations=15 -n "$WORKERS" --dist loadgroup --no-loadscope-reorder "$@"
fi
rc=$?
if [ "$rc" -eq 5 ]; then echo "pytest collected no tests: failing"; exit 1; fi
exit "$rc"
