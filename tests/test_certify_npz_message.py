"""The ``certify`` CLI on a file that is not an ``.npz``: one clear error line, exit 2 (issue 16)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from monitor.cli import main

_NUMPY_HINTS = ("unsafely", "allow_pickle", "Traceback", "pickled")


def _run(capsys, *args) -> tuple[int, str, str]:
    try:
        code = main(["certify", *map(str, args)])
    except SystemExit as exc:  # argparse / CLI exits
        code = exc.code
    out, err = capsys.readouterr()
    return int(code or 0), out, err


@pytest.mark.parametrize("content", [
    b"# monitor\n\nCertified collision-free motion for MuJoCo.\n",  # a README
    pickle.dumps({"times": [0.0, 1.0]}),  # a pickle: np.load would suggest allow_pickle=True
    b"",  # an empty file
])
def test_non_npz_file_one_line_no_numpy_hint(tmp_path, capsys, content):
    path = tmp_path / "README.md"
    path.write_bytes(content)
    code, out, err = _run(capsys, path, "--model", "arm")
    assert code == 2
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "README.md" in lines[0] and "not a readable .npz" in lines[0] and "np.savez" in lines[0]
    assert not any(h in err for h in _NUMPY_HINTS), err


def test_object_array_member_no_numpy_hint(tmp_path, capsys):
    path = tmp_path / "obj.npz"
    np.savez(path, times=np.array([0.0, 1.0], dtype=object), qpos=np.zeros((2, 6)))
    code, _, err = _run(capsys, path, "--model", "arm")
    assert code == 2 and "'times' has dtype object" in err
    assert not any(h in err for h in _NUMPY_HINTS), err
