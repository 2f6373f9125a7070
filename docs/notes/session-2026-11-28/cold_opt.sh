#!/bin/bash
# Cold first certify (the bench's start-up script, empty numba cache) under NUMBA_OPT=$1.
# usage: bash cold_opt.sh OPT   (run from a checkout; prints user s, sys s, wall s, then the script's START line)
tree=$(cd "$(dirname "$0")/../../.." && pwd)
work=$(mktemp -d)
"$tree/.venv/bin/python" - "$tree" "$work/start.py" <<'PY'
import re, sys
src = open(sys.argv[1] + "/monitor/bench/targets.py").read()
open(sys.argv[2], "w").write(re.search(r'_START_SCRIPT = r"""(.*?)"""', src, re.S).group(1))
PY
NUMBA_CACHE_DIR=$work/cache NUMBA_OPT=$1 PYTHONPATH=$tree /usr/bin/time -f "%U %S %e" \
    "$tree/.venv/bin/python" "$work/start.py" "$(date +%s.%N)" 2>"$work/err" | grep START
tail -1 "$work/err"
rm -rf "$work"
