"""Red team 7's forgery as files (genuine + forged, under /tmp/replay/demo), to review with the base and
this tree: the test's own forger (tests/test_review_replay.py). Run from the tree root."""
import sys
from pathlib import Path

sys.path.insert(0, "tests")
import test_review_replay as T  # noqa: E402

out = Path("/tmp/replay/demo")
out.mkdir(parents=True, exist_ok=True)
model, _ = T._bounce_log(out / "bounce.mcap")
print(T.forge_interior_rows(out / "bounce.mcap", model, out / "forged.mcap"), "written to", out)
