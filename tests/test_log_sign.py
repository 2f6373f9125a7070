"""Signed logs (monitor.log.sign): HMAC checkpoints make a forged log fail ``review --verify --key-file``.

Oracles: the forger's own edit (we know which window and which record it changed, so we know the
first checkpoint that must fail and how many windows stay signed), the writer's own window count
at the moment the file was copied (a "killed" writer), and the key (a wrong or missing key must
never verify). Red team 11's two forgeries that passed ``review --verify`` with exit 0 (an episode
split after a made-up state; a predictor relabel) are rebuilt as in
``docs/notes/redteam-11/episode_and_predictor_forgeries.py`` and re-sealed with
``monitor.log.digest`` (the forger has the library, not the key).
"""

from __future__ import annotations

import hmac
import json
import shutil
import types

import jsonschema
import mujoco
import numpy as np
import pytest
from mcap_rewrite import rewrite
from test_log_digest import XML, seal_copy
from test_review_applied import _arm_run
from test_review_replay import BOUNCE, INTEGRATION, _recertified

from monitor.certify.certificate import Certificate, PairResult
from monitor.cli import main
from monitor.errors import LogKeyError
from monitor.gate import Gate
from monitor.log import MonitorLog, read_log, replay, topics
from monitor.log.sign import KEY_FILE_ENV, check_signatures, key_id, load_key

KEY = bytes(range(7, 39))  # 32 bytes
OTHER_KEY = bytes(range(100, 132))


@pytest.fixture(autouse=True)
def _no_key_from_the_environment(monkeypatch):
    monkeypatch.delenv(KEY_FILE_ENV, raising=False)


@pytest.fixture
def key_file(tmp_path):
    p = tmp_path / "log.key"
    p.write_bytes(KEY + b"\n")
    return p


def _review(*args, capsys):
    code = main(["review", "--json", *map(str, args)])
    return code, json.loads(capsys.readouterr().out)["logs"][0]


# --------------------------------------------------------------------------- a scripted log (no engine)


def _window(log, model, k):
    t0 = 0.01 * k
    plan = types.SimpleNamespace(times=np.array([t0, t0 + 0.01]), qpos=np.tile(model.qpos0, (2, 1)),
                                 model=model)
    pr = PairResult(("floor", "g"), ("world", "b"), "certified", "toleranced", 1, 0, (), 0.9, None)
    log.write_window(t0, plan, Certificate("certified", (t0, t0 + 0.01), 0.0, 1e-3, "auto", None, None, 0.9,
                                           (pr,), {}))


def _scripted(path, n=5, key=KEY, snapshots=None, **kw):
    """A signed MonitorLog of ``n`` windows; ``snapshots[k]``: a copy of the file after window k."""
    model = mujoco.MjModel.from_xml_string(XML)
    log = MonitorLog(path, model=model, metadata={"pairs": "mujoco"}, foxglove=False, key=key, **kw)
    for k in range(n):
        _window(log, model, k)
        if snapshots is not None:
            snapshots[k] = path.read_bytes()
    log.close()
    return log


@pytest.mark.parametrize("index", [True, False], ids=["finalised", "journal"])
def test_a_signed_log_verifies_with_its_key_only(tmp_path, index):
    path = tmp_path / "a.mcap"
    log = _scripted(path, index=index)
    assert log.key_id == key_id(KEY) and KEY not in path.read_bytes()
    c = read_log(path)
    assert c.run["signature"]["key_id"] == key_id(KEY)
    ok = check_signatures(c, KEY)
    assert (ok.status, ok.valid, ok.checkpoints, ok.signed_windows) == ("verified", 7, 7, 5)  # open, 5, close
    assert ok.signed_close
    assert not ok.critical and not ok.unverifiable
    bad = check_signatures(c, OTHER_KEY)
    assert bad.status == "wrong_key" and bad.critical and bad.unsigned_windows == [0, 1, 2, 3, 4]
    final = c.signatures[-1]  # its HMAC by the standard library's one-shot, over the documented input
    f = final.payload
    names = ("algorithm", "key_id", "checkpoint", "windows", "messages", "attachments", "metadata")
    text = "|".join(str(f[k]) for k in names) + "|1"
    data = b"monitor-log-signature/1\0" + text.encode() + b"\0" + final.chain
    assert f["final"] is True and f["mac"] == hmac.digest(KEY, data, "sha256").hex()
    for payload in c.topic(topics.SIGNATURE):  # each checkpoint matches its registered schema
        fields = {k: v for k, v in payload.items() if k != "_log_time"}
        jsonschema.validate(fields, topics.schema(topics.SIGNATURE))
    none = check_signatures(c, None)
    assert none.status == "not_checked" and not none.critical
    assert any(n.startswith("signature not checked: no key") for n in none.notes)


