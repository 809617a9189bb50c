"""One program model shared by many runs (issue 87 item 1; interp/runtime/model.py): a model is
loaded once and frozen; each run, and each tool, reads its own copy of its data memory, system
variables, I/O image and stand-ins (``ProgramModel.data``). The same model serves runs one after
the other and at once (threads), each equal to a run built on a model of its own; the model's
objects are never written: a write to one raises.

Seen failing first: on the loaded program of issue 76 a second run of one loaded program raised
"a loaded program serves one run" (interp/runtime/loaded.py ``LoadedProgram.attach``), and a
run's writes went to the loaded data lists."""

from __future__ import annotations

import threading

import pytest

from interp.run import RunSinks, _interpreter, global_value, load_program, make_runtime, plan_cell, run_spec
from interp.runtime.core import Runtime
from interp.runtime.model import ProgramModel, RunData, load_model
from robot.trace import TraceWriter

from .helpers import refuse_runs, write

INTERPS = ("tree", "vm")

SRC = """
DEF prog()
  DECL INT i
  $OV_PRO = 50
  FOR i = 1 TO 3
    count = count + 1
    $OUT[5] = NOT $OUT[5]
    WAIT SEC 0.1
  ENDFOR
  total = total + count * 10
  ok_sig = TRUE
  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""

# the values are the DECL's: HOME's axes, a REAL computed by no one, an array element set alone
DAT = """
DEFDAT prog PUBLIC
  DECL E6AXIS HOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
  DECL REAL speed=2.5
  DECL INT counts[3]
  counts[2]=7
  DECL GLOBAL INT count=0
  DECL REAL total=1.5
  SIGNAL ok_sig $OUT[7]
ENDDAT
"""


@pytest.fixture
def prog(tmp_path):
    write(tmp_path, "prog.dat", DAT)
    return write(tmp_path, "prog.src", SRC)


def _spec(prog, interp):
    return run_spec(prog, mujoco=False, max_sim_time=5.0, interp=interp, check=False)


def _run(model, spec) -> dict:
    """A run of `spec` on `model` (as interp/run.py ``make_runtime`` builds one): its trace, I/O
    changes, end and the data list's values after it."""
    tw = TraceWriter(keep=True)
    rt = Runtime(model, lambda data: plan_cell(data, spec), spec, RunSinks(trace=tw), interpreter=_interpreter)
    res = rt.run()
    dat = rt.program.module("prog").data
    return {"trace": [dict(e) for e in tw.events], "io": list(rt.io.log),
            "end": (res.reason, res.text, round(res.sim_time, 6), res.steps),
            "values": (dat["COUNT"].get(), dat["TOTAL"].get(), rt.io.get_out(7), rt.sysvars.store["$OV_PRO"])}


def test_a_tool_reads_its_copy_of_the_model_without_a_run(prog, monkeypatch):
    """load_program gives a tool its own copy of the model (no controller, no network hub): the
    data lists' DECL values, an array element set alone; the cell is planned from it."""
    refuse_runs(monkeypatch)
    spec = run_spec(prog, mujoco=False)
    data = load_program(spec)
    assert isinstance(data, RunData) and isinstance(data.model, ProgramModel)
    assert global_value(data, "prog", "speed") == 2.5
    assert global_value(data, "prog", "counts").data[1] == 7
    home = global_value(data, "prog", "HOME")
    assert (home.f["A2"], home.f["A3"]) == (-90.0, 90.0)
    assert global_value(data, "prog", "nothing") is None
    plan = plan_cell(data, spec.with_(start="HOME"))
    assert plan.start.where == "HOME" and plan.start.why == "--start"
    assert list(plan.start_axes)[:3] == [0.0, -90.0, 90.0]


@pytest.mark.parametrize("interp", INTERPS)
def test_one_model_serves_two_runs_at_once(prog, interp):
    """Two threads run one model at the same time; each run equals a run on a model of its own
    (trace, I/O changes, end, values), and each starts from the DECL values: COUNT 0 -> 3 by the
    FOR loop, TOTAL 1.5 + 3 * 10, the SIGNAL's output set, $OV_PRO 50."""
    spec = _spec(prog, interp)
    alone = _run(ProgramModel(spec), spec)
    assert alone["end"][0] == "completed"
    assert alone["values"] == (3, 31.5, True, 50)
    assert [e["value"] for e in alone["trace"] if e["kind"] == "io" and e["signal"] == "$OUT[5]"] == [True, False, True]
    model = ProgramModel(spec)
    got: list = [None, None]
    barrier = threading.Barrier(2)

    def run(k):
        barrier.wait()
        got[k] = _run(model, spec)
    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert got[0] == alone and got[1] == alone


