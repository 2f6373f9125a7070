"""Digest seal (monitor.log.digest): a sealed log reads back as sealed; any later edit,
reordering, dropped record or changed attachment is a mismatch; an unsealed log says so.

The writer hook is simulated by :func:`seal_copy`, which copies a log record by record
through the plain ``mcap`` Writer and feeds each record to a :class:`Digest` exactly as
``MonitorLog`` would (see ``docs/notes/issue-15.md`` for the hook).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from monitor.cli import main
from monitor.log import MonitorLog, read_log
from monitor.log.digest import METADATA_DIGEST, Digest

XML = """
<mujoco><worldbody>
  <body name="b" pos="0 0 1"><freejoint/><geom name="g" type="sphere" size="0.1"/></body>
  <geom name="floor" type="plane" size="1 1 0.1"/>
</worldbody></mujoco>
"""


def _log(path: Path) -> Path:
    import types

    from monitor.certify.certificate import Certificate, PairResult

    model = mujoco.MjModel.from_xml_string(XML)
    with MonitorLog(path, model=model, metadata={"pairs": "mujoco"}, foxglove=False) as log:
        for k in range(5):
            t0 = 0.01 * k
            q = np.tile(model.qpos0, (2, 1))
            plan = types.SimpleNamespace(times=np.array([t0, t0 + 0.01]), qpos=q, model=model)
            pr = PairResult(("floor", "g"), ("world", "b"), "certified", "toleranced", 1, 0, (), 0.9, None)
            cert = Certificate("certified", (t0, t0 + 0.01), 0.0, 1e-3, "auto", None, None, 0.9, (pr,), {})
            log.write_window(t0, plan, cert)
    return path


def seal_copy(src: Path, dst: Path, *, chunked: bool = False, edit=None, swap: int | None = None) -> None:
    """Copy ``src`` sealing it like the writer hook; ``edit(i, data)`` / ``swap`` then tamper
    with the copy *after* the seal was computed (a forger who does not recompute it)."""
    with open(src, "rb") as fi, open(dst, "wb") as fo:
        r = make_reader(fi)
        comp = CompressionType.ZSTD if chunked else CompressionType.NONE
        w = Writer(fo, use_chunking=chunked, compression=comp)
        w.start(library=r.get_header().library)
        d = Digest()
        s = r.get_summary()
        smap = {sid: w.register_schema(x.name, x.encoding, x.data) for sid, x in s.schemas.items()}
        cmap = {cid: w.register_channel(c.topic, c.message_encoding, smap.get(c.schema_id, 0), c.metadata)
                for cid, c in s.channels.items()}
        for m in r.iter_metadata():
            if m.name == METADATA_DIGEST:  # the writer's own seal: replaced by this copy's
                continue
            w.add_metadata(m.name, m.metadata)
            d.metadata(m.name, m.metadata)
        for a in r.iter_attachments():
            w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)
            d.attachment(a.name, a.media_type, a.data)
        msgs = [(ch, m) for _, ch, m in r.iter_messages(log_time_order=False)]
        for ch, m in msgs:
            d.message(ch.topic, m.log_time, m.publish_time, m.sequence, m.data)
        if swap is not None:
            msgs[swap], msgs[swap + 1] = msgs[swap + 1], msgs[swap]
        for i, (ch, m) in enumerate(msgs):
            data = m.data if edit is None else edit(i, m.data)
            w.add_message(cmap[ch.id], m.log_time, data, m.publish_time, m.sequence)
        w.add_metadata(METADATA_DIGEST, d.seal())
        w.finish()


@pytest.mark.parametrize("chunked", [False, True])
def test_sealed_log_reads_as_sealed(tmp_path, chunked, capsys):
    src = _log(tmp_path / "a.mcap")
    assert read_log(src).seal_status == "sealed"  # MonitorLog seals on close (finalised, chunked file)
    dst = tmp_path / "sealed.mcap"
    seal_copy(src, dst, chunked=chunked)
    c = read_log(dst)
    assert c.seal_status == "sealed", c.seal_detail
    assert main(["review", str(dst)]) == 0
    capsys.readouterr()


def _same_length_digit_edit(i, data):
    return data.replace(b'"clearance":0.9', b'"clearance":0.8', 1) if i == 3 else data


@pytest.mark.parametrize("how", ["edit", "swap"])
def test_edit_or_reorder_after_sealing_is_detected(tmp_path, capsys, how):
    src = _log(tmp_path / "a.mcap")
    dst = tmp_path / f"{how}.mcap"
    if how == "edit":
        seal_copy(src, dst, edit=_same_length_digit_edit)
    else:
        seal_copy(src, dst, swap=2)
    c = read_log(dst)
    assert c.seal_status == "mismatch" and "edited or reordered" in c.seal_detail
    assert main(["review", str(dst)]) == 2
    assert "INTEGRITY: digest seal: the log changed after its writer sealed it" in capsys.readouterr().out


def test_dropped_record_changes_the_counts(tmp_path):
    src = _log(tmp_path / "a.mcap")
    sealed = tmp_path / "s.mcap"
    seal_copy(src, sealed)
    # drop one message from the sealed copy (keeping its seal): the counts disagree
    dst = tmp_path / "drop.mcap"
    with open(sealed, "rb") as fi, open(dst, "wb") as fo:
        r = make_reader(fi)
        w = Writer(fo, use_chunking=False)
        w.start()
        s = r.get_summary()
        smap = {sid: w.register_schema(x.name, x.encoding, x.data) for sid, x in s.schemas.items()}
        cmap = {cid: w.register_channel(c.topic, c.message_encoding, smap.get(c.schema_id, 0), c.metadata)
                for cid, c in s.channels.items()}
        for m in r.iter_metadata():
            w.add_metadata(m.name, m.metadata)
        for a in r.iter_attachments():
            w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)
        for i, (_, ch, m) in enumerate(r.iter_messages(log_time_order=False)):
            if i != 1:
                w.add_message(cmap[ch.id], m.log_time, m.data, m.publish_time, m.sequence)
        w.finish()
    c = read_log(dst)
    assert c.seal_status == "mismatch" and "messages" in c.seal_detail and "sealed vs" in c.seal_detail
