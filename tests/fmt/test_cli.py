"""`krl fmt` on files: in-place rewrite in the file's own encoding, --check / --diff exit codes
and output, unparsable files reported (file:line:col) and left untouched."""

from __future__ import annotations

import os
import stat

from click.testing import CliRunner

from app import main
import krl.fmt.core
from krl.limits import MAX_FOLDER_DEPTH
import krl.source
import krl.syntax.engines
import krl.syntax.parse

MESSY = b"DEF t( )\r\nx=1 ; caf\xe9 = \x81 kept\r\nEND\r\n"          # cp1252, with an undefined byte
TIDY = b"DEF t()\r\n   x = 1 ; caf\xe9 = \x81 kept\r\nEND\r\n"
BROKEN = b"DEF u()\nIF a THEN\nx=1\nEND\n"


def run(*args):
    return CliRunner().invoke(main, ["fmt", *map(str, args)])


def test_rewrites_in_place_in_the_same_encoding(tmp_path):
    f = tmp_path / "t.src"
    f.write_bytes(MESSY)
    os.chmod(f, 0o640)
    res = run(f)
    assert res.exit_code == 0, res.output
    assert f.read_bytes() == TIDY
    assert stat.S_IMODE(f.stat().st_mode) == 0o640
    assert "1 file reformatted" in res.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["t.src"]          # no temporary file left


def test_utf8_bom_is_written_back(tmp_path):
    f = tmp_path / "t.src"
    f.write_bytes(b"\xef\xbb\xbfDEF t()\nx=\"\xc3\xa4\"\nEND\n")
    assert run(f).exit_code == 0
    assert f.read_bytes() == b"\xef\xbb\xbfDEF t()\n   x = \"\xc3\xa4\"\nEND\n"


def test_check_exits_1_with_a_diff_and_writes_nothing(tmp_path):
    f = tmp_path / "t.src"
    f.write_bytes(MESSY)
    res = run("--check", f)
    assert res.exit_code == 1
    assert f.read_bytes() == MESSY
    out = res.stdout.splitlines()
    assert out[0] == f"--- {f} (original)"
    assert out[1] == f"+++ {f} (formatted)"
    assert "-DEF t( )" in out and "+DEF t()" in out
    assert "-x=1 ; caf\xe9 = \\x81 kept" in out          # the C1 control is shown escaped
    assert "+   x = 1 ; caf\xe9 = \\x81 kept" in out
    assert " END" in out
    assert "1 file would be reformatted" in res.stderr


def test_check_exits_0_when_formatted(tmp_path):
    f = tmp_path / "t.src"
    f.write_bytes(TIDY)
    res = run("--check", f)
    assert res.exit_code == 0
    assert res.stdout == ""


def test_diff_writes_nothing_and_exits_0(tmp_path):
    f = tmp_path / "t.src"
    f.write_bytes(MESSY)
    res = run("--diff", f)
    assert res.exit_code == 0
    assert "+DEF t()" in res.stdout.splitlines()
    assert f.read_bytes() == MESSY


def test_unparsable_file_is_reported_and_untouched_exit_2(tmp_path):
    bad, good = tmp_path / "u.src", tmp_path / "t.src"
    bad.write_bytes(BROKEN)
    good.write_bytes(MESSY)
    res = run(tmp_path)                          # a folder: both files
    assert res.exit_code == 2
    assert bad.read_bytes() == BROKEN
    assert good.read_bytes() == TIDY             # the good one is still formatted
    assert f"{bad}:2:1: error[E010]" in res.stderr
    res = run("--check", bad, good)
    assert res.exit_code == 2                    # 2 wins over "would change"


def test_keyword_case_and_indent_options(tmp_path):
    f = tmp_path / "t.src"
    f.write_bytes(b"DEF t()\nIF a THEN\nhalt\nENDIF\nEND\n")
    assert run("--keyword-case", "lower", "--indent", "2", f).exit_code == 0
    assert f.read_bytes() == b"def t()\n  if a then\n    halt\n  endif\nend\n"


def test_indent_tab_and_a_bad_indent(tmp_path):
    f = tmp_path / "t.src"
    f.write_bytes(b"DEF t()\nhalt\nEND\n")
    assert run("--indent", "x", f).exit_code == 2          # click's usage error
    assert f.read_bytes() == b"DEF t()\nhalt\nEND\n"
    assert run("--indent", "tab", f).exit_code == 0
    assert f.read_bytes() == b"DEF t()\n\tHALT\nEND\n"


def test_missing_file_and_binary_file_are_errors(tmp_path):
    b = tmp_path / "b.src"
    b.write_bytes(b"DEF\x00")
    res = run(tmp_path / "nope.src", b)
    assert res.exit_code == 2
    assert "E001" in res.stderr
    assert "Traceback" not in res.output


def test_stdin_to_stdout_in_the_same_encoding():
    res = CliRunner().invoke(main, ["fmt", "-"], input=MESSY)
    assert res.exit_code == 0, res.output
    assert res.stdout_bytes == TIDY


def test_stdin_syntax_error_writes_nothing_and_exits_2():
    res = CliRunner().invoke(main, ["fmt", "-"], input=BROKEN)
    assert res.exit_code == 2
    assert res.stdout_bytes == b""
    assert "<stdin>:2:1: error[E010]" in res.stderr


def test_stdin_check():
    assert CliRunner().invoke(main, ["fmt", "--check", "-"], input=TIDY).exit_code == 0
    res = CliRunner().invoke(main, ["fmt", "--check", "-"], input=MESSY)
    assert res.exit_code == 1
    assert "+DEF t()" in res.stdout.splitlines()


def _warning(path, why):
    return f"{path}:1:1: warning[W002]: not read: {why}"


