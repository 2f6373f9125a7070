import sys, json
sys.path.insert(0, "tests")
from pathlib import Path
from test_review_replay import _forge, _verify
from monitor.log import topics
out = Path("/tmp/rt11"); src = out / "bounce.mcap"
which = sys.argv[1]
rec = {"window": 3, "fields": {}}
if which == "qposadr": rec["fields"]["jnt_qposadr"] = {"shape": [1], "values": [100000000]}
if which == "bodyparent": rec["fields"]["body_parentid"] = {"shape": [3], "values": [0, 0, 1000000]}
if which == "integrator": rec["options"] = {"integrator": 99}
if which == "iters": rec["options"] = {"iterations": 10**9, "tolerance": 0.0, "ls_iterations": 10**9, "ls_tolerance": 0.0}
if which == "timestep0": rec["options"] = {"timestep": 0.0}
if which == "condim": rec["fields"]["geom_condim"] = {"shape": [2], "values": [100, 100]}
if which == "dofadr": rec["fields"]["jnt_dofadr"] = {"shape": [1], "values": [-5]}
def meta(name, v):
    return v
# append a model edit metadata record: use rewrite's metadata hook can't add; use msg? model edits are metadata records
from mcap_rewrite import rewrite
import mcap_rewrite
from monitor.log.writer import encode_metadata
orig = mcap_rewrite.Writer
class W(orig):
    def finish(self):
        self.add_metadata(topics.METADATA_MODEL_EDIT, encode_metadata(rec))
        super().finish()
mcap_rewrite.Writer = W
_forge(src, out / f"E_{which}.mcap")
import time; t = time.perf_counter()
code, ver = _verify(out / f"E_{which}.mcap", trust_model_edits=True)
print(which, code, time.perf_counter() - t, [(f["severity"], f["index"], f["reason"][:200]) for f in ver["findings"]][:4], flush=True)
