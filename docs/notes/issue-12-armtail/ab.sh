#!/bin/bash
# Interleaved before/after processes: BASE tree, this tree, BASE, this tree, ...
# usage: BASE=/tmp/armtail/base bash docs/notes/issue-12-armtail/ab.sh split "monitor/Arm-v0 60 3" ROUNDS
#        BASE=/tmp/armtail/base bash docs/notes/issue-12-armtail/ab.sh bench "brake 10 3" ROUNDS
# (BASE: a copy of the base commit, e.g. `git archive 1c16a97 | tar -x -C $BASE`, warmed up once)
D=$(cd "$(dirname "$0")" && pwd)
TREE=$(cd "$D/../../.." && pwd)
case "$1" in
  split) S="$TREE/docs/notes/issue-12-gate-4/split.py" ;;
  bench) S="$D/benchgym.py" ;;
esac
for r in $(seq ${3:-2}); do
  for t in "${BASE:?set BASE}" "$TREE"; do (cd "$t" && PYTHONPATH="$t" /work/main/.venv/bin/python "$S" $2 2>/dev/null); done
done
