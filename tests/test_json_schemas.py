"""Every JSON output of the project has a documented schema (docs/schemas/, listed in
docs/json.md), and each output, made here by the real command on small inputs, validates
against it (issue 27: "JSON output with one truth")."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

from conformance import harness as H

from conformance.report import run_cases, write_report

from app.bench import all_figures, engine_rates
from app.log import log_group
from click.testing import CliRunner

from recovery.pipeline import run_recovery

from robot.trace import json_schema, read_trace
from tests import forkserver
from tests.forkserver import krl_command
from tests.robot.test_kukatrace import MOTIONS, write_recording

REPO = Path(__file__).resolve().parents[1]
SCHEMAS = REPO / "docs" / "schemas"


def krl() -> list[str]:
    """`krl` as these tests start it: a fork of the worker's fork server (tests/forkserver.py,
    the same `app.main` without the import of the project at each start)."""
    return krl_command()
GOOD = "DEF good()\n  DECL INT n\n  n = 1\nEND\n"
BAD = "DEF bad()\n  IF x THEN\nEND\n"


def _registry() -> Registry:
    res = [Resource.from_contents(json.loads(p.read_text())) for p in sorted(SCHEMAS.glob("*.schema.json"))]
    return Registry().with_resources((r.contents["$id"], r) for r in res)


def validate(name: str, instance) -> None:
    schema = json.loads((SCHEMAS / f"{name}.schema.json").read_text())
    Draft202012Validator(schema, registry=_registry()).validate(instance)


def test_every_schema_is_valid_and_documented():
    doc = (REPO / "docs" / "json.md").read_text(encoding="utf-8")
    for p in sorted(SCHEMAS.glob("*.schema.json")):
        schema = json.loads(p.read_text())
        Draft202012Validator.check_schema(schema)
        assert schema["$id"] == p.name
        assert f"schemas/{p.name}" in doc, f"{p.name} is not described in docs/json.md"


def test_trace_schema_file_is_current():
    assert json.loads((SCHEMAS / "trace.schema.json").read_text()) == json_schema(), \
        "run: python -m robot.trace --schema > docs/schemas/trace.schema.json"


def test_parse_and_check_json(tmp_path):
    (tmp_path / "good.src").write_text(GOOD)
    (tmp_path / "bad.src").write_text(BAD)
    for extra in ([], ["--antlr-errors"]):
        out = subprocess.run([*krl(), "parse", "--format", "json", *extra, str(tmp_path / "good.src"),
                              str(tmp_path / "bad.src")], capture_output=True, text=True, check=False)
        objs = [json.loads(line) for line in out.stdout.splitlines()]
        assert len(objs) == 2
        for obj in objs:
            validate("parse", obj)
        assert ("antlr_errors" in objs[1]) == bool(extra)
    with pytest.raises(Exception, match="errors"):           # the old raw list is not allowed back
        validate("parse", dict(objs[1], errors=[]))
    out = subprocess.run([*krl(), "check", "--format", "json", str(tmp_path / "bad.src")], capture_output=True,
                         text=True, check=False)
    (obj,) = [json.loads(line) for line in out.stdout.splitlines()]
    validate("check", obj)
    assert obj["errors"] == 1


def test_recovery_summary_and_check_report(tmp_path):
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    (corpus / "good.src").write_text(GOOD)
    (corpus / "bad.src").write_text(BAD)
    run_recovery(corpus, tmp_path / "rec", jobs=1, use_cache=False)
    validate("recovery-summary", json.loads((tmp_path / "rec" / "summary.json").read_text()))
    backup = tmp_path / "backups" / "b"
    shutil.copytree(REPO / "tests" / "lsp" / "fixtures" / "backup", backup)
    res = subprocess.run([*krl(), "check", "--report", str(tmp_path / "report"), str(tmp_path / "backups")],
                         capture_output=True, text=True, check=False)
    report = json.loads((tmp_path / "report" / "check_report.json").read_text())
    validate("check-report", report)
    assert report["backups"], res.stdout + res.stderr


def test_conformance_summary_and_trace(tmp_path):
    case = H.load_case(REPO / "conformance" / "cases" / "053_lin_straight")
    write_report(tmp_path / "conf", run_cases([case], ["tree"]), plots=False)
    validate("conformance-summary", json.loads((tmp_path / "conf" / "summary.json").read_text()))
    trace = tmp_path / "run.jsonl"
    subprocess.run([*krl(), "run", str(case.path / "program.src"), "--trace", str(trace)], capture_output=True,
                   check=False)
    events = list(read_trace(trace))
    assert {e["kind"] for e in events} >= {"motion", "stmt", "end"}
    for ev in events:
        validate("trace", ev)


def test_bench_outputs(tmp_path):
    validate("bench", all_figures(repeat=1, sim_seconds=0.5, parse_kb=4))

    corpus = tmp_path / "c"
    corpus.mkdir()
    (corpus / "a.src").write_text(GOOD * 20)
    validate("bench-parse", engine_rates(corpus, repeat=1))
    # a fork of the worker's fork server (tests/forkserver.py), which has imported what the bench
    # imports: ``python -m robot.limits_bench`` without NumPy's, SciPy's and MuJoCo's import
    out = subprocess.run([str(forkserver.shared().launcher), "-m", "robot.limits_bench"], capture_output=True, text=True,
                         check=False, cwd=REPO)
    rows = [json.loads(line) for line in out.stdout.splitlines()]
    assert len(rows) >= 5
    for row in rows:
        validate("limits", row)


DIFF_OLD = {
    "R1/System/$config.dat": "DEFDAT $CONFIG\nDECL FRAME TOOL_DATA[16]\nTOOL_DATA[1]={X 0.0,Y 0.0,Z 100.0,A 0.0,B 0.0,C 0.0}\n"
                             "DECL BOOL STOPM_FLAG=TRUE\nENDDAT\n",
    "R1/Program/m.src": "DEF m()\n  SPTP XP1 WITH $APO=SAPO_PTP(PPDAT1)\nEND\nDEFFCT INT f()\n  RETURN 1\nENDFCT\n"
                        "DEFFCT INT f()\n  RETURN 2\nENDFCT\n",
    "R1/Program/m.dat": "DEFDAT m\nDECL E6POS XP1={X 1.0,Y 2.0,Z 3.0,A 0.0,B 0.0,C 0.0,S 2,T 10}\n"
                        "DECL PDAT PPDAT1={VEL 100.0,ACC 100.0,APO_DIST 500.0,APO_MODE #CDIS}\n"
                        "DECL CHAR name[8]\nname[]=\"old\"\nEXT WEAV_DEF(INT:IN)\nENDDAT\n",
}
DIFF_NEW = {
    "R1/System/$config.dat": DIFF_OLD["R1/System/$config.dat"].replace("Z 100.0", "Z 105.5").replace("=TRUE", "=FALSE"),
    "R1/Program/m.src": DIFF_OLD["R1/Program/m.src"].replace("  SPTP", "  HALT\n  SPTP"),
    "R1/Program/m.dat": DIFF_OLD["R1/Program/m.dat"].replace("X 1.0", "X 1.5").replace("APO_DIST 500.0", "APO_DIST 200.0")
                        .replace('"old"', '"new"').replace("EXT WEAV_DEF(INT:IN)\n", "")
                        + "",
}


def _write_tree(root: Path, files: dict) -> None:
    for rel, text in files.items():
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)


def test_diff_and_graph_json(tmp_path):
    _write_tree(tmp_path / "old", DIFF_OLD)
    _write_tree(tmp_path / "new", DIFF_NEW)
    new_dat = tmp_path / "new" / "R1" / "Program" / "m.dat"
    new_dat.write_text(new_dat.read_text().replace("ENDDAT", "DECL E6POS XP2={X 0.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0}\nENDDAT"))
    out = subprocess.run([*krl(), "diff", "--format", "json", str(tmp_path / "old"), str(tmp_path / "new")],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    validate("diff", doc)
    # every kind the schema knows is exercised once
    assert all(doc["summary"][k] for k in ("points", "frames", "values", "routines", "declarations", "motions"))
    assert doc["duplicates"] and doc["duplicates"][0]["code"] == "E102"
    out = subprocess.run([*krl(), "graph", "--format", "json", str(tmp_path / "new")], capture_output=True, text=True,
                         check=False)
    assert out.returncode == 0, out.stderr
    validate("graph", json.loads(out.stdout))


def test_trace_show_and_compare_json(tmp_path):
    # a recording written in KUKA Trace's formats (tests/robot/test_kukatrace.py), compared with itself
    stem = str(write_recording(tmp_path, "demo", MOTIONS))
    for args, name in ((["trace", "show", stem, "--json"], "trace-show"),
                       (["trace", "compare", stem, stem, "--json"], "trace-compare")):
        res = subprocess.run(krl() + args, capture_output=True, text=True, cwd=tmp_path, timeout=120)
        assert res.returncode == 0, res.stderr
        validate(name, json.loads(res.stdout))


def test_log_show_and_summary_json(event_logs):
    """krl log show / summary --format json on the shared archive's smallest log (26 records)."""
    res = CliRunner().invoke(log_group, ["show", "--format", "json", str(event_logs / "KrcLogI.evt")])
    assert res.exit_code == 0, res.output
    objs = [json.loads(line) for line in res.output.splitlines()]
    assert len(objs) == 26
    for obj in objs:
        validate("log-record", obj)
    res = CliRunner().invoke(log_group, ["summary", "--format", "json", str(event_logs / "KrcLogI.evt")])
    assert res.exit_code == 0, res.output
    validate("log-summary", json.loads(res.output))
