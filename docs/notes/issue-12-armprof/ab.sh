#!/bin/bash
# Interleaved processes, base tree vs this tree: bash docs/notes/issue-12-armprof/ab.sh BASE NEW ENV PAIRS GSTEPS USTEPS REPS
# Prints one JSON line per process, prefixed by "base" / "new"; the order alternates each pair.
BASE=$1; NEW=$2; ENV=$3; PAIRS=$4; GS=${5:-30}; US=${6:-1000}; REPS=${7:-5}
PY=/work/main/.venv/bin/python
HERE=$(cd "$(dirname "$0")" && pwd)
for i in $(seq 1 "$PAIRS"); do
  if (( i % 2 )); then order="base new"; else order="new base"; fi
  for w in $order; do
    if [ "$w" = base ]; then T=$BASE; else T=$NEW; fi
    echo "$w $(cd /tmp && PYTHONPATH=$T $PY "$HERE/ab_one.py" "$ENV" "$GS" "$US" "$REPS" 2>/dev/null | tail -1)"
  done
done
