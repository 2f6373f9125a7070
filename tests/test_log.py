"""MonitorLog writer + reader: round trip, schemas, timestamps, model attachments, foxglove."""

from __future__ import annotations

import json
import shutil
import sys
import types
from pathlib import Path

import mujoco
import numpy as np
import pytest
from mcap.reader import make_reader

from monitor.certify.certificate import Certificate, PairResult, Witness
from monitor.errors import InvalidInputError
from monitor.log import MonitorLog, load_model, read_log, topics
from monitor.log.reader import geometry_deviation
from monitor.log.writer import XML_GEOMETRY_TOL, default_path, export_model

REPO = Path(__file__).resolve().parents[1]
ARM = REPO / "models" / "arm" / "scene.xml"

SMALL_XML = """
<mujoco model="small">
  <asset><mesh name="wedge" vertex="0 0 0  0.1 0 0  0 0.1 0  0 0 0.1  0.1 0.1 0.1"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="table" pos="0.6 0 0.2"><geom name="table_top" type="box" size="0.2 0.3 0.02"/></body>
    <body name="link1" pos="0 0 0.3">
      <joint name="j1" type="hinge" axis="0 0 1"/>
      <geom name="link1_geom" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body name="hand" pos="0.3 0 0" euler="10 20 30">
        <geom name="hand_mesh" type="mesh" mesh="wedge" pos="0.01 0 0"/>
      </body>
    </body>
    <body name="target" mocap="true" pos="0.4 0.2 0.3">
      <geom name="target_geom" type="sphere" size="0.03"/>
    </body>
    <body name="cube" pos="0.6 0.1 0.5">
      <freejoint/><geom name="cube_geom" type="box" size="0.02 0.03 0.04"/>
    </body>
  </worldbody>
</mujoco>
"""


def small_model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(SMALL_XML)


def fake_plan(model, t0: float, dt: float = 0.01, rng=None):
    """Stand-in for monitor.Plan: times (2,), qpos (2, nq), mocap poses."""
    q = np.tile(model.qpos0, (2, 1))
    if rng is not None:
        q[:, 0] += rng.uniform(-1, 1, 2)
    return types.SimpleNamespace(times=np.array([t0, t0 + dt]), qpos=q, model=model,
                                 mocap_pos=np.array([[0.4, 0.2, 0.3]]), mocap_quat=np.array([[1.0, 0, 0, 0]]))


def hand_cert(k: int, verdict: str, t0: float, dt: float = 0.01) -> Certificate:
    wit = None
    if verdict == "violation":
        wit = Witness(t0 + dt / 2, ("hand_mesh", "table_top"), np.array([0.5, 0.01 * k, 0.2]),
                      -1e-3 * (k + 1))
    ok = verdict == "certified"
    pr = PairResult(("hand_mesh", "table_top"), ("hand", "table"), verdict, "toleranced", 10 + k, 3,
                    () if ok else ((t0, t0 + dt),), 0.01 * (k + 1) if ok else float("-inf"), wit)
    culled = PairResult(("link1_geom", "cube_geom"), ("link1", "cube"), "certified", "culled", 0, 0, (), 0.5)
    return Certificate(verdict, (t0, t0 + dt), 0.001, 1e-3, "auto", wit,
                       None if verdict == "certified" else t0, 0.01 * (k + 1) if verdict == "certified"
                       else float("-inf"), (pr, culled),
                       {"wall_seconds": 1e-4 * (k + 1), "checker_mix": {"toleranced": 1, "culled": 1}})


def write_demo_log(path, n=12, model=None, foxglove=True, verdicts=None, **kw):
    model = model if model is not None else small_model()
    rng = np.random.default_rng(1)
    certs, plans = [], []
    with MonitorLog(path, model=model, metadata={"margin": 0.001, "epsilon": 1e-3, "pairs": "mujoco",
                                                 "predictor": "rollout"}, foxglove=foxglove, **kw) as log:
        for k in range(n):
            v = verdicts[k] if verdicts else ("violation" if k % 5 == 3 else "uncertain" if k % 7 == 6
                                              else "certified")
            t0 = 0.01 * k
            c, p = hand_cert(k, v, t0), fake_plan(model, t0, rng=rng)
            log.write_window(t0, p, c, np.array([0.1 * k, 0.2]), np.array([0.0, 0.2]) if v != "certified"
                             else np.array([0.1 * k, 0.2]), replaced=v != "certified", wall_time=1e9 + k)
            certs.append(c)
            plans.append(p)
    return model, certs, plans


