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
    arrived: asyncio.Queue = asyncio.Queue()

    @client.feature(L.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def on_diagnostics(params: L.PublishDiagnosticsParams):
        arrived.put_nowait((time.perf_counter(), params))

    await client.start_io(sys.executable, "-m", "krl.lsp")
    await client.initialize_async(L.InitializeParams(capabilities=L.ClientCapabilities(), root_uri=folder.as_uri()))
    client.initialized(L.InitializedParams())

    async def until(version: int) -> tuple[float, list]:
        while True:
            t, params = await asyncio.wait_for(arrived.get(), 600)
            if params.uri == uri and params.version == version:
                return t, params.diagnostics

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


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m krl.lsp.bench", description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=3000)
    ap.add_argument("--runs", type=int, default=20)
    args = ap.parse_args(argv)
    res = asyncio.run(measure(args.lines, args.runs))
    print(f"{res['lines']} lines; open: {res['open_ms']} ms")
    print(f"didChange -> publishDiagnostics, valid edit:  median {res['edit_median_ms']} ms, "
          f"p90 {res['edit_p90_ms']} ms ({res['edit_runs']} runs)")
    print(f"didChange -> publishDiagnostics, syntax error: median {res['error_median_ms']} ms, "
          f"p90 {res['error_p90_ms']} ms ({res['error_runs']} runs)")
    print(json.dumps(res))


if __name__ == "__main__":
    main()
