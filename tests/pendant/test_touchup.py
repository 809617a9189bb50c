"""Touch-up writes the data list as the pendant does (issue 36): only the point's numbers change,
in the file's own encoding and line ends, atomically; checked on the first Cartesian and the first
axis point of the corpus's data lists (copies in a temporary folder: make test one data list of
each repository, make nightly every one under 200 KB), and through the page in T1."""

from __future__ import annotations

import shutil

import pytest

from krl.source import decode_bytes
from pendant.touchup import CARTESIAN, TouchUpError, touch_up
from robot.datalist import DataListError, read_data_list
from tests.chromium import POLL_MS
from tests.pendant.harness import browser_page, pendant_server, select, wait_state

POS = {"X": 1234.5678, "Y": -98.7654, "Z": 1500.25, "A": -179.5, "B": 12.125, "C": 90.0, "S": 6, "T": 27}
AXES = [10.5, -90.25, 100.0, 0.0, 45.5, -12.75]


def _points(values) -> tuple[str | None, str | None]:
    cart = axis = None
    for name, dv in values.items():
        v = dv.value
        if isinstance(v, dict) and {"X", "Y", "Z"} <= set(v) and cart is None:
            cart = name
        elif isinstance(v, dict) and {"A1", "A2", "A3"} <= set(v) and "X" not in v and axis is None:
            axis = name
    return cart, axis


def _declares_points(upper: bytes) -> bool:
    return b"AXIS " in upper or b"POS " in upper


def _readable(paths: list, n: int | None):
    """The first `n` (None: all) of `paths` that read as data lists declaring a point, with their values."""
    out = []
    for dat in paths:
        try:
            values = read_data_list(dat)
        except DataListError:
            continue
        if _points(values) != (None, None):
            out.append((dat, values))
        if len(out) == n:
            break
    return out


@pytest.mark.parametrize("per_repository", [1, pytest.param(None, marks=pytest.mark.slow)], ids=["first", "all"])
def test_touch_up_every_corpus_data_list(shared_corpus, tmp_path, per_repository):
    """``make test`` touches up the points of the first data list (in path order) of each repository of
    the corpus that reads and declares a point (13 repositories: every writer's style, KSS 8 backups
    and flat exports alike, rawpython's $machine.dat among them, whose points are refused: not on
    their declaration line); make nightly those of every data list under 200 KB (the same check on
    each: only the count differs). Points touched up today (2026-11-29): 8 and 76. The sweep read
    each data list's bytes twice and, by a misplaced ``or``, took files over 200 KB (KUKA-Script's
    My_Job.dat, 253 KB: the largest parse of the sweep)."""
    done = 0
    candidates = [p for p in sorted(shared_corpus.rglob("*.dat"))
                  if p.stat().st_size < 200_000 and _declares_points(p.read_bytes().upper())]
    repos = {}
    for p in candidates:
        repos.setdefault(p.relative_to(shared_corpus).parts[0], []).append(p)
    for dat, values in [d for ps in repos.values() for d in _readable(ps, per_repository)]:
        for name in _points(values):
            if name is None:
                continue
            copy = tmp_path / f"{done}.dat"
            shutil.copyfile(dat, copy)
            before = copy.read_bytes()
            try:
                new = touch_up(copy, name, POS, AXES)
            except TouchUpError as exc:
                assert "not on its declaration line" in str(exc) or "does not end on its line" in str(exc), exc
                assert copy.read_bytes() == before          # refused: nothing written
                continue
            after = copy.read_bytes()
            (t0, e0), (t1, e1) = decode_bytes(before), decode_bytes(after)
            assert e1 == e0 or {e0, e1} <= {"ascii", "utf-8"}, (dat, e0, e1)
            l0, l1 = t0.splitlines(keepends=True), t1.splitlines(keepends=True)
            line = values[name].line
            assert len(l0) == len(l1)
            assert [a for i, a in enumerate(l0) if i != line - 1] == [b for i, b in enumerate(l1) if i != line - 1]
            assert l0[line - 1][-2:] == l1[line - 1][-2:]   # its line end kept (CRLF stays CRLF)
            got = read_data_list(copy)[name].value
            for k, v in new.items():
                assert abs(float(got[k]) - float(v)) < 1e-6, (dat, name, k)
            for k in set(got) - set(new):
                assert got[k] == values[name].value[k]          # the components not touched up
            if set(new) & set(CARTESIAN):
                assert abs(got["X"] - POS["X"]) < 1e-6
            done += 1
    assert done >= (8 if per_repository else 70), f"only {done} points touched up in the corpus"


def test_touch_up_from_the_page_in_t1(pw, tmp_path):
    ws = tmp_path / "cell"
    ws.mkdir()
    (ws / "prog.src").write_text("DEF prog()\r\n  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}\r\n  PTP XP1\r\nEND\r\n",
                                 encoding="cp1252")
    dat = ws / "prog.dat"
    dat.write_bytes("DEFDAT prog\r\n; Schweißpunkt\r\nDECL E6POS XP1={X 900.0,Y 0.0,Z 1200.0,A 0.0,B 90.0,C 0.0,"
                    "S 2,T 0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}\r\nENDDAT\r\n".encode("cp1252"))
    with pendant_server(ws, "--no-realtime") as url, browser_page(pw, url) as page:
        select(page, "prog.src", run_mode="MSTEP", mode="T1")
        page.click("#start")
        s = wait_state(page, "s.state == 'stopped' && s.stop && s.stop.reason == 'step'")
        page.fill("#touchup-name", "XP1")
        page.click("#touchup")
        page.wait_for_function("() => window.pendant.module && window.pendant.module.points.some("
                               "p => p.name == 'XP1' && Math.abs(p.frame[2] - 1200) > 1)", polling=POLL_MS)
        pos = s["position"]["pos"]
    raw = dat.read_bytes()
    assert "Schweißpunkt".encode("cp1252") in raw and b"\r\n" in raw and raw.count(b"\n") == raw.count(b"\r\n")
    got = read_data_list(dat)["XP1"].value
    for k in ("X", "Y", "Z", "A", "B", "C"):
        assert abs(got[k] - pos[k]) < 1e-3, k
    assert got["E1"] == 0.0