def test_round_trip_messages_metadata_timestamps(tmp_path):
    path = tmp_path / "run.mcap"
    model, certs, plans = write_demo_log(path)
    c = read_log(path)
    assert c.complete and c.unreadable_bytes == 0 and c.stop_reason is None and c.bad_payloads == 0
    got = c.certificates()
    assert len(got) == len(certs)
    for k, (msg, cert) in enumerate(zip(got, certs)):
        assert msg["index"] == k
        assert msg["_log_time"] == int(round((1e9 + k) * 1e9))  # wall clock, ns
        assert msg["wall_time"] == 1e9 + k and msg["episode"] == 0 and msg["sim_time"] == 0.01 * k
        back = Certificate.from_dict(msg)
        assert back.to_dict() == cert.to_dict()
    pl = c.plans_by_index()
    for k, p in enumerate(plans):
        assert np.array_equal(np.asarray(pl[k]["qpos"]), p.qpos)  # repr floats: exact
        assert np.array_equal(np.asarray(pl[k]["times"]), p.times)
        assert np.array_equal(np.asarray(pl[k]["mocap_pos"]), p.mocap_pos)
    n_bad = sum(1 for x in certs if x.verdict != "certified")
    assert len(c.topic(topics.VIOLATION)) == n_bad
    for v in c.topic(topics.VIOLATION):
        assert v["verdict"] in ("violation", "uncertain")
        assert all(p["verdict"] != "certified" for p in v["pairs"])
    acts = c.topic(topics.ACTION)
    assert sum(a["replaced"] for a in acts) == n_bad
    run = c.run
    assert run["margin"] == 0.001 and run["pairs"] == "mujoco" and run["predictor"] == "rollout"
    assert run["mujoco_version"] == mujoco.__version__
    assert run["version.mcap"] and run["version.numpy"] == np.__version__


def test_official_reader_and_json_schemas(tmp_path):
    import jsonschema

    path = tmp_path / "run.mcap"
    write_demo_log(path)
    with open(path, "rb") as f:
        r = make_reader(f)
        s = r.get_summary()
        names = [x.name for x in s.schemas.values()]
        assert len(names) == len(set(names))  # every schema registered once
        topics_seen = {ch.topic for ch in s.channels.values()}
        assert set(topics.JSON_TOPICS) <= topics_seen
        schemas = {sid: json.loads(x.data) for sid, x in s.schemas.items() if x.encoding == "jsonschema"}
        n = 0
        for schema, ch, msg in r.iter_messages():
            assert msg.publish_time < msg.log_time  # sim time vs wall clock
            if ch.message_encoding == "json":
                jsonschema.validate(json.loads(msg.data), schemas[schema.id])
                n += 1
        assert n == s.statistics.message_count - sum(
            s.statistics.channel_message_counts[cid] for cid, ch in s.channels.items()
            if ch.message_encoding != "json")
        atts = {a.name for a in r.iter_attachments()}
        assert {topics.ATTACHMENT_XML, topics.ATTACHMENT_MJB} <= atts
        assert {m.name for m in r.iter_metadata()} >= {topics.METADATA_RUN, topics.METADATA_MODEL}


def test_foxglove_messages_decode_and_quaternions(tmp_path):
    pytest.importorskip("foxglove")
    from mcap_protobuf.decoder import DecoderFactory
    from scipy.spatial.transform import Rotation

    path = tmp_path / "fox.mcap"
    model, certs, plans = write_demo_log(path, n=6)
    data = mujoco.MjData(model)
    seen_tf = 0
    entities = set()
    markers = 0
    with open(path, "rb") as f:
        r = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, ch, msg, dec in r.iter_decoded_messages(topics=list(topics.FOXGLOVE_TOPICS)):
            k = int(round(msg.publish_time / 1e7))  # publish_time = sim time (ns)
            if ch.topic == topics.TRANSFORMS:
                data.qpos[:] = plans[k].qpos[0]
                data.mocap_pos[:] = plans[k].mocap_pos
                data.mocap_quat[:] = plans[k].mocap_quat
                mujoco.mj_kinematics(model, data)
                assert len(dec.transforms) == model.nbody - 1
                for tf in dec.transforms:
                    b = model.body(tf.child_frame_id).id
                    np.testing.assert_allclose([tf.translation.x, tf.translation.y, tf.translation.z],
                                               data.xpos[b], atol=1e-12)
                    # independent check of the (x, y, z, w) convention: scipy uses (x, y, z, w)
                    R = Rotation.from_quat([tf.rotation.x, tf.rotation.y, tf.rotation.z, tf.rotation.w])
                    np.testing.assert_allclose(R.as_matrix(), data.xmat[b].reshape(3, 3), atol=1e-12)
                seen_tf += 1
            else:
                for e in dec.entities:
                    if ch.topic == topics.MARKERS:
                        assert e.id == "witness" and e.frame_id == "world"
                        markers += 1
                    else:
                        entities.add(e.id)
    assert seen_tf == 6
    assert {f"geom/{model.geom(g).name}" for g in range(model.ngeom)} <= entities
    assert markers == sum(c.verdict != "certified" for c in certs)


