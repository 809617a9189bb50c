"""The loaded programs a process keeps (issue 87: "make test and the variants sweep load each
backup's model once"): interp/runtime/program.py ``checked_workspace`` keeps the checked
workspaces within krl/limits.py ``MODEL_CACHE_BYTES`` of estimated memory in a segmented LRU
(interp/runtime/sizedcache.py), interp/runtime/model.py ``load_model`` one model per robot with
each workspace.

Seen failing first: with the plain LRU of 8 workspaces and 8 models before, a backup's
workspace run again after ten other programs was loaded and checked again (the suite's profile:
the palletizer backup's model built up to 4 times by one worker, conformance case 001's up to 10
times)."""

from __future__ import annotations

import gc
import os
import weakref

import pytest

from interp import run as run_mod
from interp.run import make_runtime, run_spec
from interp.runtime import model as M
from interp.runtime import program as P
from interp.runtime.program import BASIS_DIR
from interp.runtime.sizedcache import PROTECTED_SHARE, SizedCache
from krl import files
from krl.limits import MODEL_BASE_BYTES, MODEL_BYTES_PER_SOURCE_BYTE, MODEL_CACHE_BYTES, WORKSPACE_BASE_BYTES
from robot.machine import load_machine
from robot.mada import load_robot
from robot.machine import DEFAULT_MACHINE_FILE

from .helpers import write

INTERPS = ("tree", "vm")
ROBOT_DATA = DEFAULT_MACHINE_FILE.parent

SRC = """
DEF prog()
  count = count + 1
  $OUT[3] = TRUE
END
"""
DAT = """
DEFDAT prog PUBLIC
  DECL GLOBAL INT count=4
ENDDAT
"""


def _folder(tmp_path, name: str):
    write(tmp_path / name, "prog.dat", DAT)
    return write(tmp_path / name, "prog.src", SRC)


def _loads(counter, prog) -> int:
    """How often `counter` (program.py WS_LOADS by folder, model.py LOADS by folder and robot)
    counts the folder of `prog`."""
    folder = str(prog.parent)
    return sum(n for k, n in counter.items() if k == folder or k.startswith(f"{folder} on "))


@pytest.mark.parametrize("interp", INTERPS)
def test_the_runs_of_one_folder_build_one_model(tmp_path, interp):
    """Runs of one program's files with other options (the interpreter, the check, the limits,
    the override) load and check the files once and build one model; another robot (the
    library's KR 180 R3200 PA, a `--robot`) builds a second model on the same checked files."""
    prog = _folder(tmp_path, "a")
    ws0, m0 = _loads(P.WS_LOADS, prog), _loads(M.LOADS, prog)
    other = "vm" if interp == "tree" else "tree"
    specs = [run_spec(prog, mujoco=False, interp=interp, max_sim_time=2.0),
             run_spec(prog, mujoco=False, interp=other, check=False),
             run_spec(prog, mujoco=False, interp=interp, max_steps=50, override=30)]
    runs = [make_runtime(s)[0] for s in specs]
    assert len({id(rt.model) for rt in runs}) == 1
    for rt in runs:      # each run starts from the DECL value and writes its own copy
        assert rt.run().reason == "completed" and rt.program.module("prog").data["COUNT"].get() == 5
    assert (_loads(P.WS_LOADS, prog) - ws0, _loads(M.LOADS, prog) - m0) == (1, 1)
    pa = load_robot("kr180_r3200_pa")
    assert pa is not load_machine() and pa.name != load_machine().name
    rt = make_runtime(specs[0].with_(robot=pa))[0]
    assert rt.model is not runs[0].model and rt.machine is pa
    assert (_loads(P.WS_LOADS, prog) - ws0, _loads(M.LOADS, prog) - m0) == (1, 2)
    assert M.LOADS[f"{prog.parent} on {pa.name}"] == 1
    assert make_runtime(specs[1].with_(robot=pa))[0].model is rt.model


