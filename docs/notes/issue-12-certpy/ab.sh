#!/bin/bash
# Alternate base / branch processes of one script: ab.sh BASE_TREE BRANCH_TREE PAIRS SCRIPT [ARGS...]
# e.g. docs/notes/issue-12-certpy/ab.sh /tmp/certpy/base $PWD 8 docs/notes/issue-12-certpy/tun_cpu.py 5
base=$1; new=$2; pairs=$3; script=$(readlink -f $4); shift 4
for i in $(seq 1 $pairs); do
  for t in $base $new; do
    (cd $t && PYTHONPATH=$t /work/main/.venv/bin/python $script "$@" 2>&1 | grep -E "^(CPU|TUN|GYM|REPLAY)")
  done
done
