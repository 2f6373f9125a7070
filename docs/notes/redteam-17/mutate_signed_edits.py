"""Red team 17, part 1 (blind): random byte mutations of a signed log WITH a genuine model edit.

Takes B (written by forge_signed_edits.py: the bounce with the wall shrunk at window 2), copied
unchunked so the edit record's JSON is plain bytes in the file, and applies N seeded mutations
(1-3 bytes changed, half of them inside the model-edit record, the run metadata or the model
attachment; or a byte inserted / deleted there). Every mutant is read and verified with the key;
a mutant that exits 0 must have exactly the genuine edit records (else: a forged edit accepted).

Run: PYTHONPATH=<tree> /work/main/.venv/bin/python docs/notes/redteam-17/mutate_signed_edits.py OUTDIR [N]
(OUTDIR as given to forge_signed_edits.py, which must have run first).
"""
from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

import numpy as np

from monitor import review
from monitor.errors import MonitorError
from monitor.log import read_log

sys.path.insert(0, str(Path(__file__).parent))
from forge_signed_edits import KEY, records, write  # noqa: E402


def main(out: Path, n: int, verbose: bool = False) -> int:
    src = out / "B_plain.mcap"
    write(src, records(out / "B.mcap"))
    data = src.read_bytes()
    g = read_log(src)
    genuine = g.model_edits
    assert genuine and review.verify_exit_code(review.verify(read_log(src), key=KEY, progress=False)) == 0
    hot = [data.find(b"monitor.model_edit"), data.find(b"monitor.run"), data.find(b"<mujoco")]
    hot = [h for h in hot if h >= 0]
    rng = np.random.default_rng(1717)
    tally: Counter = Counter()
    bad = 0
    p = out / "mutant.mcap"
    for _ in range(n):
        b = bytearray(data)
        if rng.random() < 0.5:
            centre = int(rng.choice(hot))
            pos = int(np.clip(centre + rng.integers(-20, 600), 8, len(b) - 9))
        else:
            pos = int(rng.integers(8, len(b) - 8))
        kind = rng.choice(["flip", "flip", "insert", "delete"])
        if kind == "flip":
            for k in range(int(rng.integers(1, 4))):
                b[min(pos + k, len(b) - 9)] = int(rng.integers(0, 256))
        elif kind == "insert":
            b[pos:pos] = bytes([int(rng.integers(0, 256))])
        else:
            del b[pos]
        p.write_bytes(bytes(b))
        try:
            c = read_log(p)
            code = review.verify_exit_code(review.verify(c, key=KEY, progress=False))
        except MonitorError as exc:
            tally[f"typed error {type(exc).__name__}"] += 1
            continue
        tally[f"exit {code}"] += 1
        if code == 0 and c.model_edits != genuine:
            bad += 1
            print("FORGED EDIT ACCEPTED", kind, pos)
        elif code == 0:  # what did the accepted mutation change? (records outside the digest)
            what = [k for k in ("messages", "metadata", "attachments", "schemas", "library", "seal")
                    if getattr(c, k) != getattr(g, k)]
            tally["exit 0, decoded contents differ in " + ("/".join(what) or "nothing")] += 1
            if "metadata" in what:
                names = sorted(k for k in set(c.metadata) | set(g.metadata)
                               if c.metadata.get(k) != g.metadata.get(k))
                tally[f"  metadata records differing: {names}"] += 1
            if "messages" in what:
                tops = sorted(k for k in set(c.messages) | set(g.messages)
                              if c.messages.get(k) != g.messages.get(k))
                tally[f"  message topics differing: {tops}"] += 1
                if verbose:
                    print(kind, pos, tops, c.problems[:3])
    print(dict(tally), f"{n} mutants, {bad} with a forged edit accepted")
    return bad


if __name__ == "__main__":
    sys.exit(1 if main(Path(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 1000) else 0)
