"""`krl cell init BACKUP BACKUP...`: the starter of a cell of several robots (issue 89 item 5;
docs/cells.md): the robots, each with its backup and entry point, and the wires matched where
the backups make them evident, each commented with why.

**Robots.** One per backup, named ``R1``, ``R2``, ... in the order given; its ``program`` is
the backup's cell program (krl/project.py ``cell_program``: ``R1/cell.src``), else the program
whose main routine is named ``CELL`` (a flat export such as ingeniado's ``main.src``, ``DEF
CELL ( )``), else the first of its programs (interp/realprograms.py ``programs_of``), the
others counted in a comment; ``workspace`` the backup.

**Signals.** The ``SIGNAL`` declarations of each backup's ``$config.dat`` (krl/project.py
``config_file``), read by the front end (krl/parsecache.py ``load_file``: parsed and built), over one
``$IN`` or ``$OUT`` bit; a group (``TO``) is left out, a wire joining one output to one input.
The comment of the declaration's line is the signal's I/O text (a backup's ``$config.dat``
comments are its I/O texts).

**Wires** proposed (:func:`propose`), for each ordered pair of robots A, B, A's output to B's input:

* *by name*: a signal declared as an output in A and one of the same name (any case) as an
  input in B: the two programs were written for each other's I/O list;
* *by number*: A's ``$OUT[n]`` and B's ``$IN[n]`` (the same number), both declared, with the
  same non-empty comment (compared without case, spaces and punctuation).

An input is driven by one wire at most (interp/robotcell.py): a later proposal for an input
already driven is written commented out, saying which wire drives it. At most
:data:`krl.limits.MAX_CELL_WIRES` wires. Every text taken from a backup passes through
:func:`krl.terminal.printable` and loses its line breaks (the file is YAML).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from krl.ast import nodes as N
from krl.limits import MAX_CELL_WIRES
from krl.parsecache import load_file
from krl.project import backup_of, cell_program, config_file, find_backups
from krl.source import read_source
from krl.terminal import printable

#: the other entry points named in a robot's comment
MAX_SHOWN_PROGRAMS = 3


@dataclass(frozen=True)
class Declared:
    """A SIGNAL of a backup's ``$config.dat`` over one bit: its name, ``$IN`` or ``$OUT``, the
    bit's number, the declaration's line and the comment of that line ("" when none)."""
    name: str
    array: str
    index: int
    line: int
    comment: str = ""


@dataclass(frozen=True)
class Robot:
    """A robot of the starter: ``name`` (R1, ...), its backup ``root``, its entry point
    ``program``, how many other programs the backup has, its signals and ``$config.dat``."""
    name: str
    root: Path
    program: Path | None
    others: int
    signals: tuple[Declared, ...]
    config: Path | None


@dataclass(frozen=True)
class Proposal:
    """A proposed wire: robot `source`'s output to robot `target`'s input, and ``why``;
    ``driven``: the wire that drives the input already (the proposal is then commented out)."""
    source: str
    output: Declared
    target: str
    input: Declared
    why: str
    driven: str = ""

    def __str__(self) -> str:
        return f"{self.source} $OUT[{self.output.index}] -> {self.target} $IN[{self.input.index}]"


def declared_signals(config: Path) -> list[Declared]:
    """The one-bit ``$IN``/``$OUT`` SIGNALs of the ``$config.dat`` `config`, in file order
    (module docstring). Raises OSError for a file that cannot be read."""
    module = load_file(config).module
    lines = read_source(config).text.splitlines()
    out = []
    for node in module.walk():
        if not isinstance(node, N.SignalDecl) or node.start is None or node.end is not None:
            continue
        array = node.start.sysvar.upper()
        if array not in ("$IN", "$OUT") or node.span is None:
            continue
        line = node.span.line
        text = lines[line - 1] if 0 < line <= len(lines) else ""
        comment = printable(text.split(";", 1)[1].strip())[:120] if ";" in text else ""
        out.append(Declared(printable(node.name)[:64], array, node.start.index, line, comment))
    return out


def _same_text(a: str, b: str) -> bool:
    key_a, key_b = (re.sub(r"[\W_]+", "", s).lower() for s in (a, b))
    return bool(key_a) and key_a == key_b


def propose(robots: list[Robot]) -> list[Proposal]:
    """The wires evident from the robots' signals (module docstring), by name first, then by
    number; each input driven once (later proposals for it carry ``driven``)."""
    found: list[Proposal] = []
    for a in robots:
        for b in robots:
            if a is b:
                continue
            ins = [s for s in b.signals if s.array == "$IN"]
            for out in (s for s in a.signals if s.array == "$OUT"):
                for inp in ins:
                    if out.name.upper() == inp.name.upper():
                        found.append(Proposal(a.name, out, b.name, inp, f"same name {out.name}"))
                    elif out.index == inp.index and _same_text(out.comment, inp.comment):
                        found.append(Proposal(a.name, out, b.name, inp,
                                              f"same number {out.index}, same comment '{out.comment}'"))
    found.sort(key=lambda p: not p.why.startswith("same name"))
    driven: dict[tuple[str, int], Proposal] = {}
    out_list = []
    for p in found:
        key = (p.target, p.input.index)
        if key in driven:
            p = Proposal(p.source, p.output, p.target, p.input, p.why, str(driven[key]))
        else:
            driven[key] = p
        out_list.append(p)
    return out_list[:MAX_CELL_WIRES]


def _entry(root: Path, programs: list[Path]) -> tuple[Path | None, int]:
    """The robot's entry point and how many other programs it has (module docstring)."""
    cell = cell_program(root)
    if cell is None:
        for p in programs:
            try:
                routines = load_file(p).module.routines
            except OSError:
                continue
            if routines and routines[0].name.upper() == "CELL":     # the main routine: the file's first
                cell = p
                break
    if cell is None and programs:
        cell = programs[0]
    others = len([p for p in programs if cell is None or p.resolve() != cell.resolve()])
    return cell, others


