#!/bin/bash
# Alternated processes of the bench's gate functions (docs/notes/session-2026-11-28-late/gate_ab.py) on two trees.
# Usage (from this tree's root): bash docs/notes/issue-12-gatechecks/ab.sh BASE_TREE NEW_TREE PAIRS REPS > out.jsonl
# One JSON line per process (gate_ab.py's: tree, per workload ratio, gated_us, ungated_us); pair i runs
# base then new for even i, new then base for odd i. Summarise with summ.py.
base=$1; new=$2; pairs=$3; reps=$4
for i in $(seq 0 $((pairs - 1))); do
  if [ $((i % 2)) -eq 0 ]; then order="$base $new"; else order="$new $base"; fi
  for t in $order; do
    PYTHONPATH=$t /work/main/.venv/bin/python docs/notes/session-2026-11-28-late/gate_ab.py "$reps" 2>/dev/null | tail -1
  done
done
