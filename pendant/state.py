"""What the pendant page shows, read from the engine on the engine's thread (pendant/engine.py
``krl/state``): the status line (with the stop's reason, number, text and place, and how a run
ended), the pointers, the threads, the message window (the controller's own messages, then the
program's KRL messages) and the simulator's notes, the I/O by number and SIGNAL name, the watch
list, the actual position.

Every text here is data for the page (JSON): the page writes it with ``textContent``, never
as markup (pendant/web/src/main.js).
"""

from __future__ import annotations

from pathlib import Path

from krl.limits import MAX_WEB_EXPRESSION_CHARS, MAX_WEB_WATCHES
from .engine import MESSAGE_TYPES, evaluate, run_time_error
from interp.debug.view import thread_list
from krl.ast import nodes as N
from interp.debug.values import value_text
from interp.runtime.errors import KrlRuntimeError
from krl.source import decode_bytes

#: I/O shown always (the rest: declared as a SIGNAL, or TRUE)
IO_ALWAYS = 16
FRAME_KEYS = ("X", "Y", "Z", "A", "B", "C")


def snapshot(eng, core, watch: list) -> dict:
    """The page's state (engine thread): ``eng`` the pendant's :class:`pendant.engine.Engine`
    (notes, signals), ``core`` its run-control engine, ``watch`` the watched expressions.
    ``seq`` numbers the snapshots in the order the engine thread took them
    (``Engine.snapshots``): the server never pushes one older than a snapshot it pushed
    already (pendant/server.py ``Pendant._push_state``)."""
    rt = core.rt
    eng.snapshots += 1
    out = {"seq": eng.snapshots, "state": core.state, "pointers": core.pointers() if rt is not None else {},
           "messages": message_rows(eng, rt)}
    if rt is None:
        return out
    if eng.signals is None:
        eng.signals = {}
    signals = eng.signals.get(rt)           # per run: a cell's robots have their own SIGNALs
    if signals is None:
        signals = eng.signals[rt] = signals_of(rt)
    ctl = rt.controller
    store = rt.sysvars.store
    body = core.stop_body or {}
    out.update({
        "modeOp": "EXT" if rt.mode_op == "EX" else rt.mode_op,
        "runMode": rt.stepping.run_mode,
        "override": _num(store.get("$OV_PRO")),
        "time": round(ctl.time, 3),
        "stop": _stop(core, body) if core.state == "stopped" else None,
        "outcome": _outcome(rt) if core.state == "ended" else None,
        "threads": _threads(rt),
        "notes": list(eng.notes),
        "path": {"run": eng.run_no, "points": len(eng.path)},
        "io": _io(rt, signals),
        "position": _position(eng, rt),
        "watch": _watch(core, watch),
    })
    return out


def message_rows(eng, rt) -> list[dict]:
    """The message window: the controller's own messages (pendant/engine.py
    :class:`SystemMessages`, kept across runs), then the KRL messages the program shows
    (interp/runtime/messages.py), each with its ``type`` as the smartHMI names it."""

    rows = [{**m, "type": MESSAGE_TYPES[m["kind"]], "softkeys": []} for m in eng.system.rows()]
    if rt is not None:
        rows += [{"handle": m.handle, "kind": m.kind, "type": MESSAGE_TYPES.get(m.kind, m.kind.lower()),
                  "origin": m.module, "text": m.text, "module": m.module, "number": m.number,
                  "softkeys": m.softkeys, "time": round(m.time, 3), "krl": True}
                 for m in rt.messages.shown]
    return rows


def _stop(core, body: dict) -> dict:
    """Why the program stands: the stop's ``reason`` and ``description`` (the engine's, e.g.
    "run-time error (1422)"), and for a run-time error its ``text``, ``number``, ``path`` and
    ``line`` (the statement that failed)."""
    out = {"reason": body.get("reason"), "description": body.get("description"), "text": body.get("text")}
    err = core.stop_error
    if err is not None:

        e = run_time_error(core.rt, core.stop_task, err)
        out.update({"number": e["number"], "text": e["text"], "path": e["path"], "line": e["line"],
                    "module": Path(e["path"]).name if e["path"] else ""})
    return out


def _outcome(rt) -> dict | None:
    """How the run ended (interp/runtime/core.py RunResult): ``reason`` (completed, error,
    halt, deadlock, max_sim_time, ...), ``text``, ``number``, ``path``, ``line``."""
    res = getattr(rt, "result", None)
    if res is None:
        return None
    return {"reason": res.reason, "text": res.text or "", "number": res.error.number if res.error is not None else None,
            "path": str(res.file) if res.file else None, "line": res.line}


