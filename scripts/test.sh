#!/usr/bin/env bash
# Set up a venv and run the fast test suite (the README's second quick-start command).
# pytest exit code 5 (no tests collected) is a failure, not a pass.
#
# The suite runs on every core (pytest-xdist, TEST_WORKERS=auto; TEST_WORKERS=0 runs it in one
# process). The numba kernels compile once (`monitor warmup`: with an empty cache about 90 s of
# CPU, on two processes) in the background from right after the dependencies' install: beside
# the editable install, the test tools' install, ruff, and pytest's own start-up and collection; each pytest process then
# waits for it on the lock file (tests/conftest.py takes the same lock before its first test,
# outside any test's duration) and loads the cached code. The phase times are printed
# (docs/notes/issue-12-suite-time.md).
set -uo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
VENV=${VENV:-.venv}
WORKERS=${TEST_WORKERS:-auto}
# one BLAS thread per process: the workers already use every core (tests/conftest.py does the same)
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} \
    MKL_NUM_THREADS=${MKL_NUM_THREADS:-1}
t_start=$SECONDS
[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV" || exit 1
# pip >= 21.3 installs a pyproject.toml project in editable mode (PEP 660): upgrade only an older pip
"$VENV/bin/python" -c 'import pip, sys; sys.exit(tuple(map(int, pip.__version__.split(".")[:2])) < (21, 3))' \
    2>/dev/null || "$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null 2>&1
requirements() {  # one requirement list of pyproject.toml, one a line: "dependencies" or an extra's name
    "$VENV/bin/python" -c 'import sys, tomllib; p = tomllib.load(open("pyproject.toml", "rb"))["project"]
print("\n".join(p["dependencies"] if sys.argv[1] == "dependencies" else p["optional-dependencies"][sys.argv[1]]))' "$1"
}
WARM_LOG=$(mktemp)
# the runtime dependencies first, so the warm-up can start beside the editable install (its own
# build environment); --no-compile: byte-code is written on first import instead (only what runs)
requirements dependencies >"$WARM_LOG.req" || exit 1
"$VENV/bin/python" -m pip install -q --no-compile -r "$WARM_LOG.req" || { rm -f "$WARM_LOG.req"; exit 1; }

# Same lock file as tests/conftest.py: next to numba's cache.
LOCK_DIR=${NUMBA_CACHE_DIR:-monitor/__pycache__}
mkdir -p "$LOCK_DIR" || exit 1
t_install=$SECONDS
# imports this tree's monitor (PYTHONPATH: the editable install is not there yet; same source files,
# so the same numba cache entries); prints "lock held" once it has the lock, and its end time when done
PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" "$VENV/bin/python" -c 'import fcntl, sys, time
lock = open(sys.argv[1], "a"); fcntl.flock(lock, fcntl.LOCK_EX)
print("monitor-warmup: lock held", flush=True)
from monitor.cli import main; rc = main(["warmup"]); print(f"monitor-warmup: ended {time.time():.1f}", flush=True)
sys.exit(rc)' "$LOCK_DIR/monitor-warmup.lock" >"$WARM_LOG" 2>&1 &
warm_pid=$!
warm_done=0
finish_warmup() {  # wait for the background compile; show its output if it failed (not fatal: tests compile)
    [ "$warm_done" = 0 ] || return 0
    warm_done=1
    wait "$warm_pid"; local warm_rc=$?
    if [ "$warm_rc" -eq 0 ]; then
        grep -E "^  child |kernels ready" "$WARM_LOG"
        local ended
        ended=$(sed -n 's/^monitor-warmup: ended //p' "$WARM_LOG")
        [ -z "$ended" ] || [ -z "${pytest_t0:-}" ] || echo "monitor warmup ended $(awk -v a="$ended" -v b="$pytest_t0" \
            'BEGIN { printf "%.0f", a - b }') s after pytest started (its processes start and collect meanwhile)"
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

"$VENV/bin/python" -m pip install -q --no-compile --no-deps -e . || { rm -f "$WARM_LOG.req"; exit 1; }
# The test extra's own requirements (not `-e .[test]`: that would reinstall the package under the compile).
requirements test >"$WARM_LOG.req" || exit 1
"$VENV/bin/python" -m pip install -q --no-compile -r "$WARM_LOG.req" || { rm -f "$WARM_LOG.req"; exit 1; }
rm -f "$WARM_LOG.req"
"$VENV/bin/python" -m ruff check monitor envs tests || exit 1
# pytest must not take the lock before the warm-up has it (its processes would compile themselves)
for _ in $(seq 600); do
    grep -q "^monitor-warmup: lock held" "$WARM_LOG" 2>/dev/null && break
    kill -0 "$warm_pid" 2>/dev/null || break
    sleep 0.1
done
echo "test.sh: venv and dependencies $((t_install - t_start)) s; editable install, test tools and ruff" \
    "$((SECONDS - t_install)) s (beside the warm-up); pytest starts while the warm-up finishes"
pytest_t0=$(date +%s.%N)
pytest_s=$SECONDS
if [ "$WORKERS" = 0 ]; then
    "$VENV/bin/python" -m pytest -q -m "not slow" --durations=15 "$@"
else
    "$VENV/bin/python" -m pytest -q -m "not slow" --durations=15 -n "$WORKERS" --dist loadgroup --no-loadscope-reorder "$@"
fi
rc=$?
echo "test.sh: pytest $((SECONDS - pytest_s)) s; whole script $((SECONDS - t_start)) s"
finish_warmup
if [ "$rc" -eq 5 ]; then echo "pytest collected no tests: failing"; exit 1; fi
exit "$rc"
