"""krl diff on real history (issue 37): the 40 pairs of consecutive real versions in
../shared/krl-history (old/, new/; origins in its MANIFEST.csv), read in place.

* On every pair (``make test``: each repository's newest pair; ``make nightly``: all),
  ``krl diff --format json`` is compared with an independent comparison of
  every declared value (tests/diff/oracle.py: both sides' data lists parsed and compared
  by the documented rules, no code of krl/diff): no miss, no false change; the JSON validates
  against docs/schemas/diff.schema.json, and nothing of Python's representation is in it.
* On fourteen pairs, the whole report is checked against deltas written by hand from reading
  ``diff -r old new`` (EXPECTED below: each line says what the commit changed).
"""

from __future__ import annotations

import json
import re

import pytest
from click.testing import CliRunner

from app import main
from tests.conftest import earlier_pair, history_pairs, large_pair
from tests.diff import oracle
from tests.test_json_schemas import validate


def _by_repository(pairs: list[str], sample: bool = False) -> list:
    """Each pair with the xdist group of its repository (make test: --dist loadgroup), so a
    repository's consecutive pairs run on one worker: the oracle parses each content once per
    process (oracle.parse_all), and the old side of a pair is mostly the new side of the one
    before (KUKA-Script's four pairs, 1.9 MB a side: 73 s of the module's 128 s when spread).
    `sample`: a pair older than its repository's newest is marked ``slow`` (tests.conftest
    earlier_pair: ``make test`` compares each repository's newest pair, ``make nightly`` all), and
    so is a pair over 1 MB a side (tests.conftest large_pair: KUKA-Script's)."""
    return [pytest.param(p, marks=[pytest.mark.xdist_group("history-" + p.split("/", 1)[0])]
                         + ([pytest.mark.slow] if sample and p != "(absent)" and (earlier_pair(p) or large_pair(p)) else []))
            for p in pairs]


PAIRS = _by_repository(history_pairs() or ["(absent)"], sample=True)


@pytest.fixture(autouse=True)
def patient_parse(monkeypatch):
    """A file's parse time limit well above krl.limits.PARSE_TIMEOUT_S: on a loaded machine a
    large file of the history may take longer than 30 s, and then it would not be compared."""
    monkeypatch.setattr("krl.diff.load.PARSE_TIMEOUT_S", 900)


#: pair -> (exit code, JSON) of its one `krl diff` run in this process: the oracle's test and the
#: test of the deltas read by hand read the same report (both in the pair's repository group,
#: so on one worker of make test)
_DIFFS: dict[str, tuple[int, dict]] = {}


def run_diff(history, pair: str) -> tuple[int, dict]:
    if pair not in _DIFFS:
        r = CliRunner().invoke(main, ["diff", "--format", "json", str(history / pair / "old"),
                                      str(history / pair / "new")])
        assert r.exit_code in (0, 1, 2), r.output
        assert "Traceback" not in r.output and "internal error" not in r.output
        _DIFFS[pair] = (r.exit_code, json.loads(r.stdout))   # the errors of files not compared are on stderr
    code, doc = _DIFFS[pair]
    return code, json.loads(json.dumps(doc))      # a copy: no test sees another's changes


def _in_oracle_form(doc: dict, files: set[str]) -> set:
    """The diff's value changes with its file names mapped to the oracle's keys (the diff names
    a file below the backup root, the oracle below the side's folder)."""
    out = set()
    for f, name, change in oracle.reported(doc):
        match = [k for k in files if k == f or k.endswith("/" + f)]
        assert len(match) == 1, (f, match)
        out.add((match[0], name, change))
    return out


# A Python representation that must never reach the output: a tuple or list of quoted words,
# a class name with a parenthesis, None/True/False outside KRL text.
_PYTHON = re.compile(r"\('|\['|\bNone\b|<[A-Za-z_.]+ object|\b[A-Z][a-z]+[A-Z][A-Za-z]*\(")


