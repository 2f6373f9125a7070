"""Red team 15: random edits and splices of a signed log, re-sealed by the forger; none may verify.

Two real signed runs with the same key (A: the ball hits the wall, a violation; B: a slower ball, a
different wall gap, no violation). Each case rewrites A record by record (``mcap`` writer, zstd chunks or
unchunked) with one edit, re-seals it with ``monitor.log.digest`` (the forger has the library, not the
key), and checks ``check_signatures`` with the key: its exit must not be 0 (a record change the chain
covers). Edits: drop / duplicate / swap / re-time / re-sequence / byte-edit a message; drop / duplicate /
swap / edit a metadata record; drop / duplicate / replace an attachment (the model, by B's); B's messages,
checkpoints, metadata or attachments spliced into A at random places; A cut at a checkpoint and B's tail
appended; channel moves (topic-preserving: the fixed hole E) and edits the chain does not cover (schema
bytes, channel metadata, attachment times, header library), for which the whole review is run and its
exit and window verdicts compared with the genuine log's.

Run: PYTHONPATH=$PWD /work/main/.venv/bin/python docs/notes/redteam-15/fuzz_edits.py [n_cases] [seed]
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
import tempfile
from pathlib import Path

import mujoco
import numpy as np
from forge_encoding import BOUNCE, KEY
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from monitor.cli import main
from monitor.gate import Gate
from monitor.log import read_log
from monitor.log.digest import METADATA_DIGEST, Digest
from monitor.log.sign import check_signatures
from monitor.review import signature_exit_code


def run_log(path: Path, qvel: float, wall_x: float) -> None:
    m = mujoco.MjModel.from_xml_string(BOUNCE.replace('pos="0.2 0 0"', f'pos="{wall_x} 0 0"'))
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = -0.25, qvel
    with Gate(m, log=path, frame_skip=50, allowed=None, on_violation="warn", log_options={"key": KEY}) as g:
        for _ in range(6):
            g.step(d, np.zeros(1))


def load(path: Path) -> dict:
    """Every record of a log as plain tuples (channels keyed by id)."""
    with open(path, "rb") as f:
        r = make_reader(f)
        s = r.get_summary()
        return {
            "library": r.get_header().library,
            "schemas": {i: (x.name, x.encoding, bytes(x.data)) for i, x in s.schemas.items()},
            "channels": {
                i: [c.topic, c.message_encoding, c.schema_id, dict(c.metadata)] for i, c in s.channels.items()
            },
            "metadata": [(m.name, dict(m.metadata)) for m in r.iter_metadata() if m.name != METADATA_DIGEST],
            "attachments": [
                [a.create_time, a.log_time, a.name, a.media_type, bytes(a.data)] for a in r.iter_attachments()
            ],
            "messages": [
                [ch.topic, m.log_time, m.publish_time, m.sequence, bytes(m.data)]
                for _, ch, m in r.iter_messages(log_time_order=False)
            ],
        }


def write(log: dict, dst: Path, chunked: bool, seal: bool = True) -> None:
    """Write ``log`` (messages routed by topic to the first channel of that topic, unless a message
    carries a sixth field, a channel id) and seal it as the writer would.
    """
    d = Digest()
    with open(dst, "wb") as fo:
        w = Writer(
            fo, use_chunking=chunked, compression=CompressionType.ZSTD if chunked else CompressionType.NONE
        )
        w.start(library=log["library"])
        smap = {i: w.register_schema(*x) for i, x in log["schemas"].items()}
        cmap, by_topic = {}, {}
        for i, (topic, enc, sid, meta) in log["channels"].items():
            cmap[i] = w.register_channel(topic, enc, smap.get(sid, 0), meta)
            by_topic.setdefault(topic, cmap[i])
        for name, vals in log["metadata"]:
            w.add_metadata(name, vals)
            d.metadata(name, vals)
        for a in log["attachments"]:
            w.add_attachment(*a)
            d.attachment(a[2], a[3], a[4])
        for msg in log["messages"]:
            topic, lt, pt, seq, data = msg[:5]
            cid = cmap[msg[5]] if len(msg) > 5 else by_topic[topic]
            w.add_message(cid, lt, data, pt, seq)
            d.message(topic, lt, pt, seq, data)
        if seal:
            w.add_metadata(METADATA_DIGEST, d.seal())
        w.finish()


def review(path: Path, key_file: Path) -> tuple[int, dict]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        code = main(["review", "--verify", "--json", "--key-file", str(key_file), str(path)])
    return code, json.loads(buf.getvalue())["logs"][0]


def _json_edit(data: bytes, rng: np.random.Generator) -> bytes:
    """One leaf of a JSON payload changed (a number nudged, a bool flipped, a string altered), nested
    values included (a rollout's start state, a witness, a pair's clearance).
    """
    o = json.loads(data)
    leaves = []

    def walk(x, path):
        items = x.items() if isinstance(x, dict) else enumerate(x) if isinstance(x, list) else ()
        for k, v in items:
            if isinstance(v, (dict, list)):
                walk(v, path + [k])
            elif isinstance(v, (int, float, bool, str)):
                leaves.append(path + [k])

    walk(o, [])
    if not leaves:
        return data + b" "
    path = leaves[int(rng.integers(len(leaves)))]
    parent = o
    for k in path[:-1]:
        parent = parent[k]
    v = parent[path[-1]]
    parent[path[-1]] = (not v) if isinstance(v, bool) else (v + 1 if isinstance(v, (int, float)) else v + "x")
    return json.dumps(o, separators=(",", ":")).encode()


def mutate(a: dict, b: dict, rng: np.random.Generator) -> tuple[str, dict]:
    """One random covered edit of log ``a`` (``b``: the other run, same key)."""
    x = json.loads(
        json.dumps({k: v for k, v in a.items() if k not in ("messages", "attachments", "schemas")})
    )
    x["messages"] = [list(m) for m in a["messages"]]
    x["attachments"] = [list(t) for t in a["attachments"]]
    x["schemas"] = dict(a["schemas"])
    x["channels"] = {int(k): v for k, v in x["channels"].items()}
    x["metadata"] = [tuple(t) for t in x["metadata"]]
    ms, md, at = x["messages"], x["metadata"], x["attachments"]
    i = int(rng.integers(len(ms)))
    kind = str(
        rng.choice(
            [
                "msg_drop",
                "msg_dup",
                "msg_swap",
                "msg_time",
                "msg_pub",
                "msg_seq",
                "msg_edit",
                "meta_drop",
                "meta_dup",
                "meta_swap",
                "meta_edit",
                "att_drop",
                "att_dup",
                "att_swap_model",
                "splice_msg",
                "splice_checkpoint",
                "splice_meta",
                "tail_from_b",
                "msg_move",
                "msg_topic",
            ]
        )
    )
    if kind == "msg_drop":
        del ms[i]
    elif kind == "msg_dup":
        ms.insert(i, list(ms[i]))
    elif kind == "msg_swap":
        j = min(i + 1, len(ms) - 1) if i + 1 < len(ms) else i - 1
        ms[i], ms[j] = ms[j], ms[i]
    elif kind == "msg_time":
        ms[i][1] += int(rng.integers(1, 10**6))
    elif kind == "msg_pub":
        ms[i][2] += int(rng.integers(1, 10**6))
    elif kind == "msg_seq":
        ms[i][3] += 1
    elif kind == "msg_edit":
        if ms[i][0].startswith("/monitor/") and ms[i][0] not in (
            "/monitor/scene",
            "/monitor/markers",
            "/monitor/tf",
        ):
            ms[i][4] = _json_edit(ms[i][4], rng)
        else:
            p = int(rng.integers(len(ms[i][4])))
            ms[i][4] = ms[i][4][:p] + bytes([ms[i][4][p] ^ 1]) + ms[i][4][p + 1 :]
    elif kind == "meta_drop":
        del md[int(rng.integers(len(md)))]
    elif kind == "meta_dup":
        j = int(rng.integers(len(md)))
        md.insert(int(rng.integers(len(md) + 1)), md[j])
    elif kind == "meta_swap":
        if len(md) > 1:
            j = int(rng.integers(len(md) - 1))
            md[j], md[j + 1] = md[j + 1], md[j]
        else:
            md.append(md[0])
    elif kind == "meta_edit":
        j = int(rng.integers(len(md)))
        name, vals = md[j]
        k = sorted(vals)[int(rng.integers(len(vals)))]
        md[j] = (name, {**vals, k: vals[k] + " "})
    elif kind == "att_drop":
        del at[int(rng.integers(len(at)))]
    elif kind == "att_dup":
        at.append(list(at[int(rng.integers(len(at)))]))
    elif kind == "att_swap_model":  # the model (xml or mjb) replaced by run B's (another wall position)
        j = int(rng.integers(len(at)))
        other = {t[2]: t for t in b["attachments"]}
        at[j] = list(other.get(at[j][2], at[j]))
        at[j][4] = other[at[j][2]][4] if at[j][2] in other else at[j][4] + b" "
    elif kind == "splice_msg":
        ms.insert(i, list(b["messages"][int(rng.integers(len(b["messages"])))]))
    elif kind == "splice_checkpoint":  # one of A's checkpoints replaced by B's of the same number
        cps = [j for j, m in enumerate(ms) if m[0] == "/monitor/signature"]
        bcp = [m for m in b["messages"] if m[0] == "/monitor/signature"]
        j = cps[int(rng.integers(len(cps)))]
        ms[j] = list(bcp[min(cps.index(j), len(bcp) - 1)])
    elif kind == "splice_meta":
        md.insert(int(rng.integers(len(md) + 1)), tuple(b["metadata"][int(rng.integers(len(b["metadata"])))]))
    elif kind == "tail_from_b":  # A up to its checkpoint after window k, then B from its own
        cps_a = [j for j, m in enumerate(ms) if m[0] == "/monitor/signature"]
        cps_b = [j for j, m in enumerate(b["messages"]) if m[0] == "/monitor/signature"]
        k = int(rng.integers(1, min(len(cps_a), len(cps_b)) - 1))
        x["messages"] = ms[: cps_a[k] + 1] + [list(m) for m in b["messages"][cps_b[k] + 1 :]]
    elif kind == "msg_move":  # to a twin channel of its topic with another encoding (hole E, fixed)
        topic = ms[i][0]
        new = max(x["channels"]) + 1
        sid = next(v[2] for v in x["channels"].values() if v[0] == topic)
        x["channels"][new] = [topic, "cbor", sid, {}]
        ms[i] = list(ms[i]) + [new]
    elif kind == "msg_topic":
        ms[i][0] = "/monitor/log" if ms[i][0] != "/monitor/log" else "/monitor/action"
    return kind, x


def uncovered(a: dict, rng: np.random.Generator) -> tuple[str, dict]:
    """One edit of what the chain does not cover (must not change review's verdicts)."""
    x = {
        **a,
        "channels": {k: list(v) for k, v in a["channels"].items()},
        "schemas": dict(a["schemas"]),
        "attachments": [list(t) for t in a["attachments"]],
    }
    kind = str(rng.choice(["schema_bytes", "channel_meta", "attachment_time", "library"]))
    if kind == "schema_bytes":
        k = sorted(x["schemas"])[int(rng.integers(len(x["schemas"])))]
        name, enc, data = x["schemas"][k]
        x["schemas"][k] = (name, enc, data + b" ")
    elif kind == "channel_meta":
        k = sorted(x["channels"])[int(rng.integers(len(x["channels"])))]
        x["channels"][k][3] = {"forged": "1"}
    elif kind == "attachment_time":
        x["attachments"][0][1] += 123
    else:
        x["library"] = "forger/0"
    return kind, x


def run(n: int = 400, seed: int = 15) -> int:
    tmp = Path(tempfile.mkdtemp(prefix="rt15-edits-"))
    key_file = tmp / "log.key"
    key_file.write_bytes(KEY)
    run_log(tmp / "a.mcap", 1.0, 0.2)
    run_log(tmp / "b.mcap", 0.5, 0.3)
    a, b = load(tmp / "a.mcap"), load(tmp / "b.mcap")
    code_a, e_a = review(tmp / "a.mcap", key_file)
    print(f"genuine A: exit {code_a}, verdicts {e_a['verdicts']}")
    rng = np.random.default_rng(seed)
    passed, kinds = 0, {}
    genuine = read_log(tmp / "a.mcap")
    dst = tmp / "x.mcap"
    for t in range(n):
        kind, x = mutate(a, b, rng)
        write(x, dst, chunked=bool(t % 2))
        c = read_log(dst)
        code = signature_exit_code(check_signatures(c, KEY).to_json())
        if code == 0 and (c.bad_payloads or c.bad_records or c.stop_kind == "corrupt"):
            code = 2  # review's read check (a skipped record): exit 2 whatever the signature says
        kinds.setdefault(kind, [0, 0])[0] += 1
        if code == 0:
            # the signature passed: did the edit change anything review reads? (a no-op edit is fine;
            # monitor.finalise is written after sealing, outside the chain, and review never reads it)
            g = genuine
            meta = {k: v for k, v in c.metadata.items() if k != "monitor.finalise"}
            same = (
                c.messages == g.messages
                and meta == {k: v for k, v in g.metadata.items() if k != "monitor.finalise"}
                and c.attachments == g.attachments
                and c.requests == g.requests
                and c.model_edits == g.model_edits
            )
            if not same:
                kinds[kind][1] += 1
                passed += 1
                print(f"  case {t} {kind}: signature exit 0 for a changed log")
    print(
        "covered edits (cases / exit 0 from the signature and read checks on a changed log):",
        ", ".join(f"{k} {v[0]}/{v[1]}" for k, v in sorted(kinds.items())),
    )
    ukinds: dict[str, list[int]] = {}
    for t in range(max(8, n // 20)):
        kind, x = uncovered(a, rng)
        write(x, dst, chunked=bool(t % 2))
        code, e = review(dst, key_file)
        changed = code != code_a or e["verdicts"] != e_a["verdicts"]
        ukinds.setdefault(kind, [0, 0])[0] += 1
        ukinds[kind][1] += changed
        if changed and code == 0:
            passed += 1
            print(f"  uncovered {kind}: exit 0 with other verdicts {e['verdicts']}")
    print(
        "uncovered edits (cases, review exit or verdicts changed):",
        ", ".join(f"{k} {v[0]}/{v[1]}" for k, v in sorted(ukinds.items())),
    )
    for name, blob in (
        ("A||B", (tmp / "a.mcap").read_bytes() + (tmp / "b.mcap").read_bytes()),
        ("B||A", (tmp / "b.mcap").read_bytes() + (tmp / "a.mcap").read_bytes()),
    ):
        dst.write_bytes(blob)
        code, e = review(dst, key_file)
        print(
            f"concatenated {name}: exit {code}, windows {e.get('windows')}, verdicts {e.get('verdicts')}, "
            f"signature {e.get('verify', {}).get('signature', {}).get('status')}"
        )
    return passed


if __name__ == "__main__":
    sys.exit(1 if run(*map(int, sys.argv[1:])) else 0)
