"""Time from ``didChange`` to ``publishDiagnostics`` for a 3,000-line program, over stdio.

``python -m krl.lsp.bench [--lines N] [--runs N]`` starts ``python -m krl.lsp`` as a subprocess,
drives it with pygls' client, opens a generated program of N lines (corpus-like statements:
motions with aggregates, FOR/IF/SWITCH blocks, $OUT and $VEL writes, WAIT SEC, FOLD lines; one
routine per ~170 lines), then edits one statement per run and measures the time until the
diagnostics of that version arrive (the debounce delay included). Two kinds of edit:

* ``edit``: a valid change inside one routine (the common case while typing);
* ``error``: a change that leaves a syntax error (the whole file is parsed again, to give the
  messages of ``krl check``).

Prints one line per kind with the median and 90th percentile in ms, and one JSON line. A
benchmark, not a test: the figures depend on the machine and its load.

``--workspace`` measures a 400-file project instead, built at bench time in a temporary folder
from the shared corpus (krl/files.py ``SHARED_CORPUS``; nothing is copied into the repository):
the ChinaMilling backup (156 files) with further corpus files copied into its ``R1/Program/corpus``
until there are 400. It opens one program of the backup and reports: the time to its first
diagnostics (the file's own parse diagnostics, published while the workspace is checked), the
time until the first check of the 400 files is done, didChange -> publishDiagnostics for edits
inside a routine and for edits that leave a syntax error (median, 95th percentile), and the
server's memory (VmRSS, VmHWM).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path


def generate(lines: int = 3000) -> str:
    """A valid KRL program of about `lines` lines (CRLF, as on the controller)."""
    out = ["&ACCESS RVP", "&REL 1", "DEF bench( )", "  DECL INT n", ";FOLD INI;%{PE}", "  BAS(#INITMOV, 0)",
           ";ENDFOLD (INI)", "  n = 0", "  bench_1( )", "END", ""]
    k = 1
    while len(out) < lines:
        body = [f"DEF bench_{k}( )", "  DECL INT i, j", "  DECL REAL d", "  DECL E6POS p",
                ";FOLD PTP HOME Vel=100 % DEFAULT;%{PE}", "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}", ";ENDFOLD"]
        for s in range(8):
            body += [f"  ; step {s}", f"  $OUT[{s + 1}] = FALSE", f"  FOR i = 1 TO {s + 3}",
                     f"    d = i * 2.5 + {s}", "    IF d > 10.0 THEN", f"      $VEL.CP = 0.{s + 1}",
                     "      LIN {X 100.0, Y 200.0, Z 300.0, A 0.0, B 90.0, C 0.0} C_DIS", "    ELSE",
                     "      j = i", "    ENDIF", "  ENDFOR", f"  WAIT SEC 0.{s}", "  p = $POS_ACT",
                     "  p.X = p.X + 10.0", "  SWITCH j", "    CASE 1", "      PTP p", "    DEFAULT",
                     "      HALT", "  ENDSWITCH"]
        out += body + ["END", ""]
        k += 1
    return "\r\n".join(out) + "\r\n"


def _collect(client) -> asyncio.Queue:
    """A queue of (arrival time, PublishDiagnosticsParams) filled by `client`."""
    from lsprotocol import types as L  # noqa: PLC0415
    arrived: asyncio.Queue = asyncio.Queue()

    @client.feature(L.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def on_diagnostics(params: L.PublishDiagnosticsParams):
        arrived.put_nowait((time.perf_counter(), params))
    return arrived


async def _until(arrived: asyncio.Queue, uri: str, version: int, timeout: float) -> tuple[float, list]:
    """(arrival time, diagnostics) of the first publication for `uri` at `version`."""
    while True:
        t, params = await asyncio.wait_for(arrived.get(), timeout)
        if params.uri == uri and params.version == version:
            return t, params.diagnostics


def _pct(values: list[float], p: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, int(round(p * (len(s) - 1))))]


async def measure(lines: int, runs: int) -> dict:
    from lsprotocol import types as L  # noqa: PLC0415
    from pygls.lsp.client import BaseLanguageClient  # noqa: PLC0415

    text = generate(lines)
    folder = Path(tempfile.mkdtemp(prefix="krl-lsp-bench-"))
    path = folder / "bench.src"
    path.write_text(text)
    uri = path.as_uri()
    client = BaseLanguageClient("krl-lsp-bench", "1")
    arrived = _collect(client)
    await client.start_io(sys.executable, "-m", "krl.lsp")
    await client.initialize_async(L.InitializeParams(capabilities=L.ClientCapabilities(), root_uri=folder.as_uri()))
    client.initialized(L.InitializedParams())

    async def until(version: int) -> tuple[float, list]:
        return await _until(arrived, uri, version, 600)

    t0 = time.perf_counter()
    client.text_document_did_open(L.DidOpenTextDocumentParams(
        text_document=L.TextDocumentItem(uri=uri, language_id="krl", version=1, text=text)))
    t_open, diags = await until(1)
    open_ms = (t_open - t0) * 1000
    version = 1
    results: dict[str, list[float]] = {"edit": [], "error": []}
    counts: dict[str, int] = {}
    src_lines = text.split("\r\n")
    targets = [i for i, ln in enumerate(src_lines) if ln.startswith("  WAIT SEC")]
    for kind, n in (("edit", runs), ("error", max(3, runs // 4))):
        for r in range(n):
            edited = list(src_lines)
            i = targets[(r * 7) % len(targets)]
            edited[i] = f"  WAIT SEC {r % 9}.5" if kind == "edit" else "  WAIT SEC"
            version += 1
            t0 = time.perf_counter()
            client.text_document_did_change(L.DidChangeTextDocumentParams(
                text_document=L.VersionedTextDocumentIdentifier(uri=uri, version=version),
                content_changes=[L.TextDocumentContentChangeWholeDocument(text="\r\n".join(edited))]))
            t1, diags = await until(version)
            results[kind].append((t1 - t0) * 1000)
            counts[kind] = len(diags)
    await client.shutdown_async(None)
    client.exit(None)
    await client.stop()
    out = {"lines": text.count("\n"), "open_ms": round(open_ms, 1)}
    for kind, values in results.items():
        out[f"{kind}_median_ms"] = round(statistics.median(values), 1)
        out[f"{kind}_p90_ms"] = round(_pct(values, 0.9), 1)
        out[f"{kind}_runs"] = len(values)
        out[f"{kind}_diagnostics"] = counts.get(kind, 0)
    return out


WORKSPACE_BASE = "HugoDanielson__ChinaMilling/KRC"
WORKSPACE_FILE = "R1/Program/KukaMiling/Main_2.src"
KRL_SUFFIXES = (".src", ".dat", ".sub")


def build_workspace(dst: Path, files: int = 400, corpus: Path | None = None) -> tuple[Path, int]:
    """Copy the corpus backup WORKSPACE_BASE to `dst`/KRC and further corpus KRL files (not
    $-files, not of that backup) into KRC/R1/Program/corpus until it holds `files` KRL files;
    returns (backup root, number of KRL files)."""
    import shutil  # noqa: PLC0415

    from krl.files import SHARED_CORPUS  # noqa: PLC0415
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


async def measure_workspace(runs: int) -> dict:
    from lsprotocol import types as L  # noqa: PLC0415
    from pygls.lsp.client import BaseLanguageClient  # noqa: PLC0415

    folder = Path(tempfile.mkdtemp(prefix="krl-lsp-bench-ws-"))
    root, count = build_workspace(folder)
    path = root / WORKSPACE_FILE
    text = path.read_bytes().decode("cp1252")
    uri = path.as_uri()
    client = BaseLanguageClient("krl-lsp-bench", "1")
    arrived = _collect(client)

    @client.feature(L.CLIENT_REGISTER_CAPABILITY)
    def on_register(params: L.RegistrationParams):
        return None                 # the editor watches the files (VS Code and Neovim do)

    await client.start_io(sys.executable, "-m", "krl.lsp")
    pid = client._server.pid
    caps = L.ClientCapabilities(workspace=L.WorkspaceClientCapabilities(
        did_change_watched_files=L.DidChangeWatchedFilesClientCapabilities(dynamic_registration=True)))
    await client.initialize_async(L.InitializeParams(capabilities=caps, root_uri=root.as_uri(),
                                                     workspace_folders=[L.WorkspaceFolder(uri=root.as_uri(), name="KRC")]))
    client.initialized(L.InitializedParams())

    async def until(version: int) -> tuple[float, list]:
        return await _until(arrived, uri, version, 900)

    t0 = time.perf_counter()
    client.text_document_did_open(L.DidOpenTextDocumentParams(
        text_document=L.TextDocumentItem(uri=uri, language_id="krl", version=1, text=text)))
    t_first, _ = await until(1)
    await client.text_document_document_symbol_async(L.DocumentSymbolParams(
        text_document=L.TextDocumentIdentifier(uri=uri)))          # answered after the first check
    t_checked = time.perf_counter()
    while not arrived.empty():
        arrived.get_nowait()
    lines = text.split("\r\n") if "\r\n" in text else text.split("\n")
    sep = "\r\n" if "\r\n" in text else "\n"
    targets = [i for i, ln in enumerate(lines) if ln.strip().upper().startswith(("WAIT SEC", "IF ", "$OUT[", "RETURN"))] or [1]
    version = 1
    results: dict[str, list[float]] = {"edit": [], "error": []}
    for kind, n in (("edit", runs), ("error", max(3, runs // 3))):
        for r in range(n):
            edited = list(lines)
            i = targets[(r * 7) % len(targets)]
            # a valid change, or one that leaves a syntax error in the statement (`x =` and no value)
            edited[i] = edited[i] + f" ;edit {r}" if kind == "edit" else "  x ="
            version += 1
            t0e = time.perf_counter()
            client.text_document_did_change(L.DidChangeTextDocumentParams(
                text_document=L.VersionedTextDocumentIdentifier(uri=uri, version=version),
                content_changes=[L.TextDocumentContentChangeWholeDocument(text=sep.join(edited))]))
            t1, diags = await until(version)
            results[kind].append((t1 - t0e) * 1000)
    times = results["edit"]
    mem = _memory(pid)
    await client.shutdown_async(None)
    client.exit(None)
    await client.stop()
    import shutil  # noqa: PLC0415
    shutil.rmtree(folder, ignore_errors=True)
    return {"files": count, "first_diagnostics_ms": round((t_first - t0) * 1000, 1),
            "first_check_ms": round((t_checked - t0) * 1000, 1),
            "edit_median_ms": round(statistics.median(times), 1), "edit_p95_ms": round(_pct(times, 0.95), 1),
            "edit_runs": len(times), "error_median_ms": round(statistics.median(results["error"]), 1),
            "error_p95_ms": round(_pct(results["error"], 0.95), 1), "error_runs": len(results["error"]),
            "rss_mib": mem.get("VmRSS"), "peak_rss_mib": mem.get("VmHWM"),
            "loadavg": Path("/proc/loadavg").read_text().split()[:3] if Path("/proc/loadavg").exists() else []}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m krl.lsp.bench", description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=3000)
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--workspace", action="store_true",
                    help="a 400-file workspace built from the shared corpus (see the module docstring)")
    args = ap.parse_args(argv)
    if args.workspace:
        res = asyncio.run(measure_workspace(args.runs))
        print(f"{res['files']} files; first diagnostics {res['first_diagnostics_ms']} ms, "
              f"first check done {res['first_check_ms']} ms")
        print(f"didChange -> publishDiagnostics, edit inside a routine: median {res['edit_median_ms']} ms, "
              f"p95 {res['edit_p95_ms']} ms ({res['edit_runs']} runs)")
        print(f"didChange -> publishDiagnostics, edit leaving a syntax error: median {res['error_median_ms']} ms, "
              f"p95 {res['error_p95_ms']} ms ({res['error_runs']} runs)")
        print(f"server memory: {res['rss_mib']} MiB resident, peak {res['peak_rss_mib']} MiB; "
              f"load average {' '.join(res['loadavg'])}")
        print(json.dumps(res))
        return
    res = asyncio.run(measure(args.lines, args.runs))
    print(f"{res['lines']} lines; open: {res['open_ms']} ms")
    print(f"didChange -> publishDiagnostics, valid edit:  median {res['edit_median_ms']} ms, "
          f"p90 {res['edit_p90_ms']} ms ({res['edit_runs']} runs)")
    print(f"didChange -> publishDiagnostics, syntax error: median {res['error_median_ms']} ms, "
          f"p90 {res['error_p90_ms']} ms ({res['error_runs']} runs)")
    print(json.dumps(res))


if __name__ == "__main__":
    main()
