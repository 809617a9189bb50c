"""A run that meets a name the backup itself never declares, in a module it calls (issue 85,
item 9: "Two programs meet an undeclared name in a called module at 42.5 s and 84.7 s: true, but
the run says 'unknown name', which reads like a gap of the simulator"), on both interpreters.

The run's error says what the checker knows (the backup's own undeclared variable: E101 at
file:line) and what KUKA's controller does with such a module (it does not compile, so the
program that calls it does not link and cannot be selected)."""

from __future__ import annotations

import pytest

from interp.realprograms import cause_of
from interp.run import make_runtime, run_spec

from .helpers import write

MAIN = "DEF main()\n  WAIT SEC 0.5\n  count_part()\nEND\n"
#: line 3 uses nCount, which nothing declares (the checker: E101 at lib.src:3:3)
LIB = "DEF lib()\nEND\nGLOBAL DEF count_part()\n  nCount = nCount + 1\nEND\n"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_an_undeclared_name_of_the_backup_is_named_as_the_checker_knows_it(tmp_path, interp):
    main = write(tmp_path, "main.src", MAIN)
    write(tmp_path, "lib.src", LIB)
    rt, _ = make_runtime(run_spec(main, mujoco=False, check=False, interp=interp, max_sim_time=5.0))
    res = rt.run()
    assert (res.reason, res.file.endswith("lib.src"), res.line) == ("error", True, 4)
    assert res.text.startswith("unknown name nCount: the backup declares no nCount (krl check: E101 at ")
    assert "lib.src:4:3" in res.text
    assert res.text.endswith("KUKA's controller does not link lib.src with that error, so no program that is or "
                             "calls lib.src can be selected")
    assert res.error.name == "nCount"
    # the program's error, not a gap of the simulator
    assert cause_of({"program": str(main), "reason": res.reason, "text": res.text, "sim_time": res.sim_time,
                     "cell_answers": 0, "robot_own": False}) == "program error"
