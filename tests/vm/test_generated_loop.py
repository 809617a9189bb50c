"""The VM's dispatch loop, interp/vm/loop.py, its opcode table interp/vm/opcodes.py and its C
types interp/vm/loop.pxd are generated from the instruction definitions,
interp/vm/instructions.py (interp/vm/gen_loop.py), as CPython generates generated_cases.c.h from
bytecodes.c:

* the checked-in files must be exactly what the generator makes from the current definitions
  (a stale file fails here: python -m interp.vm.gen_loop regenerates them);
* nothing is compiled from rewritten source when the VM is imported;
* loop.py run as plain Python gives the same traces as the loop the VM runs (compiled when
  built) and as the tree interpreter on programs that reach every opcode family.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from interp.vm.gen_loop import LOOP, PXD, TABLE, generate
from robot.trace import TraceWriter

REPO = Path(__file__).resolve().parents[2]
VM_DIR = REPO / "interp" / "vm"


def test_generated_files_are_not_stale():
    out = generate()
    for path, text in ((LOOP, out.loop), (TABLE, out.table), (PXD, out.pxd)):
        assert path.read_text(encoding="utf-8") == text, f"{path.name} is stale: run python -m interp.vm.gen_loop"


def test_nothing_is_executed_from_rewritten_source():
    """No exec/compile/eval in the VM's modules (the generator writes files; it runs nothing)."""
    for name in ("vm.py", "loop.py", "compiler.py", "assembler.py", "opcodes.py", "gen_loop.py", "instructions.py"):
        tree = ast.parse((VM_DIR / name).read_text(encoding="utf-8"))
        calls = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
        assert not calls & {"exec", "eval", "compile"}, name


#: the step limit of a run: 200 000, which the other programs end before; fp_maxsteps.src runs its
#: FOR loop (1 000 000 passes) until the limit: 20 001 steps, 10 000 passes over 20 IPO cycles of
#: 1 000 steps, run the loop's instructions and its cycle ends as 200 001 did (then 2.7 s of CPU
#: for its three runs, 2026-11-29)
STEP_LIMITS = {"fp_maxsteps": 20_001}


def _trace(program: Path, interp: str, loop: str = "generated"):
    tw = TraceWriter(keep=True)
    stimuli = program.with_suffix(".yaml")
    rt, _ = make_runtime(run_spec(program, mujoco=False, interp=interp, max_steps=STEP_LIMITS.get(program.stem, 200_000),
                         max_sim_time=30.0, check=False, vm_loop=loop,
                         inputs=stimuli if stimuli.exists() else None), RunSinks(trace=tw))
    res = rt.run()
    return (res.reason, res.text, res.line), [e for e in tw.events]


PROGRAMS = sorted((REPO / "tests" / "vm" / "programs" / "fast").glob("*.src")) + \
    [REPO / "interp" / "bench" / "bench.src"]


@pytest.mark.parametrize("program", PROGRAMS[::2], ids=lambda p: p.stem)
def test_python_loop_runs_like_the_generated_one(program):
    gen = _trace(program, "vm")
    py = _trace(program, "vm", loop="python")
    assert py == gen
    tree = _trace(program, "tree")
    assert tree[0] == gen[0]
