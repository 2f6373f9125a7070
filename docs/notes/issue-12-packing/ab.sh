#!/bin/bash
# A/B, interleaved: bash ab.sh ROUNDS SCRIPT [ARGS...]  (old = /tmp/h12y_base: main bc78fcb via git archive)
# Prints each run's line prefixed with its tree.
R=$1; shift
NEW=$(cd "$(dirname "$0")/../../.." && pwd)
for r in $(seq "$R"); do
  for tree in /tmp/h12y_base "$NEW"; do
    echo "[$( [ "$tree" = "$NEW" ] && echo new || echo old )] $(PYTHONPATH=$tree /work/main/.venv/bin/python "$@" 2>&1 | tail -1)"
  done
done