# a $config.dat naming its robot in MACHINE_DEF[1] (KUKA's MACHINE_DEF_T, as
# tests/robot/test_named_robot.py writes it), lying flat beside the program (issue 85 item 6)
CONFIG = """DEFDAT  $CONFIG
STRUC MACHINE_DEF_T CHAR NAME[24],INT COOP_KRC_INDEX,CHAR PARENT[24],FRAME ROOT,ESYS MECH_TYPE,CHAR GEOMETRY[255]
DECL MACHINE_DEF_T MACHINE_DEF[16]
MACHINE_DEF[1]={NAME[] "%s",COOP_KRC_INDEX 1,PARENT[] "WORLD",ROOT {X 0.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0},MECH_TYPE #ROBOT,GEOMETRY[] " "}
ENDDAT
"""


@pytest.mark.parametrize("named", ["KR 10 R1420", "KR 10 R1440-2"])
def test_the_runs_of_a_folder_naming_its_robot_build_one_model(tmp_path, named):
    """A folder whose $config.dat names its robot (a model of the catalogue, and one of neither
    catalogue nor library: the KR 6 R900 stands in) drives the same robot at every run, so its
    runs share one model (each run built a robot and a model of its own: the variants sweep's
    flat MACHINE_DEF variant built 40 models for 40 runs)."""
    write(tmp_path, "$config.dat", CONFIG % named)
    prog = write(tmp_path, "cell.src", "DEF cell()\n  $OUT[1] = TRUE\nEND\n")
    m0 = _loads(M.LOADS, prog)
    runs = [make_runtime(run_spec(prog, mujoco=False, interp=i, max_sim_time=1.0))[0] for i in INTERPS]
    assert runs[0].machine is runs[1].machine and runs[0].model is runs[1].model
    assert runs[0].machine.named.startswith(f"{named}, the robot the backup names")
    assert _loads(M.LOADS, prog) - m0 == 1


def test_a_robot_held_by_a_cached_model_is_found_again_past_many_machine_data(tmp_path):
    """A folder run on the robot of a ``$machine.dat`` (``--robot``) builds its model once, also
    when more machine data files than the robot loader keeps (16, robot/heldcache.py) were read
    between its runs: the loader gives the robot the model holds, not a new one (cleared past 16
    before, it made a new robot, and a model is keyed by its robot: the suite's workers built
    ChinaMilling's and kukaKRLmagic's models twice). A robot nothing holds any more is read again."""
    prog = _folder(tmp_path, "a")
    dat = (ROBOT_DATA / "kr3_r540.dat").read_text(encoding="utf-8")
    mada = write(tmp_path / "mada", "$machine.dat", dat)
    m0 = _loads(M.LOADS, prog)
    first = make_runtime(run_spec(prog, mujoco=False, robot=mada))[0]
    for k in range(20):                             # other machine data files, each read once
        load_robot(write(tmp_path / f"other{k}", "$machine.dat", dat))
    again = make_runtime(run_spec(prog, mujoco=False, robot=mada))[0]
    assert again.machine is first.machine and again.model is first.model
    assert _loads(M.LOADS, prog) - m0 == 1
    alone = weakref.ref(load_robot(write(tmp_path / "alone", "$machine.dat", dat)))
    for k in range(20, 40):
        load_robot(write(tmp_path / f"other{k}", "$machine.dat", dat))
    gc.collect()
    assert alone() is None and first.machine is load_robot(mada)