def test_folder_links_and_fifos_are_reported_never_read_nor_written(tmp_path):
    outside = tmp_path / "outside.src"
    outside.write_bytes(MESSY)
    tree = tmp_path / "tree"
    tree.mkdir()
    good = tree / "good.src"
    good.write_bytes(MESSY)
    link = tree / "link.src"
    link.symlink_to(outside)
    fifo = tree / "x.src"
    os.mkfifo(fifo)
    shown = tree / "l\x1b[2J.src"                 # a name with a terminal control sequence
    shown.symlink_to(outside)

    res = run("--check", tree)
    assert res.exit_code == 1                    # good.src would change; skipped entries do not count
    assert f"--- {good} (original)" in res.stdout.splitlines()
    assert str(link) not in res.stdout and str(fifo) not in res.stdout

    res = run(tree)
    assert res.exit_code == 0, res.output        # documented: links and FIFOs do not change the status
    assert good.read_bytes() == TIDY             # only the normal file is formatted
    assert outside.read_bytes() == MESSY         # the link's target outside the folder is untouched
    assert link.is_symlink() and os.readlink(link) == str(outside)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    err = res.stderr.splitlines()
    assert _warning(link, "a symbolic link (never followed)") in err
    assert _warning(fifo, "a FIFO (never opened)") in err
    assert _warning(tree / "l\\x1b[2J.src", "a symbolic link (never followed)") in err
    assert "\x1b" not in res.stderr
    assert err[-1] == "1 file reformatted, 0 unchanged, 3 not read (links, FIFOs, devices, too deep folders)"


def test_a_named_link_is_still_followed(tmp_path):
    target = tmp_path / "target.src"
    target.write_bytes(MESSY)
    link = tmp_path / "named.src"
    link.symlink_to(target)
    assert run(link).exit_code == 0
    assert target.read_bytes() == TIDY and link.is_symlink()     # as docs/security.md says


def test_a_folder_too_deep_is_reported_and_not_entered(tmp_path):
    root = tmp_path / "deep"
    shallow = root / "a.src"
    folders = [root]
    for _ in range(MAX_FOLDER_DEPTH + 1):        # the last folder is MAX_FOLDER_DEPTH + 1 levels below root
        folders.append(folders[-1] / "d")
    try:
        folders[-1].mkdir(parents=True)
        shallow.write_bytes(MESSY)
        deepest = folders[-1] / "z.src"
        deepest.write_bytes(MESSY)
        fine = folders[-2] / "y.src"             # MAX_FOLDER_DEPTH levels down: still entered
        fine.write_bytes(MESSY)
        res = run(root)
        assert res.exit_code == 0, res.output
        assert shallow.read_bytes() == TIDY and fine.read_bytes() == TIDY
        assert deepest.read_bytes() == MESSY
        assert _warning(folders[-1], f"folder more than {MAX_FOLDER_DEPTH} levels deep (not entered)") \
            in res.stderr.splitlines()
    finally:
        for folder in reversed(folders):        # iteratively, deepest first
            if folder.exists():
                for f in folder.iterdir():
                    if not f.is_dir():
                        f.unlink()
                folder.rmdir()


NO_THEN = b"DEF v()\nIF a\n  x=1\nENDIF\nEND\n"


def _count_parses_and_reads(monkeypatch) -> dict:
    """Wrap every way a file is parsed (the Python parser, the engine entry point) or read."""

    counts = {"parse": 0, "read": 0}

    def counting(fn, key):
        def wrapper(*args, **kwargs):
            counts[key] += 1
            return fn(*args, **kwargs)
        return wrapper

    parse_text = counting(krl.syntax.parse.parse_text, "parse")
    monkeypatch.setattr(krl.syntax.parse, "parse_text", parse_text)
    monkeypatch.setattr(krl.fmt.core, "parse_text", parse_text)
    monkeypatch.setattr(krl.syntax.engines, "parse_sources", counting(krl.syntax.engines.parse_sources, "parse"))
    monkeypatch.setattr(krl.source, "read_limited", counting(krl.source.read_limited, "read"))
    return counts


def _located(stderr: str, path) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith(f"{path}:")]


def test_a_syntax_error_is_read_and_parsed_once_and_printed_as_krl_parse_prints_it(tmp_path, monkeypatch):
    bad, worse = tmp_path / "u.src", tmp_path / "v.src"
    bad.write_bytes(BROKEN)
    worse.write_bytes(NO_THEN)
    expected = {
        # counted by hand: the IF on line 2 is never closed; END (line 4) is where it shows
        bad: [f"{bad}:2:1: error[E010]: missing ENDIF for the IF at line 2",
              f"{bad}:4:1: note: END reached here while the IF is open"],
        # the line `IF a` ends (column 5) where THEN must come
        worse: [f"{worse}:2:5: error[E012]: IF needs THEN after the condition"],
    }
    parsed = {f: _located(CliRunner().invoke(main, ["parse", str(f)]).output, f) for f in (bad, worse)}
    for f in (bad, worse):
        counts = _count_parses_and_reads(monkeypatch)
        res = run(f)
        monkeypatch.undo()
        assert res.exit_code == 2
        assert counts == {"parse": 1, "read": 1}, f
        assert _located(res.stderr, f) == parsed[f] == expected[f]
        assert f.read_bytes() in (BROKEN, NO_THEN)


def test_stdin_syntax_error_is_parsed_once(monkeypatch):
    counts = _count_parses_and_reads(monkeypatch)
    res = CliRunner().invoke(main, ["fmt", "-"], input=NO_THEN)
    assert res.exit_code == 2
    assert counts["parse"] == 1
    assert _located(res.stderr, "<stdin>") == ["<stdin>:2:5: error[E012]: IF needs THEN after the condition"]
