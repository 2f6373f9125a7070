"""Crash tolerance: killed writers, truncated copies, random bytes, corrupt records."""

from __future__ import annotations

import io
import os
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader

from monitor.cli import main
from monitor.log import MAX_MESSAGES_PER_WINDOW, read_log, topics
from monitor.log.reader import MAGIC

REPO = Path(__file__).resolve().parents[1]

WRITER = r'''
import os, sys, types
import numpy as np, mujoco
sys.path.insert(0, sys.argv[4])
from mcap.writer import Writer
from monitor.certify.certificate import Certificate, PairResult, Witness
from monitor.log import MonitorLog
mode, n, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
crash_at = int(sys.argv[5]) if len(sys.argv) > 5 else -1
XML = """<mujoco><asset><mesh name="w" vertex="0 0 0 .1 0 0 0 .1 0 0 0 .1"/></asset><worldbody>
<body name="table" pos=".6 0 .2"><geom name="table_top" type="box" size=".2 .3 .02"/></body>
<body name="arm" pos="0 0 .3"><joint type="hinge" axis="0 0 1"/><geom name="hand" type="mesh" mesh="w"/>
<geom name="link" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/></body></worldbody></mujoco>"""
model = mujoco.MjModel.from_xml_string(XML)
count = [0]
orig = Writer.add_message
def counting(self, *a, **k):
    orig(self, *a, **k)
    count[0] += 1
    if count[0] == crash_at:
        os._exit(3)            # killed in the middle of a window
Writer.add_message = counting
log = MonitorLog(path, model=model, foxglove=True, index=mode != "journal")
for k in range(n):
    v = "violation" if k % 4 == 2 else "certified"
    t0 = 0.002 * k
    w = Witness(t0, ("hand", "table_top"), np.array([.5, 0, .2]), -1e-3) if v == "violation" else None
    pr = PairResult(("hand", "table_top"), ("arm", "table"), v, "toleranced", 5, 2, (), 0.01, w)
    c = Certificate(v, (t0, t0 + 0.002), 0.0, 1e-3, "auto", w, t0 if w else None, 0.01, (pr,),
                    {"wall_seconds": 1e-4})
    q = np.array([[0.01 * k], [0.01 * k + 0.01]])
    plan = types.SimpleNamespace(times=np.array([t0, t0 + 0.002]), qpos=q, model=model)
    log.write_window(t0, plan, c, np.array([0.1]), np.array([0.1]), replaced=v != "certified")
    print(k + 1, count[0], flush=True)   # windows completed, messages handed to the writer
if mode in ("finish", "journal"):
    log.close()
    os._exit(0)
os._exit(1)                               # killed between windows: no finish(), no close()
'''


def _run_writer(tmp_path, mode, n, crash_at=-1):
    script = tmp_path / "writer.py"
    script.write_text(WRITER)
    path = tmp_path / f"{mode}.mcap"
    r = subprocess.run([sys.executable, str(script), mode, str(n), str(path), str(REPO), str(crash_at)],
                       capture_output=True, text=True, timeout=60)
    lines = [tuple(map(int, ln.split())) for ln in r.stdout.split("\n") if ln.strip()]
    return path, r.returncode, lines


def _official_count(data: bytes) -> int:
    """Messages yielded by mcap's NonSeekingReader before it stops (may include one cut message)."""
    n = 0
    try:
        for _ in NonSeekingReader(io.BytesIO(data)).iter_messages(log_time_order=False):
            n += 1
    except (McapError, struct.error, ValueError):
        pass
    return n


@pytest.fixture(scope="module")
def between_run(tmp_path_factory):
    """One writer killed between windows after 40 complete ones (no finish(), no close()): its file,
    exit code and per-window (windows, messages) lines. Read only; shared by the tests below (the
    message count after each window is the same in every mode that writes an index)."""
    return _run_writer(tmp_path_factory.mktemp("between"), "between", 40)


