"""Red team 15: a signed log cut at byte offsets (a killed writer, a truncated copy).

Property: review never exits 0 for a copy that lacks the writer's signed close (the final checkpoint:
for the journal the end of that message record, for the finalised file the end of the chunk that holds
it), and never crashes (only typed errors; an unusable file is exit 2).

Offsets: every record boundary of the file and boundary +-1, plus seeded random offsets; for each, the
signature check and the read checks that need no engine (a lower bound on review's exit: verify can only
add findings); on a seeded sample, the full ``review --verify --key-file`` CLI in process.

Run: PYTHONPATH=$PWD /work/main/.venv/bin/python docs/notes/redteam-15/fuzz_cuts.py [n_random] [n_cli]
"""

from __future__ import annotations

import contextlib
import io
import struct
import sys
import tempfile
from pathlib import Path

import numpy as np
from forge_encoding import KEY, signed_run  # same directory

from monitor.cli import main
from monitor.errors import LogFormatError
from monitor.log import read_log
from monitor.log.sign import check_signatures
from monitor.review import signature_exit_code


def top_records(data: bytes) -> list[tuple[int, int, int]]:
    """(opcode, start, end) of the top-level records after the leading magic."""
    out, pos = [], 8
    while pos + 9 <= len(data):
        op, n = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        if pos + 9 + n > len(data):
            break
        out.append((op, pos, pos + 9 + n))
        pos += 9 + n
    return out


def closed_from(data: bytes, journal: bool) -> int:
    """Smallest prefix length that holds the final checkpoint."""
    if journal:
        p = data.index(b'"final":true')
        return data.index(b'"}', p) + 2
    return max(end for op, _, end in top_records(data) if op == 0x06)  # the last chunk


def cli(path: Path, key_file: Path) -> tuple[int, str]:
    buf, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
        code = main(["review", "--verify", "--key-file", str(key_file), str(path)])
    return code, err.getvalue()


def run(n_random: int = 2000, n_cli: int = 60) -> int:
    tmp = Path(tempfile.mkdtemp(prefix="rt15-cuts-"))
    key_file = tmp / "log.key"
    key_file.write_bytes(KEY)
    rng = np.random.default_rng(15)
    bad = 0
    for journal in (True, False):
        src = tmp / ("journal.mcap" if journal else "final.mcap")
        if journal:
            import mujoco
            from forge_encoding import BOUNCE

            from monitor.gate import Gate

            m = mujoco.MjModel.from_xml_string(BOUNCE)
            d = mujoco.MjData(m)
            d.qpos[0], d.qvel[0] = -0.25, 1.0
            with Gate(
                m,
                log=src,
                frame_skip=50,
                allowed=None,
                on_violation="warn",
                log_options={"key": KEY, "index": False},
            ) as g:
                for _ in range(6):
                    g.step(d, np.zeros(1))
        else:
            signed_run(src)
        data = src.read_bytes()
        closed = closed_from(data, journal)
        offs = {0, 1, 7, 8, len(data)}
        for _, a, b in top_records(data):
            offs.update((a - 1, a, a + 1, b - 1, b, b + 1))
        offs.update(int(x) for x in rng.integers(0, len(data) + 1, n_random))
        offs = sorted(o for o in offs if 0 <= o <= len(data))
        cut = tmp / "cut.mcap"
        zero_open = crashes = 0
        for o in offs:
            cut.write_bytes(data[:o])
            try:
                c = read_log(cut)
            except LogFormatError:
                continue  # typed: review exits 2
            except Exception as exc:  # noqa: BLE001
                crashes += 1
                print(f"  CRASH reading at {o}: {type(exc).__name__}: {exc}")
                continue
            code = signature_exit_code(check_signatures(c, KEY).to_json())
            if code == 0 and o < closed:
                zero_open += 1
                print(f"  EXIT-0 SIGNATURE for a cut at {o} < {closed} (no signed close)")
        sample = sorted(int(x) for x in rng.choice(offs, size=min(n_cli, len(offs)), replace=False))
        cli_zero = cli_crash = 0
        codes: dict[int, int] = {}
        for o in sample:
            cut.write_bytes(data[:o])
            try:
                code, err = cli(cut, key_file)
            except Exception as exc:  # noqa: BLE001
                cli_crash += 1
                print(f"  CLI CRASH at {o}: {type(exc).__name__}: {exc}")
                continue
            codes[code] = codes.get(code, 0) + 1
            if code == 0 and o < closed:
                cli_zero += 1
                print(f"  CLI EXIT 0 for a cut at {o} < {closed}")
        print(
            f"{'journal' if journal else 'finalised'} ({len(data)} B, closed from {closed}): {len(offs)} cuts "
            f"read: {zero_open} exit-0 signatures without the close, {crashes} crashes; {len(sample)} CLI "
            f"reviews: codes {codes}, {cli_zero} exit 0 without the close, {cli_crash} crashes"
        )
        bad += zero_open + crashes + cli_zero + cli_crash
    return bad


if __name__ == "__main__":
    sys.exit(1 if run(*map(int, sys.argv[1:])) else 0)