def test_quaternion_conversion_matches_mujoco_rotation():
    pytest.importorskip("foxglove")
    from scipy.spatial.transform import Rotation

    from monitor.log.foxglove_scene import mj_quat, xyzw

    rng = np.random.default_rng(3)
    for _ in range(20):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        R_mj = np.empty(9)
        mujoco.mju_quat2Mat(R_mj, q)
        R_fx = Rotation.from_quat(xyzw(q)).as_matrix()  # scipy and Foxglove: (x, y, z, w)
        np.testing.assert_allclose(R_fx, R_mj.reshape(3, 3), atol=1e-12)
        x, y, z, w = xyzw(q)
        np.testing.assert_array_equal(mj_quat(types.SimpleNamespace(x=x, y=y, z=z, w=w)), q)


def test_foxglove_missing_is_skipped(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "foxglove", None)
    monkeypatch.setitem(sys.modules, "foxglove.messages", None)
    monkeypatch.delitem(sys.modules, "monitor.log.foxglove_scene", raising=False)
    path = tmp_path / "nofox.mcap"
    with MonitorLog(path, model=small_model()) as log:
        assert not log.foxglove_enabled and "foxglove" in log.foxglove_error
        log.write_window(0.0, fake_plan(log._model, 0.0), hand_cert(0, "certified", 0.0))
    c = read_log(path)
    assert c.counts.get(topics.SCENE, 0) == 0 and c.counts[topics.CERTIFICATE] == 1


def test_model_attachments_rebuild_without_original_files(tmp_path):
    src = tmp_path / "scene"
    shutil.copytree(ARM.parent, src)
    model = mujoco.MjModel.from_xml_path(str(src / "scene.xml"))
    path = tmp_path / "arm.mcap"
    with MonitorLog(path, model=model, foxglove=False) as log:
        log.write_window(0.0, fake_plan(model, 0.0), hand_cert(0, "certified", 0.0))
    shutil.rmtree(src)  # review must not need the original files
    c = read_log(path)
    assert any(k.startswith(topics.ASSET_PREFIX) for k in c.attachments)
    m_xml, how = load_model(c, "xml")
    assert "model.xml" in how
    rng = np.random.default_rng(0)
    for _ in range(3):
        q = model.qpos0 + rng.uniform(-1, 1, model.nq)
        assert geometry_deviation(model, m_xml, q) <= XML_GEOMETRY_TOL
    m_mjb, _ = load_model(c, "mjb")
    assert geometry_deviation(model, m_mjb, q) == 0.0
    assert load_model(c, "auto")[1].startswith("model.mjb")
    names = [m_xml.geom(g).name for g in range(m_xml.ngeom)]
    assert names == [model.geom(g).name for g in range(model.ngeom)]


def test_export_when_model_is_not_the_last_compiled(tmp_path):
    model = mujoco.MjModel.from_xml_path(str(ARM))
    mujoco.MjModel.from_xml_string(SMALL_XML)  # now mj_saveLastXML(model) cannot work
    exp = export_model(model)
    assert exp.mjb
    if exp.xml is None:
        assert "xml_error" in exp.info
    else:  # whatever path produced it, it must match
        back = mujoco.MjModel.from_xml_string(exp.xml, assets=exp.assets)
        assert geometry_deviation(model, back) <= XML_GEOMETRY_TOL
    # with the source given, the XML is always produced and matches
    exp2 = export_model(model, source=ARM)
    assert exp2.xml is not None, exp2.info
    back = mujoco.MjModel.from_xml_string(exp2.xml, assets=exp2.assets)
    assert geometry_deviation(model, back) <= XML_GEOMETRY_TOL