def test_a_killed_writer_keeps_its_signed_windows_and_reports_the_tail(tmp_path):
    snaps: dict[int, bytes] = {}
    _scripted(tmp_path / "full.mcap", snapshots=snaps)
    between = tmp_path / "between.mcap"  # killed after window 3 returned (flushed)
    between.write_bytes(snaps[3])
    c = check_signatures(read_log(between), KEY)
    assert (c.status, c.signed_windows, c.unsigned_windows, c.signed_close) == ("partial", 4, [], False)
    # a copy cut right after a checkpoint reads exactly like this: the windows it may hide cannot be
    # ruled out, so the log is not "verified" (review exits 2, below)
    assert not c.critical and len(c.unverifiable) == 1 and "no signed close" in c.unverifiable[0]
    inside = tmp_path / "inside.mcap"  # killed inside window 4: its checkpoint (the last record) is cut
    inside.write_bytes(snaps[4][:-20])
    c = check_signatures(read_log(inside), KEY)
    assert (c.status, c.signed_windows, c.unsigned_windows) == ("partial", 4, [4])
    assert not c.critical and len(c.unverifiable) == 1 and "1 window(s) (4)" in c.unverifiable[0]


def test_review_cli_codes_for_a_killed_and_a_forged_scripted_log(tmp_path, key_file, capsys):
    snaps: dict[int, bytes] = {}
    _scripted(tmp_path / "full.mcap", snapshots=snaps)
    inside = tmp_path / "inside.mcap"
    inside.write_bytes(snaps[4][:-20])
    code, entry = _review("--key-file", key_file, inside, capsys=capsys)
    assert code == 2 and entry["signature"]["unsigned_windows"] == [4]
    between = tmp_path / "between.mcap"  # cut exactly after window 3's checkpoint: later windows hidden
    between.write_bytes(snaps[3])
    code, entry = _review("--key-file", key_file, between, capsys=capsys)
    assert code == 2 and entry["signature"]["status"] == "partial" and not entry["signature"]["signed_close"]
    code, entry = _review("--key-file", key_file, tmp_path / "full.mcap", capsys=capsys)
    assert code == 0 and entry["signature"]["status"] == "verified"
    # a checkpoint-preserving copy whose window 1 certificate is edited, then re-sealed
    forged = tmp_path / "forged.mcap"
    seal_copy(tmp_path / "full.mcap", forged, edit=None)
    tmp = tmp_path / "edited.mcap"
    rewrite(forged, tmp, msg=lambda t, o: {**o, "clearance": 0.5}
            if t == topics.CERTIFICATE and o["index"] == 1 else o)
    seal_copy(tmp, forged)
    code, entry = _review("--key-file", key_file, forged, capsys=capsys)
    sig = entry["signature"]
    assert code == 1 and sig["first_bad"]["checkpoint"] == 2 and sig["signed_windows"] == 1
    nomodel = tmp_path / "nomodel.mcap"  # attachments dropped: --verify cannot run, the signature still fails
    rewrite(tmp_path / "full.mcap", tmp, attachments=lambda name, data: None)
    seal_copy(tmp, nomodel)
    code, entry = _review("--verify", "--key-file", key_file, nomodel, capsys=capsys)
    assert "error" in entry["verify"] and code == 1 and entry["signature"]["first_bad"]["checkpoint"] == 0


