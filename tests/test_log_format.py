"""Log format version 2, read with the ``mcap`` library (issue 16 acceptance).

Checks on a demo-style log (two episodes, violations, uncertain windows, blocked actions):
wall-clock ``log_time`` rising through the file, ``episode`` + ``sim_time`` in every JSON
payload, chunk + message indexes with a summary on a cleanly closed log, ``null`` for
unknown values, a ``foxglove.Log`` channel, metadata values not double-encoded, attachment
times set; a killed writer's journal turned into an indexed file by ``review --reindex``.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
import types
from pathlib import Path

import mujoco
import numpy as np
import pytest
from mcap.reader import make_reader

from monitor.certify.certificate import Certificate, PairResult, Witness
from monitor.cli import main
from monitor.log import MonitorLog, read_log, topics
from monitor.log.writer import encode_metadata, finalise_log

REPO = Path(__file__).resolve().parents[1]

XML = """<mujoco model="fmt"><worldbody>
<body name="table" pos=".6 0 .2"><geom name="table_top" type="box" size=".2 .3 .02"/></body>
<body name="arm" pos="0 0 .3"><joint name="yaw" type="hinge" axis="0 0 1"/>
<geom name="link" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/></body></worldbody></mujoco>"""

VERDICTS = ["certified", "certified", "violation", "certified", "uncertain", "certified"]
"""Per-episode verdict pattern (two episodes are written)."""


def _cert(verdict: str, t0: float, dt: float = 0.01) -> Certificate:
    wit = Witness(t0 + dt / 2, ("link", "table_top"), np.array([0.5, 0.0, 0.2]), -1e-3) \
        if verdict == "violation" else None
    clear = 0.02 if verdict == "certified" else float("-inf")  # -inf: no bound known
    pr = PairResult(("link", "table_top"), ("arm", "table"), verdict, "toleranced", 4, 2,
                    () if verdict == "certified" else ((t0, t0 + dt),), clear, wit)
    return Certificate(verdict, (t0, t0 + dt), 0.001, 1e-3, "auto", wit,
                       None if verdict == "certified" else t0, clear, (pr,),
                       {"wall_seconds": 1e-4, "budget_left": float("inf")})


def write_two_episodes(path: Path, **kw) -> mujoco.MjModel:
    """Two episodes whose sim time both start at 0, as a gated env with a reset writes them."""
    model = mujoco.MjModel.from_xml_string(XML)
    with MonitorLog(path, model=model, env_id="monitor/Arm-v0",
                    metadata={"margin": 0.001, "pairs": "mujoco", "predictor": "rollout", "note": "1.0"},
                    **kw) as log:
        for _episode in range(2):
            for k, v in enumerate(VERDICTS):
                t0 = 0.01 * k
                plan = types.SimpleNamespace(times=np.array([t0, t0 + 0.01]),
                                             qpos=np.array([[0.1 * k], [0.1 * k + 0.05]]), model=model)
                log.write_window(t0, plan, _cert(v, t0), np.array([0.3]),
                                 np.array([0.0]) if v != "certified" else np.array([0.3]),
                                 replaced=v != "certified")
    return model


@pytest.fixture(scope="module")
def demo_log(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("fmt") / "demo.mcap"
    t_before = time.time_ns()
    write_two_episodes(path)
    path.with_suffix(".t").write_text(f"{t_before} {time.time_ns()}")
    return path


def _messages(path: Path):
    with open(path, "rb") as f:
        r = make_reader(f)
        return [(ch.topic, ch.message_encoding, sch.name if sch else None, m)
                for sch, ch, m in r.iter_messages(log_time_order=False)]


def test_wall_clock_log_time_rises_through_the_file(demo_log):
    t_before, t_after = map(int, demo_log.with_suffix(".t").read_text().split())
    msgs = _messages(demo_log)
    log_times = [m.log_time for *_, m in msgs]
    assert log_times == sorted(log_times)  # file order is log-time order: episodes never interleave
    assert t_before <= log_times[0] and log_times[-1] <= t_after  # wall clock, not 1970
    certs = [(m.log_time, json.loads(m.data)) for t, _, _, m in msgs if t == topics.CERTIFICATE]
    assert len(certs) == 2 * len(VERDICTS)
    assert all(a[0] < b[0] for a, b in zip(certs, certs[1:]))  # strictly rising window by window
    for log_ns, c in certs:
        assert log_ns == max(int(round(c["wall_time"] * 1e9)), log_ns)  # log_time is the window's wall clock
    # publish_time = sim time of the window (ns), restarting with each episode
    pub = [m.publish_time for t, _, _, m in msgs if t == topics.CERTIFICATE]
    assert pub == [int(round(0.01 * k * 1e9)) for k in range(len(VERDICTS))] * 2


def test_episode_and_sim_time_in_every_json_payload(demo_log):
    n = 0
    for topic, enc, _, m in _messages(demo_log):
        if enc != "json":
            continue
        d = json.loads(m.data)
        assert isinstance(d["episode"], int) and isinstance(d["sim_time"], float), topic
        assert m.publish_time == int(round(d["sim_time"] * 1e9)), topic
        n += 1
    eps = [json.loads(m.data)["episode"] for t, _, _, m in _messages(demo_log) if t == topics.CERTIFICATE]
    assert eps == [0] * len(VERDICTS) + [1] * len(VERDICTS)
    assert n > 2 * len(VERDICTS)


def test_closed_log_is_chunked_and_indexed_with_summary(demo_log):
    with open(demo_log, "rb") as f:
        r = make_reader(f)
        s = r.get_summary()
        assert s is not None and s.statistics is not None
        assert s.chunk_indexes and all(ci.message_index_offsets for ci in s.chunk_indexes)
        assert s.statistics.message_count == len(_messages(demo_log))
        assert s.statistics.chunk_count == len(s.chunk_indexes)
        assert {a.name for a in s.attachment_indexes} >= {topics.ATTACHMENT_MJB, topics.ATTACHMENT_XML}
        assert {m.name for m in s.metadata_indexes} >= {topics.METADATA_RUN, topics.METADATA_FINALISE}
        # an indexed read by time range returns exactly the messages of that range
        certs = [m for t, _, _, m in _messages(demo_log) if t == topics.CERTIFICATE]
        lo, hi = certs[3].log_time, certs[8].log_time
        got = [m for _, ch, m in r.iter_messages(topics=[topics.CERTIFICATE], starting_at=lo, ending_at=hi)]
        assert [m.log_time for m in got] == [m.log_time for m in certs[3:9]]
    c = read_log(demo_log)  # the crash-tolerant reader reads the indexed file the same
    assert c.complete and len(c.certificates()) == 2 * len(VERDICTS)


def test_unknown_values_are_null(demo_log):
    raw = demo_log.read_bytes()
    assert b"1e+308" not in raw and b"1e308" not in raw
    unc = [json.loads(m.data) for t, _, _, m in _messages(demo_log) if t == topics.CERTIFICATE]
    bad = [c for c in unc if c["verdict"] != "certified"]
    assert bad and all(c["clearance"] is None for c in bad)
    assert all(c["stats"]["budget_left"] is None for c in unc)
    assert all(c["clearance"] == 0.02 for c in unc if c["verdict"] == "certified")
    back = Certificate.from_dict(bad[0])
    assert back.clearance == float("-inf")  # null reads back as "no bound"


def test_foxglove_log_channel(demo_log):
    import jsonschema

    logs = [(sch, m) for t, _, sch, m in _messages(demo_log) if t == topics.LOG]
    assert {sch for sch, _ in logs} == {"foxglove.Log"}
    per_episode = [v for v in VERDICTS if v != "certified"]
    assert len(logs) == 2 * len(per_episode)
    schema = topics.schema(topics.LOG)
    levels = []
    for _, m in logs:
        d = json.loads(m.data)
        jsonschema.validate(d, schema)
        assert d["timestamp"]["sec"] * 10**9 + d["timestamp"]["nsec"] == m.log_time
        assert "action replaced" in d["message"]
        levels.append(d["level"])
    assert levels == [4 if v == "violation" else 3 for v in per_episode] * 2  # error / warning
    assert "violation link / table_top" in json.loads(logs[0][1].data)["message"]


def test_metadata_values_not_double_encoded_and_attachment_times(demo_log):
    with open(demo_log, "rb") as f:
        r = make_reader(f)
        run = {}
        for m in r.iter_metadata():
            if m.name == topics.METADATA_RUN:
                run.update(m.metadata)
        atts = list(r.iter_attachments())
    assert run["env_id"] == "monitor/Arm-v0"  # not "\"monitor/Arm-v0\""
    assert run["pairs"] == "mujoco" and run["note"] == "1.0" and run["version.mujoco"] == mujoco.__version__
    assert json.loads(run["margin"]) == 0.001 and json.loads(run["format_version"]) == topics.FORMAT_VERSION
    assert "margin" in run[topics.METADATA_JSON_KEYS].split(",")
    assert "env_id" not in run[topics.METADATA_JSON_KEYS].split(",")
    decoded = read_log(demo_log).run
    assert decoded["note"] == "1.0" and decoded["margin"] == 0.001
    assert topics.METADATA_JSON_KEYS not in decoded
    t_before, t_after = map(int, demo_log.with_suffix(".t").read_text().split())
    assert atts and all(t_before <= a.log_time <= t_after and a.create_time == a.log_time for a in atts)


def test_reserved_metadata_key_and_bad_episode(tmp_path):
    from monitor.errors import InvalidInputError

    with pytest.raises(InvalidInputError, match="_json_keys"):
        encode_metadata({topics.METADATA_JSON_KEYS: 1})
    model = mujoco.MjModel.from_xml_string(XML)
    with MonitorLog(tmp_path / "e.mcap", model=model, foxglove=False) as log:
        plan = types.SimpleNamespace(times=np.array([0.0, 0.01]), qpos=np.zeros((2, 1)), model=model)
        log.write_window(0.0, plan, _cert("certified", 0.0), episode=3)
        with pytest.raises(InvalidInputError, match="episode"):
            log.write_window(0.01, plan, _cert("certified", 0.0), episode=2)
        assert log.new_episode() == 4
        log.write_window(0.02, plan, _cert("certified", 0.0))
    assert [c["episode"] for c in read_log(tmp_path / "e.mcap").certificates()] == [3, 4]


KILLED = r'''
import os, sys, types
sys.path.insert(0, sys.argv[2])
sys.path.insert(0, sys.argv[3])
import numpy as np
from test_log_format import write_two_episodes
import monitor.log.writer as w
w.MonitorLog.close = lambda self: os._exit(1)   # killed before close: the journal is all there is
write_two_episodes(__import__("pathlib").Path(sys.argv[1]))
'''


def _summary_or_none(p: Path):
    from mcap.exceptions import McapError

    with open(p, "rb") as f:
        try:
            return make_reader(f).get_summary()
        except McapError:
            return None


def test_review_reindex_turns_a_killed_writers_journal_into_an_indexed_file(tmp_path, capsys):
    script = tmp_path / "killed.py"
    script.write_text(KILLED)
    path = tmp_path / "killed.mcap"
    r = subprocess.run([sys.executable, str(script), str(path), str(REPO), str(REPO / "tests")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, r.stderr
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"  # also a journal cut inside a record
    cut.write_bytes(data[:-7])
    for p in (path, cut):
        before = read_log(p)
        assert not before.complete
        assert _summary_or_none(p) is None  # journal: no footer, no summary, no index
        assert main(["review", "--reindex", str(p)]) == 0
        err = capsys.readouterr().err
        assert f"reindexed {p}" in err
        with open(p, "rb") as f:
            rd = make_reader(f)
            s = rd.get_summary()
            assert s.chunk_indexes and s.statistics.message_count == before.n_messages
            assert sum(1 for _ in rd.iter_messages()) == before.n_messages
        after = read_log(p)
        assert after.complete and after.certificates() == before.certificates()
        fin = after.metadata[topics.METADATA_FINALISE]
        assert fin["source_complete"] is False
        assert (fin["dropped_bytes"] > 0) == (p == cut)
    assert "cut record dropped" in err
    assert main(["review", "--reindex", str(tmp_path / "nope.mcap")]) == 2
    assert "cannot reindex" in capsys.readouterr().err


def test_finalise_is_idempotent_on_a_finished_log(tmp_path):
    path = tmp_path / "twice.mcap"
    write_two_episodes(path, foxglove=False)
    a = read_log(path)
    res = finalise_log(path)
    b = read_log(path)
    assert res.source_complete and res.dropped_bytes == 0 and res.windows == 2 * len(VERDICTS)
    assert b.complete and b.certificates() == a.certificates() and b.run == a.run
    assert b.attachments == a.attachments


def test_stl_assets_hold_the_compiled_mesh_exactly(tmp_path):
    """Attached STL (written by trimesh) parsed with numpy: triangles equal the compiled mesh bit for bit."""
    xml = ("<mujoco><asset><mesh name='w' vertex='0 0 0 .1 0 0 0 .1 0 0 0 .1 .07 .07 .07'/></asset>"
           "<worldbody><body><geom type='mesh' mesh='w'/></body></worldbody></mujoco>")
    model = mujoco.MjModel.from_xml_string(xml)
    with MonitorLog(tmp_path / "m.mcap", model=model, foxglove=False):
        pass
    att = read_log(tmp_path / "m.mcap").attachments
    (name,) = [k for k in att if k.startswith(topics.ASSET_PREFIX)]
    blob = att[name]
    (n,) = np.frombuffer(blob[80:84], "<u4")
    rec = np.frombuffer(blob[84:], dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    assert len(rec) == n == model.mesh_facenum[0] and len(blob) == 84 + 50 * n
    V = model.mesh_vert[: model.mesh_vertnum[0]]
    F = model.mesh_face[: model.mesh_facenum[0]]
    assert np.array_equal(rec["v"], V[F])
