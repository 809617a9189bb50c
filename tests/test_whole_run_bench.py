"""tools/whole_run_bench.py (issue 48, "whole runs as the unit of speed"): two worker processes
(this checkout measured against itself as the baseline) run a corpus entry point with
``--inputs auto``; the rows have both sides, the same I/O and end, and the nightly reads the
summary into its figures. No timing is asserted (a benchmark prints ratios; it is not tested by
time)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from conformance.nightly.figures import read_night
from krl.files import SHARED_CORPUS

REPO = Path(__file__).resolve().parent.parent
#: a short whole run: the ChinaMilling backup's SPS.SUB, idle but for its submit program
ONLY = "HugoDanielson__ChinaMilling/KRC/R1/System/sps.sub"


def test_side_by_side_rows_and_the_nightly_figures(tmp_path):
    if not (SHARED_CORPUS / ONLY).is_file():
        pytest.skip("the shared corpus is not here")
    day = tmp_path / "2026-11-25"
    day.mkdir()
    out = day / "whole-runs.json"
    res = subprocess.run([sys.executable, str(REPO / "tools" / "whole_run_bench.py"), "--baseline", str(REPO),
                          "--only", ONLY, "--sim-time", "5", "--json", str(out)],
                         capture_output=True, text=True, cwd=REPO, timeout=600, check=False)
    assert res.returncode == 0, res.stderr[-2000:]
    data = json.loads(out.read_text())
    (row,) = data["rows"]
    assert row["program"] == ONLY
    for side in ("new", "base"):
        r = row[side]
        assert r["reason"] == "max_sim_time" and r["sim_s"] == pytest.approx(5.0, abs=0.012)
        assert r["cpu_s"] == pytest.approx(r["setup_s"] + r["run_s"], abs=0.002)
    assert row["same"] is True            # one checkout against itself: the same I/O and end
    s = data["summary"]
    assert s["entry_points"] == 1 and s["same"] == 1 and s["new"]["sim_s"] == pytest.approx(5.0, abs=0.012)
    assert "speedup of the total" in res.stdout and "same I/O and end on 1 of 1" in res.stdout
    night = read_night(day)
    assert night.figures["bench.whole_runs_sim_per_cpu"] == s["new"]["sim_per_cpu"] > 0
    assert night.figures["whole_runs.over_3s"] == s["new"]["over_3s"]
    assert "whole-runs-history.json: not written this night" in night.notes
    # the nightly's second file, the history backups' whole runs (make nightly), read the same way
    (day / "whole-runs-history.json").write_text(out.read_text())
    night = read_night(day)
    assert night.figures["bench.whole_runs_history_sim_per_cpu"] == s["new"]["sim_per_cpu"]
    assert night.figures["whole_runs_history.over_3s"] == s["new"]["over_3s"]
    assert not any(n.startswith("whole-runs") for n in night.notes)


@pytest.mark.slow       # (three whole front-end runs of loose corpus files, one of 16,000 lines: 90 s at load 15)
def test_cells_report_the_corpus_palletizers_that_stop_at_t0():
    """``--cells``: the corpus's palletizing programs that are not measured (loose files that stop
    at t=0 on an error: tools/whole_run_bench.py ``CORPUS_STOPPED``) are each printed with their
    end; ``--only`` matching no cell leaves the table empty."""
    stopped = {"Bugaj32__KUKA-pick-and-place-palletizing/main.src": "main.src:9",
               "paulovictor237__KUKA-Paletizador/Script_Code/MainProgram.src": "Padrao_STR_Iniciar.src:5",
               "paulovictor237__KUKA-Script/file_in/My_Job.src": "My_Job.src:16686"}
    if not all((SHARED_CORPUS / rel).is_file() for rel in stopped):
        pytest.skip("the shared corpus is not here")
    res = subprocess.run([sys.executable, str(REPO / "tools" / "whole_run_bench.py"), "--cells", "--only",
                          "no such cell", "--sim-time", "5"],
                         capture_output=True, text=True, cwd=REPO, timeout=600, check=False)
    assert res.returncode == 0, res.stderr[-2000:]
    lines = [ln for ln in res.stdout.splitlines() if ln.startswith("not measured: ")]
    assert lines == [f"not measured: {rel} stops at t=0 s (error, {where})" for rel, where in stopped.items()]


#: ../shared/krl-history: a pair's side whose programs lie outside any backup, and a backup's SPS.SUB
HISTORY = SHARED_CORPUS.parent / "krl-history"
LOOSE = "AutodeskRoboticsLab__Mimic/01-9e0f9529/old/"
HISTORY_SUB = "HugoDanielson__ChinaMilling/02-8cf009a2/old/KRC/R1/System/sps.sub"


def _bench(*args: str) -> tuple[subprocess.CompletedProcess, dict]:
    out = Path(args[args.index("--json") + 1])
    res = subprocess.run([sys.executable, str(REPO / "tools" / "whole_run_bench.py"), *args],
                         capture_output=True, text=True, cwd=REPO, timeout=600, check=False)
    assert res.returncode == 0, res.stderr[-2000:]
    return res, json.loads(out.read_text())


@pytest.mark.slow       # (three runs of the bench, two with a backup's SPS.SUB on both sides: 200 s at load 16)
def test_history_takes_both_sides_entry_points_and_the_baseline_may_run_without_parking(tmp_path):
    """``--history``: the programs of a pair's side outside any backup are entry points too (the
    Mimic pair's old side holds two loose programs, no backup: none without it); ``--baseline-spins
    off``: this checkout against itself with the spin watch off on the baseline side, the same I/O
    and end (parking's evidence), the I/O digest printed on each row."""
    if not (HISTORY / LOOSE).is_dir() or not (HISTORY / HISTORY_SUB).is_file():
        pytest.skip("the shared history is not here")
    _res, data = _bench("--history", "--corpus", str(HISTORY), "--only", LOOSE, "--sim-time", "1",
                        "--json", str(tmp_path / "loose.json"))
    assert sorted(Path(r["program"]).name for r in data["rows"]) == ["example.src", "template.src"]
    _res, data = _bench("--corpus", str(HISTORY), "--only", LOOSE, "--sim-time", "1",
                        "--json", str(tmp_path / "backups.json"))
    assert data["rows"] == []
    res, data = _bench("--history", "--corpus", str(HISTORY), "--only", HISTORY_SUB, "--sim-time", "10",
                       "--baseline", str(REPO), "--baseline-spins", "off", "--json", str(tmp_path / "onoff.json"))
    (row,) = data["rows"]
    assert row["program"] == HISTORY_SUB and row["same"] is True
    assert data["summary"]["new"]["spins"] == "park" and data["summary"]["base"]["spins"] == "off"
    new = row["new"]
    assert new["sim_s"] == pytest.approx(10.0, abs=0.012) and new["io_events"] > 0
    assert new["parks"] > 0 and row["base"]["parks"] == 0      # (parked on this side only)
    (line,) = [ln for ln in res.stdout.splitlines() if ln.startswith(HISTORY_SUB[-58:])]
    assert new["io_sha"] in line.split()