def test_one_model_serves_a_hundred_runs_one_after_the_other(prog):
    """A hundred runs of one model, each equal to the run on a model of its own: what one run
    wrote (its data list, its outputs, $OV_PRO) is not where the next one starts."""
    spec = _spec(prog, "vm")
    alone = _run(ProgramModel(spec), spec)
    model = ProgramModel(spec)
    for k in range(100):
        assert _run(model, spec) == alone, f"run {k + 1}"


def test_the_model_is_never_written(prog):
    """The model is frozen once loaded: its attributes, its data lists' values (a variable, an
    array element, a structure's component), its system variables and its I/O image refuse a
    write; a run on it leaves it as it was."""
    spec = _spec(prog, "tree")
    model = ProgramModel(spec)
    own = model.program.module("prog")
    with pytest.raises(AttributeError):
        model.notes = ()
    with pytest.raises(TypeError):
        own.data["COUNT"].set(5)
    with pytest.raises(TypeError):
        own.data["COUNTS"].get().data[0] = 1
    with pytest.raises(TypeError):
        own.data["HOME"].get().f["A1"] = 1.0
    with pytest.raises(TypeError):
        model.sysvars.store["$OV_PRO"] = 10
    with pytest.raises(TypeError):
        model.sysvars.store["$TOOL"].f["X"] = 1.0
    with pytest.raises((TypeError, AttributeError)):
        model.io.set_out(5, True, "program")
    assert _run(model, spec)["values"] == (3, 31.5, True, 50)
    assert own.data["COUNT"].get() == 0 and own.data["TOTAL"].get() == 1.5
    assert model.sysvars.store["$OV_PRO"] == 100 and not model.io.get_out(7)


def test_the_programs_of_one_backup_share_a_model(tmp_path):
    """Every program of the same files runs on one model (the process's, interp/runtime/model.py
    ``load_model``): which program runs is the run's. A file changed makes another model."""
    write(tmp_path, "prog.dat", DAT)
    a = write(tmp_path, "prog.src", SRC)
    b = write(tmp_path, "other.src", "DEF other()\n  count = count + 2\nEND\n")
    rt_a, _ = make_runtime(_spec(a, "tree"))
    rt_b, _ = make_runtime(_spec(b, "vm"))
    assert rt_a.model is rt_b.model and rt_b.program.main_path.name == "other.src"
    assert rt_b.run().reason == "completed" and rt_b.program.module("prog").data["COUNT"].get() == 2
    assert rt_a.model.program.module("prog").data["COUNT"].get() == 0
    write(tmp_path, "other.src", "DEF other()\n  count = count + 3\nEND\n")
    assert load_model(_spec(b, "vm").with_(robot=rt_a.machine)) is not rt_a.model


def test_a_run_copies_a_data_list_when_it_first_reads_it(tmp_path):
    """A run's copy of a model shares the modules' code and copies a data list's values only
    when the run first reads that list (program.py ``ModuleRT.copy``): a list the program never
    names is never copied, and until then the idle watch images the model's values
    (``slot_values``), equal to the copy's once it is made; the system data lists' declarations
    are the run's own references."""
    write(tmp_path, "prog.dat", DAT)
    write(tmp_path, "other.dat", "DEFDAT other PUBLIC\n  DECL INT n=4\n  DECL E6AXIS P={A1 1.0}\nENDDAT\n")
    write(tmp_path, "$custom.dat", "DEFDAT $CUSTOM PUBLIC\n  DECL INT $SIM_EXTRA=5\nENDDAT\n")
    prog = write(tmp_path, "prog.src", SRC.replace("  total = total", "  $SIM_EXTRA = $SIM_EXTRA + 1\n  total = total"))
    spec = _spec(prog, "vm")
    rt, _ = make_runtime(spec)
    other, model_other = rt.program.module("other"), rt.model.program.module("other")
    assert "store" not in vars(other) and other.slot_values() is model_other.store
    assert rt.run().reason == "completed"
    assert "store" not in vars(other), "a data list the run never named was copied"
    before = other.slot_values()
    assert other.data["N"].get() == 4 and "store" in vars(other)
    assert other.slot_values() is not model_other.store and list(other.slot_values()) == list(before)
    assert other.data["P"].get() is not model_other.data["P"].get()
    other.data["N"].set(9)
    assert model_other.data["N"].get() == 4 and rt.model.data().program.module("other").data["N"].get() == 4
    declared = rt.model.sysvars.declared
    assert list(declared) == ["$SIM_EXTRA"]
    own, span = rt.sysvars.declared["$SIM_EXTRA"]
    assert own is not declared["$SIM_EXTRA"][0] and span == declared["$SIM_EXTRA"][1]
    assert own is rt.program.module("$custom").data["$SIM_EXTRA"] and own.get() == 6
    assert declared["$SIM_EXTRA"][0].get() == 5
