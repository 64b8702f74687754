"""Every snippet of docs/python.md and docs/scale-out.md, run as written.

Each ```python block runs in a fresh interpreter from a scratch directory that sees the
repository's `scenes/` (so the files the snippets write stay out of the checkout), with
matplotlib drawing off-screen. The `python -m facette.distributed` lines of the ```sh
blocks run the same way. The other shell lines (pip installs, maturin, Slurm scripts) are
not run here: the installs are what scripts/test.sh does before the tests, and the Slurm
lines need a cluster (their `facette render --part` / `facette merge` commands are the
command line's, tested in crates/cli).
"""

import os
import pathlib
import re
import shlex
import signal
import subprocess
import sys
import time

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def blocks(doc, lang):
    text = (REPO / "docs" / doc).read_text()
    return re.findall(rf"```{lang}\n(.*?)```", text, flags=re.S)


PYTHON_BLOCKS = [(doc, k, code) for doc in ("python.md", "scale-out.md") for k, code in enumerate(blocks(doc, "python"))]


def distributed_lines(doc):
    """The `python -m facette.distributed …` commands of a doc's sh blocks (backslash
    continuations joined)."""
    out = []
    for block in blocks(doc, "sh"):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.split(" #")[0].strip()
            if line.startswith("python -m facette.distributed"):
                out.append(line)
    return out


@pytest.fixture
def workdir(tmp_path):
    (tmp_path / "scenes").symlink_to(REPO / "scenes")
    return tmp_path


def env():
    e = dict(os.environ, MPLBACKEND="Agg")
    return e


def test_the_docs_have_the_snippets_this_file_runs():
    # Guards the extraction: an edit that renamed the fences would make the tests below
    # run nothing.
    assert len(blocks("python.md", "python")) >= 5
    assert len(blocks("scale-out.md", "python")) >= 1
    assert len(distributed_lines("scale-out.md")) == 2


@pytest.mark.parametrize("doc, k, code", PYTHON_BLOCKS, ids=[f"{d}#{k}" for d, k, _ in PYTHON_BLOCKS])
def test_python_snippet_runs(doc, k, code, workdir):
    p = subprocess.Popen([sys.executable, "-c", code], cwd=workdir, env=env(), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    if "except KeyboardInterrupt" in code:
        # The Ctrl-C example renders for a minute unless interrupted: interrupt it, as
        # its reader would, once the render has started.
        time.sleep(3.0)
        p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0, f"{doc} block {k} failed:\n{err[-3000:]}"
    if "fit(" in code:
        # The walkthrough's fit recovers the parameters it claims to.
        assert "'alpha': 0.2" in out or "'alpha': 0.19" in out, out


@pytest.mark.parametrize("line", distributed_lines("scale-out.md"))
def test_distributed_command_line_runs(line, workdir):
    args = shlex.split(line)
    r = subprocess.run([sys.executable] + args[1:], cwd=workdir, env=env(), capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    out = args[args.index("-o") + 1]
    assert (workdir / out).stat().st_size > 0
