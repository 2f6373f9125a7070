#!/bin/bash
# Alternate BASE / NEW trees: N pairs of the bench's own start-up script (startup.py: a fresh
# empty NUMBA_CACHE_DIR per cold run, then one warm process on the same cache); one JSON line per run.
# Usage: bash ab.sh N OUT BASE_TREE NEW_TREE   (BASE_TREE e.g. a `git archive ff8b94e | tar -x` copy)
N=${1:-2}; OUT=${2:-ab.txt}; BASE=${3:?base tree}; NEW=${4:?new tree}
HERE=$(cd "$(dirname "$0")" && pwd)
for i in $(seq "$N"); do
  for t in "$BASE" "$NEW"; do
    date -u +%H:%M:%S | tr '\n' ' ' >> "$OUT"
    /work/main/.venv/bin/python "$HERE/startup.py" "$t" >> "$OUT"
  done
done
echo END >> "$OUT"
