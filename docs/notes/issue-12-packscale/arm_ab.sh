#!/bin/bash
# usage: BASE=<copy of cd87859> NEW=<this tree> OUT=arm_ab.jsonl ./arm_ab.sh
out=${OUT:-arm_ab.jsonl}
for i in 1 2 3; do
  for t in $NEW $BASE $BASE $NEW; do
    echo "{\"round\": $i, \"r\": $(PYTHONPATH=$t timeout 900 /work/main/.venv/bin/python $(dirname $0)/ab.py gate arm 7 2>/dev/null | tail -n 1)}" >> $out
  done
done
echo done >> $out