def test_a_folder_run_again_is_kept_past_many_run_once(tmp_path, monkeypatch):
    """A program's checked files asked for again after another program's stay while twelve
    programs loaded once each (each a folder of its own, as a test's or a variant's) pass
    through a cache that holds five of them: the last run loads nothing, the first of the others
    is loaded again (the LRU of 8 before loaded the kept one again; a first run's model build
    that asked the cache twice protected every folder). Asked for again at once (the runs of
    one program in turn) they are not protected: past the stream they are loaded again."""
    keep, quick = _folder(tmp_path, "kept"), _folder(tmp_path, "quick")
    spec, quick_spec = (run_spec(p, mujoco=False).with_(robot=load_machine()) for p in (keep, quick))
    monkeypatch.setattr(P, "_CACHE", SizedCache(MODEL_CACHE_BYTES))
    M.load_model(spec)
    cost = P._CACHE.used                            # its files', its workspace's and its model's
    monkeypatch.setattr(P, "_CACHE", SizedCache(int(cost * 5.5)))
    first = M.load_model(spec)
    assert M.load_model(spec) is first
    once = []

    def load_once(k):
        once.append(write(tmp_path / f"once{k}", "once.src", f"DEF once()\n  $OUT[{k + 1}] = TRUE\nEND\n"))
        M.load_model(run_spec(once[-1], mujoco=False).with_(robot=load_machine()))
        assert P._CACHE.used <= P._CACHE.budget
    load_once(0)
    assert M.load_model(spec) is first              # asked for after another: protected
    quick_model = M.load_model(quick_spec)
    assert M.load_model(quick_spec) is quick_model  # asked for at once: on probation
    loaded, quick_loaded = _loads(P.WS_LOADS, keep), _loads(P.WS_LOADS, quick)
    for k in range(1, 13):
        load_once(k)
    assert M.load_model(spec) is first and _loads(P.WS_LOADS, keep) == loaded
    M.load_model(quick_spec)
    assert _loads(P.WS_LOADS, quick) == quick_loaded + 1
    again = _loads(P.WS_LOADS, once[1])
    M.load_model(run_spec(once[1], mujoco=False).with_(robot=load_machine()))
    assert _loads(P.WS_LOADS, once[1]) == again + 1


def test_the_programs_of_a_folder_leave_the_cache_when_it_is_forgotten(tmp_path, monkeypatch):
    """``forget_below(folder)`` (what tests/conftest.py does with a test's own tmp_path at its
    end) drops the checked workspaces at and below the folder, with their models, and keeps the
    others, also one in a folder whose name starts with the forgotten one's: a run of the
    dropped folder loads its files again, a run of a kept one loads nothing."""
    monkeypatch.setattr(P, "_CACHE", SizedCache(MODEL_CACHE_BYTES))
    own = [_folder(tmp_path / "own", "a"), _folder(tmp_path / "own" / "b", "c")]
    kept = [_folder(tmp_path, "own2"), _folder(tmp_path, "other")]
    specs = {p: run_spec(p, mujoco=False).with_(robot=load_machine()) for p in own + kept}
    models = {p: M.load_model(s) for p, s in specs.items()}
    before = {p: _loads(P.WS_LOADS, p) for p in specs}
    assert P.forget_below(tmp_path / "own") == 2
    assert len(P._CACHE) == 2
    for p in kept:
        assert M.load_model(specs[p]) is models[p] and _loads(P.WS_LOADS, p) == before[p]
    for p in own:
        assert M.load_model(specs[p]) is not models[p] and _loads(P.WS_LOADS, p) == before[p] + 1
    assert P.forget_below(tmp_path / "elsewhere") == 0 and len(P._CACHE) == 4


def test_the_cache_keeps_within_its_budget():
    """SizedCache (a segmented LRU): the estimated bytes held never pass the budget; a new
    entry goes first when nothing was asked for twice; an entry asked for again is protected
    and outlives a stream of new ones; the protected part holds at most PROTECTED_SHARE of the
    budget; an entry larger than the budget is kept alone."""
    c = SizedCache(100)
    for k in range(5):
        c.put(k, f"v{k}", 30)
        assert c.used <= 100
    assert c.keys() == [2, 3, 4]               # the oldest went first
    assert c.get(2) == "v2" and c.get(0) is None
    for k in range(10, 20):                   # a stream of entries used once
        c.put(k, k, 30)
        assert c.used <= 100
    assert c.get(2) == "v2" and c.keys() == [18, 19, 2]
    for k in (18, 19):                         # three protected: 90 > 80, the oldest demoted
        c.get(k)
    assert PROTECTED_SHARE * 100 < 90 and c.keys() == [2, 18, 19] and c.used == 90
    c.put("big", "B", 500)
    assert c.keys() == ["big"] and c.used == 500
    c.put("next", "n", 10)
    assert c.keys() == ["next"]
    c.drop("next")
    assert len(c) == 0 and c.used == 0


