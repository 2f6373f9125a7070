#!/bin/bash
# Alternated processes of docs/notes/session-2026-11-28-late/gate_ab.py (the bench's own gym_gate,
# tunnel_gate, hand30_gate) on two trees; one JSON line per process, tagged by side.
# Usage (from this tree's root): bash docs/notes/issue-12-gatepath/ab.sh BASE_TREE NEW_TREE PAIRS REPS > OUT
# (AB_SCRIPT=docs/notes/issue-12-gatepath/gate_ab_full.py runs the full-size blocks instead)
base=$1; new=$2; pairs=$3; reps=$4
script=$(pwd)/${AB_SCRIPT:-docs/notes/session-2026-11-28-late/gate_ab.py}
for i in $(seq 1 "$pairs"); do
  if [ $((i % 2)) -eq 1 ]; then order="base new"; else order="new base"; fi
  for side in $order; do
    if [ "$side" = base ]; then tree=$base; else tree=$new; fi
    echo "$side $i $(cd /tmp && PYTHONPATH=$tree /work/main/.venv/bin/python "$script" "$reps" 2>/dev/null)"
  done
done
