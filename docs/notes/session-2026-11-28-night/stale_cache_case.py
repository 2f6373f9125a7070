import sys
sys.path.insert(0,'tests')
from test_window_kernel import _fingers
import monitor
m,s,p=_fingers(0.07,0.02)
c=monitor.certify(s,p,epsilon=1e-3,method="toleranced")
print(c.pairs[0].method, c.stats.get("pairs_culled"), {k:v for k,v in c.stats.items() if 'wall' not in k})