def test_same_sized_other_model_is_not_attached_as_xml():
    """mj_saveLastXML copies a model into the LAST spec if sizes agree: the check must catch it."""
    xml_b = (SMALL_XML.replace('size="0.2 0.3 0.02"', 'size="0.25 0.3 0.02"')
             .replace('pos="0.6 0 0.2"', 'pos="0.1 0 0.2"').replace("table_top", "table_tip"))
    model = small_model()
    mujoco.MjModel.from_xml_string(xml_b)
    exp = export_model(model)
    if exp.xml is not None:
        back = mujoco.MjModel.from_xml_string(exp.xml, assets=exp.assets)
        assert geometry_deviation(model, back) <= XML_GEOMETRY_TOL
        assert back.geom("table_top").id == model.geom("table_top").id
    else:
        assert "xml_error" in exp.info


def test_export_pins_mesh_geoms_where_mujoco_places_them():
    """A mesh geom alone in its body sits at the body's inertial frame (``geom_sameframe`` INERTIA):
    after a centre-of-mass edit (``body_ipos``, domain randomisation) MuJoCo moves it there and
    ignores ``geom_pos``. Base b036d4c pinned the exported geom at ``geom_pos``: the recompiled XML
    was 0.21 m off and no XML was attached. Oracle: MuJoCo's own ``geom_xpos`` of both models
    (:func:`geometry_deviation`, ``mj_kinematics``), at ``qpos0`` and a random pose."""
    xml = """<mujoco><asset><mesh name="tet" vertex="0 0 0  1 0 0  0 1 0  0 0 1" scale=".1 .1 .1"/></asset>
    <worldbody><body name="b" pos="0 -0.5 0"><freejoint/><geom name="m" type="mesh" mesh="tet"/></body>
    <body name="c" pos="0.5 0 0"><freejoint/><geom name="m2" type="mesh" mesh="tet" pos="0.1 0 0"/>
    <geom name="s" type="sphere" size="0.02"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    g = model.geom("m").id
    assert int(model.geom_sameframe[g]) == int(mujoco.mjtSameFrame.mjSAMEFRAME_INERTIA)  # set-up
    model.body_ipos[model.body("b").id] += (0.0, 0.2, 0.05)
    exp = export_model(model)
    assert exp.xml is not None, exp.info
    back = mujoco.MjModel.from_xml_string(exp.xml, assets=exp.assets)
    q = np.array(model.qpos0)
    q[:3], q[3:7] = (0.1, 0.2, 0.3), np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
    for qpos in (None, q):
        assert geometry_deviation(model, back, qpos) <= XML_GEOMETRY_TOL


def test_plan_model_attached_lazily_and_default_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    p = default_path("monitor/Arm-v0")
    assert p.parent == Path("logs") and p.name.startswith("monitor_Arm-v0-") and p.suffix == ".mcap"
    model = small_model()
    with MonitorLog(env_id="Arm-v0", foxglove=False) as log:
        path = log.path
        log.write_window(0.5, fake_plan(model, 0.5), hand_cert(0, "certified", 0.5))
    assert path.parent.resolve() == (tmp_path / "logs").resolve() and path.name.startswith("Arm-v0-")
    c = read_log(path)
    assert topics.ATTACHMENT_MJB in c.attachments and c.run["env_id"] == "Arm-v0"


def test_bad_input_raises_typed_errors(tmp_path):
    model = small_model()
    log = MonitorLog(tmp_path / "x.mcap", model=model, foxglove=False)
    cert = hand_cert(0, "certified", 0.0)
    for t in (-1.0, float("nan"), float("inf")):
        with pytest.raises(InvalidInputError, match="sim_time"):
            log.write_window(t, fake_plan(model, 0.0), cert)
    bad = cert.to_dict()
    bad["verdict"] = "safe"
    with pytest.raises(InvalidInputError, match="verdict"):
        log.write_window(0.0, fake_plan(model, 0.0), bad)
    with pytest.raises(InvalidInputError, match="plan"):
        log.write_window(0.0, object(), cert)
    log.close()
    log.close()  # idempotent
    with pytest.raises(InvalidInputError, match="closed"):
        log.write_window(0.0, fake_plan(model, 0.0), cert)
