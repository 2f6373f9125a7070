#!/usr/bin/env bash
# Set up a venv and run the fast test suite (the README's second quick-start command).
# pytest exit code 5 (no tests collected) is a failure, not a pass.
set -uo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
VENV=${VENV:-.venv}
[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV" || exit 1
"$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null 2>&1
"$VENV/bin/python" -m pip install -q -e ".[test]" || exit 1
"$VENV/bin/python" -m ruff check monitor envs tests || exit 1
"$VENV/bin/python" -m pytest -q -m "not slow" "$@"
rc=$?
if [ "$rc" -eq 5 ]; then echo "pytest collected no tests: failing"; exit 1; fi
exit "$rc"
