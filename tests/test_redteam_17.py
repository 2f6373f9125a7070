"""Red team 17: signed model-edit records accepted by review (dca48aa); armprof's two cuts.

Guards (nothing broke on dca48aa; these pin what held). Part 1's threat model: the forger rewrites
a signed log (holding no key); the auditor runs ``review --verify`` with the key and without
``trust_model_edits``. Oracles: the forger's own edit (which record was added / changed), a second
genuine run signed with the same key (a real edit record to copy), and the genuine log's edits.
Part 2: the braking tail's stop rule and the pair-method names against their closed forms (the
pre-armprof code: ``max(|row|) <= tol`` per row; ``np.full(n, "culled")`` and plain ``str``s).
The full fuzzers: ``docs/notes/redteam-17/``.
"""
from __future__ import annotations

import json
from types import SimpleNamespace

import mujoco
import numpy as np
import pytest
from mcap.records import Message, Metadata
from mcap_rewrite import file_records, write_records
from test_review_replay import BOUNCE

from monitor import review
from monitor.certify import engine
from monitor.gate import Gate, _first_at_rest
from monitor.log import read_log, topics
from monitor.log.reader import _decode_metadata
from monitor.log.writer import encode_metadata

KEY = b"red team 17 key: 0123456789abcdef"


def _signed_bounce(path, shrink_at=None, steps=4):
    """A signed Gate log of a ball flying at a wall (window 2 bounces); the wall halved at ``shrink_at``."""
    m = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0
    with Gate(m, log=path, frame_skip=50, allowed=None, on_violation="warn", log_options={"key": KEY}) as g:
        for k in range(steps):
            if k == shrink_at:
                m.geom_size[0, 0] *= 0.5
            g.step(d, np.zeros(1))


def _verify(path):
    ver = review.verify(read_log(path), key=KEY, progress=False)
    accepted = any("covered by the log's valid signature" in n for n in ver["notes"])
    return review.verify_exit_code(ver), ver["signature"]["status"], accepted


def _edit(rec, fn):
    vals = _decode_metadata(dict(rec.metadata))
    fn(vals)
    return Metadata(name=rec.name, metadata=encode_metadata(vals))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("rt17")
    a, b = d / "plain.mcap", d / "edited.mcap"
    _signed_bounce(a)
    _signed_bounce(b, shrink_at=2)
    return d, file_records(a), file_records(b)


def _relabel_bounce(recs):
    """Window 2 (the bounce) relabelled certified, its violation and log lines dropped."""
    tops = {r.id: r.topic for r in recs if type(r).__name__ == "Channel"}
    out = []
    for r in recs:
        if isinstance(r, Message) and tops[r.channel_id] in topics.JSON_TOPICS:
            obj = json.loads(r.data)
            if isinstance(obj, dict) and obj.get("index") == 2:
                if tops[r.channel_id] in (topics.VIOLATION, topics.LOG):
                    continue
                if tops[r.channel_id] == topics.CERTIFICATE:
                    obj["verdict"] = "certified"
                    data = json.dumps(obj, separators=(",", ":")).encode()
                    r = Message(channel_id=r.channel_id, sequence=r.sequence, log_time=r.log_time,
                                publish_time=r.publish_time, data=data)
        out.append(r)
    return out


def test_an_edit_record_the_gate_did_not_write_is_never_accepted(runs):
    """A genuine edit record (another run, same key) or a forged one added / duplicated / re-tagged /
    changed, at the start, before checkpoint 0, before the final checkpoint or at the end, with and
    without the bounce relabelled: the signature never verifies, exit 1, the edits are not accepted."""
    d, plain, edited = runs
    (e,) = [r for r in edited if isinstance(r, Metadata) and r.name == topics.METADATA_MODEL_EDIT]
    tiny = _edit(e, lambda v: v["fields"]["geom_size"]["values"].__setitem__(0, 1e-4))  # the wall gone
    retag = _edit(e, lambda v: v.__setitem__("window", 0))
    first_msg = next(k for k, r in enumerate(plain) if isinstance(r, Message))
    sig = {r.id for r in plain if type(r).__name__ == "Channel" and r.topic == topics.SIGNATURE}
    last_sig = max(k for k, r in enumerate(plain) if isinstance(r, Message) and r.channel_id in sig)
    forged = {
        "copied, end": plain + [e],
        "copied, first message": plain[:first_msg] + [e] + plain[first_msg:],
        "copied, before the final checkpoint": plain[:last_sig] + [e] + plain[last_sig:],
        "tiny wall, relabelled, end": _relabel_bounce(plain) + [tiny],
        "re-tagged, first": [retag] + plain,
        "own edit duplicated": edited + [e],
        "own edit replaced": [tiny if r is e else r for r in edited],
        "own edit re-tagged": [retag if r is e else r for r in edited],
    }
    for k, (name, recs) in enumerate(forged.items()):
        p = d / f"forged{k}.mcap"
        write_records(p, recs, chunked=k % 2 == 1)
        code, status, accepted = _verify(p)
        assert (code, status, accepted) == (1, "mismatch", False), name


