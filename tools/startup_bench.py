"""What deferring an import saves on a real command's start-up (issue 62, "Imports"):
``krl --help``, ``krl check FILE``, ``krl lsp`` up to its answer to ``initialize``, ``krl run
FILE`` (a four-line program on the default cell) and ``krl check --reach FILE`` (its points
against the robot and the cell, interp/reach.py).

An import inside a function (instead of at the top of its module) is worth its surprise only where
a command a user waits for would otherwise import a module it does not need. Method, from one run:

1. **Commands.** Each command runs in a fresh process, ``--repeat`` times; the modules it holds
   when it is done (``krl --help`` printed its help, ``krl check`` its diagnostics, the language
   server answered ``initialize`` and shut down, ``krl run`` ended its program, ``krl check
   --reach`` printed its report) are read from
   ``sys.modules`` at exit, and its CPU seconds (user + system of the process and its children,
   ``os.times``) are the best of the repeats.
2. **Sites.** Every ``import``/``from ... import`` inside a ``def`` of the project's packages is
   found in the sources (``ast``; relative imports resolved).
3. **What a site saves.** For each command, one process imports every module the command imported
   (so it holds what the command holds), then forks once per site whose function's module is among
   them; the child runs the site's import statement and reports its CPU milliseconds
   (``time.process_time``); best of ``--repeat`` forks. That is what moving the import to the top
   of its module would add to that command's start-up. A site whose module no command imports
   saves nothing on any of them. A site that saves at least ``--min-ms`` on some command is listed
   with the command and the figure; tests/test_imports_inside_functions.py requires each import
   inside a function to name this benchmark (or an allowed reason that is not a cost).
4. **Before and after.** With ``--against REF`` the commands also run on a detached worktree of
   the git revision REF (its untracked build output, the generated parser and the compiled loops,
   copied from this checkout), alternating with this checkout's runs so that both see the same
   load; the table prints both CPU figures and their ratio.

Figures are CPU, not wall time, so that a loaded machine changes them less; still, compare only
figures from one run.

Usage::

    python tools/startup_bench.py [--repeat 3] [--min-ms 3] [--against REF] [--sites] [--commands-only] [--json OUT]

Exit status 0; 2 when a command fails to start. Run from a checkout with its ``.venv`` (the
commands run as ``python -m app`` with the checkout first on ``sys.path``).
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PACKAGES = ("app", "krl", "interp", "robot", "recovery", "conformance", "net", "pendant", "audit")
SKIPPED = {"generated", "build", "dist", "node_modules", "__pycache__"}
#: the build output a checkout needs to run and git does not hold (copied for --against)
BUILT = ("krl/syntax/generated", "interp/vm/*.so", "robot/*.so", "robot/kinematics/*.so")

#: ``krl`` with its arguments, writing the names of the modules it holds when it exits to the
#: file named by $STARTUP_BENCH_MODULES (``sys.modules``: ``-X importtime`` does not see a module
#: loaded by ``importlib.import_module``, as ``krl``'s subcommands are)
_KRL = r"""
import atexit, os, runpy, sys
def _dump():
    with open(os.environ["STARTUP_BENCH_MODULES"], "w", encoding="utf-8") as f:
        f.write("\n".join(sys.modules))
atexit.register(_dump)
_os_exit = os._exit
def _exit(code):                 # the language server ends by os._exit, past atexit
    _dump()
    _os_exit(code)
os._exit = _exit
sys.argv = ["krl", *sys.argv[1:]]
runpy.run_module("app", run_name="__main__", alter_sys=True)
"""

#: ``krl lsp`` (the command of argv[1]) up to its answer to ``initialize`` (LSP framing on
#: stdin/stdout), then shutdown and exit
_LSP_DRIVER = r"""
import json, subprocess, sys
def frame(obj):
    body = json.dumps(obj).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body
p = subprocess.Popen([sys.executable, "-c", sys.argv[1], "lsp"], stdin=subprocess.PIPE,
                     stdout=subprocess.PIPE, stderr=subprocess.PIPE)
p.stdin.write(frame({"jsonrpc": "2.0", "id": 1, "method": "initialize",
                     "params": {"processId": None, "rootUri": None, "capabilities": {}}}))
p.stdin.flush()
head = b""
while not head.endswith(b"\r\n\r\n"):
    c = p.stdout.read(1)
    if not c:
        sys.exit("krl lsp closed its output before answering initialize")
    head += c
