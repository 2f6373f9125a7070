"""Hostile and damaged files: the reader and ``review`` stay fast, small and honest.

Work bounds are checked deterministically (records walked, bytes read, tracemalloc peak);
a SIGALRM guard turns a hang into a failure instead of a stuck test run. Sparse files
(``truncate``) stand for huge ones without using disk.
"""

from __future__ import annotations

import os
import signal
import struct
import tracemalloc
import zlib
from contextlib import contextmanager
from pathlib import Path

import mujoco
import numpy as np
import pytest
from mcap_rewrite import rewrite

from monitor.certify.certificate import Certificate, PairResult, Witness
from monitor.cli import main
from monitor.errors import LogFormatError
from monitor.log import MonitorLog, read_log, topics
from monitor.log.reader import MAGIC, MAX_SKIPPED_IN_A_ROW, check_xml_safe, load_model

XML = """
<mujoco model="hostile">
  <worldbody>
    <body name="table" pos="0.6 0 0.2"><geom name="table_top" type="box" size="0.2 0.3 0.02"/></body>
    <body name="link1" pos="0 0 0.2">
      <joint name="j1" type="hinge" axis="0 0 1"/>
      <geom name="link1_geom" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
    </body>
  </worldbody>
</mujoco>
"""
VERDICTS = ["certified", "violation", "certified", "uncertain", "certified", "violation", "certified",
            "certified"]
MB = 1024 * 1024


@contextmanager
def deadline(seconds: int):
    """Fail (not hang) when the block takes longer than ``seconds`` (a hang guard, not a benchmark)."""
    def boom(*_):
        raise TimeoutError(f"took longer than {seconds} s")

    old = signal.signal(signal.SIGALRM, boom)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


@contextmanager
def peak_memory(limit_bytes: int):
    tracemalloc.start()
    try:
        yield
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < limit_bytes, f"peak Python allocation {peak / MB:.1f} MB >= {limit_bytes / MB:.0f} MB"


def _cert(k: int, verdict: str, t0: float, dt: float = 0.01) -> Certificate:
    wit = None
    if verdict == "violation":
        wit = Witness(t0 + dt / 2, ("link1_geom", "table_top"), np.array([0.3, 0.0, 0.21]), -2e-3)
    ok = verdict == "certified"
    pr = PairResult(("table_top", "link1_geom"), ("table", "link1"), verdict, "toleranced", 7, 2,
                    () if ok else ((t0, t0 + dt),), 0.05 if ok else float("-inf"), wit)
    return Certificate(verdict, (t0, t0 + dt), 0.0, 1e-3, "auto", wit, None if ok else t0,
                       pr.clearance, (pr,), {"wall_seconds": 1e-4})


def _plan(model, t0, dt=0.01):
    import types

    return types.SimpleNamespace(times=np.array([t0, t0 + dt]), qpos=np.zeros((2, 1)), model=model)


@pytest.fixture
def log_path(tmp_path) -> Path:
    model = mujoco.MjModel.from_xml_string(XML)
    path = tmp_path / "small.mcap"
    # index=False: the closed journal stays unchunked, so tests can damage single raw records
    with MonitorLog(path, model=model, metadata={"margin": 0.0, "epsilon": 1e-3, "pairs": "all"},
                    foxglove=False, index=False) as log:
        for k, v in enumerate(VERDICTS):
            log.write_window(0.01 * k, _plan(model, 0.01 * k), _cert(k, v, 0.01 * k))
    return path


def _record(opcode: int, body: bytes) -> bytes:
    return struct.pack("<BQ", opcode, len(body)) + body


def _with_attachments(src: Path, dst: Path, replace: dict[str, bytes | None]) -> None:
    """Copy a log, replacing (bytes) or dropping (None) the named attachments."""
    rewrite(src, dst, attachments=lambda name, data: replace.get(name, data))


# --------------------------------------------------------------------------- zeros, sparse, floods


