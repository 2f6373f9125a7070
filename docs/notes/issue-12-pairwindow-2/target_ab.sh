#!/bin/bash
# The bench's pair-window target row (target_row.py) for two trees, alternated:
# bash target_ab.sh TREE_A TREE_B ROUNDS
A=$1; B=$2; N=${3:-2}
PY=/work/main/.venv/bin/python
HERE=$(cd "$(dirname "$0")" && pwd)
for i in $(seq "$N"); do
  echo -n "A ($A): "; PYTHONPATH=$A $PY "$HERE/target_row.py"
  echo -n "B ($B): "; PYTHONPATH=$B $PY "$HERE/target_row.py"
done
