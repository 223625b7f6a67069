"""Progress when stderr is not a terminal (issue 19 item 3): a line every few seconds of
long work, nothing for short work or when not asked."""

from __future__ import annotations

import subprocess
import sys

from craters._shared import progress_bar


def test_lines_when_not_a_terminal(capsys, monkeypatch):
    monkeypatch.setenv("CRATERFORM_PROGRESS_S", "0")  # every update is "long enough"
    assert list(progress_bar(range(3), enabled=True, desc="craters")) == [0, 1, 2]
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("craters: 1/3 (33 %), ") and err[0].endswith(" s")
    assert err[-1].startswith("craters: 3/3 (100 %)")
    with progress_bar(total=10, enabled=True, desc="LOD 0 (MB)") as bar:
        bar.update(4)
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("LOD 0 (MB): 4/10 (40 %)") and "done" in err[-1]


def test_quiet_for_short_work_and_when_not_asked(capsys):
    assert list(progress_bar(range(1000), enabled=True, desc="x")) == list(range(1000))
    assert list(progress_bar(range(3), enabled=False)) == [0, 1, 2]
    assert capsys.readouterr().err == ""


def test_a_build_logs_its_progress_to_a_file():
    """`latlong build` with stderr redirected (not a terminal) prints progress lines."""
    code = ("import sys; from latlong.cli import main; "
            "sys.exit(main(['build', '--magnitude', '16', '--seed', '1', '--preset', "
            "'fbm-cratered', '-o', 'b.npz']))")
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        proc = subprocess.run([sys.executable, "-c", code], cwd=tmp, capture_output=True,
                              text=True, env={**__import__("os").environ,
                                              "CRATERFORM_PROGRESS_S": "0"}, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert any("%" in line and line.endswith(" s") for line in proc.stderr.splitlines()), \
        proc.stderr
