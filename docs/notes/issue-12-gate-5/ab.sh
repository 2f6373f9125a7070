#!/bin/bash
# Alternate processes base / new, PAIRS times, each running rows.py ROWS; JSON lines to stdout.
# usage: BASE=/tmp/gatepy/base NEW=/work/wt/gatepy bash ab.sh PAIRS ROW [ROW ...]
# (env GATE5_REPS / GATE5_GSTEPS / GATE5_USTEPS pass through to rows.py)
pairs=$1; shift
here=$(cd "$(dirname "$0")" && pwd)
for i in $(seq "$pairs"); do
  for tree in "$BASE" "$NEW"; do
    (cd "$tree" && PYTHONPATH="$tree" /work/main/.venv/bin/python "$here/rows.py" "$@" 2>/dev/null | sed "s|^|$i |")
  done
done
