"""The command line: --version, the program name in usage, plain-text help, progress bars."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from monitor.cli import SUBCOMMANDS, build_parser, main, plain_text, prog_name, version

REPO = Path(__file__).resolve().parents[1]
REST = re.compile(r"``|:(func|class|meth|mod|data|attr):`|\*\*\w")


def test_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    out = capsys.readouterr().out.strip()
    import monitor

    assert out == f"monitor {version()}" and version() == monitor.__version__


def test_prog_name_script_vs_module():
    assert prog_name("/usr/local/bin/monitor") == "monitor"
    assert prog_name("/x/site-packages/monitor/__main__.py") == "python -m monitor"
    assert build_parser("monitor").format_usage().startswith("usage: monitor ")
    r = subprocess.run([sys.executable, "-m", "monitor", "--help"], cwd=REPO, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0 and r.stdout.startswith("usage: python -m monitor ")


def test_console_script_usage_says_monitor(tmp_path):
    """Run main() the way the installed ``monitor`` script does (argv[0] = .../bin/monitor)."""
    code = ("import sys; sys.argv = ['/venv/bin/monitor', 'review', '--help']; "
            "from monitor.cli import main; main()")
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0
    assert r.stdout.startswith("usage: monitor review ")
    assert "python -m monitor" not in r.stdout.splitlines()[0]


@pytest.mark.parametrize("sub", [None, *SUBCOMMANDS])
def test_help_has_no_raw_rest(sub, capsys):
    with pytest.raises(SystemExit):
        main(["--help"] if sub is None else [sub, "--help"])
    out = capsys.readouterr().out
    assert out.startswith("usage: ")
    assert not REST.search(out), REST.search(out)


def test_plain_text():
    assert plain_text("see :func:`monitor.certify` and ``x.npz``, **one** per plan") == \
        "see monitor.certify and x.npz, one per plan"
    assert plain_text(None) is None


def test_rollouts_step_progress_on_stderr(capsys):
    from monitor.rollouts import RandomPolicy, rollouts

    s = rollouts("tunnel", RandomPolicy(hold=5), episodes=1, steps=6, seeds=3, workers=1, progress=True)
    err = capsys.readouterr().err
    assert s.episodes[0].steps == 6
    assert "episode 0 (seed 3)" in err and "/6 [" in err and "gated rollouts" in err
    rollouts("tunnel", RandomPolicy(hold=5), episodes=1, steps=3, seeds=3, workers=1, progress=False)
    assert capsys.readouterr().err == ""


def test_demo_progress_bar_on_stderr():
    r = subprocess.run([sys.executable, "-m", "monitor", "demo", "--steps", "2", "--no-log", "--progress"],
                       cwd=REPO, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "gated steps" in r.stderr and "/2 [" in r.stderr
    assert "%|" not in r.stdout and "monitor demo:" in r.stdout  # the bar goes to stderr only