def test_an_entry_asked_for_again_at_once_is_not_protected():
    """SizedCache: asked for again while it is the last key asked for or put (the runs of one
    program one after the other), an entry stays on probation and goes before the entries asked
    for again after others; two entries asked for in turn are both protected and outlive a
    stream of new ones."""
    c = SizedCache(100)
    c.put("case", 1, 20)
    assert c.get("case") == 1 and c.get("case") == 1       # tree, VM: correlated
    c.put("backup", 2, 30)
    c.put("partner", 3, 20)
    assert c.get("backup") == 2 and c.get("partner") == 3   # each asked for after another
    assert c.keys() == ["case", "backup", "partner"]        # probation, then protected
    for k in range(3):
        c.put(k, k, 20)
    assert c.keys() == [1, 2, "backup", "partner"]         # the case went first, then 0
    assert c.get("case") is None and c.get("backup") == 2 and c.get("partner") == 3
    c.put("x", 4, 10)
    assert c.get("x") == 4 and c.get("x") == 4 and c.keys()[-2:] == ["backup", "partner"]
    c.clear()
    c.put("x", 4, 10)
    assert c.get("y") is None and c.get("x") == 4 and c.keys() == ["x"] and c._protected == {"x": (4, 10)}


def test_the_budget_is_what_the_limits_say():
    """The process's cache is bounded by krl/limits.py's documented figures (docs/security.md):
    192 MiB; a workspace is charged its files' bytes times MODEL_BYTES_PER_SOURCE_BYTE (64),
    128 KiB more, and 512 KiB for each model built on it."""
    assert P._CACHE.budget == MODEL_CACHE_BYTES == 192 * 1024 * 1024
    assert MODEL_BYTES_PER_SOURCE_BYTE == 64
    assert (WORKSPACE_BASE_BYTES, MODEL_BASE_BYTES) == (128 * 1024, 512 * 1024)


def _charge(paths, models: int) -> int:
    """What krl/limits.py says a workspace of the files `paths` with `models` models is charged."""
    return sum(os.path.getsize(p) for p in paths) * MODEL_BYTES_PER_SOURCE_BYTE + WORKSPACE_BASE_BYTES \
        + models * MODEL_BASE_BYTES


def test_a_program_on_the_basis_layer_is_charged_its_own_files_and_its_models(tmp_path, monkeypatch):
    """A workspace checked on the process's BASIS layer is charged its own files only (the
    layer holds the BASIS once for every program on it), and each model built on it adds one
    model's charge (a second robot: two); a folder with its own bas.src, checked whole with the
    BASIS's other files, is charged all of them. Before, a program on the layer was charged its
    33 kB of BASIS files too, 2.1 MB, about five times what it holds (krl/limits.py)."""
    monkeypatch.setattr(P, "_CACHE", SizedCache(MODEL_CACHE_BYTES))
    prog = _folder(tmp_path, "a")
    spec = run_spec(prog, mujoco=False).with_(robot=load_machine())
    model = M.load_model(spec)
    assert model.program.ws.layer is not None
    own = [prog, prog.with_suffix(".dat")]
    assert P._CACHE.used == _charge(own, 1)
    M.load_model(spec.with_(robot=load_robot("kr180_r3200_pa")))
    assert P._CACHE.used == _charge(own, 2)
    M.load_model(spec)                              # the first robot's again: no new model
    assert P._CACHE.used == _charge(own, 2)
    whole = write(tmp_path / "b", "prog.src", "DEF prog()\n  BAS(#INITMOV, 0)\nEND\n")
    write(tmp_path / "b", "bas.src", "DEF BAS(c:IN, v:IN)\n  DECL INT c, v\nEND\n")
    model = M.load_model(run_spec(whole, mujoco=False).with_(robot=load_machine()))
    assert model.program.ws.layer is None
    _m, project, extra = P.program_files(str(whole), None, [])
    assert len(extra) == len(P.all_basis_files()) - 1          # the BASIS's but its bas.src
    assert P._CACHE.used == _charge(own, 2) + _charge([*project.files, *extra], 1)