def test_killed_between_windows_loses_nothing(between_run):
    path, rc, lines = between_run
    assert rc == 1 and lines[-1][0] == 40
    written = lines[-1][1]
    c = read_log(path)
    assert not c.complete and c.stop_reason and "footer" in c.stop_reason
    assert c.unreadable_bytes == 0  # the last record is complete: nothing but the summary is missing
    assert c.n_messages == written  # documented loss when killed between windows: 0
    assert len(c.certificates()) == 40
    assert _official_count(path.read_bytes()) == written


@pytest.mark.parametrize("window", [0, 7, 23])
def test_killed_inside_a_window_loses_at_most_one_window(tmp_path, window, between_run):
    # find the message count at the end of window `window - 1` from a clean run, crash 2 messages later
    # (the shared 40-window run: its first windows are the same as a separate run's of window + 1)
    _, _, lines = between_run
    before = lines[window - 1][1] if window else 0
    crash_at = before + 2
    path, rc, lines = _run_writer(tmp_path, "mid", 40, crash_at)
    assert rc == 3 and len(lines) == window
    c = read_log(path)
    lost = crash_at - c.n_messages
    assert 0 <= lost <= MAX_MESSAGES_PER_WINDOW
    assert len(c.certificates()) >= window  # every completed window is there
    assert c.n_messages >= before
    assert main(["review", str(path)]) == (0 if window else 2)


def test_sigkill_mid_rollout(tmp_path):
    script = tmp_path / "writer.py"
    script.write_text(WRITER)
    path = tmp_path / "kill.mcap"
    proc = subprocess.Popen([sys.executable, str(script), "kill", "100000", str(path), str(REPO)],
                            stdout=subprocess.PIPE, text=True)
    done = 0
    for line in proc.stdout:  # wait until some windows are through, then SIGKILL
        done = int(line.split()[0])
        if done >= 150:
            break
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    c = read_log(path)
    # every window reported complete before the kill is in the file (flushed per window)
    assert len(c.certificates()) >= done
    assert [m["index"] for m in c.certificates()] == list(range(len(c.certificates())))


def _message_ends(data: bytes) -> list[int]:
    """End offsets of every message record of an unchunked MCAP (independent framing walk)."""
    ends, pos = [], len(MAGIC)
    while pos + 9 <= len(data):
        op, ln = struct.unpack_from("<BQ", data, pos)
        pos += 9 + ln
        if op == 0x05:
            ends.append(pos)
        if op == 0x02:  # footer
            break
    return ends


