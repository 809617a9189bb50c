"""`krl cell init BACKUP [PROGRAM]`: a starter cell file (issue 22, "The cell"; issue 34);
`krl cell init --from-run TRACE`: the answers of a ``--inputs auto`` run as rules.

**The starter** lists every input that the program reads — in ``WAIT FOR``, the conditions
of ``IF``, ``WHILE``, ``REPEAT ... UNTIL``, ``INTERRUPT DECL ... WHEN``, and the selector of
``SWITCH`` (``SWITCH Program_PLC``, a SIGNAL group), directly or through the variables assigned
from it (``ParcaTip = GI_ProductType`` then ``IF ParcaTip == 10``: krl/semantics/inputflow.py,
read "through ParcaTip") — with the SIGNAL name, its input, the
place it is declared and the comment of that declaration line (``$config.dat`` comments are
the I/O texts of a backup), and each with a rule to fill in, commented out. For PROGRAM only
what it runs is read: its own routines and every routine it calls (the checker's resolution
of each call, transitively, interrupt routines and TRIGGER actions included), not the whole
backup. An input passed to a routine whose parameter a condition reads
(``WaitPermit(bPermisoEntradaBPAbajo)`` and ``WAIT FOR bPermit`` in the library routine) is
read at that condition "through" the parameter: the parameter flow is followed through any
number of calls. Without PROGRAM every program of the backup is read.

Names are resolved by the checker (the annotations of krl/semantics: a Name's symbol and
storage, a call's routine, a SIGNAL's declaration), never by matching text. Every text taken
from the backup (comments, file names) passes through :func:`krl.terminal.printable` and loses
its line breaks: the file is YAML whose comments cannot be escaped from. Files of the KUKA
system folders (System, Mada, STEU, ``$``-files) and of the project's own BASIS are not read;
``TP`` (P00, the technology packages) is, since P00's program-number handshake reads cell
inputs. Where a backup's files lie flat, a file's header lines say whose it is (krl/project.py
rule 7, ``kuka_folder``): ``&PARAM DISKPATH`` naming TP is read, KUKA's delivery header (which
names no folder: bas.src, tm_bib.src, and P00 too) is not. Every rule the file writes is valid YAML and a valid rule once its ``#`` are taken
away (tests/robot/test_cell.py uncomments them). The EKI channels and RSI contexts the
programs open are listed in a commented ``network:`` section (docs/network.md).

**From a run** (:func:`from_run`): each ``answer`` event of the trace (interp/runtime/autocell.py)
becomes a commented rule that sets the same inputs; its ``when`` is the last output the program
switched on before the answer (the request a PLC would answer), else ``"TRUE"``; ``after`` is
the time from that output to the answer; the comment names the statement it released, its
condition and the time.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from krl.ast import nodes as N
from krl.project import kuka_folder, machine_data_file
from krl.semantics.resolve import LOCAL, ROUTINE
from krl.source import read_source
from krl.terminal import printable
from net.partners import PARTNERS
from interp.run import global_value, load_program, run_spec
from interp.runtime.autocell import input_flow
from interp.runtime.values import Arr
from krl.semantics.inputflow import production_values, var_key
from robot.machine import library_robots, load_machine

#: places listed per input; the rest are counted
MAX_PLACES = 8


@dataclass
class InputUse:
    """One input the programs read: ``name`` (SIGNAL name, or ``$IN[n]``), ``address``
    (``$IN[n]`` or ``$IN[a] TO $IN[b]``), where it is declared and its comment, where it is read."""

    name: str
    address: str
    declared: str = ""
    comment: str = ""
    group: bool = False
    reads: list[str] = field(default_factory=list)
    #: the value a producing cell gives it (krl/semantics/inputflow.py Decision) or None
    given: object = None


def _conditions(routine: N.Routine):
    """(kind, condition) of every WAIT FOR, IF, WHILE, REPEAT, SWITCH and INTERRUPT DECL of
    `routine`."""
    for node in routine.walk():
        if isinstance(node, N.WaitFor):
            yield "WAIT FOR", node.cond
        elif isinstance(node, N.If):
            yield "IF", node.cond
        elif isinstance(node, N.While):
            yield "WHILE", node.cond
        elif isinstance(node, N.Repeat):
            yield "UNTIL", node.cond
        elif isinstance(node, N.Switch):
            yield "SWITCH", node.selector
        elif isinstance(node, N.InterruptDecl):
            yield "INTERRUPT", node.when


def _calls(routine: N.Routine):
    for node in routine.walk():
        if isinstance(node, N.Call):
            yield node


def _callee(call: N.Call):
    """(owner module index, Routine) a call runs, or None (a built-in, nothing declares it)."""
    c = call.ann.callee if call.ann is not None else None
    return (c.owner, c.routine) if c is not None and c.kind == ROUTINE else None


def _param_index(e, routine: N.Routine) -> int | None:
    """The parameter of `routine` that the Name `e` is, or None."""
    if not isinstance(e, N.Name) or e.ann is None or e.ann.place is None:
        return None
    st = e.ann.place
    layout = routine.ann.layout if routine.ann is not None else None
    if st.kind == LOCAL and layout is not None and st.slot < layout.nparams:
        return st.slot
    return None


def _line_comment(path: str, line: int, cache: dict) -> str:
    if path not in cache:
        try:
            cache[path] = read_source(path).text.splitlines()
        except Exception:  # noqa: BLE001 - an unreadable file: no comment
            cache[path] = []
    lines = cache[path]
    if not 0 < line <= len(lines):
        return ""
    text = lines[line - 1]
    return printable(text.split(";", 1)[1].strip())[:120] if ";" in text else ""


def _skipped(path: str, root: Path) -> bool:
    """True for a file the starter does not read: outside the backup `root` (the project's
    BASIS), a ``$``-file, or KUKA's (krl/project.py rule 7 ``kuka_folder``: by its folder, else
    by its header lines where the files lie flat), but TP's: P00's handshake reads cell inputs."""
    p = Path(path).resolve()
    base = root.resolve()
    if base != p and base not in p.parents:
        return True        # the project's BASIS, or a file outside the backup
    return p.name.startswith("$") or kuka_folder(p, base) not in (None, "tp")


def reachable(loaded, program: Path | None) -> list[tuple[N.Routine, object]]:
    """(routine, unit) of every routine the program `program` runs — its main routine and
    every routine reached by a resolved call, transitively — or of every routine of the run's
    files when `program` is None; in a stable order."""
    units = loaded.program.ws.units
    where: dict[int, object] = {}
    for u in units:
        if u.src is not None and u.src.module is not None:
            for r in u.src.module.routines:
                where[id(r)] = u
    if program is None:
        return [(r, where[id(r)]) for u in units if u.src is not None and u.src.module is not None
                for r in u.src.module.routines]
    m = loaded.program.module_of(program)
    if m is None or m.main is None:
        return []
    todo = [m.main]
    seen: dict[int, N.Routine] = {}
    while todo:
        r = todo.pop()
        if id(r) in seen or id(r) not in where:
            continue
        seen[id(r)] = r
        for call in _calls(r):
            got = _callee(call)
            if got is not None:
                todo.append(got[1])
    return [(r, where[id(r)]) for r in seen.values()]


def _param_reads(routines: list[tuple[N.Routine, object]]) -> dict:
    """id(routine) -> {parameter index: [(kind, Name node, file)]}: the conditions that read
    each parameter, directly or in a routine it is passed on to (a fixed point over the calls)."""
    reads: dict[int, dict[int, list]] = {}
    for r, u in routines:
        d = reads.setdefault(id(r), {})
        for kind, cond in _conditions(r):
            for e in cond.walk():
                k = _param_index(e, r)
                if k is not None:
                    d.setdefault(k, []).append((kind, e, u.src.path))
    changed = True
    while changed:
        changed = False
        for r, _u in routines:
            d = reads[id(r)]
            for call in _calls(r):
                got = _callee(call)
                if got is None or id(got[1]) not in reads:
                    continue
                inner = reads[id(got[1])]
                for j, a in enumerate(call.args):
                    k = _param_index(a, r)
                    if k is None or j not in inner:
                        continue
                    have = d.setdefault(k, [])
                    for item in inner[j]:
                        if item not in have:
                            have.append(item)
                            changed = True
    return reads


def inputs_read(loaded, root: Path, program: Path | None = None) -> list[InputUse]:
    """The inputs read by the routines `program` runs (every routine of the run when None)
    that lie in the backup `root`, in order of first reading (module docstring)."""
    found: dict[str, InputUse] = {}
    cache: dict = {}
    routines = reachable(loaded, program)
    mine = [(r, u) for r, u in routines if u.src is not None and not _skipped(u.src.path, root)]
    params = _param_reads(routines)

    def note(use: InputUse | None, place: str) -> None:
        if use is None:
            return
        use = found.setdefault(use.name, use)
        if place not in use.reads:
            use.reads.append(place)

    fl = input_flow(loaded.program)
    for r, u in mine:
        shown = _shown(u.src.path, root)
        for kind, cond in _conditions(r):
            for e in cond.walk():
                note(_input(e, root, cache), f"{shown}:{e.span.line} ({kind})")
                key = var_key(e, r) if isinstance(e, N.Name) else None
                for a in sorted(fl.depends.get(key, ()) if key is not None else (),
                                key=lambda a: (a.first, a.last or 0)):
                    note(_use_of(a, root, cache), f"{shown}:{e.span.line} ({kind}, through {printable(e.name)})")
        for call in _calls(r):
            got = _callee(call)
            inner = params.get(id(got[1]), {}) if got is not None else {}
            for j, a in enumerate(call.args):
                if a is None or j not in inner:
                    continue
                use = _input(a, root, cache)
                if use is None:
                    continue
                pname = got[1].params[j].name if j < len(got[1].params) else "?"
                for kind, e, path in inner[j]:
                    note(use, f"{_shown(path, root)}:{e.span.line} ({kind}, through parameter {pname} "
                              f"from {shown}:{call.span.line})")
    return list(found.values())


def _use_of(a, root: Path, cache: dict) -> InputUse:
    """The InputUse of an input the flow found (krl/semantics/inputflow.py Input)."""
    if a.last is None and not a.name:
        return InputUse(f"$IN[{a.first}]", f"$IN[{a.first}]")
    addr = f"$IN[{a.first}]" if a.last is None else f"$IN[{a.first}] TO $IN[{a.last}]"
    declared = comment = ""
    if a.declared:
        path, line = a.declared
        declared = _shown(path, root) + f":{line}"
        comment = _line_comment(path, line, cache)
    return InputUse(a.name.upper(), addr, declared, comment, group=a.last is not None)


def _given(loaded, root: Path, program: Path | None, uses: dict) -> None:
    """Sets ``given`` of each InputUse of `uses` (name -> InputUse) that the production search
    decides (krl/semantics/inputflow.py ``production_values``) for `program` (every routine when
    None)."""
    roots = None
    if program is not None:
        m = loaded.program.module_of(program)
        roots = [m.main] if m is not None and m.main is not None else []
    for d in production_values(loaded.program.ws, roots, input_flow(loaded.program)):
        use = _use_of(d.input, root, {})
        use = uses.setdefault(use.name, use)
        if use.given is None:
            use.given = d


def _shown(path: str, root: Path) -> str:
    try:
        return printable(str(Path(path).resolve().relative_to(root.resolve())))
    except ValueError:
        return printable(Path(path).name)


def _input(e: N.Node, root: Path, cache: dict) -> InputUse | None:
    if isinstance(e, N.Index) and isinstance(e.base, N.Name) and e.base.name.upper() == "$IN" \
            and len(e.indices) == 1 and isinstance(e.indices[0], N.IntLit):
        n = e.indices[0].value
        return InputUse(f"$IN[{n}]", f"$IN[{n}]")
    if not isinstance(e, N.Name) or e.ann is None or e.ann.symbol is None:
        return None
    sym = e.ann.symbol
    decl = sym.decl
    if sym.kind != "signal" or not isinstance(decl, N.SignalDecl) or decl.start is None:
        return None
    if decl.start.sysvar.upper() != "$IN":
        return None
    a = decl.start.index
    b = decl.end.index if decl.end is not None else None
    addr = f"$IN[{a}]" if b is None else f"$IN[{a}] TO $IN[{b}]"
    path = sym.path or (decl.span.file if decl.span is not None else "")
    declared = ""
    if path:
        declared = _shown(path, root) + f":{decl.span.line}"
    comment = _line_comment(path, decl.span.line, cache) if path else ""
    return InputUse(sym.name.upper(), addr, declared, comment, group=b is not None)


def _key(name: str) -> str:
    """A signal name as a YAML flow-mapping key: a SIGNAL name as it is, ``$IN[n]`` quoted."""
    return name if name.replace("_", "A").isalnum() else json.dumps(name)


def _network_calls() -> dict[str, str]:
    """{KRL function: partner key} of the calls that name what a program opens of a network
    partner (net/partner.py ``Partner.opens``: ``EKI_Init`` a channel, ``RSI_CREATE`` a context)."""

    return {call: p.key for p in PARTNERS for call in p.opens}


def network_opened(loaded, root: Path) -> list[tuple[str, str, str]]:
    """(kind, name, where) of every EKI channel and RSI context the modules of `loaded` in the
    backup `root` open (``EKI_Init("NAME")``, ``RSI_CREATE("NAME", ...)``; a name held in a
    global CHAR array is read from its data list), in order of first use."""

    found: dict[tuple[str, str], tuple[str, str, str]] = {}
    calls = _network_calls()
    main = Path(loaded.program.main_path).stem
    for m in loaded.program.modules:
        src = m.unit.src
        if src is None or _skipped(src.path, root):
            continue
        shown = printable(str(Path(src.path).resolve().relative_to(root.resolve())))
        for node in src.module.walk():
            if not isinstance(node, N.Call) or node.name.upper() not in calls or not node.args:
                continue
            arg = node.args[0]
            name = None
            if isinstance(arg, N.StrLit):
                name = arg.value
            elif isinstance(arg, (N.Name, N.Index)):
                base = arg if isinstance(arg, N.Name) else arg.base
                if isinstance(base, N.Name):
                    v = global_value(loaded, main, base.name)
                    name = v.text() if isinstance(v, Arr) else None
            if not name:
                continue
            kind = calls[node.name.upper()]
            key = (kind, name.upper())
            if key not in found:
                found[key] = (kind, printable(name)[:64], f"{shown}:{node.span.line}")
    return list(found.values())


def _network_lines(opened: list[tuple[str, str, str]], root: Path) -> list[str]:
    """The commented `network:` section of the starter (docs/network.md): each partner's lines
    for what the backup opens of it (net/partner.py ``Partner.starter``)."""

    if not opened:
        return []
    out = ["# network:            # the partners (docs/network.md); without this key every EKI channel",
           "#                     # stays \"not connected\" and the run is not paced to the wall clock"]
    for partner in PARTNERS:
        mine = [(name, where) for kind, name, where in opened if kind == partner.key]
        out += [printable(line) for line in partner.starter(mine, root)]
    return out


def starter(uses: list[InputUse], programs: list[str], own_robot: bool = True,
            network: list[str] = ()) -> str:
    """The text of the starter cell file (YAML; every rule commented out, each valid once
    uncommented). `own_robot`: the backup has machine data of its own (else the file asks for
    the cell's robot). `network`: the commented ``network:`` lines."""

    names = ", ".join(library_robots())
    robot = (f"# robot: NAME       # the backup's own robot (its R1/Mada/$machine.dat) runs; a name of "
             f"robot/data overrides it: {names}" if own_robot else
             f"# robot: NAME       # this backup has no R1/Mada/$machine.dat: name the cell's robot "
             f"(robot/data: {names}); without, the KR 6 R900 runs")
    out = ["# Starter cell file written by `krl cell init` (issue 22; robot/cellrules.py, docs/robot.md).",
           "# Programs: " + ", ".join(printable(p) for p in programs),
           "# Every input the programs read is listed with a rule to fill in: uncomment it, write in",
           "# `when` the program's output (or condition) the PLC answers, in `after` its delay (s).",
           "# A rule fires on the rising edge of `when`; run with: krl run PROGRAM --inputs THIS_FILE",
           "# (or let the automatic cell answer: krl run PROGRAM --inputs auto --trace RUN.jsonl, then",
           "# krl cell init --from-run RUN.jsonl writes its answers as rules)",
           robot,
           "# start: XHOME      # where the robot stands at the start (a point name or an E6AXIS literal)",
           "presets:",
           "  autoext: false      # true: Automatic External ($I_O_ACTCONF; P00 of a cell program)",
           "  # pgno: 1           # the program number the PLC answers in P00's handshake",
           *network,
           "rules:"]
    if not uses:
        out.append("  # (the programs read no input in a condition)")
    for u in uses:
        head = f"  # {u.name}" + (f" = {u.address}" if u.address != u.name else "")
        if u.declared:
            head += f"   declared {u.declared}"
        if u.comment:
            head += f"   ; {u.comment}"
        out.append(head)
        for place in u.reads[:MAX_PLACES]:
            out.append(f"  #   read at {place}")
        if len(u.reads) > MAX_PLACES:
            out.append(f"  #   ... and {len(u.reads) - MAX_PLACES} more places")
        value = "0}   # a number: the group's bits, bit 0 on its first input" if u.group else "true}"
        if u.given is not None:
            d = u.given
            out.append(f"  #   a producing cell gives {_value(d.value).upper()}: the program's production path "
                       f"at {printable(_shown_name(d.file))}:{d.line} ({d.kind}) needs it")
            value = f"{_value(d.value)}}}"
        after = "0.0" if u.given is not None else "1.0"
        out += ["  # - when: \"TRUE\"", f"  #   after: {after}", f"  #   set: {{{_key(u.name)}: {value}", ""]
    return "\n".join(out).rstrip() + "\n"


def cell_init(root: Path, programs: list[Path], whole: bool = False) -> str:
    """The starter cell file for `programs` of the backup `root` (see the module docstring):
    what each program runs; with `whole` (no program asked), every routine of the backup."""

    found: dict[str, InputUse] = {}
    opened: dict[tuple[str, str], tuple[str, str, str]] = {}
    covered: set[str] = set()
    for prog in programs:
        if whole and str(prog.resolve()) in covered:
            continue        # its module was loaded with an earlier program's files (one backup)
        # the starter reads inputs and moves no robot: the backup's machine data are not read
        # (a robot the model refuses must not stop it; docs/robot.md), the default robot stands in
        loaded = load_program(run_spec(prog, mujoco=False, check=False, robot=load_machine()))
        covered |= {str(Path(m.unit.src.path).resolve()) for m in loaded.program.modules if m.unit.src is not None}
        mine = {u.name: u for u in inputs_read(loaded, root, None if whole else prog)}
        _given(loaded, root, None if whole else prog, mine)
        for u in mine.values():
            have = found.setdefault(u.name, u)
            if have is not u:
                have.reads += [r for r in u.reads if r not in have.reads]
                have.given = have.given or u.given
        for o in network_opened(loaded, root):
            opened.setdefault((o[0], o[1].upper()), o)
    shown = []
    for p in programs:
        try:
            shown.append(str(p.resolve().relative_to(root.resolve())))
        except ValueError:
            shown.append(p.name)
    return starter(list(found.values()), shown, own_robot=machine_data_file(root) is not None,
                   network=_network_lines(list(opened.values()), root))


# ---------------------------------------------------------------------- from a run
def from_run(events, source: str = "") -> str:
    """The rules file of the answers of a ``--inputs auto`` run: `events` the trace's events
    (robot/trace.py ``read_trace``), `source` the trace's name for the header (module
    docstring). Every rule is commented out, each valid once uncommented."""
    out = ["# Cell rules from the answers of an automatic cell (krl run --inputs auto), written by",
           f"# `krl cell init --from-run{' ' + printable(source) if source else ''}` (issue 34; robot/cellrules.py).",
           "# Each answer set the inputs a starving program waited for. Uncomment a rule to keep it and",
           "# write in `when` what the PLC really answers (the program's output that asks for it).",
           "rules:"]
    last_on: tuple[float, str] | None = None
    n = 0
    seen: set = set()
    for ev in events:
        kind = ev.get("kind")
        if kind == "io" and ev.get("source") in ("program", "trigger") and ev.get("value") is True \
                and str(ev.get("signal", "")).startswith("$OUT["):
            last_on = (float(ev["t"]), str(ev["signal"]))
        if kind != "answer":
            continue
        sets = ev.get("sets") or {}
        names = ev.get("names") or {}
        t = float(ev["t"])
        items = []
        for sig, v in sets.items():
            name = names.get(sig)
            if name and name.replace("_", "A").isalnum():
                items.append(f"{_key(printable(name).upper())}: {_value(v)}")
            elif sig.count("[") == 1 and ".." not in sig:
                items.append(f"{_key(printable(sig))}: {_value(v)}")
            else:       # a group without a SIGNAL name: its bits
                a, b = sig[4:-1].split("..")
                for i, bit in enumerate(range(int(a), int(b) + 1)):
                    items.append(f"{_key(f'$IN[{bit}]')}: {_value(bool((int(v) >> i) & 1))}")
        if not items:
            continue
        when, after = '"TRUE"', 0.5
        if last_on is not None and last_on[0] <= t:
            when, after = json.dumps(last_on[1]), round(t - last_on[0], 3)
        key = (when, tuple(items))
        place = f"{printable(Path(str(ev.get('file', ''))).name)}:{ev.get('line')}"
        out.append(f"  # at {t:.3f} s: {printable(str(ev.get('statement', '')))} at {place}"
                   + (f": {printable(str(ev.get('condition')))[:100]}" if ev.get("condition") else ""))
        if key in seen:
            out.append("  # (the same rule as above)")
            continue
        seen.add(key)
        n += 1
        out += [f"  # - when: {when}", f"  #   after: {after}", f"  #   set: {{{', '.join(items)}}}", ""]
    if n == 0:
        out.append("  # (the run has no answers of the automatic cell: was it run with --inputs auto and --trace?)")
    return "\n".join(out).rstrip() + "\n"


def _shown_name(path: str) -> str:
    return str(path).replace("\\", "/").rsplit("/", 1)[-1]


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(int(v))
