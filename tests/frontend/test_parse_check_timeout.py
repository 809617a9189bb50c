"""`krl parse` and `krl check` stop a file that parses too long (issue 12): the worker that
parses it is killed after --timeout, the file gets error E005 and the other files are still
parsed and checked. The stuck parse below swallows every exception, as a parser stuck in a C
extension (or a SIGALRM raised inside a garbage-collector callback) would."""

from __future__ import annotations

import time
from pathlib import Path

from app.check import run_check
from app import parse as syntax_cli
from app.parse import run_parse
import krl.workspace as workspace_mod
import pytest

#: each test waits out a parse or check timeout: make test runs these on one worker (tests/conftest.py, ``wall_clock``)
pytestmark = pytest.mark.wall_clock


def _stubborn() -> None:
    while True:
        try:
            time.sleep(3600)
        except BaseException:  # noqa: BLE001, S110
            pass


def _files(tmp_path: Path) -> list[Path]:
    (tmp_path / "stuck.src").write_text("DEF stuck()\nEND\n")
    (tmp_path / "good.src").write_text("DEF good()\n  INT n\n  n = 1\nEND\n")
    (tmp_path / "bad.src").write_text("DEF bad()\n  IF TRUE THEN\nEND\n")
    return [tmp_path / n for n in ("stuck.src", "good.src", "bad.src")]


def test_parse_timeout_stops_one_file_and_parses_the_others(tmp_path: Path, monkeypatch) -> None:
    real = syntax_cli.file_diagnostics

    def file_diagnostics(path, **kw):
        if path.name == "stuck.src":
            _stubborn()
        return real(path, **kw)

    monkeypatch.setattr(syntax_cli, "file_diagnostics", file_diagnostics)
    files = _files(tmp_path)
    lines: list[str] = []
    assert run_parse(files, echo=lines.append, timeout=4, jobs=2) == 1
    located = [ln for ln in lines if ": error[" in ln]
    assert located[0] == f"{files[0]}:1:1: error[E005]: file not parsed within 4 s (--timeout; the parse was stopped)"
    assert len(located) == 2 and located[1].startswith(f"{files[2]}:")     # bad.src, in file order
    assert lines[-1] == "2 errors in 3 files"


def test_check_timeout_stops_one_file_and_checks_the_others(tmp_path: Path, monkeypatch) -> None:
    real = workspace_mod.parse_source

    def parse_source(src, *a, **kw):
        if Path(src.path).name == "stuck.src":
            _stubborn()
        return real(src, *a, **kw)

    monkeypatch.setattr(workspace_mod, "parse_source", parse_source)
    _files(tmp_path)
    lines: list[str] = []
    assert run_check([str(tmp_path)], echo=lines.append, timeout=4, jobs=2) == 1
    errors = [ln for ln in lines if ": error[" in ln]
    assert f"{tmp_path / 'stuck.src'}:1:1: error[E005]: file not checked: not parsed within 4 s " \
           "(--timeout; the parse was stopped)" in errors
    assert any(ln.startswith(f"{tmp_path / 'bad.src'}:") for ln in errors)
    assert not any("good.src" in ln for ln in errors)
    assert lines[-1].endswith("in 3 files")
