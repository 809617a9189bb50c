"""The pendant's single-robot keys in a cell of several robots (issue 89; pendant/cell.py): choose a
robot, and the operating mode, the drives, a breakpoint, a jog, a touch-up, the watch list and
Stop act on that robot, through the same handlers as for one robot (pendant/server.py), on the
cell's run under the debug engine (interp/debug/cellrun.py). Driven in-process (the server's
handlers without a page), on both interpreters.

Expected values by hand from the programs: R1 moves A1 to 20 deg and waits for $IN[5] (never
set); R2 (at X 2000, turned 180 deg) moves A1 to -30 deg, then waits 12 ms over and over
(line 4). The cell stops at its start in R1's program (R1 comes first); a jog of R2's A1 by +5
deg there moves R2 alone (0 -> 5; R1 stays at its start, A1 0). At R2's breakpoint (line 4) R2
stands at A1 -30 once its motion has ended, a jog of +10 takes it to -20, R1 stands at its
own 20: the two robots are mirror images about their XZ planes (A1 +20 and -20, the other axes
equal), so the point touched up in R2's data list has R1's X and Z and the negative of its Y.
R2's folder's $config.dat declares SIGNAL R2_GRIP $OUT[3]: the I/O view names it for R2, not R1.
"""

from __future__ import annotations

import asyncio

import pytest

from pendant.cell import CellPendant
from pendant.engine import EngineError
from robot.datalist import read_data_list

R1 = "DEF r1()\n  PTP {A1 20, A2 -90, A3 90, A4 0, A5 0, A6 0}\n  WAIT FOR $IN[5]\nEND\n"
R2 = ("DEF r2()\n  PTP {A1 -30, A2 -90, A3 90, A4 0, A5 0, A6 0}\n  LOOP\n    WAIT SEC 0.012\n"
      "  ENDLOOP\nEND\n")
R2_DAT = ("DEFDAT r2\nDECL E6POS XP={X 900.0,Y 0.0,Z 1200.0,A 0.0,B 90.0,C 0.0,S 2,T 0,"
          "E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}\nENDDAT\n")
R2_CONFIG = "DEFDAT $CONFIG\nSIGNAL R2_GRIP $OUT[3]\nENDDAT\n"
CELL = "robots:\n  R1: {program: r1/r1.src}\n  R2: {program: r2/r2.src, base: [2000, 0, 0, 180, 0, 0]}\n"


def _names(state: dict, n: int) -> list:
    """The SIGNAL names the I/O view gives $OUT[n]."""
    return next(r["names"] for r in state["io"]["$OUT"] if r["index"] == n)


async def _until(pendant: CellPendant, test) -> dict:
    for _ in range(2400):
        s = await pendant.state()
        if test(s):
            return s
        await asyncio.sleep(0.025)
    raise AssertionError(f"not reached: {s.get('state')} {s.get('stop')}")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_keys_act_on_the_chosen_robot(tmp_path, interp):
    for folder in ("r1", "r2"):          # each robot's folder (R2's: its program, data list and $config.dat)
        (tmp_path / folder).mkdir()
    for name, text in (("r1/r1.src", R1), ("r2/r2.src", R2), ("r2/r2.dat", R2_DAT), ("r2/$config.dat", R2_CONFIG),
                       ("cell.yaml", CELL)):
        (tmp_path / name).write_text(text, encoding="ascii")
    pendant = CellPendant(tmp_path / "cell.yaml", realtime=False, interp=interp)

    async def key(op, **args):
        await pendant.handle(None, {"op": op, **args})
        return await pendant.state()

    async def scenario():
        await pendant.select("")
        s = await pendant.state()
        assert (s["state"], s["stop"]["reason"], s["cell"]["chosen"]) == ("stopped", "entry", "R1")
        assert s["program"].endswith("r1.src") and s["modeOp"] == "AUT"
        assert _names(s, 3) == []                                      # R1 declares no SIGNAL
        # the modes and the drives are each robot's
        await key("chooseRobot", robot="R2")
        s = await key("modeOp", value="T1")
        assert (s["modeOp"], s["program"].endswith("r2.src")) == ("T1", True)
        assert _names(s, 3) == ["R2_GRIP"]                             # R2's own SIGNAL
        await key("drives", on=True)
        s = await key("chooseRobot", robot="R1")
        assert (s["modeOp"], s["drives"]) == ("AUT", False)
        with pytest.raises(EngineError, match="drives of R1 are off"):
            await key("start")
        with pytest.raises(EngineError, match="only in T1"):          # R1 is in AUT
            await key("jog", system="AXIS", axis=1, step=5)
        await key("drives", on=True)
        # a jog of R2 at the cell's start (the cell stands in R1's program): R2 alone moves
        await key("chooseRobot", robot="R2")
        s = await key("jog", system="AXIS", axis=1, step=5)
        assert s["position"]["axes"][:2] == pytest.approx([5, -90])
        s = await key("chooseRobot", robot="R1")
        assert s["position"]["axes"][:2] == pytest.approx([0, -90])
        # R2's breakpoint, set with R2 chosen (its workspace); Start runs the cell to it
        await key("chooseRobot", robot="R2")
        await key("breakpoint", path=str(tmp_path / "r2" / "r2.src"), line=4, on=True)
        await key("start")
        s = await _until(pendant, lambda s: s["state"] == "stopped" and s["stop"]["reason"] == "breakpoint")
        assert s["pointers"]["advanceRun"]["line"] == 4
        s = await key("jog", system="AXIS", axis=1, step=10)
        assert s["position"]["axes"][:3] == pytest.approx([-20, -90, 90])
        r2 = s["position"]["pos"]
        await key("touchup", path=str(tmp_path / "r2" / "r2.dat"), name="XP")
        s = await key("watch", exprs=["XP.Y"])                         # R2's program's copy of the point
        assert float(s["watch"][0]["value"]) == pytest.approx(r2["Y"], abs=1e-3)
        s = await key("chooseRobot", robot="R1")
        r1 = s["position"]["pos"]
        assert s["position"]["axes"][:3] == pytest.approx([20, -90, 90])
        assert "not declared" in s["watch"][0]["error"]                # R1's program has no XP
        got = read_data_list(tmp_path / "r2" / "r2.dat")["XP"].value
        assert abs(r1["Y"]) > 100
        assert (got["X"], got["Y"], got["Z"]) == pytest.approx((r1["X"], -r1["Y"], r1["Z"]), abs=1e-3)
        # Stop with R1 chosen stops the cell in R1's program (R2's statements come every 12 ms)
        await key("chooseRobot", robot="R2")
        await key("breakpoint", path=str(tmp_path / "r2" / "r2.src"), line=4, on=False)
        await key("chooseRobot", robot="R1")
        await key("start")
        await _until(pendant, lambda s: s["state"] == "running")
        await key("stop")
        await _until(pendant, lambda s: s["state"] == "stopped")
        core = pendant.engine.core
        assert core.stop_task is core.cell.runs[0].runtime.robot
        with pytest.raises(EngineError, match="stands in R1's program"):   # R2 chosen: its program runs the backward motion
            await key("chooseRobot", robot="R2")
            await key("backward")
        await key("cancel")

    try:
        asyncio.run(scenario())
    finally:
        pendant.engine.cancel()
