"""Bad input: encodings, line endings and unparseable files each get a classified row."""

from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path
import csv

import pytest

from krl.syntax.parse import parse_text
from krl.source import decode_bytes, encode_text, read_source, source_from_bytes
from recovery.scan import scan
from krl.limits import MAX_FILE_BYTES
from krl.syntax.engines import parse_file
from recovery import scan as scan_mod
from recovery.report import summarise, write_report
from tests.forkserver import krl_command

VALID = "DEF t()\n  ; Grüße, Maß\n  x = 1\nEND\n"


def test_utf8_with_bom(tmp_path: Path) -> None:
    p = tmp_path / "a.src"
    p.write_bytes(b"\xef\xbb\xbf" + VALID.encode("utf-8"))
    src = read_source(p)
    assert (src.encoding, src.text) == ("utf-8-sig", VALID)
    assert parse_text(src.text).ok


def test_cp1252_fallback_keeps_every_byte(tmp_path: Path) -> None:
    p = tmp_path / "a.src"
    data = VALID.encode("cp1252") + b"; undefined in cp1252: \x81\x9d\n"
    p.write_bytes(data)
    src = read_source(p)
    assert src.encoding == "cp1252"
    assert "Grüße" in src.text
    assert src.text.endswith("\x81\x9d\n")        # decoded as Latin-1, nothing lost
    assert src.text.encode("cp1252", errors="ignore")  # still text
    assert parse_text(src.text).ok


def test_mixed_line_endings(tmp_path: Path) -> None:
    p = tmp_path / "a.src"
    p.write_bytes(b"DEF t()\r\n  x = 1\n  y = 2\r  z = 3\r\nEND")
    assert parse_text(read_source(p).text).ok


def test_classified_rows(tmp_path: Path) -> None:
    (tmp_path / "empty.src").write_bytes(b"\r\n  \r\n")
    (tmp_path / "bin.dat").write_bytes(b"DEFDAT x\x00\x00\x01ENDDAT")
    (tmp_path / "big.SRC").write_bytes(b"DEF t()\n" + b"x = 1\n" * 10 + b"END\n")
    (tmp_path / "ok.Sub").write_bytes(VALID.encode())
    (tmp_path / "notes.txt").write_bytes(b"not KRL")
    rows = {r.path: r for r in scan(tmp_path, "g", jobs=1, use_cache=False, progress=False)}
    assert set(rows) == {"empty.src", "bin.dat", "big.SRC", "ok.Sub"}
    assert rows["empty.src"].status == "empty"
    assert rows["bin.dat"].status == "binary"
    assert rows["ok.Sub"].ok and rows["big.SRC"].ok
    assert read_source(tmp_path / "big.SRC", max_bytes=20).status == "too_large"


def _stubborn(*_args):
    """A parse that never ends and swallows every exception (as a parser stuck in a C
    extension, or a SIGALRM raised inside a garbage-collector callback, would)."""
    while True:
        try:
            time.sleep(3600)
        except BaseException:  # noqa: BLE001, S110 - the point: nothing in here stops it
            pass


@pytest.mark.wall_clock   # waits out the parse timeout (tests/conftest.py)
def test_timeout_is_a_row_not_a_hang(tmp_path: Path, monkeypatch) -> None:
    # The worker that parses slow.src never returns on its own; the scan kills it after the
    # timeout and goes on with the other files (parse_row is patched before the workers fork).

    (tmp_path / "slow.src").write_text(VALID)
    (tmp_path / "after.src").write_text(VALID)
    real = scan_mod.parse_row

    def parse_row(rel, data, sha):
        if rel == "slow.src":
            _stubborn()
        return real(rel, data, sha)

    monkeypatch.setattr(scan_mod, "parse_row", parse_row)
    rows = {r.path: r for r in scan(tmp_path, "g", jobs=1, use_cache=False, progress=False, timeout=3)}
    assert rows["slow.src"].status == "timeout", rows["slow.src"]
    assert "killed after 3 s" in rows["slow.src"].detail
    assert rows["after.src"].ok


def test_parse_json_output_and_exit_codes(tmp_path: Path) -> None:
    good = tmp_path / "good.src"
    good.write_text(VALID)
    bad = tmp_path / "bad.src"
    bad.write_text("DEF t()\n  IF x THEN\nEND\n")
    # `krl` as a fork of the worker's fork server (tests/forkserver.py): the command's exit
    # status and output, without the import at each of the three starts
    krl = krl_command()
    ok = subprocess.run([*krl, "parse", str(good)], capture_output=True, text=True)
    assert ok.returncode == 0
    out = subprocess.run([*krl, "parse", "--json", str(good), str(bad)], capture_output=True, text=True)
    assert out.returncode == 1
    objs = [json.loads(line) for line in out.stdout.splitlines()]
    assert [o["ok"] for o in objs] == [True, False]
    # the one truth: the missing ENDIF is named at the IF (line 2), and no raw list beside it
    assert [(d["code"], d["line"]) for d in objs[1]["diagnostics"]][:1] == [("E010", 2)]
    assert "errors" not in objs[1] and "antlr_errors" not in objs[1]
    out = subprocess.run([*krl, "parse", "--json", "--antlr-errors", str(bad)], capture_output=True, text=True)
    err = json.loads(out.stdout.splitlines()[0])["antlr_errors"][0]
    assert set(err) >= {"line", "column", "message", "offending", "expected", "rule_stack"}
    assert err["line"] == 3 and "ENDIF" in err["expected"]
    assert err["rule_stack"][0] == "module"


