#!/bin/bash
# usage: BASE=<copy of cd87859> NEW=<this tree> OUT=results.jsonl ./run_ab.sh
# interleaved A/B: base (cd87859 copy) vs this tree, alternating processes
out=${OUT:-ab_results.jsonl}
for i in 1 2 3 4; do
  for w in pusher arm hand30; do
    for t in $BASE $NEW; do
      echo "{\"round\": $i, \"mode\": \"gate\", \"w\": \"$w\", \"r\": $(PYTHONPATH=$t timeout 900 /work/main/.venv/bin/python $(dirname $0)/ab.py gate $w 7 2>/dev/null | tail -n 1)}" >> $out
    done
  done
  for w in pusher arm hand30; do
    for t in $BASE $NEW; do
      echo "{\"round\": $i, \"mode\": \"replay\", \"w\": \"$w\", \"r\": $(PYTHONPATH=$t timeout 900 /work/main/.venv/bin/python $(dirname $0)/ab.py replay $w 30 5 2>/dev/null | tail -n 1)}" >> $out
    done
  done
done
echo done >> $out
