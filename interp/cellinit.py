"""`krl cell init BACKUP [PROGRAM]`: a starter cell file (issue 22, "The cell").

It lists every input that the program(s) read — in ``WAIT FOR``, the conditions of ``IF``,
``WHILE``, ``REPEAT ... UNTIL``, and ``INTERRUPT DECL ... WHEN`` — with the SIGNAL name, its
input, the place it is declared and the comment of that declaration line (``$config.dat``
comments are the I/O texts of a backup), and each with a rule to fill in, commented out.

Names are resolved by the checker (the annotations of krl/semantics: a Name's symbol, a
SIGNAL's declaration), never by matching text. Every text taken from the backup (comments, file
names) passes through :func:`krl.terminal.printable` and loses its line breaks: the file is YAML
whose comments cannot be escaped from. Files of the KUKA system folders (System, Mada, STEU,
``$``-files) and of the project's own BASIS are not read; ``TP`` (P00, the technology packages)
is, since P00's program-number handshake reads cell inputs. The EKI channels and RSI contexts
the programs open are listed in a commented ``network:`` section (docs/network.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from krl.ast import nodes as N
from krl.project import system_folder_of
from krl.terminal import printable



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


def _conditions(module: N.Module):
    """(kind, condition) of every WAIT FOR, IF, WHILE, REPEAT and INTERRUPT DECL of `module`."""
    for node in module.walk():
        if isinstance(node, N.WaitFor):
            yield "WAIT FOR", node.cond
        elif isinstance(node, N.If):
            yield "IF", node.cond
        elif isinstance(node, N.While):
            yield "WHILE", node.cond
        elif isinstance(node, N.Repeat):
            yield "UNTIL", node.cond
        elif isinstance(node, N.InterruptDecl):
            yield "INTERRUPT", node.when


def _line_comment(path: str, line: int, cache: dict) -> str:
    if path not in cache:
        try:
            from krl.source import read_source  # noqa: PLC0415

            cache[path] = read_source(path).text.splitlines()
        except Exception:  # noqa: BLE001 - an unreadable file: no comment
            cache[path] = []
    lines = cache[path]
    if not 0 < line <= len(lines):
        return ""
    text = lines[line - 1]
    return printable(text.split(";", 1)[1].strip())[:120] if ";" in text else ""


def _skipped(path: str, root: Path) -> bool:
    p = Path(path)
    try:
        rel = p.resolve().relative_to(root.resolve())
    except ValueError:
        return True        # the project's BASIS, or a file outside the backup
    # KUKA's system folders (krl/project.py), but TP: P00's handshake reads cell inputs
    return p.name.startswith("$") or system_folder_of(rel) not in (None, "tp")


def inputs_read(rt, root: Path) -> list[InputUse]:
    """The inputs read by the modules of the run `rt` (an :class:`interp.runtime.core.Runtime`
    built for the program) that lie in the backup `root`, in order of first reading."""
    found: dict[str, InputUse] = {}
    cache: dict = {}
    for m in rt.program.modules:
        src = m.unit.src
        if src is None or _skipped(src.path, root):
            continue
        shown = printable(str(Path(src.path).resolve().relative_to(root.resolve())))
        for kind, cond in _conditions(src.module):
            for e in cond.walk():
                use = _input(e, root, cache)
                if use is None:
                    continue
                use = found.setdefault(use.name, use)
                place = f"{shown}:{e.span.line} ({kind})"
                if place not in use.reads:
                    use.reads.append(place)
    return list(found.values())


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
        try:
            declared = printable(str(Path(path).resolve().relative_to(root.resolve())))
        except ValueError:
            declared = printable(Path(path).name)
        declared += f":{decl.span.line}"
    comment = _line_comment(path, decl.span.line, cache) if path else ""
    return InputUse(sym.name.upper(), addr, declared, comment, group=b is not None)


NETWORK_CALLS = {"EKI_INIT": "eki", "EKI_LOAD": "eki", "RSI_CREATE": "rsi", "RSI_LOAD": "rsi"}


def network_opened(rt, root: Path) -> list[tuple[str, str, str]]:
    """(kind, name, where) of every EKI channel and RSI context the modules of `rt` in the
    backup `root` open (``EKI_Init("NAME")``, ``RSI_CREATE("NAME", ...)``; a name held in a
    global CHAR array is read from its data list), in order of first use."""
    from interp.run import global_value  # noqa: PLC0415

    from interp.runtime.values import Arr  # noqa: PLC0415

    found: dict[tuple[str, str], tuple[str, str, str]] = {}
    main = Path(rt.program.main_path).stem
    for m in rt.program.modules:
        src = m.unit.src
        if src is None or _skipped(src.path, root):
            continue
        shown = printable(str(Path(src.path).resolve().relative_to(root.resolve())))
        for node in src.module.walk():
            if not isinstance(node, N.Call) or node.name.upper() not in NETWORK_CALLS or not node.args:
                continue
            arg = node.args[0]
            name = None
            if isinstance(arg, N.StrLit):
                name = arg.value
            elif isinstance(arg, (N.Name, N.Index)):
                base = arg if isinstance(arg, N.Name) else arg.base
                if isinstance(base, N.Name):
                    v = global_value(rt, main, base.name)
                    name = v.text() if isinstance(v, Arr) else None
            if not name:
                continue
            kind = NETWORK_CALLS[node.name.upper()]
            key = (kind, name.upper())
            if key not in found:
                found[key] = (kind, printable(name)[:64], f"{shown}:{node.span.line}")
    return list(found.values())


def _network_lines(opened: list[tuple[str, str, str]], root: Path) -> list[str]:
    """The commented `network:` section of the starter (docs/network.md)."""
    from net.ekiconfig import find_config  # noqa: PLC0415
    from net.rsi import find_context  # noqa: PLC0415

    if not opened:
        return []
    out = ["# network:            # the partners (docs/network.md); without this key every EKI channel",
           "#                     # stays \"not connected\" and the run is not paced to the wall clock"]
    eki = [o for o in opened if o[0] == "eki"]
    if eki:
        out.append("#   eki:")
        for _, name, where in eki:
            cfg = find_config(name, None, root)
            note = f"config {printable(str(cfg.relative_to(root)))}" if cfg is not None else \
                "no Config/User/Common/EthernetKRL/" + name + ".xml in the backup: name one with config:"
            out.append(f"#     {name}: {{address: 127.0.0.1:54600}}   # opened at {where}; {note}")
    for _, name, where in [o for o in opened if o[0] == "rsi"]:
        ctx = find_context(name, None, root)
        note = f"context {printable(str(ctx.relative_to(root)))}" if ctx is not None else \
            "no SensorInterface/" + name + ".rsi.xml in the backup: name one with config:"
        out.append(f"#   rsi: {{address: 127.0.0.1:49152}}   # the sensor; context {name} created at {where}; {note}")
    return out


def starter(uses: list[InputUse], programs: list[str], own_robot: bool = True,
            network: list[str] = ()) -> str:
    """The text of the starter cell file (YAML; every rule commented out). `own_robot`: the
    backup has machine data of its own (else the file asks for the cell's robot)."""
    from robot.machine import library_robots  # noqa: PLC0415

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
           robot,
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
        for place in u.reads[:8]:
            out.append(f"  #   read at {place}")
        if len(u.reads) > 8:
            out.append(f"  #   ... and {len(u.reads) - 8} more places")
        key = u.name if not u.name.startswith("$") else f"\"{u.name}\""
        value = "0   # a number: the group's bits" if u.group else "true"
        out += ["  # - when: \"TRUE\"", "  #   after: 1.0", f"  #   set: {{{key}: {value}}}", ""]
    return "\n".join(out).rstrip() + "\n"


def cell_init(root: Path, programs: list[Path]) -> str:
    """The starter cell file for `programs` of the backup `root` (see the module docstring)."""
    from interp.run import make_runtime  # noqa: PLC0415
    from robot.machine import load_machine  # noqa: PLC0415

    found: dict[str, InputUse] = {}
    opened: dict[tuple[str, str], tuple[str, str, str]] = {}
    covered: set[str] = set()
    for prog in programs:
        if str(prog.resolve()) in covered:
            continue        # its module was loaded with an earlier program's files (one backup)
        # the starter reads inputs and moves no robot: the backup's machine data are not read
        # (a robot the model refuses must not stop it; docs/robot.md), the default robot stands in
        rt, _ = make_runtime(prog, mujoco=False, check=False, robot=load_machine())
        covered |= {str(Path(m.unit.src.path).resolve()) for m in rt.program.modules if m.unit.src is not None}
        for u in inputs_read(rt, root):
            have = found.setdefault(u.name, u)
            if have is not u:
                have.reads += [r for r in u.reads if r not in have.reads]
        for o in network_opened(rt, root):
            opened.setdefault((o[0], o[1].upper()), o)
    shown = []
    for p in programs:
        try:
            shown.append(str(p.resolve().relative_to(root.resolve())))
        except ValueError:
            shown.append(p.name)
    from krl.project import machine_data_file  # noqa: PLC0415

    return starter(list(found.values()), shown, own_robot=machine_data_file(root) is not None,
                   network=_network_lines(list(opened.values()), root))