def test_a_signed_edit_record_moved_among_messages_is_still_the_runs_edit(runs):
    """Control: the position of a metadata record among messages is not signed (a chunked file moves
    it); an edit record names its window, so moving it changes nothing: verified, accepted, and the
    edits read are the genuine ones. (Else the forgeries above would hold vacuously.)"""
    d, _, edited = runs
    genuine = read_log(d / "edited.mcap").model_edits
    (e,) = [r for r in edited if isinstance(r, Metadata) and r.name == topics.METADATA_MODEL_EDIT]
    rest = [r for r in edited if r is not e]
    first_msg = next(k for k, r in enumerate(rest) if isinstance(r, Message))
    for chunked in (False, True):
        p = d / f"moved{int(chunked)}.mcap"
        write_records(p, rest[:first_msg] + [e] + rest[first_msg:], chunked=chunked)
        assert _verify(p) == (0, "verified", True)
        assert read_log(p).model_edits == genuine


def _max_rule(q, tol):
    stop = np.abs(q).max(axis=1) <= tol
    return int(stop.argmax()) if stop.any() else None


def test_first_at_rest_equals_the_max_rule_on_special_values():
    """NaN / +-inf / +-0.0 / subnormals / values one ulp either side of the tolerance, tolerances NaN,
    +-inf, +-0.0, negative; empty and float32 inputs (seeded)."""
    rng = np.random.default_rng(17)
    special = np.array([np.nan, np.inf, -np.inf, 0.0, -0.0, 5e-324, 1e-3, -1e-3,
                        np.nextafter(1e-3, 1), np.nextafter(1e-3, 0)])
    n = 0
    for tol in (1e-3, 0.0, -0.0, -1e-3, np.inf, -np.inf, np.nan):
        for _ in range(60):
            q = rng.choice(special, size=(int(rng.integers(0, 6)), int(rng.integers(1, 5))))
            q[rng.random(q.shape) < 0.3] = 0.0
            for v in (q, q.astype(np.float32)):
                assert _first_at_rest(v, tol) == _max_rule(v, tol), (v.tolist(), tol)
                n += 1
    assert n == 7 * 60 * 2


def test_pair_method_names_equal_the_plain_string_fill():
    """``_WindowPairs.methods`` with the 0-d object-array fills: the same dtype, values and exact ``str``
    elements as ``np.full(n, "culled", dtype=object)`` plus ``str`` assignments, on random code / surv /
    unfinished masks and results with odd method names (empty selections included)."""
    KS = engine._kernels()
    codes = [KS.WK_CULLED, KS.WK_SS, KS.WK_STATIC_VIOL, KS.WK_STATIC_CERT, KS.WK_CERT, KS.WK_VIOL]
    names = ["", "culled", "static", "toleranced", "budget", "é", "x" * 200]
    rng = np.random.default_rng(1717)
    for _ in range(300):
        n = int(rng.integers(0, 9))
        sel = np.sort(rng.choice(500, size=n, replace=False)).astype(np.int64)
        code = rng.choice(codes, size=n).astype(np.int64)
        surv = np.flatnonzero(rng.random(n) < 0.6).astype(np.int64)
        unfin = rng.random(n) < 0.2
        results = {int(sel[i]): SimpleNamespace(method=str(rng.choice(names)))
                   for i in rng.choice(n, size=int(rng.integers(0, n + 1)), replace=False)} if n else {}
        want = np.full(n, "culled", dtype=object)
        for i, s in enumerate(sel.tolist()):
            if s in results:
                want[i] = results[s].method
        c = code[surv]
        want[surv[(c == KS.WK_STATIC_VIOL) | (c == KS.WK_STATIC_CERT)]] = "static"
        want[surv[(c == KS.WK_CERT) | (c == KS.WK_VIOL)]] = "toleranced"
        want[unfin] = "budget"
        got = engine._WindowPairs.methods(SimpleNamespace(sel=sel, code=code, surv=surv, unfin=unfin,
                                                          results=results))
        assert got.dtype == want.dtype and got.shape == (n,)
        assert got.tolist() == want.tolist() and all(type(x) is str for x in got)