def test_a_folder_run_by_two_programs_stays_past_programs_on_the_layer(tmp_path, monkeypatch):
    """The sequence that built ChinaMilling's model twice in one worker of a whole make test,
    small: a folder run by two of its programs in turn (asked for at once: on probation), then
    twelve small programs on the BASIS layer run once each, then the folder again. Charged their
    own files, the twelve (about 0.65 MiB each) leave the folder (about 2 MiB) in a cache of
    12 MiB: it is loaded and its model built once. Charged their BASIS files too (2.1 MB each
    before), they pushed it out and it was built twice."""
    monkeypatch.setattr(P, "_CACHE", SizedCache(12 * 1024 * 1024))
    folder = tmp_path / "backup"
    decls = "".join(f"  DECL GLOBAL INT value_{k}={k}\n" for k in range(800))
    write(folder, "shared.dat", f"DEFDAT shared PUBLIC\n{decls}ENDDAT\n")
    progs = [write(folder, f"p{k}.src", f"DEF p{k}()\n  value_{k} = value_{k} + 1\nEND\n") for k in (1, 2)]
    assert 20_000 < sum(os.path.getsize(f) for f in folder.iterdir()) < 30_000
    robot = load_machine()
    first = [M.load_model(run_spec(p, mujoco=False).with_(robot=robot)) for p in progs]
    assert first[0] is first[1]
    for k in range(12):
        once = write(tmp_path / f"once{k}", "once.src", f"DEF once()\n  $OUT[{k + 1}] = TRUE\nEND\n")
        M.load_model(run_spec(once, mujoco=False).with_(robot=robot))
        assert P._CACHE.used <= P._CACHE.budget
    assert M.load_model(run_spec(progs[0], mujoco=False).with_(robot=robot)) is first[0]
    assert (_loads(P.WS_LOADS, progs[0]), _loads(M.LOADS, progs[0])) == (1, 1)


def test_a_recharged_entry_keeps_its_place_and_the_budget():
    """SizedCache.recost (a workspace's models charged after it was put): the entry's charge
    changes in its place; past the budget the others go, least recent first, never the entry
    itself; a key not held changes nothing."""
    c = SizedCache(100)
    for k in ("a", "b", "c"):
        c.put(k, k, 20)
    c.recost("a", 30)
    assert c.keys() == ["a", "b", "c"] and c.used == 70
    c.recost("a", 75)
    assert c.keys() == ["a", "c"] and c.used == 95      # b, the least recent but a, went
    c.recost("missing", 50)
    assert c.keys() == ["a", "c"] and c.used == 95
    c.recost("a", 200)                                  # larger than the budget: kept alone
    assert c.keys() == ["a"] and c.used == 200


@pytest.mark.parametrize("interp", INTERPS)
def test_a_file_changed_between_two_runs_is_seen_by_the_second(tmp_path, interp):
    """The model a run starts from is keyed by its files (interp/runtime/program.py
    ``checked_workspace``: path, size, modification time): a data list edited right after a run
    (the same size: ``count=4`` to ``count=7``) and a module added beside the program, with the
    program edited to call it, are what the next run of the same process runs (a new model),
    and a third run with nothing changed starts from that model again."""
    prog = _folder(tmp_path, "a")
    first = make_runtime(run_spec(prog, mujoco=False, interp=interp))[0]
    assert first.run().reason == "completed" and first.program.module("prog").data["COUNT"].get() == 5
    assert first.program.module("helper") is None
    dat = prog.with_suffix(".dat")
    before = dat.stat().st_size
    dat.write_text(dat.read_text(encoding="utf-8").replace("count=4", "count=7"), encoding="utf-8")
    assert dat.stat().st_size == before
    write(tmp_path / "a", "helper.src", "GLOBAL DEF helper()\n  $OUT[5] = TRUE\nEND\n")
    prog.write_text(SRC.replace("$OUT[3] = TRUE", "$OUT[3] = TRUE\n  helper()"), encoding="utf-8")
    second = make_runtime(run_spec(prog, mujoco=False, interp=interp))[0]
    assert second.model is not first.model
    assert second.run().reason == "completed"
    assert second.program.module("prog").data["COUNT"].get() == 8
    assert second.program.module("helper") is not None and second.controller.io.get_out(5) is True
    assert make_runtime(run_spec(prog, mujoco=False, interp=interp))[0].model is second.model


