#!/usr/bin/env bash
# Set up a venv and run the fast test suite (the README's second quick-start command).
# pytest exit code 5 (no tests collected) is a failure, not a pass.
#
# The suite runs on every core (pytest-xdist, TEST_WORKERS=auto; TEST_WORKERS=0 runs it in one
# process). The numba kernels compile once (`monitor warmup`: with an empty cache about 50 s of
# CPU, spread over two processes for the independent kernels) in the background while pip
# installs the test tools and ruff runs; pytest starts when it is done, so its workers load
# the cached code at once instead of idling on a compile (tests/conftest.py still takes the
# same lock file before each worker's own warm-up).
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
warm_done=0
finish_warmup() {  # wait for the background compile; show its output if it failed (not fatal: tests compile)
    [ "$warm_done" = 0 ] || return 0
    warm_done=1
    wait "$warm_pid"; local warm_rc=$?
    if [ "$warm_rc" -eq 0 ]; then
        grep -E "^  child |kernels ready" "$WARM_LOG"
    elif [ "$warm_rc" -ne 143 ]; then
        echo "monitor warmup failed ($warm_rc):"; cat "$WARM_LOG"
    fi
    rm -f "$WARM_LOG"
}
stop_warmup() {  # never leave the background compile (or its child processes) running
    if [ "$warm_done" = 0 ]; then
        pkill -TERM -P "$warm_pid" 2>/dev/null
        kill "$warm_pid" 2>/dev/null
        finish_warmup
    fi
}
trap stop_warmup EXIT

# The test extra's own requirements (not `-e .[test]`: that would reinstall the package under the compile).
"$VENV/bin/python" -c 'import tomllib; print("\n".join(tomllib.load(open("pyproject.toml", "rb"))
    ["project"]["optional-dependencies"]["test"]))' >"$WARM_LOG.req" || exit 1
"$VENV/bin/python" -m pip install -q --no-compile -r "$WARM_LOG.req" || { rm -f "$WARM_LOG.req"; exit 1; }
rm -f "$WARM_LOG.req"
"$VENV/bin/python" -m ruff check monitor envs tests || exit 1
warm_t0=$SECONDS
finish_warmup
echo "monitor warmup finished; waited $((SECONDS - warm_t0)) s for it after installing and linting"
if [ "$WORKERS" = 0 ]; then
    "$VENV/bin/python" -m pytest -q -m "not slow" --durations=15 "$@"
else
    "$VENV/bin/python" -m pytest -q -m "not slow" --durations=15 -n "$WORKERS" --dist loadgroup --no-loadscope-reorder "$@"
fi
rc=$?
if [ "$rc" -eq 5 ]; then echo "pytest collected no tests: failing"; exit 1; fi
exit "$rc"