def test_50_mb_of_zeros_after_the_magic_is_rejected_at_once(tmp_path):
    p = tmp_path / "zeros.mcap"
    with open(p, "wb") as f:
        f.write(MAGIC)
        f.truncate(50 * MB)  # sparse zeros
    with deadline(10), peak_memory(4 * MB):
        c = read_log(p)
    assert c.stop_kind == "corrupt" and "reserved opcode 0x00" in c.stop_reason
    assert c.records_walked == 1 and c.bytes_read < 64
    assert main(["review", str(p)]) == 2


def test_sparse_4_gb_file_after_a_genuine_head(tmp_path, log_path):
    p = tmp_path / "sparse.mcap"
    with open(p, "wb") as f:
        data = log_path.read_bytes()
        f.write(data[: len(data) // 2])  # a genuine log cut in its data section, then 4 GB of holes
        f.truncate(4 * 1024 * MB)
    with deadline(10), peak_memory(16 * MB):
        c = read_log(p)
    assert c.stop_kind == "corrupt" and c.bytes_read < log_path.stat().st_size + 64
    assert c.unreadable_bytes > 4000 * MB


def test_flood_of_private_records_stops_after_the_cap(tmp_path):
    p = tmp_path / "private.mcap"
    rec = _record(0x80, b"")
    with open(p, "wb") as f:
        f.write(MAGIC + rec * (MAX_SKIPPED_IN_A_ROW + 5000))
    with deadline(20):
        c = read_log(p)
    assert c.stop_kind == "corrupt" and "index/private records in a row" in c.stop_reason
    assert c.records_walked <= MAX_SKIPPED_IN_A_ROW + 2


def test_record_claiming_gigabytes_is_not_allocated(tmp_path):
    p = tmp_path / "huge_record.mcap"
    with open(p, "wb") as f:
        f.write(MAGIC + struct.pack("<BQ", 0x09, 3 * 1024 * MB))  # an attachment "of 3 GB"
        f.truncate(3 * 1024 * MB + 100)
    with deadline(10), peak_memory(16 * MB):
        c = read_log(p)
    assert c.stop_kind == "corrupt" and "above the" in c.stop_reason


def _chunk(compression: str, data: bytes, claimed: int, crc: int = 0) -> bytes:
    comp = compression.encode()
    body = (struct.pack("<QQQI", 0, 0, claimed, crc) + struct.pack("<I", len(comp)) + comp
            + struct.pack("<Q", len(data)) + data)
    return _record(0x06, body)


def test_decompression_bomb_and_lying_chunks_are_bad_records(tmp_path):
    import zstandard

    bomb = zstandard.ZstdCompressor(level=3).compress(bytes(300 * MB))  # ~10 kB on disk
    assert len(bomb) < MB
    p = tmp_path / "chunks.mcap"
    header = _record(0x01, struct.pack("<I", 0) + struct.pack("<I", 4) + b"test")
    with open(p, "wb") as f:
        f.write(MAGIC + header + _chunk("zstd", bomb, 1000) + _chunk("zstd", bomb, 2 ** 40)
                + _chunk("", b"\x00" * 64, 64) + _chunk("lz4", b"garbage", 100)
                + _chunk("", b"x" * 64, 64, crc=12345))
    with deadline(20), peak_memory(64 * MB):
        c = read_log(p)
    assert c.bad_records == 5, c.problems
    assert any("chunk decompresses to 1001+ bytes" in x for x in c.problems)
    assert any("claims 1099511627776 uncompressed bytes" in x for x in c.problems)
    assert any("reserved opcode 0x00 at chunk record" in x for x in c.problems)
    assert any("chunk CRC mismatch" in x for x in c.problems)


def test_fifo_as_log_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "fifo.mcap"
    os.mkfifo(fifo)
    with deadline(5):
        with pytest.raises(LogFormatError, match="not a regular file"):
            read_log(fifo)
        assert main(["review", str(fifo)]) == 2


# --------------------------------------------------------------------------- model XML safety


@pytest.mark.parametrize("xml, why", [
    ('<mujoco><include file="/etc/passwd"/></mujoco>', "contains <include>"),
    ("<mujoco><INCLUDE file='x.xml'/></mujoco>", "contains <include>"),
    ('<mujoco><compiler meshdir="/etc"/></mujoco>', "sets meshdir"),
    ('<mujoco><asset><mesh file="/etc/passwd"/></asset></mujoco>', "is not the plain name"),
    ('<mujoco><asset><mesh file="../../x.stl"/></asset></mujoco>', "is not the plain name"),
    ('<mujoco><asset><mesh file="&#47;etc&#47;passwd"/></asset></mujoco>', "is not the plain name"),
    ('<mujoco><asset><texture fileback="nope.png"/></asset></mujoco>', "is not the plain name"),
])
def test_unsafe_model_xml_is_refused(xml, why):
    with pytest.raises(LogFormatError, match=why):
        check_xml_safe(xml.encode(), {"&#47;etc&#47;passwd": b"", "x.stl": b""})


@pytest.mark.parametrize("target", ["fifo", "/etc/passwd"])
def test_include_in_the_logged_model_is_refused_without_blocking(tmp_path, log_path, capsys, target):
    """The issue's attack: model.xml includes a FIFO (MuJoCo would block on it forever) or
    /etc/passwd (opened and parsed), and model.mjb is dropped so that the XML is used."""
    if target == "fifo":
        target = str(tmp_path / "fifo.xml")
        os.mkfifo(target)
    xml = f'<mujoco model="x"><include file="{target}"/><worldbody/></mujoco>'.encode()
    p = tmp_path / "include.mcap"
    _with_attachments(log_path, p, {topics.ATTACHMENT_XML: xml, topics.ATTACHMENT_MJB: None})
    with deadline(10):
        code = main(["review", "--verify", str(p)])
    out = capsys.readouterr().out
    assert code == 2 and "contains <include>: refused" in out


def test_plain_asset_names_still_load(log_path):
    c = read_log(log_path)
    model, how = load_model(c, "xml")
    assert model.ngeom == 2 and "model.xml" in how


# --------------------------------------------------------------------------- bit rot


@pytest.mark.parametrize("seed", range(8))
def test_bit_rot_never_drops_violations_with_exit_0(tmp_path, log_path, capsys, seed):
    """20 random bytes changed anywhere after the magic: review either exits non-zero or still
    reports every window and every violation (oracle: the intact log)."""
    assert main(["review", "--json", str(log_path)]) == 0
    import json

    want = json.loads(capsys.readouterr().out)["logs"][0]
    data = bytearray(log_path.read_bytes())
    rng = np.random.default_rng(seed)
    for pos in rng.choice(np.arange(len(MAGIC), len(data)), size=20, replace=False):
        data[pos] = (data[pos] + 1 + int(rng.integers(255))) % 256
    p = tmp_path / f"rot{seed}.mcap"
    p.write_bytes(bytes(data))
    with deadline(20):
        code = main(["review", "--json", str(p)])
    res = json.loads(capsys.readouterr().out)
    if code == 0:
        got = res["logs"][0]
        assert got["verdicts"] == want["verdicts"] and got["windows"] == want["windows"]


def test_damaged_closed_file_is_corrupt_not_truncated(tmp_path, log_path):
    data = bytearray(log_path.read_bytes())
    i = data.index(b'{"index":3')
    data[i - 31: i - 22] = b"\x00" * 9  # wipe the header of that message record (body head: 22 bytes)
    p = tmp_path / "mid.mcap"
    p.write_bytes(bytes(data))
    c = read_log(p)
    assert c.closed_by_writer and c.stop_kind == "corrupt"
    assert main(["review", str(p)]) == 2


def test_attachment_crc_is_checked(tmp_path, log_path):
    data = bytearray(log_path.read_bytes())
    i = data.index(b"table_top")
    data[i] = ord("T")
    p = tmp_path / "att.mcap"
    p.write_bytes(bytes(data))
    c = read_log(p)
    assert c.bad_records >= 1 and any("attachment CRC mismatch" in x for x in c.problems)
    assert zlib.crc32(b"") == 0
