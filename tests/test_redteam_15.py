"""Red team 15: signed logs (``docs/notes/redteam-15.md``). Each test failed on 6b62b52.

Forgery E: the digest chain, and so every signed checkpoint, covers a message's topic, times, sequence
and payload, not its channel record. A forger moved a window's messages, unchanged, to a channel of the
same topic whose message encoding is not json (an added twin channel, or the same channel id defined
again in the journal); the reader counted them and never decoded them: the windows vanished, every
checkpoint still verified and the seal still matched (``review --verify --key-file`` exit 0 with a
violation hidden). Oracles: the forger's own edit (which windows it moved, hence how many certificates
precede each checkpoint) and the writer's window count in each checkpoint.

Writer side: a ``Gate(log_options={"key": ...})`` wrote its key into every pickle or deep copy of the
gate, and a bad key surfaced only at the first step.
"""

from __future__ import annotations

import copy
import json
import pickle

import mujoco
import numpy as np
import pytest
from mcap.data_stream import RecordBuilder
from mcap.records import Channel, Message
from mcap.stream_reader import StreamReader
from mcap_rewrite import rewrite
from test_log_digest import XML, seal_copy
from test_log_sign import KEY, _review, _scripted, key_file, signed_bounce  # noqa: F401 - fixtures

from monitor.errors import LogKeyError
from monitor.gate import Gate
from monitor.log import read_log, topics
from monitor.log.reader import MAGIC
from monitor.log.sign import KEY_FILE_ENV, check_signatures


@pytest.fixture(autouse=True)
def _no_key_from_the_environment(monkeypatch):
    monkeypatch.delenv(KEY_FILE_ENV, raising=False)


def _hide_on_twin(src, dst, first):
    """Every JSON message of window ``first`` on, unchanged, on a twin channel with encoding "cbor"."""
    tmp = dst.with_suffix(".unsealed.mcap")
    rewrite(src, tmp, chunked=True, encoding=lambda topic, o: "cbor" if o.get("index", -1) >= first else None)
    seal_copy(tmp, dst, chunked=True)  # the seal would even have matched unchanged: channels are not digested


def _redefine_in_journal(src, dst, first):
    """Before window ``first``'s first message, each JSON channel id defined again with encoding "cbor"."""
    out, chans, done = RecordBuilder(), {}, False
    with open(src, "rb") as f:
        records = list(StreamReader(f, skip_magic=False).records)
    for rec in records:
        if isinstance(rec, Channel):
            chans.setdefault(rec.id, rec)
        elif isinstance(rec, Message) and not done and chans[rec.channel_id].topic in topics.JSON_TOPICS \
                and json.loads(rec.data)["index"] == first:
            for c in chans.values():
                if c.topic in topics.JSON_TOPICS:
                    Channel(c.id, c.topic, "cbor", dict(c.metadata), c.schema_id).write(out)
            done = True
        rec.write(out)
    dst.write_bytes(MAGIC + out.end() + MAGIC)


@pytest.mark.parametrize("how", ["twin_channel", "journal_redefinition"])
def test_windows_moved_to_a_channel_that_is_not_json_fail_the_signature(tmp_path, how):
    src = tmp_path / "a.mcap"
    _scripted(src, n=5, index=how == "twin_channel")  # 5 certified windows: 5 certificates, 5 plans
    dst = tmp_path / "hidden.mcap"
    (_hide_on_twin if how == "twin_channel" else _redefine_in_journal)(src, dst, 3)
    c = read_log(dst)
    assert c.counts[topics.CERTIFICATE] == 5 and len(c.topic(topics.CERTIFICATE)) == 3  # 2 not decoded
    assert c.bad_payloads == 4 and "not json" in c.problems[0]  # windows 3, 4: certificate and plan each
    sig = check_signatures(c, KEY)
    # checkpoint 4 (after window 3) says 4 windows; 3 certificates can be read before it
    assert sig.status == "mismatch" and sig.first_bad["checkpoint"] == 4 and sig.signed_windows == 3
    assert "4 window(s), 3 certificate(s)" in sig.first_bad["reason"]


