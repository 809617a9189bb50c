"""One run of a KRL program: controller + runtime + interpreter (used by `krl run`, the
tests and the real-programs report)."""

from __future__ import annotations

from pathlib import Path

from interp.runtime.core import RunResult, Runtime


def make_runtime(program, *, workspace=None, inputs=None, trace=None, max_sim_time=None,
                 max_steps=None, submit=None, mujoco: bool = True, controller=None,
                 robot_budget=None, interp: str = "tree") -> tuple[Runtime, object]:
    """Build the runtime and the interpreter (``interp``: tree or vm) for ``program``
    (not started yet)."""
    from interp.tree import TreeInterpreter  # noqa: PLC0415

    if controller is None:
        from robot.controller import Controller  # noqa: PLC0415

        controller = Controller(trace=trace, stimuli=str(inputs) if inputs else None, mujoco=mujoco)
    rt = Runtime(program, workspace=workspace, controller=controller, trace=trace,
                 max_sim_time=max_sim_time, max_steps=max_steps, robot_budget=robot_budget)
    if interp == "vm":
        from interp.vm import VM  # noqa: PLC0415

        interp = VM(rt)
    else:
        interp = TreeInterpreter(rt)
    rt.add_task("robot", Path(program).stem, lambda: interp.run_program())
    for sub in submit or ():
        sp = Path(sub).resolve()
        if sp.stem.upper() not in rt.program.index:
            rt.program._add_file(sp)  # noqa: SLF001
        rt.add_task("submit", sp.stem, lambda name=sp.stem: interp.run_program(name))
    return rt, interp


def run_program(program, **kw) -> RunResult:
    rt, _ = make_runtime(program, **kw)
    return rt.run()
