#!/bin/bash
# interleaved A/B: base (ca04081) vs new (h16-replay), whole gate run in a fresh process each
cd /tmp
for i in 1 2 3 4 5 6; do
  for which in tunnel arm; do
    if [ $((i % 2)) = 1 ]; then order="base new"; else order="new base"; fi
    for t in $order; do
      if [ $t = base ]; then tree=/tmp/replay/base; else tree=/work/wt/replay; fi
      n=400; [ $which = arm ] && n=300
      echo "$i $t $(PYTHONPATH=$tree /work/main/.venv/bin/python /tmp/replay/bench_step.py $which $n /tmp/replay/ab_${t}_${which}.mcap 2>/dev/null | grep step_us)"
    done
  done
done
