"""The project's BASIS checked once per process and shared (krl/basislayer.py,
interp/runtime/program.py ``shared_layer``): a program checked on the layer says what the same
program checked whole with its BASIS says (tests/interp/basis_layer_compare.py ``facts``), the
programs it cannot serve are checked whole (and would have meant something else on it), and
nothing of the layer is written by the checks and runs on it."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from interp.runtime import program as P
from interp.runtime.sizedcache import SizedCache
from krl.limits import MODEL_CACHE_BYTES
from krl.parsecache import load_project
from krl.semantics.resolve import NATIVE, ROUTINE

from .basis_layer_compare import checked_whole, facts
from .helpers import run_krl

REPO = Path(__file__).resolve().parents[2]
CASES = sorted(p for p in (REPO / "conformance" / "cases").iterdir() if p.is_dir())


@pytest.fixture(autouse=True)
def _own_cache(monkeypatch):
    """Each test checks its programs in a cache of checked workspaces of its own
    (interp/runtime/program.py ``_CACHE``; :func:`_layered` empties it of the program's folder
    to check it afresh): the process's is kept. Before, :func:`_layered` dropped a conformance
    case's workspace, with its models, from the process's cache, and the next test of the worker
    that ran the case built its model again (tests/vm/test_fast_paths.py ``test_quiet_steps_sweep``:
    12 of the 116 models built again by a worker of a whole make test, 2026-11-29, issue 87)."""
    monkeypatch.setattr(P, "_CACHE", SizedCache(MODEL_CACHE_BYTES))


def _layered(main: Path):
    """(workspace of checked_workspace, True when it was checked on the layer, the whole one);
    the program's folder checked afresh (in the test's own cache: :func:`_own_cache`)."""
    _main, project, extra = P.program_files(str(main), None, [])
    for k in P._CACHE.keys():
        if k[0] == str(project.root):
            P._CACHE.drop(k)
    before = P.LAYER_USES["layer"]
    ws = P.checked_workspace(project, extra)
    return ws, P.LAYER_USES["layer"] > before, checked_whole(project, extra)


def _assert_same(a, b) -> None:
    fa, fb = facts(a), facts(b)
    assert fa.keys() == fb.keys()
    for k in fa:
        assert fa[k] == fb[k], k


def _case_on_layer_equals_whole(case: Path) -> None:
    main = next(case.glob("*.src"))
    ws, on_layer, whole = _layered(main)
    assert on_layer            # no case has its own $config.dat, bas.src or a GLOBAL the BASIS names
    assert ws.layer is not None and [u.name for u in ws.units[:len(ws.layer.units)]] == \
        [u.name for u in ws.layer.units]
    _assert_same(ws, whole)


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=lambda p: p.name)
def test_every_conformance_case_on_the_layer_equals_it_checked_whole(case):
    """Every case (make nightly: 0.3-0.6 s of CPU each, the comparison of every annotation)."""
    _case_on_layer_equals_whole(case)


@pytest.mark.parametrize("case", CASES[::10], ids=lambda p: p.name)
def test_a_sample_of_conformance_cases_on_the_layer_equals_them_checked_whole(case):
    """Every tenth case in make test (the rest nightly, above)."""
    _case_on_layer_equals_whole(case)


def test_corpus_programs_and_example_folders_equal_checked_whole():
    mains = [REPO / "corpus" / "programs" / "loops.src", REPO / "examples" / "network" / "wait_global.src"]
    mains += sorted((REPO / "examples" / "scara").glob("*.src"))[:1]
    seen = 0
    for main in mains:
        ws, on_layer, whole = _layered(main)
        _assert_same(ws, whole)
        seen += on_layer
    assert seen >= 1


def _write(folder: Path, files: dict) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        (folder / name).write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
    return folder / next(n for n in files if n.endswith(".src"))


_USES_BASIS = {
    "prog.src": """
        DEF prog()
          DECL INT n
          BAS(#INITMOV, 0)
          n = shared_count + 1
          $OUT[3] = $IN[2]
          PTP_PARAMS(50)
          helper(n)
          $OV_PRO = 50
        END
        DEF PTP_PARAMS(v:IN)
          DECL REAL v
          $VEL_AXIS[1] = v
        END
        """,
    "prog.dat": """
        DEFDAT prog PUBLIC
          DECL GLOBAL INT shared_count = 2
          DECL GLOBAL REAL my_speed = 0.5
        ENDDAT
        """,
    "helper.src": """
        DEF helper(k:IN)
          DECL INT k
          shared_count = k + 1
          $VEL.CP = my_speed
          $TOOL = TOOL_DATA[1]
        END
        """,
}


def _natives_bas_calls() -> list[str]:
    layer = P.shared_layer(P.all_basis_files())
    unit = next(u for u in layer.units if u.name.upper() == "BAS")
    names = []
    for r in unit.routines:
        stack = list(r.body)
        while stack:
            x = stack.pop()
            ann = getattr(x, "ann", None)
            callee = getattr(ann, "callee", None)
            if callee is not None and callee.kind == NATIVE:
                names.append(callee.name.upper())
            for v in (getattr(x, f) for f in getattr(type(x), "__dataclass_fields__", {}) if f not in ("ann", "span")):
                stack.extend(v if isinstance(v, list) else [v])
    return sorted(set(names))


def _shapes() -> dict:
    native = _natives_bas_calls()[0]        # a built-in bas.src calls: a program's GLOBAL routine would take its calls
    return {
        "uses basis, globals of its own": (_USES_BASIS, ""),
        "a GLOBAL routine bas.src calls": ({
            "prog.src": "DEF prog()\n  BAS(#INITMOV, 0)\nEND\n",
            "lib.src": f"DEF lib()\nEND\nGLOBAL DEF {native}(x:IN)\n  DECL INT x\nEND\n"}, f"global {native}"),
        "a GLOBAL variable that repeats a $config.dat one": ({
            "prog.src": "DEF prog()\n  BAS(#INITMOV, 0)\nEND\n",
            "prog.dat": "DEFDAT prog PUBLIC\n  DECL GLOBAL INT DEF_VEL_PTP = 7\nENDDAT\n"}, "global DEF_VEL_PTP"),
        "a GLOBAL routine named as a bas.src local one": ({
            "prog.src": "DEF prog()\n  INITMOV()\nEND\nGLOBAL DEF INITMOV()\n  $OUT[1] = TRUE\nEND\n"}, "global INITMOV"),
        "its own $config.dat": ({
            "prog.src": "DEF prog()\n  my_flag = TRUE\n  BAS(#INITMOV, 0)\nEND\n",
            "$config.dat": "DEFDAT $CONFIG\n  DECL BOOL my_flag = FALSE\nENDDAT\n"}, "system data list $CONFIG"),
        "a syntax error": ({
            "prog.src": "DEF prog()\n  IF THEN\n  BAS(#INITMOV, 0)\nEND\n"}, "not parsed"),
    }


@pytest.mark.parametrize("shape", list(_shapes()))
def test_generated_shapes_on_the_layer_or_whole_equal_checked_whole(tmp_path, shape):
    files, refusal = _shapes()[shape]
    main = _write(tmp_path / "p", files)
    _m, project, extra = P.program_files(str(main), None, [])
    layer = P.shared_layer(extra)
    assert layer.refusal(load_project(project, str(project.root), None)) == refusal
    ws, on_layer, whole = _layered(main)
    assert on_layer == (refusal == "")
    assert (ws.layer is not None) == on_layer
    _assert_same(ws, whole)


def test_a_global_routine_bas_src_calls_changes_its_meaning_checked_whole(tmp_path):
    """Why the layer refuses such a program: checked whole, bas.src's call of the built-in goes
    to the program's routine; on the layer it would still go to the built-in."""
    native = _natives_bas_calls()[0]
    main = _write(tmp_path / "p", _shapes()["a GLOBAL routine bas.src calls"][0])
    _m, project, extra = P.program_files(str(main), None, [])
    whole = checked_whole(project, extra)
    layer = P.shared_layer(extra)

    def callees(ws, unit_name):
        unit = next(u for u in ws.units if u.name.upper() == unit_name)
        out = []
        for r in unit.routines:
            stack = list(r.body)
            while stack:
                x = stack.pop()
                c = getattr(getattr(x, "ann", None), "callee", None)
                if c is not None and c.name.upper() == native:
                    out.append(c.kind)
                for f in getattr(type(x), "__dataclass_fields__", {}):
                    if f not in ("ann", "span"):
                        v = getattr(x, f)
                        stack.extend(v if isinstance(v, list) else [v])
        return out

    assert callees(whole, "BAS") and set(callees(whole, "BAS")) == {ROUTINE}
    assert set(callees(layer.workspace, "BAS")) == {NATIVE}


def test_own_bas_src_is_checked_whole(tmp_path):
    main = _write(tmp_path / "p", {"prog.src": "DEF prog()\n  BAS(#INITMOV, 0)\nEND\n",
                                   "bas.src": "DEF BAS(c:IN, v:IN)\n  DECL INT c, v\nEND\n"})
    _m, _project, extra = P.program_files(str(main), None, [])
    assert P.shared_layer(extra) is None
    ws, on_layer, whole = _layered(main)
    assert not on_layer and ws.layer is None
    _assert_same(ws, whole)


def test_one_layer_per_process_for_the_same_basis():
    extra = P.all_basis_files()
    assert P.shared_layer(extra) is P.shared_layer(list(extra))
    assert P.shared_layer(extra[:-1]) is None


# ---------------------------------------------------------------------- the layer is never written

_SCALARS = (str, int, float, bool, bytes, type(None))


def _fingerprint(root) -> dict:
    """Every object reachable from `root` (fields, slots, items; not functions, classes or
    modules): id -> (type, its scalars and the ids of what it holds). Equal fingerprints: no
    object changed, none was added or dropped."""
    out: dict = {}
    keep = []
    stack = [root]
    while stack:
        x = stack.pop()
        if isinstance(x, _SCALARS) or id(x) in out or callable(x) and not hasattr(x, "__dataclass_fields__") \
                or type(x).__module__ in ("builtins",) and not isinstance(x, (list, tuple, dict, set, frozenset)):
            continue
        keep.append(x)
        if isinstance(x, dict):
            parts = [v for kv in x.items() for v in kv]
        elif isinstance(x, (list, tuple)):
            parts = list(x)
        elif isinstance(x, (set, frozenset)):
            parts = sorted(x, key=lambda v: (type(v).__name__, v if isinstance(v, _SCALARS) else id(v)))
        else:
            names = [n for c in type(x).__mro__ for n in getattr(c, "__slots__", ()) if n != "__weakref__"]
            names += list(getattr(x, "__dict__", {}))
            parts = [getattr(x, n, None) for n in names]
        out[id(x)] = (type(x).__name__, tuple(p if isinstance(p, _SCALARS) else ("@", id(p)) for p in parts))
        stack.extend(p for p in parts if not isinstance(p, _SCALARS))
    out["keep"] = ("", (len(keep),))
    return out


def test_the_shared_layer_is_never_written_by_checks_and_runs(tmp_path):
    layer = P.shared_layer(P.all_basis_files())
    before = _fingerprint(layer)
    assert len(before) > 5000            # its ASTs, annotations, scopes and places
    for i, case in enumerate(CASES[:12]):
        ws, on_layer, _whole = _layered(next(case.glob("*.src")))
        assert on_layer and ws.layer is layer
    main = _write(tmp_path / "p", _USES_BASIS)
    ws, on_layer, _whole = _layered(main)
    assert on_layer
    for interp in ("tree", "vm"):
        r = run_krl(tmp_path / interp, "DEF prog()\n  DECL INT n\n  BAS(#INITMOV, 0)\n  n = 3\n"
                    "  $OUT[2] = n == 3\n  PTP {A1 10}\nEND\n", interp=interp, max_sim_time=5.0)
        assert r.rt.program.module("prog") is not None
        assert any(m.name == "BAS" for m in r.rt.program.modules)
    assert _fingerprint(layer) == before
