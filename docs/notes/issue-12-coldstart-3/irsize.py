"""Per-function size of numba's unoptimised LLVM IR from a NUMBA_DUMP_LLVM=1 run of trace.py.

Run: NUMBA_DUMP_LLVM=1 NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=<tree> python trace.py > dump.txt
     python irsize.py dump.txt
"""
import re
import sys

txt = open(sys.argv[1]).read()
parts = re.split(r'\n-+LLVM DUMP (.*?)-+\n', txt)
rows = []
for i in range(1, len(parts), 2):
    name, body = parts[i], parts[i + 1]
    rows.append((body.count('\n'), body.count('extractvalue'), body.count('NRT_incref') + body.count('NRT_decref'),
                 name[:80]))
rows.sort(reverse=True)
print("total IR lines", sum(r[0] for r in rows), "functions", len(rows))
print("lines  extractvalue  NRT-calls  function")
for r in rows[:int(sys.argv[2]) if len(sys.argv) > 2 else 15]:
    print(*r)
