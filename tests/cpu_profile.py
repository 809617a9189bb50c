"""Where the suite's CPU goes: a pytest plugin that records, per test and per fixture, the CPU
time of the process that runs it (an xdist worker, or the one process of ``-n 0``).

Off unless ``KRL_TEST_CPU=<stem>`` is set (tests/conftest.py registers it then). Each process
appends one JSON line per test and per costly fixture to ``<stem>.<worker>.jsonl`` as it goes (a
run still going can be read); ``python -m tests.cpu_profile <stem>`` merges them and prints the
tests, files and fixtures that take most. Figures (seconds):

- ``self``: the worker's own user+sys CPU (``resource.getrusage(RUSAGE_SELF)``) over the test's
  setup, call and teardown;
- ``children``: the user+sys CPU of the processes the test started and waited for
  (``RUSAGE_CHILDREN``; a process kept by a session fixture counts where it is reaped, a Dask
  cluster's workers at the teardown of the last test that used it; a process reaped by another,
  such as Chromium's renderers, counts nowhere: docs/architecture.md, "The test suite", on the
  cgroup's figures);
- ``wall``, ``start`` (seconds since the worker started) and the worker's id, for the schedule's
  tail;
- per worker at its end, how often it built each folder's program model on each robot
  (interp/runtime/model.py ``LOADS``: ``"<folder> on <robot>"``) and each folder's checked
  workspace (interp/runtime/program.py ``WS_LOADS``); read only where a test imported those
  modules; and per test the models (``loads``) and checked workspaces (``checked``) it built,
  from which the report lists the tests that built a model (a folder's on a robot) or a checked
  workspace its worker had built before;
- per fixture (``pytest_fixture_setup``): the setup's CPU, inclusive of the fixtures it requests
  that were made for it, with its scope; and per worker the CPU spent before the first test
  (start-up, imports and collection).
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
from collections import defaultdict
from pathlib import Path

import pytest


def _cpu() -> tuple[float, float]:
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime, kids.ru_utime + kids.ru_stime


def _loads() -> tuple[dict, dict]:
    """(the models, the checked workspaces) this process built so far (by folder and robot, by folder)
    (interp/runtime/model.py ``LOADS``, interp/runtime/program.py ``WS_LOADS``; read, never
    imported here: empty before a test imports them)."""
    model, program = sys.modules.get("interp.runtime.model"), sys.modules.get("interp.runtime.program")
    return (dict(model.LOADS) if model is not None else {}), (dict(program.WS_LOADS) if program is not None else {})


class CpuProfile:
    """The plugin; ``out`` is the JSON file's stem (``KRL_TEST_CPU``)."""

    def __init__(self, out: str) -> None:
        self.out = out
        self.t0 = time.monotonic()
        self.before_first: dict | None = None
        self.worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
        self.file = open(f"{out}.{self.worker}.jsonl", "a", encoding="utf-8")   # noqa: SIM115 (the session's)

    def _write(self, kind: str, record: dict) -> None:
        self.file.write(json.dumps({"kind": kind, "worker": self.worker, **record}) + "\n")
        self.file.flush()

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item, nextitem):
        if self.before_first is None:
            s, c = _cpu()
            self.before_first = {"self": s, "children": c, "wall": time.monotonic() - self.t0}
            self._write("start", self.before_first)
        s0, c0 = _cpu()
        w0 = time.monotonic()
        before = _loads()
        yield
        s1, c1 = _cpu()
        record = {"test": item.nodeid, "self": round(s1 - s0, 4), "children": round(c1 - c0, 4),
                  "wall": round(time.monotonic() - w0, 4), "start": round(w0 - self.t0, 3)}
        for key, old, new in zip(("loads", "checked"), before, _loads()):
            built = {k: n - old.get(k, 0) for k, n in new.items() if n != old.get(k, 0)}
            if built:
                record[key] = built
        self._write("test", record)

    @pytest.hookimpl(hookwrapper=True)
    def pytest_fixture_setup(self, fixturedef, request):
        s0, c0 = _cpu()
        yield
        s1, c1 = _cpu()
        if s1 - s0 + c1 - c0 >= 0.05:
            self._write("fixture", {"fixture": fixturedef.argname, "scope": fixturedef.scope,
                                    "baseid": fixturedef.baseid, "test": request.node.nodeid,
                                    "self": round(s1 - s0, 4), "children": round(c1 - c0, 4)})

    def pytest_unconfigure(self, config):
        model = sys.modules.get("interp.runtime.model")   # read, never imported here
        program = sys.modules.get("interp.runtime.program")
        if model is not None:
            self._write("models", {"loads": dict(model.LOADS),
                                   "workspaces": dict(program.WS_LOADS) if program is not None else {}})
        s, c = _cpu()
        self._write("total", {"self": s, "children": c, "wall": time.monotonic() - self.t0})
        self.file.close()