def _num(v):
    return v if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def _threads(rt) -> list[dict]:

    out = []
    try:
        threads = thread_list(rt)
    except Exception:  # noqa: BLE001 - a thread list between two cycles may be incomplete
        return out
    for tid, name, _task, frames in threads:
        f = frames[0] if frames else None
        path = str(f.module.path) if f is not None and f.module is not None else None
        out.append({"id": tid, "name": name, "routine": f.name if f is not None else None,
                    "path": path, "line": f.line if f is not None else None})
    return out


def signals_of(rt) -> list[dict]:
    """The SIGNAL declarations the program sees (global scope: $config.dat and public data
    lists), read from the checked AST (nothing is evaluated, so the run is not touched): name,
    I/O (``$IN``/``$OUT``/``$ANIN``/``$ANOUT``), first and last index, and the long text (the
    comment of the declaration line, as KUKA's WorkVisual writes them)."""

    scope = rt.program.ws.global_scope
    out = []
    lines_cache: dict[str, list[str]] = {}
    for _key, sym in sorted(scope.values.items()):
        d = sym.decl
        if sym.kind != "signal" or not isinstance(d, N.SignalDecl) or d.start is None:
            continue
        out.append({"name": sym.name, "io": d.start.sysvar.upper(), "first": d.start.index,
                    "last": d.end.index if d.end is not None else None, "text": _long_text(sym, lines_cache)})
        if len(out) >= 2000:
            break
    return out


def _long_text(sym, cache: dict) -> str:
    span = getattr(sym.decl, "span", None)
    if span is None or not span.file:
        return ""
    lines = cache.get(span.file)
    if lines is None:
        try:
            data = Path(span.file).read_bytes()[:4 * 1024 * 1024]
            lines = decode_bytes(data)[0].splitlines()
        except Exception:  # noqa: BLE001 - a long text is optional
            lines = []
        cache[span.file] = lines
    if not 1 <= span.line <= len(lines):
        return ""
    text = lines[span.line - 1]
    i = text.find(";")
    return text[i + 1:].strip()[:80] if i >= 0 else ""


def _io(rt, signals: list[dict]) -> dict:
    io = rt.controller.io
    names: dict[tuple[str, int], list[str]] = {}
    texts: dict[tuple[str, int], str] = {}
    for sig in signals:
        if sig["last"] is None and sig["io"] in ("$IN", "$OUT"):
            key = (sig["io"], sig["first"])
            names.setdefault(key, []).append(sig["name"])
            if sig["text"] and key not in texts:
                texts[key] = sig["text"]
    rows = {}
    for arr, get in (("$IN", io.get_in), ("$OUT", io.get_out)):
        shown = set(range(1, IO_ALWAYS + 1)) | {n for (a, n) in names if a == arr}
        rows[arr] = [{"index": n, "value": bool(get(n)), "names": names.get((arr, n), []),
                      "text": texts.get((arr, n), "")} for n in sorted(shown) if 1 <= n <= 8192]
    return rows


def _frame(v) -> dict | None:
    f = getattr(v, "f", None)
    if not isinstance(f, dict):
        return None
    out = {}
    for k in FRAME_KEYS + ("S", "T"):
        x = f.get(k)
        if isinstance(x, (int, float)) and not isinstance(x, bool):
            out[k] = round(float(x), 3)
    return out


def _position(eng, rt) -> dict:
    ctl = rt.controller
    store = rt.sysvars.store
    key = (ctl.cycle, ctl.time, tuple(float(v) for v in ctl.actual.axis_act()))
    cached = getattr(eng, "pos_cache", None)        # $POS_ACT is the same until the robot moves
    if cached is not None and cached[0] == key:
        pos = cached[1]
    else:
        try:
            pos = ctl.actual.pos_act()
        except Exception:  # noqa: BLE001 - a pose outside the model shows as unknown
            pos = None
        eng.pos_cache = (key, pos)
    return {"axes": [round(float(v), 4) for v in ctl.actual.axis_act()],
            "pos": {k: round(float(v), 3) for k, v in pos.items()} if pos else None,
            "base": _frame(store.get("$BASE")), "tool": _frame(store.get("$TOOL"))}


def _watch(core, exprs: list) -> list[dict]:

    out = []
    for text in exprs[:MAX_WEB_WATCHES]:
        text = str(text)[:MAX_WEB_EXPRESSION_CHARS]
        try:
            out.append({"expr": text, "value": value_text(evaluate(core, text))})
        except KrlRuntimeError as exc:
            out.append({"expr": text, "error": exc.message[:200]})
        except Exception as exc:  # noqa: BLE001 - the watch shows why it has no value
            out.append({"expr": text, "error": str(exc)[:200]})
    return out