@pytest.fixture(scope="module")
def finished_log(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("crash")
    path, rc, lines = _run_writer(tmp, "journal", 30)  # closed, not finalised: unchunked records
    assert rc == 0
    return path


def test_truncated_copies_recover_every_complete_message(tmp_path, finished_log, capsys):
    data = finished_log.read_bytes()
    ends = _message_ends(data)
    rng = np.random.default_rng(20261122)
    cuts = sorted(rng.integers(0, len(data), size=10).tolist())
    for cut in cuts:
        p = tmp_path / f"cut{cut}.mcap"
        p.write_bytes(data[:cut])
        expected = sum(e <= cut for e in ends)
        if cut < len(MAGIC):
            with pytest.raises(Exception, match="not an MCAP file"):
                read_log(p)
        else:
            c = read_log(p)
            assert c.n_messages == expected, cut
            assert c.unreadable_bytes == cut - c.readable_bytes
            assert _official_count(data[:cut]) in (expected, expected + 1)
        code = main(["review", str(p)])
        out = capsys.readouterr()
        assert code in (0, 2)
        assert "Traceback" not in out.out + out.err
        if code == 0:
            assert "incomplete log" in out.out
        else:
            assert "error:" in out.err


def test_cli_subprocess_on_truncated_and_random_input(tmp_path, finished_log):
    data = finished_log.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: int(len(data) * 0.8)])
    rnd = tmp_path / "random.mcap"
    rnd.write_bytes(np.random.default_rng(0).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    r = subprocess.run([sys.executable, "-m", "monitor", "review", str(cut), str(rnd)], cwd=REPO,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr + r.stdout
    assert "not an MCAP file" in r.stderr
    assert "incomplete log" in r.stdout and "windows" in r.stdout


def test_garbage_inputs_give_clear_messages(tmp_path, capsys):
    rng = np.random.default_rng(5)
    cases = {
        "random.mcap": rng.integers(0, 256, 4096, dtype=np.uint8).tobytes(),
        "magic_then_random.mcap": MAGIC + rng.integers(0, 256, 4096, dtype=np.uint8).tobytes(),
        "empty.mcap": b"",
        "text.mcap": b"hello world\n" * 10,
    }
    for name, blob in cases.items():
        (tmp_path / name).write_bytes(blob)
        assert main(["review", str(tmp_path / name)]) == 2, name
        out = capsys.readouterr()
        assert "Traceback" not in out.err
        assert name in out.err
    assert main(["review", str(tmp_path / "missing.mcap")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_corrupt_record_and_payload(tmp_path, finished_log, capsys):
    data = bytearray(finished_log.read_bytes())
    ends = _message_ends(bytes(data))
    # (a) a JSON payload damaged in place (framing intact): skipped and counted
    a = bytearray(data)
    k = next(e for e in ends[len(ends) // 2:] if data[e - 1:e] == b"}")  # a JSON message
    a[k - 6:k] = b"\xff\xfe{{{{"
    pa = tmp_path / "payload.mcap"
    pa.write_bytes(bytes(a))
    c = read_log(pa)
    assert c.complete and c.n_messages == len(ends) and c.bad_payloads == 1
    assert sum(len(v) for v in c.messages.values()) + 1 == sum(
        n for t, n in c.counts.items() if t in topics.JSON_TOPICS)
    # (b) a record length field overwritten: reading stops there, the part before is kept
    b = bytearray(data)
    start = ends[len(ends) // 2]
    b[start + 1:start + 9] = struct.pack("<Q", 2**62)
    pb = tmp_path / "length.mcap"
    pb.write_bytes(bytes(b))
    c = read_log(pb)
    assert not c.complete and "claims" in c.stop_reason
    assert c.n_messages == len(ends) // 2 + 1
    # the file still ends with the closing magic: its writer finished it, so this is damage
    # (bit rot), not a killed writer, and review must not exit 0 on the readable half (issue 15)
    assert c.stop_kind == "corrupt"
    assert main(["review", str(pb)]) == 2
    assert "DAMAGED" in capsys.readouterr().out


def test_recovery_speed_smoke(tmp_path):
    """Not a timing assertion: the reader handles a few thousand windows (progress bar path)."""
    path, rc, lines = _run_writer(tmp_path, "between", 3000)
    t = time.perf_counter()
    c = read_log(path, progress=True)
    assert len(c.certificates()) == 3000
    dt = time.perf_counter() - t
    os.environ.get("CI") or print(f"read {path.stat().st_size / 1e6:.1f} MB in {dt:.2f} s")
    assert c.counts[topics.CERTIFICATE] == 3000


def test_chunked_compressed_copy_reads_the_same(tmp_path, finished_log):
    """Logs re-written by other tools (chunked, zstd) read the same; a cut loses only the open chunk."""
    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer

    dst = tmp_path / "chunked.mcap"
    with open(finished_log, "rb") as fi, open(dst, "wb") as fo:
        r = make_reader(fi)
        w = Writer(fo, chunk_size=4096, compression=CompressionType.ZSTD)
        w.start()
        s = r.get_summary()
        smap = {sid: w.register_schema(x.name, x.encoding, x.data) for sid, x in s.schemas.items()}
        cmap = {cid: w.register_channel(c.topic, c.message_encoding, smap.get(c.schema_id, 0))
                for cid, c in s.channels.items()}
        for a in r.iter_attachments():
            w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)
        for _, ch, msg in r.iter_messages(log_time_order=False):
            w.add_message(cmap[ch.id], msg.log_time, msg.data, msg.publish_time, msg.sequence)
        w.finish()
    a, b = read_log(finished_log), read_log(dst)
    assert b.complete and b.counts == a.counts and b.certificates() == a.certificates()
    data = dst.read_bytes()
    c = read_log(_write(tmp_path / "cut.mcap", data[: len(data) // 2]))
    assert 0 < len(c.certificates()) < len(a.certificates()) and not c.complete


def _write(p: Path, blob: bytes) -> Path:
    p.write_bytes(blob)
    return p