def test_a_folder_made_a_backup_between_two_runs_is_seen_by_the_second(tmp_path, monkeypatch):
    """Whether a program lies in a KRC backup is asked of every folder above it at each run's
    start (krl/project.py ``backup_of``); krl/files.py ``child`` keeps a folder's listing while
    the folder's times are those it was listed with. Here every listing is kept at once (as if
    each folder had been still long enough: ``_settled``): a ``System/$config.dat`` written
    into the program's folder after a first run still makes the second run's folder a backup,
    and its ``$config.dat`` the one the run loads; removed again, the third run's is not."""
    monkeypatch.setattr(files, "_LISTINGS", {})
    monkeypatch.setattr(files, "_settled", lambda st, listed_at: True)
    prog = _folder(tmp_path, "cell")
    spec = run_spec(prog, mujoco=False).with_(robot=load_machine())
    first = make_runtime(spec)[0]
    assert not first.program.backup and str(tmp_path / "cell") in files._LISTINGS
    config = write(tmp_path / "cell" / "System", "$config.dat", (BASIS_DIR / "$config.dat").read_text(encoding="utf-8"))
    second = make_runtime(spec)[0]
    assert second.program.backup and second.program.workspace == tmp_path / "cell"
    assert second.program.system_dir == config.parent
    config.unlink()
    config.parent.rmdir()
    third = make_runtime(spec)[0]
    assert not third.program.backup


XHOME_CONFIG = """
DEFDAT $CONFIG
  DECL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 30.0,A6 0.0}
ENDDAT
"""


def test_a_start_position_is_solved_once_per_robot_and_points(tmp_path, monkeypatch):
    """Where a run of ``--inputs auto`` starts (the backup's XHOME: interp/run.py ``plan_cell``)
    is solved once per checked workspace, robot, mode and values of the points it reads, and
    each run gets its own array with the same values: a second run of the same program solves
    nothing; another program of the backup with an XHOME of its own (its data list's), or
    another robot, solves its own; the first program's start is kept beside them."""
    write(tmp_path, "R1/System/$config.dat", XHOME_CONFIG)
    prog = write(tmp_path, "R1/Program/prog.src", "DEF prog()\n  $OUT[1] = TRUE\nEND\n")
    other = write(tmp_path, "R1/Program/other.src", "DEF other()\n  $OUT[2] = TRUE\nEND\n")
    write(tmp_path, "R1/Program/other.dat",
          "DEFDAT other\n  DECL E6AXIS XHOME={A1 20.0,A2 -80.0,A3 85.0,A4 0.0,A5 25.0,A6 0.0}\nENDDAT\n")
    solved = []
    real = run_mod.start_axes

    def counting(*args):
        solved.append(args[-1])
        return real(*args)
    monkeypatch.setattr(run_mod, "start_axes", counting)

    def start(program, robot):
        spec = run_spec(program, inputs="auto", mujoco=False, robot=robot)
        return run_mod.plan_cell(run_mod.load_program(spec), spec).start_axes
    kr6, pa = load_machine(), load_robot("kr180_r3200_pa")
    first, second = start(prog, kr6), start(prog, kr6)
    assert list(first) == [0.0, -90.0, 90.0, 0.0, 30.0, 0.0] and first is not second
    assert list(second) == list(first) and len(solved) == 1
    first[0] = 45.0                                 # a run's array is its own
    assert start(prog, kr6)[0] == 0.0 and len(solved) == 1
    assert list(start(other, kr6)) == [20.0, -80.0, 85.0, 0.0, 25.0, 0.0] and len(solved) == 2
    assert start(other, kr6)[0] == 20.0 and len(solved) == 2
    start(prog, pa)
    assert len(solved) == 3 and start(prog, kr6)[0] == 0.0 and len(solved) == 3
