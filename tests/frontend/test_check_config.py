"""`krl check --ignore CODE` and a backup's krl.toml (krl/semantics/config.py)."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import pytest

from app.check import run_check

DEMO = ("DEF demo()\n"
        "  INT i\n"
        "  ;FOLD x\n"                     # W021 at 3
        "  i = counter + undeclared\n"    # E101 at 4
        "  i = 2.5\n"                     # W202 at 5
        "END\n")


@pytest.fixture
def backup(tmp_path) -> Path:
    root = tmp_path / "KRC"
    (root / "R1/System").mkdir(parents=True)
    (root / "R1/Program").mkdir(parents=True)
    (root / "R1/System/$config.dat").write_text("DEFDAT $CONFIG\n  DECL INT counter = 0\nENDDAT\n")
    (root / "R1/Program/demo.src").write_text(DEMO)
    return root


def codes(path, *ignore) -> tuple[int, list[tuple[str, str, int]]]:
    out: list[str] = []
    status = run_check([str(path)], fmt="json", echo=out.append, ignore=list(ignore))
    diags = [d for line in out for d in json.loads(line)["diagnostics"]]
    return status, [(d["code"], d["severity"], d["line"]) for d in diags]


ALL = [("W021", "warning", 3), ("E101", "error", 4), ("W202", "warning", 5)]


def test_everything_reported_by_default(backup):
    assert codes(backup) == (1, ALL)


def test_ignore_a_code_or_a_prefix(backup):
    assert codes(backup, "W021") == (1, [ALL[1], ALL[2]])
    assert codes(backup, "W") == (1, [ALL[1]])
    assert codes(backup, "E101") == (0, [ALL[0], ALL[2]])


def test_unknown_code_on_the_command_line_is_a_usage_error(backup):
    out: list[str] = []
    assert run_check([str(backup)], echo=out.append, ignore=["X999"]) == 2
    assert out == ["krl check: --ignore: unknown diagnostic code 'X999' (see docs/diagnostics.md)"]


def test_krl_toml_ignores_selects_and_changes_severities(backup):
    (backup / "krl.toml").write_text('[check]\nignore = ["W021"]\n[check.severity]\nW202 = "error"\nE101 = "warning"\n')
    assert codes(backup) == (1, [("E101", "warning", 4), ("W202", "error", 5)])
    (backup / "krl.toml").write_text('[check]\nselect = ["E"]\n')
    assert codes(backup) == (1, [ALL[1]])
    (backup / "krl.toml").write_text('[check.severity]\nE101 = "off"\n')
    assert codes(backup) == (0, [ALL[0], ALL[2]])


@pytest.mark.parametrize("text, message", [
    ('[check]\nignore = ["Q1"]\n', "check.ignore: unknown diagnostic code 'Q1'"),
    ('[check]\nignored = ["W021"]\n', "unknown key 'ignored' in [check]"),
    ('[check.severity]\nW021 = "loud"\n', "check.severity.W021: 'loud' is not one of error, warning, off"),
    ('[check\n', "not valid TOML"),
])
def test_bad_krl_toml_names_the_file(backup, text, message):
    (backup / "krl.toml").write_text(text)
    out: list[str] = []
    assert run_check([str(backup)], echo=out.append) == 2
    assert out[0].startswith(f"krl check: {backup / 'krl.toml'}: ") and message in out[0]


def test_krl_toml_above_the_checked_folder_is_not_adopted(backup):
    (backup.parent / "krl.toml").write_text('[check]\nignore = ["E"]\n')
    assert codes(backup) == (1, ALL)


def test_krl_toml_inside_a_backup_archive(backup, tmp_path):
    (backup / "krl.toml").write_text('[check]\nignore = ["W"]\n')
    archive = tmp_path / "b.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        for p in sorted(backup.rglob("*")):
            zf.write(p, p.relative_to(tmp_path).as_posix())
    assert codes(archive) == (1, [ALL[1]])
    (backup / "krl.toml").write_text('[check]\nignore = ["Q1"]\n')
    with zipfile.ZipFile(archive, "w") as zf:
        for p in sorted(backup.rglob("*")):
            zf.write(p, p.relative_to(tmp_path).as_posix())
    out: list[str] = []
    assert run_check([str(archive)], echo=out.append) == 2
    assert out[0].startswith(f"krl check: {archive}/KRC/krl.toml: check.ignore: unknown diagnostic code 'Q1'")