def _again(parts: list, key: str) -> list:
    """(worker, start, folder, times, test) of each test that built a folder's model or checked
    workspace (`key`: "loads", "checked") its worker had built before, in each worker's order."""
    again = []
    for p in parts:
        seen: set = set()
        for k, v in sorted(p["tests"].items(), key=lambda x: x[1]["start"]):
            for folder, n in v.get(key, {}).items():
                if folder in seen or n > 1:
                    again.append((p["worker"], v["start"], folder, n if folder in seen else n - 1, k))
                seen.add(folder)
    return again


def _report(stem: str, top: int = 60) -> None:
    parts = []
    for path in sorted(Path(stem).parent.glob(Path(stem).name + ".*.jsonl")):
        part = {"worker": path.suffixes[-2][1:], "total": None, "before_first": None, "tests": {}, "fixtures": [],
                "models": {}, "workspaces": {}}
        for line in path.read_text(encoding="utf-8").splitlines():
            r = json.loads(line)
            if r["kind"] == "test":
                part["tests"][r["test"]] = r
            elif r["kind"] == "fixture":
                part["fixtures"].append(r)
            elif r["kind"] == "models":
                part["models"] = r["loads"]
                part["workspaces"] = r.get("workspaces", {})
            else:
                part["total" if r["kind"] == "total" else "before_first"] = r
        parts.append(part)
    tests = {k: v for p in parts for k, v in p["tests"].items()}
    cpu = {k: v["self"] + v["children"] for k, v in tests.items()}
    print(f"{len(tests)} tests, {sum(cpu.values()):.0f} s CPU in tests "
          f"(self {sum(v['self'] for v in tests.values()):.0f}, children {sum(v['children'] for v in tests.values()):.0f})")
    for p in parts:
        t, b = p["total"] or {"self": 0, "children": 0, "wall": 0}, p["before_first"] or {}
        print(f"  worker {p['worker']}: total self {t['self']:.0f} children {t['children']:.0f} wall {t['wall']:.0f}; "
              f"before first test self {b.get('self', 0):.1f} wall {b.get('wall', 0):.1f}")
    files = defaultdict(float)
    for k, v in cpu.items():
        files[k.split("::")[0]] += v
    print("\nfiles:")
    for f, v in sorted(files.items(), key=lambda x: -x[1])[:top]:
        print(f"  {v:8.1f}  {f}")
    print("\ntests:")
    for k, v in sorted(cpu.items(), key=lambda x: -x[1])[:top]:
        print(f"  {v:8.1f}  wall {tests[k]['wall']:7.1f} start {tests[k]['start']:7.0f} {tests[k]['worker']}  {k}")
    fx = defaultdict(lambda: [0.0, 0, ""])
    for p in parts:
        for f in p["fixtures"]:
            key = (f["baseid"], f["fixture"])
            fx[key][0] += f["self"] + f["children"]
            fx[key][1] += 1
            fx[key][2] = f["scope"]
    print("\nfixtures (inclusive setup CPU, times made):")
    for (base, name), (v, n, scope) in sorted(fx.items(), key=lambda x: -x[1][0])[:top]:
        print(f"  {v:8.1f}  x{n:<4} {scope:8} {base}::{name}")
    loads = defaultdict(list)
    for p in parts:
        for folder, n in p["models"].items():
            loads[folder].append(n)
    print("\nmodels loaded (interp/runtime/model.py LOADS: per worker that loaded it; a backup's "
          "folder, or a test's own program's, on a robot):")
    for folder, ns in sorted(loads.items(), key=lambda x: (-max(x[1]), x[0]))[:top]:
        print(f"  {max(ns):4d} most in one worker, {len(ns)} workers  {folder}")
    print(f"  {len(loads)} models, {sum(1 for ns in loads.values() if max(ns) > 1)} loaded more than once by a worker")
    checked = defaultdict(list)
    for p in parts:
        for folder, n in p["workspaces"].items():
            checked[folder].append(n)
    print("\nchecked workspaces loaded (interp/runtime/program.py WS_LOADS, the costly part of a model):")
    for folder, ns in sorted(checked.items(), key=lambda x: (-max(x[1]), x[0]))[:top // 3]:
        print(f"  {max(ns):4d} most in one worker, {len(ns)} workers  {folder}")
    print(f"  {len(checked)} folders, {sum(1 for ns in checked.values() if max(ns) > 1)} loaded more than once by a worker")
    for key, what in (("loads", "models"), ("checked", "checked workspaces")):
        again = _again(parts, key)
        print(f"\n{what} built again by a worker ({sum(a[3] for a in again)}; worker, start, folder, test):")
        for w, start, folder, n, k in again[:top]:
            print(f"  {w} {start:7.0f} x{n} {folder}  {k}")
    print("\ntail (last tests to end, per worker):")
    for p in parts:
        ends = sorted(p["tests"].items(), key=lambda x: -(x[1]["start"] + x[1]["wall"]))[:5]
        for k, v in ends:
            print(f"  {p['worker']} start {v['start']:7.0f} wall {v['wall']:6.1f}  {k}")


if __name__ == "__main__":
    _report(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 60)
