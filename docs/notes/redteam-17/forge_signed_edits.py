"""Red team 17, part 1: try to get a model-edit record the gate did not write accepted by
``review --verify`` with the key (no --trust-model-edits), since dca48aa accepts the edit records
of a log whose signature status is "verified".

Two signed runs with ONE key (the forger holds neither the key nor anything but the files):
* A: the bounce (a ball flying at an elastic wall), 6 windows, window 2 a violation, no edits;
* B: the same scene, at window 2 the wall shrunk (geom_size[0, 0] *= 0.5): B's edit record is genuine.
Forgeries are record-level rewrites in FILE ORDER (the forger controls where every metadata record
sits among the messages, unchunked or re-chunked), with or without the window-2 relabel.
Control rows (a faithful copy, a chunked copy, metadata moved among messages): must stay "verified",
else every "held" below would be vacuous.

Run: PYTHONPATH=<tree> /work/main/.venv/bin/python docs/notes/redteam-17/forge_signed_edits.py OUTDIR
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from mcap.records import Channel, Message, Metadata

from monitor import review
from monitor.log import read_log, topics
from monitor.log.digest import METADATA_DIGEST
from monitor.log.reader import _decode_metadata
from monitor.log.writer import encode_metadata

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests"))
from mcap_rewrite import file_records, write_records  # noqa: E402
from test_redteam_17 import KEY, _signed_bounce  # noqa: E402


def run(path: Path, shrink_at: int | None, steps: int = 6) -> None:
    """The signed bounce (tests/test_redteam_17.py), the wall halved at ``shrink_at``."""
    _signed_bounce(path, shrink_at, steps)


def records(path: Path) -> list:
    return file_records(path)


def write(path: Path, recs: list, chunked: bool = False) -> None:
    write_records(path, recs, chunked=chunked)


def topic_of(recs: list) -> dict[int, str]:
    return {r.id: r.topic for r in recs if isinstance(r, Channel)}


def relabel_window2(recs: list) -> list:
    """Window 2 (the bounce) relabelled certified, its violation and log-line messages dropped."""
    tops = topic_of(recs)
    out = []
    for r in recs:
        if isinstance(r, Message):
            t = tops[r.channel_id]
            obj = json.loads(r.data) if t in topics.JSON_TOPICS else None
            if isinstance(obj, dict) and obj.get("index") == 2:
                if t == topics.CERTIFICATE:
                    obj["verdict"] = "certified"
                    r = Message(channel_id=r.channel_id, sequence=r.sequence, log_time=r.log_time,
                                publish_time=r.publish_time,
                                data=json.dumps(obj, separators=(",", ":")).encode())
                elif t in (topics.VIOLATION, topics.LOG):
                    continue
        out.append(r)
    return out


def meta(recs: list, name: str) -> list:
    return [r for r in recs if isinstance(r, Metadata) and r.name == name]


def edited(rec: Metadata, fn) -> Metadata:
    vals = _decode_metadata(dict(rec.metadata))
    fn(vals)
    return Metadata(name=rec.name, metadata=encode_metadata(vals))


def insert_before(recs: list, new: list, pred) -> list:
    i = next(k for k, r in enumerate(recs) if pred(r))
    return recs[:i] + new + recs[i:]


def is_sig(recs):
    tops = topic_of(recs)
    return lambda r: isinstance(r, Message) and tops[r.channel_id] == topics.SIGNATURE


def last_sig_index(recs):
    f = is_sig(recs)
    return max(k for k, r in enumerate(recs) if f(r))


def outcome(path: Path) -> tuple[str, int, bool]:
    c = read_log(path)
    ver = review.verify(c, key=KEY, progress=False)
    code = review.verify_exit_code(ver)
    accepted = any("covered by the log's valid signature" in n for n in ver["notes"])
    return ver["signature"]["status"], code, accepted


def main(out: Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    a, b = out / "A.mcap", out / "B.mcap"
    run(a, None)
    run(b, 2)
    ra, rb = records(a), records(b)
    edit_b = meta(rb, topics.METADATA_MODEL_EDIT)
    assert len(edit_b) == 1, [r.name for r in rb if isinstance(r, Metadata)]
    e = edit_b[0]
    tiny = edited(e, lambda v: v["fields"]["geom_size"]["values"].__setitem__(0, 1e-4))
    retag = edited(e, lambda v: v.__setitem__("window", 0))
    extra_key = edited(e, lambda v: v.__setitem__("note", "x"))
    runA = meta(ra, topics.METADATA_RUN)
    cases: dict[str, tuple[list, bool, bool]] = {}  # name -> (records, chunked, must stay verified)
    # controls
    cases["control A faithful copy"] = (ra, False, True)
    cases["control A re-chunked"] = (ra, True, True)
    cases["control B faithful copy"] = (rb, False, True)
    rb_moved = [r for r in rb if r is not e]
    cases["control B edit record moved to the end of the file"] = (rb_moved + [e], False, False)
    cases["control B edit record moved to just after the run metadata"] = (
        insert_before(rb_moved, [e], lambda r: isinstance(r, Message)), False, True)
    # forgeries on A (no edit of its own), with and without the window-2 relabel
    for tag, base in (("", ra), ("relabel + ", relabel_window2(ra))):
        sig = is_sig(base)
        cases[tag + "A + B's edit at the file end"] = (base + [e], False, False)
        cases[tag + "A + B's edit before the final checkpoint"] = (
            base[:last_sig_index(base)] + [e] + base[last_sig_index(base):], False, False)
        cases[tag + "A + B's edit before the first message"] = (
            insert_before(base, [e], lambda r: isinstance(r, Message)), False, False)
        cases[tag + "A + B's edit before checkpoint 0"] = (insert_before(base, [e], sig), False, False)
        cases[tag + "A + tiny-wall edit (window 2) at the file end, chunked"] = (base + [tiny], True, False)
        cases[tag + "A + edit re-tagged window 0, first"] = (
            insert_before(base, [retag], lambda r: isinstance(r, Metadata)), False, False)
        cases[tag + "A run metadata replaced by B's"] = (
            [meta(rb, topics.METADATA_RUN)[0] if r is runA[0] else r for r in base] + [e], False, False)
        cases[tag + "A + edit named monitor.finalise"] = (base + [Metadata("monitor.finalise", e.metadata)],
                                                          False, None)
        cases[tag + "A + edit named monitor.digest"] = (base + [Metadata(METADATA_DIGEST, e.metadata)],
                                                        False, None)
    # forgeries on B (its own genuine edit record)
    cases["B edit duplicated"] = (rb + [e], False, False)
    cases["B edit duplicated right after itself"] = (
        [x for r in rb for x in ((r, r) if r is e else (r,))], False, False)
    cases["B edit replaced by a tiny-wall one"] = ([tiny if r is e else r for r in rb], False, False)
    cases["B edit re-tagged window 0"] = ([retag if r is e else r for r in rb], False, False)
    cases["B edit with an extra key"] = ([extra_key if r is e else r for r in rb], False, False)
    cases["B edit dropped"] = ([r for r in rb if r is not e], False, False)
    cases["B edit swapped with the run metadata (order)"] = (
        [e if r is meta(rb, topics.METADATA_RUN)[0] else meta(rb, topics.METADATA_RUN)[0] if r is e else r
         for r in rb], False, False)
    cases["B second model_edit name variant 'monitor.model_edit ' added"] = (
        rb + [Metadata("monitor.model_edit ", tiny.metadata)], False, False)
    rows = []
    broken = 0
    for k, (name, (recs, chunked, keep)) in enumerate(cases.items()):
        p = out / f"case{k:02d}.mcap"
        write(p, recs, chunked)
        status, code, accepted = outcome(p)
        if keep is None:
            ok = True  # the record is not an edit record (report only)
        elif keep:
            ok = status == "verified" and code == 0
        else:
            ok = not (code == 0 and status == "verified" and accepted) and code != 0
        broken += not ok
        rows.append((name, status, code, accepted, "ok" if ok else "BROKEN"))
        print(f"{name:70s} status={status:9s} exit={code} edits_accepted={accepted} {rows[-1][-1]}")
    print(f"{len(rows)} cases, {broken} broken")
    return broken


if __name__ == "__main__":
    sys.exit(1 if main(Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/rt17")) else 0)
