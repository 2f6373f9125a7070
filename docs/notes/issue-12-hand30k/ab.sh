#!/bin/bash
# Alternate BASE / NEW processes: the hand30 gated/ungated ratio (issue-12-tail-design/ratios.py:
# gated and ungated blocks interleaved in one process, thread time) and the isolated joint certify
# (certab.py on the captured plans of capture.py).
# Usage: bash ab.sh PAIRS OUT BASE_TREE NEW_TREE JOINT_PKL   (BASE_TREE: a `git archive ca04081` copy)
N=$1; OUT=$2; BASE=$3; NEW=$4; PKL=$5
HERE=$(cd "$(dirname "$0")" && pwd)
X=$HERE/../issue-12-tail-design
for i in $(seq "$N"); do
  for t in "$BASE" "$NEW"; do
    echo "== $(date -u +%H:%M:%S) $t load $(cut -d' ' -f1 /proc/loadavg)" >> "$OUT"
    (cd /tmp && PYTHONPATH=$t:$X /work/main/.venv/bin/python "$X/ratios.py" hand30 9 0.25 | grep RATIOS >> "$OUT")
    (cd /tmp && PYTHONPATH=$t /work/main/.venv/bin/python "$HERE/certab.py" "$PKL" 5 | grep CERT >> "$OUT")
  done
done
echo END >> "$OUT"
