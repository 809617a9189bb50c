"""How fast the language server answers, over stdio, with pygls' client (a benchmark, not a
test: the figures depend on the machine and its load, which every report line states).

``python -m krl.lsp.bench`` (no option) measures each KRC backup of the shared corpus as it is
(krl/files.py ``SHARED_CORPUS``, read in place: edits are made in the editor's buffer and never
saved): the server opens the backup's largest file and the bench reports

* **first diagnostics**: didOpen -> the first publishDiagnostics of the file (the file's own
  parse diagnostics in a workspace of 20 files or more, or the diagnostics the cache holds);
* **checked**: didOpen -> the first publication whose diagnostics (the never-read hints,
  severity Hint, aside: no check finding) are those of the finished analysis;
* **ready**: didOpen -> the answer to a documentSymbol request (the analysis every feature
  reads is done);
* **edit**: didChange -> publishDiagnostics for an edit of one value (an integer literal
  assigned on a line, counted up: one routine or one data-list value changes per edit), median
  and 95th percentile; **error**: for an edit that leaves a syntax error in a statement.

Each backup is measured twice: with an empty parse and check cache (cold) and again with the
cache the first run filled (warm). ``--baseline DIR`` runs the same measurements on the server
of another checkout (its ``krl`` package, e.g. a worktree of an older commit) interleaved with
this one, and prints each figure of both and their ratio. ``--cpu`` prints, beside the wall
times, the CPU time the server's process tree spent (the server, its Java parse worker and its
worker processes, psutil): until ready, and per edit (p50, p95) -- the figures that a loaded
machine changes least.

``--workspace`` measures a 400-file project instead, built at bench time in a temporary folder
from the shared corpus (nothing is copied into the repository): the ChinaMilling backup (156
files) with further corpus files copied into its ``R1/Program/corpus`` until there are 400.
``--generated`` measures a generated 3,000-line program (:func:`krl.lsp.sample.generate`). ``--json`` prints
one JSON document at the end.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import re
import shutil
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from krl.cputime import tree_cpu_s
from lsprotocol import types as L
from pygls.lsp.client import BaseLanguageClient
from krl.source import decode_bytes
from krl.files import SHARED_CORPUS
from krl.project import find_backups, project_of
from krl.lsp.sample import generate


def _pct(values: list[float], p: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, int(round(p * (len(s) - 1))))]


def loadavg() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "?"


def _memory(pid: int) -> dict[str, float]:
    out = {}
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            key, _, value = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                out[key] = round(int(value.split()[0]) / 1024, 1)       # MiB
    except OSError:
        pass
    return out


# ---------------------------------------------------------------------- edits

_VALUE = re.compile(r"(=\s*)(-?\d+)(\s*(?:;.*)?)$")
_ERROR_LINE = re.compile(r"^\s*(WAIT SEC|IF |\$OUT\[|[A-Za-z_]\w*\s*=)", re.IGNORECASE)


def value_lines(lines: list[str]) -> list[int]:
    """Lines that assign an integer literal (a statement ``x = 5`` or a declaration
    ``DECL INT x=5``): the places of the value edits."""
    return [i for i, ln in enumerate(lines) if _VALUE.search(ln) and not ln.lstrip().startswith(";")]


def edit_value(line: str) -> str:
    """The line with its assigned integer counted up by one."""
    return _VALUE.sub(lambda m: f"{m.group(1)}{int(m.group(2)) + 1}{m.group(3)}", line, count=1)


# ---------------------------------------------------------------------- one server

@dataclass
class Server:
    """How to start a server: its checkout (None: this one) and cache folder."""
    name: str
    checkout: Path | None = None
    cache: Path | None = None

    def env(self) -> dict[str, str]:
        env = dict(os.environ)
        if self.checkout is not None:
            env["PYTHONPATH"] = str(self.checkout)
        if self.cache is not None:
            env["KRL_CACHE_DIR"] = str(self.cache)
        return env


@dataclass
class Run:
    """The figures of one server on one workspace."""
    server: str
    workspace: str
    files: int
    file: str
    first_ms: float = 0.0
    checked_ms: float = 0.0
    ready_ms: float = 0.0
    edit: list[float] = field(default_factory=list)
    error: list[float] = field(default_factory=list)
    diagnostics: int = 0
    rss_mib: float | None = None
    load: str = ""
    ready_cpu_ms: float = 0.0
    edit_cpu: list[float] = field(default_factory=list)

    def summary(self) -> dict:
        out = {"server": self.server, "workspace": self.workspace, "files": self.files, "file": self.file,
               "first_diagnostics_ms": round(self.first_ms, 1), "checked_ms": round(self.checked_ms, 1),
               "ready_ms": round(self.ready_ms, 1), "diagnostics": self.diagnostics, "rss_mib": self.rss_mib,
               "load": self.load, "ready_cpu_ms": round(self.ready_cpu_ms, 1)}
        for kind in ("edit", "error", "edit_cpu"):
            values = getattr(self, kind)
            if values:
                out[f"{kind}_p50_ms"] = round(statistics.median(values), 1)
                out[f"{kind}_p95_ms"] = round(_pct(values, 0.95), 1)
                out[f"{kind}_runs"] = len(values)
        return out


async def measure_file(server: Server, root: Path, path: Path, runs: int, errors: int, label: str) -> Run:
    """Open `path` of the workspace `root` in a fresh server, time its first diagnostics, its
    check, then `runs` value edits and `errors` edits that leave a syntax error."""

    raw = path.read_bytes()
    text = decode_bytes(raw)[0]
    uri = path.as_uri()
    client = BaseLanguageClient("krl-lsp-bench", "1")
    arrived: asyncio.Queue = asyncio.Queue()

    @client.feature(L.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def on_diagnostics(params: L.PublishDiagnosticsParams):
        arrived.put_nowait((time.perf_counter(), params))

    @client.feature(L.CLIENT_REGISTER_CAPABILITY)
    def on_register(params: L.RegistrationParams):
        return None                 # the editor watches the files (VS Code and Neovim do)

    await client.start_io(sys.executable, "-m", "krl.lsp", env=server.env(),
                          cwd=str(server.checkout) if server.checkout else None)
    pid = client._server.pid
    caps = L.ClientCapabilities(workspace=L.WorkspaceClientCapabilities(
        did_change_watched_files=L.DidChangeWatchedFilesClientCapabilities(dynamic_registration=True)))
    await client.initialize_async(L.InitializeParams(capabilities=caps, root_uri=root.as_uri(),
                                                     workspace_folders=[L.WorkspaceFolder(uri=root.as_uri(), name=root.name)]))
    client.initialized(L.InitializedParams())
    files = sum(1 for p in root.rglob("*") if p.is_file() and p.suffix.lower() in (".src", ".dat", ".sub"))
    run = Run(server.name, label, files, str(path.relative_to(root)), load=loadavg())

    async def until(version: int, timeout: float = 900) -> tuple[float, list]:
        while True:
            t, params = await asyncio.wait_for(arrived.get(), timeout)
            if params.uri == uri and params.version == version:
                return t, params.diagnostics

    c0 = tree_cpu_s(pid)
    t0 = time.perf_counter()
    client.text_document_did_open(L.DidOpenTextDocumentParams(
        text_document=L.TextDocumentItem(uri=uri, language_id="krl", version=1, text=text)))
    published = [await until(1)]
    run.first_ms = (published[0][0] - t0) * 1000
    await client.text_document_document_symbol_async(L.DocumentSymbolParams(
        text_document=L.TextDocumentIdentifier(uri=uri)))          # answered after the analysis
    run.ready_ms = (time.perf_counter() - t0) * 1000
    run.ready_cpu_ms = (tree_cpu_s(pid) - c0) * 1000
    await asyncio.sleep(0.2)            # the publication of the finished check follows its analysis
    while not arrived.empty():
        t, params = arrived.get_nowait()
        if params.uri == uri and params.version == 1:
            published.append((t, params.diagnostics))
    def checked(diags: list) -> list:
        return [d for d in diags if d.severity != L.DiagnosticSeverity.Hint]
    final = checked(published[-1][1])
    run.checked_ms = (next(t for t, d in published if checked(d) == final) - t0) * 1000
    run.diagnostics = len(final)

    sep = "\r\n" if "\r\n" in text else "\n"
    lines = text.split(sep)
    targets = value_lines(lines) or [i for i, ln in enumerate(lines) if ln.strip()][-1:]
    version = [1]
    cpu: list[float] = []

    async def change() -> float:
        """Send the buffer as it is now; ms until its diagnostics arrive (then a pause, so
        that the next edit is analysed at once: the server's leading edge)."""
        version[0] += 1
        c1 = tree_cpu_s(pid)
        t1 = time.perf_counter()
        client.text_document_did_change(L.DidChangeTextDocumentParams(
            text_document=L.VersionedTextDocumentIdentifier(uri=uri, version=version[0]),
            content_changes=[L.TextDocumentContentChangeWholeDocument(text=sep.join(lines))]))
        t2, _ = await until(version[0])
        cpu.append((tree_cpu_s(pid) - c1) * 1000)
        await asyncio.sleep(0.2)
        return (t2 - t1) * 1000

    for r in range(runs):
        i = targets[(r * 7) % len(targets)]
        lines[i] = edit_value(lines[i]) if _VALUE.search(lines[i]) else lines[i] + " ;edit"
        run.edit.append(await change())
    run.edit_cpu = list(cpu)
    places = [i for i, ln in enumerate(lines) if _ERROR_LINE.match(ln)] or targets
    for r in range(errors):
        i = places[(r * 5) % len(places)]
        kept = lines[i]
        lines[i] = kept.rstrip() + " ="             # a statement left without its value
        run.error.append(await change())
        lines[i] = kept
        await change()
    run.rss_mib = _memory(pid).get("VmRSS")
    await client.shutdown_async(None)
    client.exit(None)
    await client.stop()
    return run


# ---------------------------------------------------------------------- workspaces

WORKSPACE_BASE = "HugoDanielson__ChinaMilling/KRC"
WORKSPACE_FILE = "R1/Program/KukaMiling/Main_2.src"
KRL_SUFFIXES = (".src", ".dat", ".sub")


def build_workspace(dst: Path, files: int = 400, corpus: Path | None = None) -> tuple[Path, int]:
    """Copy the corpus backup WORKSPACE_BASE to `dst`/KRC and further corpus KRL files (not
    $-files, not of that backup) into KRC/R1/Program/corpus until it holds `files` KRL files;
    returns (backup root, number of KRL files)."""
    corpus = corpus or SHARED_CORPUS
    base = corpus / WORKSPACE_BASE
    if not base.is_dir():
        raise SystemExit(f"the shared corpus is not at {corpus}: --workspace needs it")
    root = dst / "KRC"
    shutil.copytree(base, root)
    count = sum(1 for p in root.rglob("*") if p.is_file() and p.suffix.lower() in KRL_SUFFIXES)
    extra = root / "R1" / "Program" / "corpus"
    for p in sorted(corpus.rglob("*")):
        if count >= files:
            break
        if not p.is_file() or p.suffix.lower() not in KRL_SUFFIXES or p.name.startswith("$") or base in p.parents:
            continue
        target = extra / p.relative_to(corpus)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(p, target)
        count += 1
    return root, count


def corpus_backups(corpus: Path | None = None) -> list[tuple[str, Path, Path]]:
    """(name, root, largest KRL file) of each KRC backup of the shared corpus, as it is."""
    corpus = corpus or SHARED_CORPUS
    out = []
    for b in find_backups(corpus):
        files = project_of(b).files
        if files:
            out.append((str(b.relative_to(corpus)), b, max(files, key=lambda f: (f.stat().st_size, str(f)))))
    return out


def _line(run: Run, base: Run | None, cpu: bool = False) -> str:
    s = run.summary()

    def fig(key: str) -> str:
        v = s.get(key)
        if v is None:
            return "-"
        if base is None:
            return f"{v:g}"
        b = base.summary().get(key)
        return f"{v:g} (base {b:g}, x{b / v:.1f})" if b and v else f"{v:g} (base {b})"
    return (f"  {run.server:<10} first {fig('first_diagnostics_ms')} ms | checked {fig('checked_ms')} ms | "
            f"ready {fig('ready_ms')} ms | edit p50 {fig('edit_p50_ms')} ms, p95 {fig('edit_p95_ms')} ms | "
            f"error p50 {fig('error_p50_ms')} ms | {s['diagnostics']} diagnostics, {s['rss_mib']} MiB | load {run.load}"
            + (f"\n  {'':<10} CPU: ready {fig('ready_cpu_ms')} ms | edit p50 {fig('edit_cpu_p50_ms')} ms, "
               f"p95 {fig('edit_cpu_p95_ms')} ms" if cpu else ""))


async def bench(targets: list[tuple[str, Path, Path]], runs: int, errors: int, baseline: Path | None,
                cpu: bool = False) -> list[dict]:
    out = []
    for label, root, path in targets:
        cache = Path(tempfile.mkdtemp(prefix="krl-lsp-bench-cache-"))
        try:
            print(f"{label}: {path.relative_to(root)} ({path.stat().st_size} bytes)", flush=True)
            base = None
            if baseline is not None:        # it has no persistent cache: one run
                base = await measure_file(Server("baseline", baseline, cache / "base"), root, path, runs, errors, label)
                print(_line(base, None, cpu), flush=True)
            for kind in ("cold", "warm"):   # an empty cache, then the one the first run filled
                run = await measure_file(Server(f"this/{kind}", None, cache), root, path, runs, errors, label)
                print(_line(run, base, cpu), flush=True)
                out.append({"cache": kind, **run.summary(), **({"baseline": base.summary()} if base else {})})
        finally:
            shutil.rmtree(cache, ignore_errors=True)
    return out


# ---------------------------------------------------------------------- the generated program

async def measure_generated(lines: int, runs: int) -> dict:
    folder = Path(tempfile.mkdtemp(prefix="krl-lsp-bench-"))
    try:
        path = folder / "bench.src"
        path.write_text(generate(lines), newline="")
        run = await measure_file(Server("this"), folder, path, runs, max(3, runs // 4), "generated")
        return run.summary()
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m krl.lsp.bench", description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=30, help="value edits per workspace")
    ap.add_argument("--errors", type=int, default=5, help="edits leaving a syntax error per workspace")
    ap.add_argument("--baseline", type=Path, help="the checkout of another server to measure side by side")
    ap.add_argument("--workspace", action="store_true", help="the 400-file workspace (module docstring)")
    ap.add_argument("--generated", action="store_true", help="a generated 3,000-line program")
    ap.add_argument("--only", help="only the corpus backups whose name holds this text")
    ap.add_argument("--json", action="store_true", help="one JSON document at the end")
    ap.add_argument("--cpu", action="store_true", help="also the CPU time of the server's process tree")
    args = ap.parse_args(argv)
    print(f"krl lsp bench, {time.strftime('%Y-%m-%d %H:%M')}, load average {loadavg()}, "
          f"{os.cpu_count()} cores", flush=True)
    if args.generated:
        res = [asyncio.run(measure_generated(3000, args.runs))]
        print(json.dumps(res[0]))
        return
    folder = None
    try:
        if args.workspace:
            folder = Path(tempfile.mkdtemp(prefix="krl-lsp-bench-ws-"))
            root, _count = build_workspace(folder)
            targets = [("400 files", root, root / WORKSPACE_FILE)]
        else:
            targets = [t for t in corpus_backups() if not args.only or args.only in t[0]]
            if not targets:
                raise SystemExit("no KRC backup found in the shared corpus")
        res = asyncio.run(bench(targets, args.runs, args.errors, args.baseline, args.cpu))
    finally:
        if folder is not None:
            shutil.rmtree(folder, ignore_errors=True)
    if args.json:
        print(json.dumps(res))


if __name__ == "__main__":
    main()
