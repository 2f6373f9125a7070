"""``review --verify`` cannot be talked into a result: every forgery of issue 15, made from a genuine log.

A genuine arm log (scripted plans, 24 windows, 4 of them violations, certified by the real
engine) is rewritten record by record as a forger would; each forged log must make
``review --verify`` exit non-zero and name the reason. Oracle: the genuine log itself
(re-verified with exit 0) and the forger's edit, which we know.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
from mcap_rewrite import rewrite

from monitor.cli import main
from monitor.log import MonitorLog, topics

REPO = Path(__file__).resolve().parents[1]
ARM = REPO / "models" / "arm" / "scene.xml"
N_WINDOWS = 24
DIVE = (5, 17)  # windows whose end pose points link2 through the floor


@pytest.fixture(scope="module")
def genuine(tmp_path_factory) -> dict[str, Any]:
    from monitor.certify.engine import certify
    from monitor.motion.plan import Plan
    from monitor.scene import Scene

    model = mujoco.MjModel.from_xml_path(str(ARM))
    scene = Scene.from_model(model, pairs="mujoco")
    path = tmp_path_factory.mktemp("forgery") / "genuine.mcap"
    q = model.qpos0.copy()
    verdicts = []
    meta = {"margin": 0.005, "epsilon": 1e-3, "pairs": "mujoco", "predictor": "scripted"}
    with MonitorLog(path, model=model, model_source=str(ARM), metadata=meta) as log:
        for k in range(N_WINDOWS):
            t0 = 0.02 * k
            q1 = q.copy()
            q1[0] = 0.1 * np.sin(k)
            q1[1] = 1.55 if k in DIVE else 0.2
            q1[2] = 0.0
            plan = Plan(np.array([t0, t0 + 0.02]), np.stack([q, q1]), model=model)
            cert = certify(scene, plan, margin=0.005, epsilon=1e-3)
            verdicts.append(cert.verdict)
            log.write_window(t0, plan, cert)
            q = q1
    bad = [k for k, v in enumerate(verdicts) if v != "certified"]
    assert len(bad) >= 2 and "certified" in verdicts
    return {"path": path, "verdicts": verdicts, "bad": bad, "model": model}


def flip(bad: list[int], extra: Callable[[str, dict], Any] | None = None) -> Callable[[str, dict], Any]:
    """The naive forgery: every violation becomes "certified" (and its violation message goes)."""
    def edit(topic: str, o: dict) -> Any:
        if topic == topics.VIOLATION and o["index"] in bad:
            return None
        if topic == topics.CERTIFICATE and o["index"] in bad:
            o.update(verdict="certified", witness=None, earliest_time=None, clearance=0.05)
            for p in o["pairs"]:
                p.update(verdict="certified", witness=None, intervals=[], clearance=0.05)
        return o if extra is None else extra(topic, o)
    return edit


def review(path: Path, capsys, *extra: str) -> tuple[int, str]:
    code = main(["review", "--verify", "--no-progress", *extra, str(path)])
    return code, capsys.readouterr().out


def test_genuine_log_verifies_with_exit_0(genuine, capsys):
    code, out = review(genuine["path"], capsys)
    assert code == 0, out
    assert (f"{N_WINDOWS} re-derived, 0 mismatch(es), 0 critical, 0 without plan, 0 error(s); "
            f"0 unverifiable, 0 with a different pair set; {N_WINDOWS} window(s) in the log") in out
    assert "model: consistent" in out


@pytest.mark.parametrize("chunked", [False, True], ids=["unchunked", "chunked-zstd"])
def test_naive_flip_is_critical(genuine, tmp_path, capsys, chunked):
    dst = tmp_path / "flip.mcap"
    rewrite(genuine["path"], dst, msg=flip(genuine["bad"]), chunked=chunked)
    code, out = review(dst, capsys)
    assert code == 1, out
    for k in genuine["bad"]:
        assert re.search(rf"window {k} t=\S+: logged certified -> recomputed violation  \[CRITICAL\]", out)


def _one_far_pair(topic, o):
    if topic == topics.CERTIFICATE:
        o["pairs"] = [p for p in o["pairs"] if p["geoms"] == ["post_b", "shelf_low"]
                      or sorted(p["geoms"]) == sorted(o["pairs"][0]["geoms"])][:1]
    return o


def _shrink_window(topic, o):
    if topic == topics.CERTIFICATE:
        o["window"] = [o["window"][0], o["window"][0] + 1e-9]
    return o


def _stationary_second_plan(topic, o):
    if topic == topics.PLAN:
        still = dict(o, qpos=[o["qpos"][0], o["qpos"][0]])
        return [o, still]
    return o


def _drop_plans(bad):
    def edit(topic, o):
        return None if topic == topics.PLAN and o["index"] in bad else o
    return edit


def _set(key, value):
    def edit(topic, o):
        if topic == topics.CERTIFICATE:
            o[key] = value
        return o
    return edit


def _capitalised_verdict(bad):
    def edit(topic, o):
        if topic == topics.CERTIFICATE and o["index"] == bad[0]:
            o["verdict"] = "Violation"
        return o
    return edit


def _run_meta(**kv):
    def edit(name, values):
        if name == topics.METADATA_RUN:
            values.update(kv)
        return values
    return edit


FORGERIES = {
    # name: (rewrite kwargs builder, expected exit, reason regex)
    "pairs-one-far-pair": (lambda bad: {"msg": flip(bad, _one_far_pair)}, 1,
                           r"\[CRITICAL\] window \d+: certificate pairs differ from the model's pair set"),
    "window-shrunk": (lambda bad: {"msg": flip(bad, _shrink_window)}, 1,
                      r"\[CRITICAL\] window \d+: window \[.*\] is not the plan's span"),
    "duplicate-plan-index": (lambda bad: {"msg": flip(bad, _stationary_second_plan)}, 1,
                             r"\[CRITICAL\] window \d+: window index \d+ has 2 plan messages"),
    "plans-removed": (lambda bad: {"msg": flip(bad, _drop_plans(bad))}, 2,
                      r"\[UNVERIFIABLE\] window \d+: no plan logged for this window"),
    "epsilon-negative": (lambda bad: {"msg": flip(bad, _set("epsilon", -1))}, 1,
                         r"\[CRITICAL\] window \d+: epsilon=-1 is invalid"),
    "method-unknown": (lambda bad: {"msg": flip(bad, _set("method", "oracle"))}, 1,
                       r"\[CRITICAL\] window \d+: unknown method 'oracle'"),
    "metadata-pairs-list": (lambda bad: {"msg": flip(bad),
                                         "metadata": _run_meta(pairs=[["post_b", "link1"]])},
                            1, r"\[CRITICAL\] window \d+: certificate pairs differ"),
    "metadata-pairs-nonsense": (lambda bad: {"msg": flip(bad), "metadata": _run_meta(pairs=5)}, 1,
                                r"\[CRITICAL\] log: logged pair policy is invalid"),
    "metadata-pairs-unknown-geom": (lambda bad: {"msg": flip(bad),
                                                 "metadata": _run_meta(pairs=[["nope", "link1"]])}, 1,
                                    r"\[CRITICAL\] log: logged pair policy .* is not valid for the attached"),
    "tolerances-negative-pad": (lambda bad: {"msg": flip(bad), "metadata": _run_meta(
        tolerances={"abs_pad": -1.0})}, 1, r"\[CRITICAL\] log: logged tolerances are invalid: abs_pad=-1.0"),
    "tolerances-nan-string": (lambda bad: {"msg": flip(bad), "metadata": _run_meta(
        tolerances={"abs_pad": "NaN"})}, 1,
        r"\[CRITICAL\] log: logged tolerances are invalid: abs_pad='NaN' "),
    "verdict-capitalised": (lambda bad: {"msg": flip(bad[1:], _capitalised_verdict(bad))}, 1,
                            r"\[CRITICAL\] window \d+: unknown verdict 'Violation'"),
    "margin-lowered": (lambda bad: {"msg": flip(bad, _set("margin", 0.0))}, 1,
                       r"\[CRITICAL\] window \d+: margin=0.0 differs from the "
                       r"(run's|logged request's) 0.005"),
}


@pytest.mark.parametrize("name", sorted(FORGERIES))
def test_forgery_is_caught_with_its_reason(genuine, tmp_path, capsys, name):
    build, want_code, reason = FORGERIES[name]
    dst = tmp_path / f"{name}.mcap"
    rewrite(genuine["path"], dst, **build(genuine["bad"]))
    code, out = review(dst, capsys)
    assert code == want_code, out
    assert re.search(reason, out), out


def _move_floor(name, data):
    if name == topics.ATTACHMENT_MJB:
        return None
    if name == topics.ATTACHMENT_XML:
        text = data.decode()
        new = re.sub(r'(<geom name="floor"[^>]*?)(/>)', r'\1 pos="0 0 -5"\2', text, count=1)
        assert new != text
        return new.encode()
    return data


def test_edited_xml_without_mjb_cannot_pass(genuine, tmp_path, capsys):
    dst = tmp_path / "xml.mcap"
    rewrite(genuine["path"], dst, msg=flip(genuine["bad"]), attachments=_move_floor)
    code, out = review(dst, capsys)
    assert code != 0, out
    assert "model.xml cannot be cross-checked against model.mjb" in out
    assert "no model.mjb attachment" in out


def test_edited_xml_next_to_mjb_is_critical(genuine, tmp_path, capsys):
    dst = tmp_path / "xml2.mcap"
    rewrite(genuine["path"], dst, msg=flip(genuine["bad"]),
            attachments=lambda n, d: d if n == topics.ATTACHMENT_MJB else _move_floor(n, d))
    for source in ("auto", "xml"):
        code, out = review(dst, capsys, "--model-source", source)
        assert code == 1, out
        assert "[CRITICAL] log: model.xml and model.mjb are different models: geometry differs" in out


def test_certificate_removed_is_a_gap(genuine, tmp_path, capsys):
    bad = genuine["bad"]
    dst = tmp_path / "gap.mcap"
    rewrite(genuine["path"], dst, msg=lambda t, o: None if o.get("index") == bad[0] else o)
    code = main(["review", str(dst)])
    out = capsys.readouterr().out
    assert code == 2 and f"INTEGRITY: certificate indices have 1 gap(s) (first: [{bad[0]}])" in out


def test_crafted_fields_cost_only_their_message(genuine, tmp_path, capsys):
    """clearance "x", witness point "zz", sim_time "abc", pairs 5, 100 000-deep JSON: skipped and
    counted; the genuine log reviewed in the same command keeps its full output."""
    bad = genuine["bad"]
    deep = "[" * 100_000 + "]" * 100_000

    def craft(topic, o):
        if topic != topics.CERTIFICATE:
            return o
        k = o["index"]
        if k == 0:
            o["clearance"] = "x"
        elif k == 1 and o.get("witness") is None:
            o["witness"] = {"time": 0.0, "geoms": ["a", "b"], "point": "zz", "distance": 0.0}
        elif k == 2:
            o["sim_time"] = "abc"
        elif k == 3:
            o["pairs"] = 5
        elif k == 4:
            return ('{"index": 4, "stats": ' + deep + "}").encode()
        return o

    dst = tmp_path / "craft.mcap"
    rewrite(genuine["path"], dst, msg=craft)
    code = main(["review", "--no-progress", str(dst), str(genuine["path"])])
    out = capsys.readouterr().out
    assert code == 2, out
    assert "SKIPPED: 1 undecodable message(s), 0 damaged record(s), 4 malformed certificate(s)" in out
    assert "JSON nested too deeply" in out
    for why in ("clearance 'x' is not a number or null", "witness.point is not three finite numbers",
                "sim_time 'abc' is not a finite number", "pairs is not a list"):
        assert why in out, why
    assert f"windows {N_WINDOWS - 5}: certified" in out  # the crafted log's other windows are kept
    genuine_line = f"windows {N_WINDOWS}: certified {N_WINDOWS - len(bad)}, violation {len(bad)}"
    assert genuine_line in out
    assert out.count("== /") == 2


def test_consistent_short_pair_policy_is_noted_and_caught_by_expect_pairs(genuine, tmp_path, capsys):
    """The strongest pair forgery: metadata and every certificate claim the same single far pair.
    The log then only claims that pair (a note says so); an auditor who requires MuJoCo's pair
    filter gets a critical finding and a recomputation over every pair."""
    far = ["post_b", "shelf_low"]

    def one_pair(topic, o):
        if topic == topics.CERTIFICATE:
            o["pairs"] = [dict(o["pairs"][0], geoms=far, bodies=["post_b", "shelf"], verdict="certified")]
        return o

    dst = tmp_path / "short.mcap"
    rewrite(genuine["path"], dst, msg=flip(genuine["bad"], one_pair),
            metadata=_run_meta(pairs=[far]))
    code, out = review(dst, capsys)
    assert "note: pair policy is an explicit list of 1 pair(s): only those pairs are certified" in out
    code, out = review(dst, capsys, "--expect-pairs", "mujoco")
    assert code == 1, out
    assert "[CRITICAL] log: logged pair policy [['post_b', 'shelf_low']] is not the required 'mujoco'" in out
    assert "logged certified -> recomputed violation  [CRITICAL]" in out