n = int([l for l in head.split(b"\r\n") if l.lower().startswith(b"content-length")][0].split(b":")[1])
p.stdout.read(n)
p.stdin.write(frame({"jsonrpc": "2.0", "id": 2, "method": "shutdown"}))
p.stdin.write(frame({"jsonrpc": "2.0", "method": "exit"}))
p.stdin.close()
err = p.stderr.read().decode()
p.wait(timeout=60)
sys.stderr.write(err)
"""

#: forked once per site: (statement, package for relative imports) in, CPU ms out
_SITE_CHILD = r"""
import importlib, os, sys, time
mods, sites = {mods!r}, {sites!r}
for m in mods:
    if m.endswith("__main__"):
        continue
    try:
        importlib.import_module(m)
    except BaseException:
        pass
out = []
for stmt, package in sites:
    best = float("inf")
    for _ in range({repeat}):
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(r)
            t = time.process_time()
            try:
                exec(stmt, {{"__package__": package, "__name__": package + "._site"}})
                ms = (time.process_time() - t) * 1000
            except BaseException:
                ms = -1.0
            os.write(w, repr(ms).encode())
            os._exit(0)
        os.close(w)
        data = b""
        while chunk := os.read(r, 64):
            data += chunk
        os.close(r)
        os.waitpid(pid, 0)
        best = min(best, float(data or b"-1"))
    out.append(best)
print(repr(out))
"""


def _env(checkout: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(checkout))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def commands(tmp: Path) -> dict[str, list[str]]:
    """The commands measured, as arguments of ``python``."""
    demo = tmp / "demo.src"
    demo.write_text("DEF demo()\n  INT i\n  i = 1\nEND\n", encoding="utf-8")
    return {"krl --help": ["-c", _KRL, "--help"],
            "krl check": ["-c", _KRL, "check", str(demo)],
            "krl lsp": ["-c", _LSP_DRIVER, _KRL],
            "krl run": ["-c", _KRL, "run", str(demo)],
            "krl check --reach": ["-c", _KRL, "check", "--reach", str(demo)]}


def run_command(argv: list[str], checkout: Path, cwd: Path) -> tuple[list[str], float]:
    """(the modules the command held when it exited, in the order they were loaded; its CPU
    seconds, children included). Raises RuntimeError when it fails."""
    listing = cwd / "modules.txt"
    listing.unlink(missing_ok=True)
    env = dict(_env(checkout), STARTUP_BENCH_MODULES=str(listing))
    t0 = os.times()
    res = subprocess.run([sys.executable, *argv], capture_output=True, text=True, cwd=cwd, env=env,
                         timeout=300)
    t1 = os.times()
    if res.returncode not in (0, 1) or not listing.exists():
        raise RuntimeError(f"{argv[2:]}: exit {res.returncode}\n{res.stderr[-2000:]}")
    mods = listing.read_text(encoding="utf-8").split()
    return mods, (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)


def module_of(path: Path, root: Path = REPO) -> str:
    rel = path.relative_to(root).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def sites(root: Path = REPO) -> list[dict]:
    """Every import inside a function of the packages: file, line, the function's module, the
    statement as absolute Python and the package it runs in."""
    out = []
    for pkg in PACKAGES:
        for path in sorted((root / pkg).rglob("*.py")):
            if any(p in SKIPPED for p in path.relative_to(root).parts):
                continue
            here = module_of(path, root)
            package = here if path.name == "__init__.py" else here.rpartition(".")[0]
            tree = ast.parse(path.read_text(encoding="utf-8"))
            seen: set[int] = set()
            for fn in ast.walk(tree):
                if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    continue
                for node in ast.walk(fn):
                    if id(node) in seen or not isinstance(node, (ast.Import, ast.ImportFrom)):
                        continue
                    seen.add(id(node))
                    out.append({"site": f"{path.relative_to(root)}:{node.lineno}", "module": here,
                                "package": package, "stmt": ast.unparse(node)})
    return out


def site_costs(mods: list[str], chosen: list[dict], checkout: Path, cwd: Path, repeat: int) -> list[float]:
    """CPU ms of each chosen site's import statement in a process that holds `mods`."""
    if not chosen:
        return []
    code = _SITE_CHILD.format(mods=list(dict.fromkeys(mods)), repeat=repeat,
                              sites=[(s["stmt"], s["package"]) for s in chosen])
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd,
                         env=_env(checkout), timeout=1800)
    if res.returncode != 0:
        raise RuntimeError(res.stderr[-2000:])
    return ast.literal_eval(res.stdout.strip().splitlines()[-1])


