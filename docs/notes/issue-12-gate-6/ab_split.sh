#!/bin/bash
# Interleaved A/B of split.py (thread time per part): BASE and NEW trees, PAIRS alternated pairs per workload.
# usage: BASE=/tmp/gate6/base NEW=$PWD bash docs/notes/issue-12-gate-6/ab_split.sh PAIRS
PY=/work/main/.venv/bin/python
S=docs/notes/issue-12-gate-4/split.py
for w in "Pusher-v5 100 3" "monitor/Arm-v0 60 3" "tunnel 400 3"; do
  for i in $(seq 1 "$1"); do
    for t in "$BASE" "$NEW"; do
      PYTHONPATH=$t $PY $S $w 2>/dev/null | grep -v Warn
    done
  done
done
