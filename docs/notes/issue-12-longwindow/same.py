"""Compare two dumps of analyse.py (``dump``): codes and result rows equal bit for bit (NaN == NaN)."""
import sys

import numpy as np

a, b = np.load(sys.argv[1]), np.load(sys.argv[2])
diff = [k for k in a.files if not np.array_equal(a[k], b[k], equal_nan=True)]
print(f"{len(a.files) // 2} windows, arrays differing: {len(diff)}", diff[:8])
