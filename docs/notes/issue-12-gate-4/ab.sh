#!/bin/bash
# Interleaved before/after: main, this tree, main, this tree (one process each; ratios to ungated in the same process).
# usage: bash docs/notes/issue-12-gate-4/ab.sh "Pusher-v5 100 3" [rounds]
S=$(cd "$(dirname "$0")" && pwd)/split.py
TREE=$(cd "$(dirname "$0")/../../.." && pwd)
for r in $(seq ${2:-2}); do
  for t in /work/main "$TREE"; do (cd "$t" && PYTHONPATH="$t" /work/main/.venv/bin/python "$S" $1); done
done