def test_an_unsigned_log_with_windows_on_a_twin_channel_is_not_exit_0(tmp_path, capsys):
    src = tmp_path / "a.mcap"
    _scripted(src, n=5, key=False)
    dst = tmp_path / "hidden.mcap"
    _hide_on_twin(src, dst, 3)
    code, entry = _review(dst, capsys=capsys)
    assert code == 2 and entry["file"]["bad_payloads"] == 4 and entry["windows"] == 3


def test_a_hidden_violation_window_fails_review_with_the_key(signed_bounce, tmp_path, key_file, capsys):  # noqa: F811
    src, _ = signed_bounce
    assert [c["verdict"] for c in read_log(src).certificates()].count("violation") == 1
    dst = tmp_path / "hidden.mcap"
    first_violation = next(c["index"] for c in read_log(src).certificates() if c["verdict"] == "violation")
    _hide_on_twin(src, dst, first_violation)  # the violation and every later window: no index gap
    assert all(c["verdict"] == "certified" for c in read_log(dst).certificates())
    code, entry = _review("--verify", "--key-file", key_file, dst, capsys=capsys)
    sig = entry["verify"]["signature"]
    assert code == 1 and sig["status"] == "mismatch"
    assert sig["first_bad"]["checkpoint"] == first_violation + 1 and sig["signed_windows"] == first_violation


def test_a_gate_does_not_copy_its_log_key_into_pickles_or_copies(tmp_path):
    model = mujoco.MjModel.from_xml_string(XML)
    g = Gate(model, log=tmp_path / "g.mcap", log_options={"key": KEY}, allowed=None)
    for clone in (pickle.loads(pickle.dumps(g)), copy.deepcopy(g)):
        assert KEY not in pickle.dumps(clone) and KEY.hex().encode() not in pickle.dumps(clone)
        with pytest.raises(LogKeyError, match="not copied"):  # the copy cannot write an unsigned log
            clone.step(mujoco.MjData(model), np.zeros(model.nu))
    assert not (tmp_path / "g.mcap").exists()
    assert KEY not in pickle.dumps(g)
    g.step(mujoco.MjData(model), np.zeros(model.nu))  # the original still signs
    g.close()
    assert check_signatures(read_log(tmp_path / "g.mcap"), KEY).status == "verified"


def test_a_gate_refuses_a_bad_log_key_when_it_is_made(tmp_path, monkeypatch):
    model = mujoco.MjModel.from_xml_string(XML)
    with pytest.raises(LogKeyError, match="at least 16"):
        Gate(model, log=tmp_path / "a.mcap", log_options={"key": KEY[:15]})
    with pytest.raises(LogKeyError, match="must be bytes"):
        Gate(model, log=tmp_path / "a.mcap", log_options={"key": KEY.hex()})
    monkeypatch.setenv(KEY_FILE_ENV, str(tmp_path / "missing.key"))
    with pytest.raises(LogKeyError, match="MONITOR_LOG_KEY_FILE"):
        Gate(model, log=tmp_path / "a.mcap")
    assert not list(tmp_path.iterdir())
    Gate(model, log=tmp_path / "a.mcap", log_options={"key": False})  # unsigned on purpose: no key read


@pytest.mark.parametrize("last", [b"\n", b" ", b"\t", b"\r"])
def test_a_key_ending_in_whitespace_is_one_key_in_code_and_in_a_key_file(tmp_path, capsys, last):
    """A random key whose last byte is ASCII whitespace (4 of 256 keys): the writer signed with the key as
    given in code, review read the same bytes from a key file and stripped the whitespace: another key id,
    "signed by another key" (exit 1) for a genuine log."""
    key = bytes(range(40, 71)) + last  # 32 bytes
    path = tmp_path / "a.mcap"
    _scripted(path, n=2, key=key)
    own_file = tmp_path / "log.key"
    own_file.write_bytes(key)  # the user's key, byte for byte
    code, entry = _review(path, "--key-file", own_file, capsys=capsys)
    assert code == 0 and entry["signature"]["status"] == "verified"
    assert check_signatures(read_log(path), key).status == "verified"  # the Python API, key as given