def test_a_sealed_log_without_its_signed_close_or_with_records_after_it_is_critical(tmp_path):
    src = tmp_path / "a.mcap"
    _scripted(src)
    cut = tmp_path / "cut.mcap"  # final checkpoint dropped, log re-sealed: a close claimed, not signed
    n = [0]

    def drop_final(topic, o):
        if topic == topics.SIGNATURE and o.get("final"):
            n[0] += 1
            return None
        return o

    rewrite(src, tmp_path / "t.mcap", msg=drop_final)
    seal_copy(tmp_path / "t.mcap", cut)
    assert n[0] == 1
    c = check_signatures(read_log(cut), KEY)
    assert c.status == "mismatch" and c.signed_windows == 5 and not c.signed_close
    assert any("claims a close" in t for t in c.critical)
    inserted = tmp_path / "inserted.mcap"  # a window inserted after window 4 (before its checkpoint)

    def insert(topic, o):
        return [o, {**o, "index": 5}] if topic == topics.CERTIFICATE and o["index"] == 4 else o

    rewrite(src, tmp_path / "t2.mcap", msg=insert)
    seal_copy(tmp_path / "t2.mcap", inserted)
    c = check_signatures(read_log(inserted), KEY)
    assert c.status == "mismatch" and c.first_bad["checkpoint"] == 5 and c.signed_windows == 4
    appended = tmp_path / "appended.mcap"  # a window appended after the signed close
    last = {k: v for k, v in read_log(src).certificates()[-1].items() if k != "_log_time"}
    rewrite(src, tmp_path / "t3.mcap", append=[(topics.CERTIFICATE, {**last, "index": 5})])
    seal_copy(tmp_path / "t3.mcap", appended)
    c = check_signatures(read_log(appended), KEY)
    assert c.status == "mismatch" and c.first_bad is None and c.unsigned_windows == [5]
    assert any(t.startswith("records after the signed close: 1 window(s) (5)") for t in c.critical)


# --------------------------------------------------------------------------- bad keys


