"""`krl debug` = `krl run` under a debugger, on real backups of the shared corpus: the default
launch (program only) starts the backup's SPS.SUB as the controller does at boot and
simulates the backup's own robot, so a breakpoint in the robot program is reached. Expected
lines and values are read off the backups' files by hand (the comments say where)."""

from __future__ import annotations

import pytest

from interp.debug.client import DapClient
from krl.files import SHARED_CORPUS

PALLETIZER = SHARED_CORPUS / "ingeniado__KRC4-Robot-Palletizer"
MILLING = SHARED_CORPUS / "HugoDanielson__ChinaMilling" / "KRC"

pytestmark = pytest.mark.skipif(not SHARED_CORPUS.is_dir(), reason="the shared corpus is beside the repository")


def test_the_default_launch_starts_sps_sub_and_reaches_the_breakpoint():
    # main.src: BAS (#INITMOV,0) (l.26) calls TQM_INI (System/bas.src l.149), whose
    # CHECK_SUBMIT_RUNS (System/tm_bib.src l.1125) loops "SubmitNotActive" while $PRO_STATE0 is
    # not #P_ACTIVE; then PTP XHOME (l.41) and VACIO = FALSE (l.45) before the main LOOP.
    main = PALLETIZER / "main.src"
    with DapClient(timeout=900) as c:
        st = c.start(main, breakpoints={main: [45]})
        assert st["body"]["reason"] == "breakpoint" and st["body"]["threadId"] == 1
        top = c.stack()[0]
        assert (top["name"], top["line"], top["source"]["path"]) == ("CELL()", 45, str(main))
        threads = {t["id"]: t["name"] for t in c.request("threads")["body"]["threads"]}
        assert threads == {1: "robot program main", 2: "submit interpreter sps"}
        assert c.value("$PRO_STATE0") == "#P_ACTIVE"
        # $config.dat l.754: SIGNAL VACIO $OUT[1]; names in any letter case
        assert c.value("vacio") == c.value("VACIO") == c.value("$OUT[1]") == "FALSE"


def test_without_the_submit_the_program_waits_in_kukas_check():
    # the same launch with noSubmit: the robot program stays in CHECK_SUBMIT_RUNS (tm_bib.src,
    # its WAIT SEC loop at l.1142) until the simulated-time limit; line 45 is never reached
    main = PALLETIZER / "main.src"
    with DapClient(timeout=900) as c:
        c.initialize()
        c.request("launch", {"program": str(main), "noSubmit": True, "maxSimTime": 3})
        c.set_breakpoints(main, [45])
        c.request("configurationDone")
        assert c.wait_event("exited")["body"]["exitCode"] == 3          # stopped at the time limit
        out = "".join(e["body"]["output"] for e in c.events if e.get("event") == "output")
        assert "tm_bib.src:114" in out and "simulated time limit" in out
        assert not [e for e in c.events if e.get("event") == "stopped"]


def test_the_backups_own_robot_and_submit_under_the_debugger():
    # Main.src: BAS (#INITMOV,0) (l.35), PTP $POS_ACT (l.36), InitVariables() (l.38);
    # R1/Mada/$machine.dat: $TRAFONAME[]="#KR210R2700_2 C4 FLR"; R1/System/sps.sub runs beside it
    main = MILLING / "R1" / "Program" / "KukaMiling" / "Main.src"
    with DapClient(timeout=900) as c:
        st = c.start(main, breakpoints={main: [38]})
        assert st["body"]["reason"] == "breakpoint" and c.stack()[0]["line"] == 38
        assert c.value("$TRAFONAME[]") == '"#KR210R2700_2 C4 FLR"'
        names = [t["name"] for t in c.request("threads")["body"]["threads"]]
        assert "submit interpreter sps" in names
