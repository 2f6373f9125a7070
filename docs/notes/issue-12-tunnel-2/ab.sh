#!/bin/bash
# A/B interleaved: base tree vs this tree, $1 pairs of processes, $2 script (step.py / pusher)
# usage: bash docs/notes/issue-12-tunnel-2/ab.sh 3 docs/notes/issue-12-tunnel-2/step.py /tmp/h12ai_base
PY=/work/main/.venv/bin/python
HERE=$(cd "$(dirname "$0")/../../.." && pwd)
for i in $(seq "$1"); do
  echo "base $(cd "$3" && PYTHONPATH=$3 $PY "$HERE/$2" 5)"
  echo "mine $(cd "$HERE" && PYTHONPATH=$HERE $PY "$HERE/$2" 5)"
done
