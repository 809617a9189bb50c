"""tools/trace_identity.py: the records of two checkouts compared byte for byte (issue 38)."""

from __future__ import annotations

import importlib.util
import io
import json
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("trace_identity", REPO / "tools" / "trace_identity.py")
TI = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(TI)


def _record(d: Path, name: str, lines: list[str], root: str, end=("completed", "", None, None, 1.0, 3)) -> None:
    """One program's record as `record` writes it, through the same sink."""
    d.mkdir(parents=True, exist_ok=True)
    sink = TI._Sink(d / f"{name}.tree.jsonl.gz", root)
    for line in lines:
        sink.write(line)
        sink.write("\n")
    sink.close()
    (d / f"{name}.tree.json").write_text(json.dumps(
        {"program": name, "interp": "tree", "end": list(end), "sha256": sink.sha.hexdigest(),
         "bytes": sink.size, "events": sink.lines}))


def test_identical_traces_of_two_checkouts_compare_equal(tmp_path):
    # the checkout's own root differs between the two records and is written <ROOT>
    ev = ['{"t":0.0,"kind":"stmt","file":"%s/kuka/p00.src","line":3}', '{"t":0.012,"kind":"end"}']
    _record(tmp_path / "a", "p", [e % "/work/a" if "%s" in e else e for e in ev], "/work/a")
    _record(tmp_path / "b", "p", [e % "/work/b" if "%s" in e else e for e in ev], "/work/b")
    out = io.StringIO()
    assert TI.compare(tmp_path / "a", tmp_path / "b", out) == 0
    assert out.getvalue().strip() == "identical 1, different 0, missing 0"


def test_a_difference_names_the_first_line_where_the_traces_part(tmp_path):
    common = ['{"t":0.0,"kind":"stmt","line":1}', '{"t":0.0,"kind":"stmt","line":2}']
    _record(tmp_path / "a", "p", common + ['{"t":0.012,"kind":"io","value":true}'], "/x")
    _record(tmp_path / "b", "p", common + ['{"t":0.024,"kind":"io","value":true}'], "/y")
    _record(tmp_path / "a", "q", common, "/x")
    out = io.StringIO()
    assert TI.compare(tmp_path / "a", tmp_path / "b", out) == 1
    text = out.getvalue()
    assert "first at line 3:" in text
    assert '"t":0.012' in text and '"t":0.024' in text
    assert "MISSING q.tree.json" in text
    assert text.strip().endswith("identical 0, different 1, missing 1")


def test_the_same_trace_with_another_end_is_a_difference(tmp_path):
    _record(tmp_path / "a", "p", ["{}"], "/x", end=("error", "x", None, 4, 0.0, 1))
    _record(tmp_path / "b", "p", ["{}"], "/y", end=("error", "x", None, 5, 0.0, 1))
    out = io.StringIO()
    assert TI.compare(tmp_path / "a", tmp_path / "b", out) == 1
    assert "first at line 2:" in out.getvalue()      # past the end of both traces: equal text


def test_last_place_counts_a_tie_rounded_apart_and_the_cut_at_180_degrees(tmp_path):
    """--last-place: one unit of the 6th decimal (a tie rounded apart) and C 180 vs -180 (the
    same rotation) make an equivalent trace; two units, or 180 vs -180 in a position, do not."""
    pose = '{"t":0.012,"kind":"pose","tcp":[%s,0.0,5.0,0.0,0.0,%s]}'
    _record(tmp_path / "a", "p", [pose % ("1208.898992", "-180.0")], "/x")
    _record(tmp_path / "b", "p", [pose % ("1208.898993", "180.0")], "/y")
    _record(tmp_path / "a", "q", [pose % ("1208.898992", "0.0")], "/x")
    _record(tmp_path / "b", "q", [pose % ("1208.898994", "0.0")], "/y")
    _record(tmp_path / "a", "r", [pose % ("180.0", "0.0")], "/x")
    _record(tmp_path / "b", "r", [pose % ("-180.0", "0.0")], "/y")
    _record(tmp_path / "a", "s", ['{"kind":"motion","target":{"C":-180.0,"X":1.0}}'], "/x")
    _record(tmp_path / "b", "s", ['{"kind":"motion","target":{"C":180.0,"X":1.0}}'], "/y")
    out = io.StringIO()
    assert TI.compare(tmp_path / "a", tmp_path / "b", out, last_place=True) == 1
    text = out.getvalue()
    assert "DIFF q.tree" in text and "DIFF r.tree" in text and "DIFF p.tree" not in text and "DIFF s.tree" not in text
    assert text.strip().endswith("identical 0, equivalent 2 (last place 1 numbers, +-180 2 angles), different 2, missing 0")
    out = io.StringIO()
    assert TI.compare(tmp_path / "a", tmp_path / "b", out) == 1     # byte for byte: all four differ
    assert out.getvalue().strip().endswith("identical 0, different 4, missing 0")


def test_recording_a_corpus_that_is_not_there_is_an_error_not_an_empty_record(tmp_path, capsys):
    # before, `record` of a missing folder wrote nothing and returned 0: compared later, an
    # empty record reads as "identical 0"
    rc = TI.main(["record", str(REPO), str(tmp_path / "rec"), "--corpus", str(tmp_path / "none")])
    assert rc == 2
    assert "no corpus at" in capsys.readouterr().err
    assert not (tmp_path / "rec").exists()
