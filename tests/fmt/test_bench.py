"""`krl bench fmt` smoke test on a two-file corpus: it runs and counts right (no timing assertions)."""

from __future__ import annotations

import json

from click.testing import CliRunner

from app.bench import bench


def test_bench_fmt_counts_files_that_parse_and_change(tmp_path):
    (tmp_path / "a.src").write_text("DEF a()\nx=1\nEND\n")          # parses, would change
    (tmp_path / "b.src").write_text("DEF b()\n   x = 1\nEND\n")     # parses, already formatted
    (tmp_path / "c.src").write_text("DEF c()\nIF\nEND\n")           # does not parse: not counted
    res = CliRunner().invoke(bench, ["fmt", str(tmp_path), "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.output.strip().splitlines()[-1])
    assert data["files"] == 2 and data["changed"] == 1
    assert data["fmt_vs_parse"] > 0 and data["parse_kb_per_s"] > 0
