#!/bin/bash
# Alternate processes base / new, PAIRS times, each running packtime.py ARGS; one line per run.
# usage: BASE=/tmp/mpack/base NEW=/work/wt/mpack bash ab.sh PAIRS WORK STEPS [PASSES]
pairs=$1; shift
here=$(cd "$(dirname "$0")" && pwd)
for i in $(seq "$pairs"); do
  for tree in "$BASE" "$NEW"; do
    tag=$([ "$tree" = "$NEW" ] && echo new || echo base)
    echo "$i $tag $(cd "$tree" && PYTHONPATH="$tree" /work/main/.venv/bin/python "$here/packtime.py" "$@" 2>&1 | tail -1)"
  done
done