@pytest.mark.parametrize("pair", PAIRS)
def test_diff_finds_every_value_change_the_oracle_finds(shared_history, pair):
    code, doc = run_diff(shared_history, pair)
    validate("diff", doc)
    expected, skipped = oracle.compare(shared_history / pair / "old", shared_history / pair / "new")
    files = set(oracle.krl_files(shared_history / pair / "old")) | set(oracle.krl_files(shared_history / pair / "new"))
    got = _in_oracle_form(doc, files)
    assert got - expected == set(), f"false changes: {sorted(got - expected)}"
    assert expected - got == set(), f"missed changes: {sorted(expected - got)}"
    # a .dat file the oracle could not parse on a side is named as not compared (or unchanged)
    named = {f.lower() for f in doc["not_compared"]}
    for k in skipped:
        old, new = (shared_history / pair / s / k for s in ("old", "new"))
        same = old.exists() and new.exists() and old.read_bytes() == new.read_bytes()
        assert same or any(n.endswith(k) for n in named) or not (old.exists() or new.exists()), k
    assert code == (1 if doc["changed"] else 2 if doc["not_compared"] else 0)
    # every KRL file of either side (matched with letter case ignored) is accounted for, a
    # file moved (the oracle's rule, oracle.moves) once
    moved = oracle.moves(oracle.krl_files(shared_history / pair / "old"), oracle.krl_files(shared_history / pair / "new"))
    assert len(doc["moved"]) == len(moved)
    s = doc["summary"]
    assert s["files_compared"] + s["unparsed_same"] + s["not_compared"] == len(files) - len(moved)
    text = json.dumps({k: doc[k] for k in ("points", "frames", "values", "declarations", "motions")})
    assert not _PYTHON.search(text), _PYTHON.search(text).group(0)


def digest(doc: dict) -> set[tuple]:
    """The report in a form written by hand: one tuple per entry (see EXPECTED)."""
    out: set[tuple] = set()
    for e in doc["points"] + doc["frames"]:
        st = tuple(sorted((c, tuple(v)) for c, v in e.get("status_turn", {}).items()))
        out.add(("point", e["file"], e["name"], e["change"],
                 tuple(sorted((c, round(v, 4)) for c, v in e["delta"].items())), st))
    for e in doc["values"]:
        out.add(("value", e["file"], e["name"], e["change"], e["old"], e["new"]))
    for e in doc["routines"]:
        out.add(("routine", e["file"], e["name"], e["change"], tuple(sorted(ln["line"] for ln in e["before"])),
                 tuple(sorted(ln["line"] for ln in e["after"]))))
    for e in doc["declarations"]:
        out.add(("decl", e["file"], e["scope"], e["name"], e["kind"], e["change"]))
    for e in doc["motions"]:
        out.add(("motion", e["file"], e["line"], tuple(sorted(e["changed"]))))
    return out


EX = "mimic/scripts/postproc/KUKA/EntertainTech/example.src"
TOP = "R1/Program/Milling/TestPiece/TopSquare"
LIOR = "KRL/ethernetkrl_workshop"

