#!/bin/bash
# Interleaved A/B of entry_bench.py: the old tree (main 691a867, exported to $OLD) vs this worktree.
# Usage: bash docs/notes/issue-12-entry/ab.sh [rounds] [reps]  (prints one JSON line per run)
# The first run of a fresh $OLD compiles its numba kernels (a few minutes).
ROUNDS=${1:-3}; REPS=${2:-300}
HERE=$(cd "$(dirname "$0")/../../.." && pwd)
OLD=${OLD:-/tmp/h12r_base}
PY=/work/main/.venv/bin/python
if [ ! -d "$OLD/monitor" ]; then mkdir -p "$OLD" && git -C "$HERE" archive 691a867 | tar -x -C "$OLD"; fi
cd /tmp
for r in $(seq "$ROUNDS"); do
  for tree in "$OLD" "$HERE"; do
    echo "$tree $(PYTHONPATH=$tree $PY "$HERE/docs/notes/issue-12-entry/entry_bench.py" "$REPS" 2>/dev/null | tail -1)"
  done
done
