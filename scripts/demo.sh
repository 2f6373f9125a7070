#!/usr/bin/env bash
# Set up a venv with a regular (non-editable) install and run the demo
# (the README's first quick-start command).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
PY=${PYTHON:-python3}
VENV=${VENV:-$ROOT/.venv-demo}
[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null 2>&1 || true
"$VENV/bin/python" -m pip install -q ".[foxglove,report]"   # report: matplotlib for review --report
# Run from outside the checkout so that the installed copy (with its packaged
# models/) is what runs, not the source tree.
cd "$(mktemp -d)"
"$VENV/bin/python" -m monitor warmup        # compile the certification kernels once (cached on disk)
"$VENV/bin/python" -m monitor demo --out "$ROOT/logs" "$@"