def test_bom_followed_by_cp1252_is_not_rejected(tmp_path: Path) -> None:
    # A UTF-8 BOM, then cp1252 text (an editor added the BOM to an old file): the BOM goes,
    # the rest decodes as cp1252; before, the BOM became "ï»¿" and the file failed at 1:1.
    p = tmp_path / "a.src"
    data = b"\xef\xbb\xbf" + VALID.encode("cp1252")
    p.write_bytes(data)
    src = read_source(p)
    assert (src.encoding, src.text) == ("cp1252+bom", VALID)
    assert parse_text(src.text).ok

    assert encode_text(src.text, src.encoding) == data


def test_central_european_code_page_is_detected(tmp_path: Path) -> None:
    # Polish comments as a KR C set up in Polish writes them (the corpus has such files):
    # 0xB3 is "ł" in cp1250 and "³" in cp1252.
    text = "DEF t()\n  ; Nieprawidłowy stan czujnika, zamocowanie narzędzia\n  x = 1\nEND\n"
    p = tmp_path / "pl.src"
    p.write_bytes(text.encode("cp1250"))
    src = read_source(p)
    assert (src.encoding, src.text) == ("cp1250", text)

    assert encode_text(src.text, src.encoding) == text.encode("cp1250")
    # German umlauts are the same bytes in cp1250 and cp1252: named cp1252, the KRL default
    de = tmp_path / "de.src"
    de.write_bytes(VALID.encode("cp1252"))
    assert (read_source(de).encoding, read_source(de).text) == ("cp1252", VALID)


def test_files_csv_records_the_encoding(tmp_path: Path) -> None:
    corpus = tmp_path / "c"
    corpus.mkdir()
    (corpus / "bom.src").write_bytes(b"\xef\xbb\xbf" + VALID.encode("utf-8"))
    (corpus / "bom1252.src").write_bytes(b"\xef\xbb\xbf" + VALID.encode("cp1252"))
    (corpus / "pl.src").write_bytes("DEF t()\n  ; zamocowanie narzędzia być\nEND\n".encode("cp1250"))
    (corpus / "plain.src").write_bytes(b"DEF t()\nEND\n")
    results = scan(corpus, "g", jobs=1, use_cache=False, progress=False)
    write_report(tmp_path / "out", summarise(results, "g", str(corpus), 0.0), results)

    with (tmp_path / "out" / "files.csv").open(newline="", encoding="utf-8") as fh:
        got = {r["path"]: (r["encoding"], r["status"]) for r in csv.DictReader(fh)}
    assert got == {"bom.src": ("utf-8-sig", "ok"), "bom1252.src": ("cp1252+bom", "ok"),
                   "pl.src": ("cp1250", "ok"), "plain.src": ("ascii", "ok")}


@pytest.mark.parametrize(("text", "page"), [
    ("; Grüße, Maß; ausgeführt", "cp1252"),
    ("; élève à côté", "cp1252"),
    ("; Nieprawidłowy stan czujnika", "cp1250"),      # 0xB3: ł in cp1250, ³ in cp1252
    ("; Dvořák žluťoučký kůň", "cp1250"),
    ("; Привет мир, как дела", "cp1251"),
])
def test_code_page_of_a_comment(text: str, page: str) -> None:
    data = f"DEF t()\r\n  x = 1 {text}\r\nEND\r\n".encode(page)
    assert decode_bytes(data) == (data.decode(page), page)


def test_a_byte_undefined_in_cp1252_does_not_switch_to_cyrillic() -> None:
    # 0x81 is undefined in cp1252 and "Ѓ" in cp1251; "café" must stay café, not "cafй".

    assert decode_bytes(b"x=1 ; caf\xe9 = \x81 kept\n") == ("x=1 ; café = \x81 kept\n", "cp1252")


def test_bytes_past_the_file_limit_are_too_large_whoever_read_them() -> None:
    """source_from_bytes is the one classifier: bytes from an editor buffer or parse_file get the
    same size limit as a file read from disk (krl/limits.py MAX_FILE_BYTES)."""

    big = b"DEF a()\nEND\n" + b";" * MAX_FILE_BYTES
    assert source_from_bytes("big.src", big).status == "too_large"
    assert parse_file(big, "big.src", "python").status == "too_large"
    assert source_from_bytes("ok.src", b"DEF a()\nEND\n").status == "ok"
