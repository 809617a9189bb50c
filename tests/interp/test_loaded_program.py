"""The loaded program apart from the run (issue 76; interp/runtime/loaded.py): a program's files
loaded and checked, its data lists initialised and its names resolvable, with no controller, no
network hub and no trace; ``plan_cell(loaded, spec)`` plans the cell from it and
``Runtime(loaded, plan, spec, sinks)`` runs on it (interp/run.py ``make_runtime``)."""

from __future__ import annotations

import pytest

from interp.run import global_value, load_program, make_runtime, plan_cell, run_spec
from interp.runtime.loaded import LoadedProgram

from .helpers import refuse_runs, write

SRC = """
DEF prog()
  PTP HOME
END
"""

# the values are the DECL's: HOME's axes, a REAL computed by no one, an array element set alone
DAT = """
DEFDAT prog
  DECL E6AXIS HOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
  DECL REAL speed=2.5
  DECL INT counts[3]
  counts[2]=7
ENDDAT
"""


@pytest.fixture
def no_run(monkeypatch):
    refuse_runs(monkeypatch)


def test_a_loaded_program_reads_its_data_lists_without_a_run(tmp_path, no_run):
    write(tmp_path, "prog.dat", DAT)
    spec = run_spec(write(tmp_path, "prog.src", SRC), mujoco=False)
    loaded = load_program(spec)
    assert isinstance(loaded, LoadedProgram) and loaded.controller is None and loaded.run is None
    assert global_value(loaded, "prog", "speed") == 2.5
    assert global_value(loaded, "prog", "counts").data[1] == 7
    home = global_value(loaded, "prog", "HOME")
    assert (home.f["A2"], home.f["A3"]) == (-90.0, 90.0)
    assert global_value(loaded, "prog", "nothing") is None
    # the cell is planned from the loaded program alone: --start names a point of its data list
    plan = plan_cell(loaded, spec.with_(start="HOME"))
    assert plan.start.where == "HOME" and plan.start.why == "--start"
    assert list(plan.start_axes)[:3] == [0.0, -90.0, 90.0]


def test_a_run_is_built_on_its_loaded_program(tmp_path):
    """make_runtime loads the program once and the run's parts read the run from then on; a
    loaded program serves one run."""
    write(tmp_path, "prog.dat", DAT)
    rt, _ = make_runtime(run_spec(write(tmp_path, "prog.src", SRC), mujoco=False, max_sim_time=5.0))
    loaded = rt.loaded
    assert loaded.run is rt and rt.program is loaded.program and rt.names is loaded.names
    assert rt.sysvars.rt is rt and rt.names.rt is rt and rt.kss.rt is rt and rt.program.rt is rt
    with pytest.raises(ValueError, match="one run"):
        loaded.attach(rt)
    assert rt.run().reason == "completed"