def backup_root(folder: Path) -> Path:
    """The KRC backup `folder` is or holds (krl/project.py: the backup at `folder` or above it,
    else the one backup below it, as ``krl run FOLDER`` takes it), else `folder` itself."""
    folder = folder.resolve()
    root = backup_of(folder, folder)
    if root is None:
        below = find_backups(folder)
        root = below[0] if len(below) == 1 else folder
    return root


def robot_of(name: str, root: Path, programs: list[Path]) -> Robot:
    """The :class:`Robot` `name` of the backup `root` (:func:`backup_root`) with its `programs`
    (interp/realprograms.py ``programs_of``)."""
    program, others = _entry(root, programs)
    config = config_file(root)
    signals = tuple(declared_signals(config)) if config is not None else ()
    return Robot(name, root, program, others, signals, config)


def _rel(path: Path, start: Path) -> str:
    return printable(os.path.relpath(path, start).replace(os.sep, "/"))


def _at(robot: Robot, s: Declared, start: Path) -> str:
    where = f"{_rel(robot.config, start)}:{s.line}" if robot.config is not None else "?"
    return f"{robot.name} {s.name} {s.array}[{s.index}] ({where}{'; ' + s.comment if s.comment else ''})"


def starter(robots: list[Robot], start: Path) -> str:
    """The text of the starter cell file of `robots` (YAML), its paths relative to the folder
    `start` where the file is to be written."""
    out = ["# Starter cell of several robots written by `krl cell init` (issue 89; docs/cells.md).",
           "# Each robot runs its backup's entry point; the wires below are proposed from the backups'",
           "# $config.dat (a SIGNAL output in one and an input of the same name in another, or the same",
           "# number with the same comment): check each, wire the rest by hand. Run: krl run THIS_FILE",
           "robots:"]
    for r in robots:
        if r.program is None:
            out.append(f"  # {r.name}: {_rel(r.root, start)} has no program")
            continue
        out.append(f"  {r.name}: {{program: {_rel(r.program, start)}, workspace: {_rel(r.root, start)}}}")
        if r.others:
            out.append(f"  #   {r.others} other program(s) of this backup may be named instead")
    by_name = {r.name: r for r in robots}
    wires = propose([r for r in robots if r.program is not None])
    out.append("wires:" if any(not p.driven for p in wires) else "wires: []")
    if not wires:
        out.append("  # (no output of one backup matches an input of another by name or by number and comment)")
    for p in wires:
        out.append(f"  # {p.why}: {_at(by_name[p.source], p.output, start)} -> {_at(by_name[p.target], p.input, start)}")
        if p.driven:
            out.append(f"  # - {p}      # not wired: {p.target} $IN[{p.input.index}] is driven by {p.driven}")
        else:
            out.append(f"  - {p}")
    return "\n".join(out) + "\n"