# pair -> (entries, comment lines edited, not compared), each written from `diff -r old new`
EXPECTED = {
    # the dummy position assigned in the routine (line 21) and a PTP un-commented (line 46)
    "AutodeskRoboticsLab__Mimic/01-9e0f9529": ({("routine", EX, "example", "changed", (21,), (21, 46))}, 1, 0),
    # a variable declared in the data list; the LIN goes to it after 4 new statement lines
    "BmadeRobots__KukaVarProxy/02-b04e507a": ({
        ("decl", "robot/var_proxy_v2.dat", "", "ghMotionBuf", "variable", "added"),
        ("routine", "robot/var_proxy_v2.src", "var_proxy_v2", "changed", (52,), (46, 47, 48, 49, 58, 61)),
    }, 0, 0),
    # one repeated $stiffness line removed
    "CentroEPiaggio__kuka-lwr/02-e499fb05": ({
        ("routine", "lwr_hw/krl/ros_control.src", "ros_control", "changed", (44,), ()),
    }, 0, 0),
    # 17 statement lines of ros_position.src removed, with 4 comment lines
    "CentroEPiaggio__kuka-lwr/03-215d3528": ({
        ("routine", "lwr_hw/krl/ros_position.src", "ros_control", "changed",
         (24, 25, 26, 29, 33, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47), ()),
    }, 4, 0),
    # a work position re-taught (X -60 -> 50, Y 0 -> 50, Z 0 -> -1.2; the others only re-written),
    # BASE_DATA[11] re-measured, STOPM_FLAG TRUE -> FALSE, four statement lines of TopSquare edited;
    # the DEFDAT renamed TopSquare -> TOPSQUARE (letter case only) and &PARAM lines are not changes
    "HugoDanielson__ChinaMilling/03-05d627c7": ({
        ("point", f"{TOP}.dat", "lfWorkPos[2]", "changed", (("X", 110.0), ("Y", 50.0), ("Z", -1.2)), ()),
        ("point", "R1/System/$config.dat", "BASE_DATA[11]", "changed",
         (("X", -17.2153), ("Y", 15.9075), ("Z", -13.4846)), ()),
        ("value", "R1/System/$config.dat", "STOPM_FLAG", "changed", True, False),
        ("routine", f"{TOP}.src", "TopSquare", "changed", (39, 88, 91, 94), (39, 88, 92, 95)),
    }, 0, 0),
    # three statements of the submit interpreter commented out
    "HugoDanielson__ChinaMilling/04-a291e98d": ({
        ("routine", "R1/System/sps.sub", "SPS", "changed", (44, 45, 46), ()),
    }, 4, 0),
    # six points with turn T 10 -> 2, nothing else
    "Yassate__KRL_Parser/03-54b44765": ({
        ("point", "codeRepo/testFiles/exampleKukaPath.dat", f"XHP0{n:02d}", "changed", (), (("T", (10, 2)),))
        for n in (5, 10, 15, 20, 25, 30)}, 0, 0),
    # two statements (and their comment) added to eki_hw_iface_send
    "ros-industrial__kuka_experimental/01-0f03b982": ({
        ("routine", "kuka_eki_hw_interface/krl/kuka_eki_hw_interface.src", "eki_hw_iface_send", "changed",
         (), (131, 132)),
    }, 1, 0),
    # RSI_CREATE's file name; the comment above it rewritten (2 lines -> 5)
    "wingljj__Kuka-RSI-real-time-control/01-78db3c8f": ({
        ("routine", "krc/PoseTrack.src", "PoseTrack", "changed", (61,), (64,)),
    }, 5, 0),
    # only the bytes changed (pure ASCII, CRLF): nothing a maintainer changed
    "wingljj__Kuka-RSI-real-time-control/02-fe5fa5d0": (set(), 49, 0),
    # a disclaimer comment added
    "RobotExMachina__Machina.NET/02-484c209c": (set(), 23, 0),
    # a variable removed from a data list; 4 comment lines; NUMPALLETS -> NumPallets and blank
    # lines are not changes
    "paulovictor237__KUKA-Paletizador/01-0f4b00f8": ({
        ("decl", "MainRoutune/Place/SetPlacePos_P1L1.dat", "", "MosaicoAtivo", "variable", "removed"),
    }, 4, 0),
    # action[1] (CHAR) becomes an INT action = -1, key[1] and temp_frame (a FRAME with a value) added;
    # the routine declares firstMove and reads the action with EKI_GetInt
    "LiorSkoury-git__Kuka_EthernetKrl_Python/01-a97e1b70": ({
        ("value", f"{LIOR}.dat", "action[1]", "removed", 0, None),
        ("value", f"{LIOR}.dat", "action", "added", None, -1),
        ("point", f"{LIOR}.dat", "temp_frame", "added", (), ()),
        ("decl", f"{LIOR}.dat", "", "action", "variable", "retyped"),
        ("decl", f"{LIOR}.dat", "", "key", "variable", "added"),
        ("decl", f"{LIOR}.dat", "", "temp_frame", "variable", "added"),
        ("decl", f"{LIOR}.src", "ethernetkrl_workshop", "firstMove", "variable", "added"),
        ("routine", f"{LIOR}.src", "ethernetkrl_workshop", "changed", ..., ...),    # most of its body
    }, None, 0),
    # a constant and its value removed from rsi_helper.dat
    "kroshu__kuka-external-control-sdk/03-39666274": ({
        ("value", "kuka_external_control_sdk/krc_setup/iiqka_os2/Program/RSI/rsi_helper.dat",
         "AXISCORRMON_NAME[]", "removed", '"AxisCorrMon_1"', None),
        ("decl", "kuka_external_control_sdk/krc_setup/iiqka_os2/Program/RSI/rsi_helper.dat", "",
         "AXISCORRMON_NAME", "constant", "removed"),
    }, 0, 0),
}


@pytest.mark.parametrize("pair", _by_repository(sorted(EXPECTED)))
def test_diff_reports_the_deltas_read_by_hand(shared_history, pair):
    entries, comments, not_compared = EXPECTED[pair]
    code, doc = run_diff(shared_history, pair)
    got = digest(doc)
    loose = {e for e in entries if ... in e}          # "..." stands for line lists not written out
    got = {e if (e[:4] + (..., ...)) not in loose else e[:4] + (..., ...) for e in got}
    assert got == entries
    if comments is not None:
        assert doc["comment_edits"] == comments
    assert len(doc["not_compared"]) == not_compared
    assert code == (1 if entries else 0)