def test_bad_keys_are_typed_errors_and_leave_no_file(tmp_path, monkeypatch, capsys):
    empty = tmp_path / "empty.key"
    empty.write_bytes(b"\n")
    short = tmp_path / "short.key"
    short.write_bytes(b"abc")
    for p, what in ((tmp_path / "missing.key", "no such file"), (empty, "empty"), (short, "at least 16")):
        with pytest.raises(LogKeyError, match=what):
            load_key(p)
        assert main(["review", "--key-file", str(p), str(tmp_path / "x.mcap")]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("error: --key-file: ") and "\n" not in err and what in err
    with pytest.raises(LogKeyError):
        MonitorLog(tmp_path / "s.mcap", key=b"too short")
    with pytest.raises(LogKeyError):
        MonitorLog(tmp_path / "s.mcap", key="a text is not a key")
    monkeypatch.setenv(KEY_FILE_ENV, str(tmp_path / "missing.key"))
    with pytest.raises(LogKeyError, match=KEY_FILE_ENV):
        MonitorLog(tmp_path / "s.mcap")
    assert not (tmp_path / "s.mcap").exists()
    assert main(["review", str(tmp_path / "x.mcap")]) == 2
    assert KEY_FILE_ENV in capsys.readouterr().err


def test_the_environment_key_file_signs_and_an_unsigned_log_fails_with_a_key(tmp_path, key_file, monkeypatch,
                                                                           capsys):
    unsigned = tmp_path / "u.mcap"
    _scripted(unsigned, key=None)
    code, entry = _review(unsigned, capsys=capsys)  # no key anywhere: as before signing existed
    assert code == 0 and entry["signature"]["status"] == "unsigned" and not entry["signature"]["notes"]
    code, entry = _review("--key-file", key_file, unsigned, capsys=capsys)
    assert code == 1
    assert any("authenticity cannot be established" in t for t in entry["signature"]["critical"])
    monkeypatch.setenv(KEY_FILE_ENV, str(key_file))
    signed = tmp_path / "s.mcap"
    log = _scripted(signed, key=None)
    assert log.key_id == key_id(KEY)
    code, entry = _review(signed, capsys=capsys)  # review reads the same variable
    assert code == 0 and entry["signature"]["status"] == "verified"
    off = tmp_path / "off.mcap"
    assert _scripted(off, key=False).key_id is None


# --------------------------------------------------------------------------- real gate runs


@pytest.mark.parametrize("how", ["environment", "user_log"])
def test_a_signed_safety_gate_run_passes_review_verify_with_the_key(tmp_path, key_file, monkeypatch, capsys,
                                                                    how):
    path = tmp_path / "arm.mcap"
    if how == "environment":  # SafetyGate(log=path) takes the key from the environment
        monkeypatch.setenv(KEY_FILE_ENV, str(key_file))
        _arm_run(path, steps=4)
        monkeypatch.delenv(KEY_FILE_ENV)
    else:  # the user's own signed MonitorLog (the gate does not close it)
        with MonitorLog(path, key=KEY) as log:
            _arm_run(log, steps=4)
    code, entry = _review("--verify", "--key-file", key_file, path, capsys=capsys)
    sig = entry["verify"]["signature"]
    assert code == 0, entry["verify"]["findings"]
    assert sig["status"] == "verified" and sig["signed_windows"] == entry["verify"]["windows"] >= 4
    code, entry = _review("--verify", path, capsys=capsys)  # no key: the old result plus a note
    assert code == 0 and any(n.startswith("signature not checked: no key") for n in entry["verify"]["notes"])


@pytest.fixture(scope="module")
def signed_bounce(tmp_path_factory):
    """Red team 11's bounce (a Gate, 6 steps, window 2 a violation), signed through ``log_options``."""
    path = tmp_path_factory.mktemp("sign") / "bounce.mcap"
    model = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(model)
    d.qpos[0], d.qvel[0] = -0.25, 1.0  # as test_review_replay._bounce_log
    with Gate(model, log=path, frame_skip=50, allowed=None, on_violation="warn",
              log_options={"key": KEY}) as g:
        for _ in range(6):
            g.step(d, np.zeros(1))
    return path, model


def _forge(src, dst, msg=None, metadata=None):
    tmp = dst.with_suffix(".unsealed.mcap")
    rewrite(src, tmp, msg=msg, metadata=metadata)
    seal_copy(tmp, dst)
    assert read_log(dst).seal_status == "sealed"


def _fabricated(src, model):
    """Red team 11's window 2: re-simulated from its start state with qvel 0 (the ball stays clear)."""
    contents = read_log(src)
    ro = replay.decode(contents.plans_by_index()[2]["rollout"], model)
    st = ro.state.copy()
    st[1 + model.nq] = 0.0
    plan, _ = replay.resimulate(model, mujoco.MjData(model), replay.Rollout(st, ro.segments, 0))
    payload = replay.encode((st, ((ro.segments[0][0], 50),), 0), int(INTEGRATION), st.size, model.nu)
    return plan, payload, _recertified(model, 2, plan.times, plan.qpos, contents)


def _episode_split(src, model, dst):
    """Forgery A: window 2 fabricated, in an episode of its own (windows 3-5 in a third one)."""
    plan, payload, cert = _fabricated(src, model)

    def msg(topic, o):
        k = o.get("index")
        if k is None:
            return o
        if k == 2:
            if topic == topics.PLAN:
                o = {**o, "qpos": plan.qpos.tolist(), "rollout": payload}
            elif topic == topics.CERTIFICATE:
                o = dict(cert)
            elif topic in (topics.VIOLATION, topics.LOG):
                return None
        if "episode" in o and k >= 2:
            o["episode"] = 1 if k == 2 else 2
        return o

    _forge(src, dst, msg=msg)
    return cert


def _predictor_relabel(src, model, dst):
    """Forgery B: window 2 fabricated as rows of "user code", the run's predictor relabelled "callable"."""
    plan, _, cert = _fabricated(src, model)

    def msg(topic, o):
        if o.get("index") != 2:
            return o
        if topic == topics.PLAN:
            o = dict(o)
            o.pop("rollout")
            o["source"], o["qpos"] = "user", plan.qpos.tolist()
            return o
        if topic == topics.CERTIFICATE:
            return dict(cert)
        return None if topic in (topics.VIOLATION, topics.LOG) else o

    def meta(name, v):
        if name == topics.METADATA_RUN:
            v["predictor"] = "callable"
        return v

    _forge(src, dst, msg=msg, metadata=meta)
    return cert


@pytest.mark.parametrize("forgery, first_bad", [(_episode_split, 3), (_predictor_relabel, 0)],
                         ids=["episode_split", "predictor_relabel"])
def test_red_team_11_forgeries_fail_with_the_key(signed_bounce, tmp_path, key_file, capsys, forgery,
                                                 first_bad):
    src, model = signed_bounce
    code, entry = _review("--verify", "--key-file", key_file, src, capsys=capsys)
    assert code == 0 and entry["verify"]["signature"]["status"] == "verified"
    assert read_log(src).certificates()[2]["verdict"] == "violation"
    dst = tmp_path / "forged.mcap"
    assert forgery(src, model, dst)["verdict"] == "certified"  # the violation is gone from the forged log
    code, entry = _review("--verify", dst, capsys=capsys)  # no key: nothing but the note tells
    assert code != 1 and any(n.startswith("signature not checked") for n in entry["verify"]["notes"])
    code, entry = _review("--verify", "--key-file", key_file, dst, capsys=capsys)
    sig = entry["verify"]["signature"]
    assert code == 1 and sig["status"] == "mismatch"
    # checkpoint 0 signs the run metadata (the relabelled predictor); checkpoint k + 1 signs window k
    assert sig["first_bad"]["checkpoint"] == first_bad and sig["signed_windows"] == max(first_bad - 1, 0)
    assert any(f["severity"] == "critical" and f["reason"].startswith("signature: signature mismatch at "
                                                                       f"checkpoint {first_bad}")
               for f in entry["verify"]["findings"])


def test_stripping_the_signatures_fails_with_the_key(signed_bounce, tmp_path, key_file, capsys):
    src, _ = signed_bounce
    bare = tmp_path / "bare.mcap"
    _forge(src, bare, msg=lambda t, o: None if t == topics.SIGNATURE else o)
    assert read_log(bare).signatures == []
    code, entry = _review("--verify", "--key-file", key_file, bare, capsys=capsys)
    assert code == 1 and "(stripped)" in entry["verify"]["signature"]["critical"][0]
    claimless = tmp_path / "claimless.mcap"  # the claim removed too: an unsigned log

    def meta(name, v):
        v.pop("signature", None)
        return v

    _forge(bare, claimless, metadata=meta)
    code, entry = _review("--verify", "--key-file", key_file, claimless, capsys=capsys)
    assert code == 1 and entry["verify"]["signature"]["status"] == "unsigned"
    code, entry = _review("--verify", claimless, capsys=capsys)  # no key: the old behaviour, no note
    assert not any("signature" in n for n in entry["verify"]["notes"])
    shutil.rmtree(tmp_path, ignore_errors=True)


def test_a_verification_made_without_the_key_takes_the_signature_check_afterwards(signed_bounce, tmp_path):
    """``review --ray`` verifies in workers without the key; the check is added in the main process."""
    from monitor import review

    src, model = signed_bounce
    dst = tmp_path / "forged.mcap"
    _episode_split(src, model, dst)
    contents = read_log(dst)
    ver = review.verify(contents)
    assert ver["signature"]["status"] == "not_checked" and ver["critical"] == 0
    ver = review.add_signature(ver, contents, KEY)
    assert ver["signature"]["first_bad"]["checkpoint"] == 3 and ver["critical"] == 1
    assert review.verify_exit_code(ver) == 1
    assert not any(n.startswith("signature not checked") for n in ver["notes"])