def baseline(ref: str, tmp: Path) -> Path:
    """A detached worktree of `ref` with this checkout's build output copied in."""
    where = tmp / "against"
    subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", "-q", str(where), ref], check=True)
    for pattern in BUILT:
        for src in REPO.glob(pattern):
            dst = where / src.relative_to(REPO)
            if src.is_dir():
                shutil.copytree(src, dst, dirs_exist_ok=True)
            else:
                shutil.copy2(src, dst)
    return where


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs of each command and forks of each site")
    ap.add_argument("--min-ms", type=float, default=3.0, help="a site that saves less is listed as saving nothing")
    ap.add_argument("--against", default=None, help="a git revision to measure the commands on as well")
    ap.add_argument("--sites", action="store_true", help="list every site with what it saves")
    ap.add_argument("--commands-only", action="store_true", help="time the commands, measure no site")
    ap.add_argument("--json", default=None, help="write the figures to this file")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as td:
        tmp = Path(td)
        cmds = commands(tmp)
        sides = {"this": REPO}
        try:
            if a.against:
                sides = {a.against: baseline(a.against, tmp), "this": REPO}
            cpu: dict[tuple[str, str], float] = {}
            loaded: dict[str, list[str]] = {}
            try:
                for _ in range(a.repeat):
                    for name, args in cmds.items():
                        for side, checkout in sides.items():
                            mods, s = run_command(args, checkout, tmp)
                            cpu[side, name] = min(cpu.get((side, name), float("inf")), s)
                            if side == "this":
                                loaded[name] = mods
            except RuntimeError as exc:
                print(f"error: a command did not start: {exc}", file=sys.stderr)
                return 2
        finally:
            if a.against:
                subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(sides[a.against])],
                               check=False)
        print("Start-up, CPU seconds (best of %d):" % a.repeat)
        for name in cmds:
            line = f"  {name:18s} {len(loaded[name]):5d} modules  this {cpu['this', name]:6.3f} s"
            if a.against:
                base = cpu[a.against, name]
                line += f"   {a.against} {base:6.3f} s   this/{a.against} {cpu['this', name] / base:5.2f}"
            print(line)
        if a.commands_only:
            return 0
        found = sites()
        saves: dict[str, dict[str, float]] = {s["site"]: {} for s in found}
        for name, mods in loaded.items():
            have = set(mods)
            chosen = [s for s in found if s["module"] in have]
            for s, ms in zip(chosen, site_costs(mods, chosen, REPO, tmp, a.repeat)):
                saves[s["site"]][name] = ms
    rows = []
    for s in found:
        per = saves[s["site"]]
        best = max(per.items(), key=lambda kv: kv[1], default=(None, 0.0))
        rows.append({**s, "saves": per, "command": best[0], "saves_ms": round(best[1], 1)})
    keep = sorted((r for r in rows if r["saves_ms"] >= a.min_ms), key=lambda r: -r["saves_ms"])
    print(f"\n{len(keep)} of {len(rows)} imports inside functions of the packages save at least "
          f"{a.min_ms:g} ms of CPU on a command's start-up (what the import at the top would add):")
    for r in keep:
        print(f"  {r['site']:42s} {r['command']:18s} {r['saves_ms']:7.1f} ms  {r['stmt'][:70]}")
    failed = [r for r in rows if any(v < 0 for v in r["saves"].values())]
    for r in failed:
        print(f"  (failed to import) {r['site']}: {r['stmt']}")
    if a.sites:
        print("\nSaving less (the module is loaded anyway, or the function's module is on no command's way):")
        for r in rows:
            if r["saves_ms"] < a.min_ms:
                where = ", ".join(f"{k} {v:.1f}" for k, v in r["saves"].items()) or "on no command's way"
                print(f"  {r['site']:42s} {where}")
    if a.json:
        Path(a.json).write_text(json.dumps({
            "commands": {f"{side} {name}": round(v, 3) for (side, name), v in cpu.items()},
            "sites": [{k: r[k] for k in ("site", "stmt", "saves", "command", "saves_ms")} for r in rows]},
            indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
