"""The conformance report: "Real programs" as a table (issue 13), HTML through the one escaping
environment (issue 12)."""

from __future__ import annotations

from conformance import report as R
from conformance.harness import Check
from conformance.nightly import write_index


def real_outcomes() -> list[R.RealOutcome]:
    a = R.RealOutcome("KRC/R1/Program/<script>x</script>.src", reasons={"tree": "completed", "vm": "completed"},
                      tree_vm=[Check("end", True, "")], cause="completed")
    b = R.RealOutcome("KRC/R1/Program/b|c.src", reasons={"tree": "max_sim_time", "vm": "error"},
                      tree_vm=[Check("end", False, "tree max_sim_time, vm error")], cause="intended end",
                      where="b.src:12", cell="corpus/cells/KRC.yaml")
    c = R.RealOutcome("KRC/R1/Program/c.src", reasons={"tree": "crash"}, crash={"tree": "KeyError: 'X'"},
                      cause="interpreter gap")
    return [a, b, c]


def test_real_programs_are_a_table(tmp_path):
    s = R.write_report(tmp_path, [], None, real_outcomes(), plots=False)
    assert s["real_programs"] == 3
    md = (tmp_path / "report.md").read_text()
    section = md[md.index("## Real programs"):]
    # no Python dict printed
    assert "{'" not in section and "{\"" not in section
    assert "| end reason (tree) | programs |" in section
    assert "| `completed` | 1 |" in section and "| `crash` | 1 |" in section and "| `max_sim_time` | 1 |" in section
    assert "| program | cause | stop at | cell | tree | vm | tree = vm | crash |" in section
    assert ("| `KRC/R1/Program/b\\|c.src` | `intended end` | `b.src:12` | `corpus/cells/KRC.yaml` | "
            "`max_sim_time` | `error` | NO |  |") in section
    assert "| `KRC/R1/Program/c.src` | `interpreter gap` |  |  | `crash` | `-` | n/a | `KeyError: 'X'` |" in section
    # every stop explained: one cause a program, counted
    assert "| cause | programs |" in section
    assert "| `completed` | 1 |" in section and "| `intended end` | 1 |" in section
    assert "Completed or intended end: 2 of 3." in section


def test_conformance_html_escapes_and_has_the_table(tmp_path):
    R.write_report(tmp_path, [], None, real_outcomes(), plots=False)
    html = (tmp_path / "report.html").read_text()
    assert "<script>" not in html
    assert "&lt;script&gt;x&lt;/script&gt;.src" in html
    table = html[html.index('id="real-programs"'):]
    assert table.count("<tr") == 4           # header + 3 programs
    assert "KeyError: &#39;X&#39;" in table


def test_nightly_index_escapes_folder_names(tmp_path):
    day = tmp_path / "2026-11-21<img src=x onerror=alert(1)>"
    (day / "conformance").mkdir(parents=True)
    (day / "conformance" / "report.html").write_text("<p>x</p>", encoding="utf-8")
    (day / "conformance" / "summary.json").write_text('{"passed": 5, "cases": 6}', encoding="utf-8")
    html = write_index(tmp_path).read_text()
    assert "<img" not in html
    assert "<td>2026-11-21&lt;img src=x onerror=alert(1)&gt;</td>" in html
    assert 'href="2026-11-21%3Cimg%20src%3Dx%20onerror%3Dalert%281%29%3E/conformance/report.html"' in html
    assert "cases 5/6" in html
