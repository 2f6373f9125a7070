#!/bin/bash
# Alternating processes base / new: the tail-design ratios.py (gated / ungated, thread time, same process).
# usage: BASE=<base tree> NEW=<this tree> bash ab_steps.sh PAIRS REPS WORK VARIANT...
pairs=$1; reps=$2; work=$3; shift 3
X=$NEW/docs/notes/issue-12-tail-design
for i in $(seq "$pairs"); do
  for T in "$BASE" "$NEW"; do
    tag=new; [ "$T" = "$BASE" ] && tag=base
    echo -n "$tag $i "
    PYTHONPATH=$T:$X /work/main/.venv/bin/python "$X/ratios.py" "$work" "$reps" "$@" 2>/dev/null | grep RATIOS
  done
done
