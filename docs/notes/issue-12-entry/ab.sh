#!/bin/bash
# Interleaved A/B of entry_bench.py: old tree (/work/main) vs this worktree, ROUNDS rounds each.
# Usage: bash docs/notes/issue-12-entry/ab.sh [rounds] [reps]  (prints one JSON line per run)
ROUNDS=${1:-3}; REPS=${2:-300}
HERE=$(cd "$(dirname "$0")/../../.." && pwd)
PY=/work/main/.venv/bin/python
cd /tmp
for r in $(seq "$ROUNDS"); do
  for tree in /work/main "$HERE"; do
    echo "$tree $(PYTHONPATH=$tree $PY "$HERE/docs/notes/issue-12-entry/entry_bench.py" "$REPS" 2>/dev/null | tail -1)"
  done
done
