"""The assembler (text -> :class:`Code`) and the disassembler (:class:`Code` -> text).

The readable assembly is the compiler's output and the VM's debugging view (clox's
``debug.c``, CPython's ``dis``). One routine is one block::

    .routine PROG DEF                       ; name, DEF or DEFFCT
    .file "/path/prog.src"
    .locals I S R                           ; frame slots (parameters first): operands s, v by name
    .temps 3                                ; temporaries (FOR state, SWITCH selector)
        .at -                               ; error region of the following instructions
        ; 4: s = 0                          ; the source line of each statement
        STMT 4
        CONST 0
        STORE_LOCAL S
    L1:
        ...
    .end

``.at LINE G Ln`` marks a *guarded* statement part (errors are placed on LINE and, after
ON_ERROR_PROCEED, execution goes on at Ln), ``.at LINE A`` a part whose errors are only
placed on LINE, ``.at -`` no placement (the runtime places the error on the statement
that ran last, as the tree interpreter does). These regions are the line table: the VM
maps an instruction address back to its source line through them.

Both directions go through one intermediate listing (:func:`format_listing`), so
``disassemble(assemble(text)) == text`` for any text the compiler writes.
"""

from __future__ import annotations

import json
import linecache
import re
from dataclasses import dataclass, field

from krl.terminal import printable

from krl.semantics.advance import StmtInfo
from interp.runtime.values import Channel, EnumValue

from . import opcodes as O


class AsmError(Exception):
    pass


@dataclass
class Region:
    kind: str          # "G" guarded, "A" annotate only
    line: int
    end: int = -1      # address where a guarded statement ends (ON_ERROR_PROCEED)


@dataclass
class Code:
    """One assembled routine: flat instruction words + pools + line table (the encoded form
    of a listing: the assembler's round trip text -> words -> text; the VM runs the linked
    form of interp/vm/vm.py instead)."""
    name: str
    kind: str = "DEF"
    file: str = ""
    words: list = field(default_factory=list)     # opcodes and operands (ints)
    consts: list = field(default_factory=list)    # constant pool
    infos: list = field(default_factory=list)     # StmtInfo per statement operand
    lnames: list = field(default_factory=list)    # frame slots
    mnames: list = field(default_factory=list)    # module slots
    gnames: list = field(default_factory=list)    # global slots
    ntemps: int = 0
    regions: list = field(default_factory=list)   # per word: Region or None


# Operand kinds (interp/vm/declarations.py KINDS) by how the text writes them: labels (jump
# targets, thunk entries), frame slots (by their .locals name), names (a resolved fact: by its
# name), and the kinds whose encoded word is an index into the constant pool.
_LABELS = "lh"
_SLOTS = "sv"
_NAMES = "nmgyokrap"
_POOLED = "cnfyokrap"
assert set(_LABELS + _SLOTS + _NAMES + _POOLED + "ixt") == set(O.OPERAND_KINDS), "an operand kind without a text form"


# ---------------------------------------------------------------------------- literals
_PLAIN = re.compile(r'[^\s"\-;][^\s";]*\Z')
_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[^\s;]+')


def fmt_const(v) -> str:
    if v is None:
        return "NONE"
    if v is True:
        return "TRUE"
    if v is False:
        return "FALSE"
    if isinstance(v, EnumValue):
        return "#" + v.name
    if isinstance(v, Channel):
        return ":" + v.name             # a channel argument (COPEN(:SER_3, HANDLE))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        r = repr(v)
        return r if any(c in r for c in ".en") else r + ".0"
    if isinstance(v, str):
        return json.dumps(v)
    raise AsmError(f"constant {v!r} has no assembly form")


def parse_const(tok: str):
    if tok == "NONE":
        return None
    if tok == "TRUE":
        return True
    if tok == "FALSE":
        return False
    if tok.startswith(":"):
        return Channel(tok[1:])
    if tok.startswith("#"):
        return EnumValue(tok[1:])
    if tok.startswith('"'):
        return json.loads(tok)
    try:
        return int(tok)
    except ValueError:
        pass
    try:
        return float(tok)
    except ValueError:
        raise AsmError(f"bad constant {tok}") from None


def fmt_name(s) -> str:
    """A name operand as text (``-`` for None); a resolved fact (a place, a Callee, a STRUC)
    is written by its name."""
    if s is None:
        return "-"
    if not isinstance(s, str):
        s = s.name
    return s if _PLAIN.match(s) else json.dumps(s)


def parse_name(tok: str):
    if tok == "-":
        return None
    if tok.startswith('"'):
        return json.loads(tok)
    return tok


def fmt_flags(s: str) -> str:
    return s or "-"


def const_key(v):
    return (type(v).__name__, v.name if isinstance(v, EnumValue) else v)


def source_comment(file: str, line: int) -> str:
    # printable: a form feed, U+0085, U+2028... in the line stays on the comment's line
    text = printable(linecache.getline(file, line).strip()) if file else ""
    return f"; {line}: {text}" if text else f"; {line}"


# ---------------------------------------------------------------------------- listing
@dataclass
class Listing:
    """The intermediate form shared by the compiler, the assembler and the disassembler:
    a routine header and a list of instructions ``(name, [operand values], region)`` with
    labels given as ``"Lx"`` strings (jump operands and region ends)."""
    name: str
    kind: str
    file: str
    lnames: list
    ntemps: int
    instrs: list = field(default_factory=list)    # (opname, operands, region-or-None)
    labels: dict = field(default_factory=dict)    # label -> instruction index


def format_listing(lst: Listing) -> str:
    """The canonical text of a listing: labels renamed L1, L2... in address order."""
    targets: set = set()
    for name, ops, reg in lst.instrs:
        kinds = O.BY_NAME[name].operands
        for k, v in zip(kinds, ops):
            if k in _LABELS:
                targets.add(lst.labels[v])
        if reg is not None and reg.kind == "G":
            targets.add(lst.labels[reg.end])
    rename = {}
    for i, pos in enumerate(sorted(targets), 1):
        rename[pos] = f"L{i}"
    lab = {k: rename[v] for k, v in lst.labels.items() if v in rename}
    out = [f".routine {lst.name} {lst.kind}", f".file {json.dumps(lst.file)}"]
    if lst.lnames:
        out.append(".locals " + " ".join(lst.lnames))
    if lst.ntemps:
        out.append(f".temps {lst.ntemps}")
    cur = "?"
    for idx, (name, ops, reg) in enumerate(lst.instrs + [("", [], None)]):
        if idx in rename:
            out.append(rename[idx] + ":")
        if not name:
            break
        rtext = "-" if reg is None else (f"{reg.line} G {lab[reg.end]}" if reg.kind == "G" else f"{reg.line} A")
        if rtext != cur:
            out.append("    .at " + rtext)
            cur = rtext
        info = O.BY_NAME[name]
        parts = []
        for k, v in zip(info.operands, ops):
            if k in _LABELS:
                parts.append(lab[v])
            elif k == "c":
                parts.append(fmt_const(v))
            elif k in _SLOTS:
                parts.append(fmt_name(lst.lnames[v]))
            elif k in _NAMES:
                parts.append(fmt_name(v))
            elif k == "f":
                parts.append(fmt_flags(v))
            elif k == "x":
                line, flags = v
                parts.append(f"{line}/{flags}" if flags else str(line))
            else:
                parts.append(str(v))
        if name in ("STMT", "STMT_G"):
            out.append("    " + source_comment(lst.file, ops[0][0]))
        out.append(("    " + name + " " + " ".join(parts)).rstrip())
    out.append(".end")
    return "\n".join(out) + "\n"


def parse_listings(text: str) -> list[Listing]:
    out: list[Listing] = []
    cur: Listing | None = None
    region = None
    pending_regions = []   # (instr index, line, kind, label)
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith(";"):
            continue
        toks = _TOKEN.findall(line)
        head = toks[0]
        try:
            if head == ".routine":
                cur = Listing(toks[1], toks[2] if len(toks) > 2 else "DEF", "", [], 0)
                region = None
                pending_regions = []
                out.append(cur)
            elif cur is None:
                raise AsmError("instruction outside .routine")
            elif head == ".file":
                cur.file = json.loads(toks[1])
            elif head == ".locals":
                cur.lnames = toks[1:]
            elif head == ".temps":
                cur.ntemps = int(toks[1])
            elif head == ".at":
                if toks[1] == "-":
                    region = None
                elif toks[2] == "G":
                    region = Region("G", int(toks[1]), toks[3])
                else:
                    region = Region("A", int(toks[1]))
            elif head == ".end":
                cur = None
            elif head.endswith(":"):
                cur.labels[head[:-1]] = len(cur.instrs)
            else:
                info = O.BY_NAME.get(head)
                if info is None:
                    raise AsmError(f"unknown opcode {head}")
                args = toks[1:]
                if len(args) != len(info.operands):
                    raise AsmError(f"{head} takes {len(info.operands)} operands, got {len(args)}")
                ops = []
                for k, t in zip(info.operands, args):
                    if k == "c":
                        ops.append(parse_const(t))
                    elif k in _SLOTS:
                        slot = {n.upper(): i for i, n in enumerate(cur.lnames)}.get(t.upper())
                        if slot is None:
                            raise AsmError(f"{t} is not in .locals")
                        ops.append(slot)
                    elif k in _NAMES:
                        ops.append(parse_name(t))
                    elif k == "f":
                        ops.append("" if t == "-" else t)
                    elif k in _LABELS:
                        ops.append(t)
                    elif k == "x":
                        a, _, b = t.partition("/")
                        ops.append((int(a), b))
                    else:
                        ops.append(int(t))
                cur.instrs.append((head, ops, region))
        except (AsmError, ValueError, IndexError, KeyError) as exc:
            raise AsmError(f"line {n}: {exc}: {raw.strip()}") from None
    return out


# ---------------------------------------------------------------------------- assemble
def encode(lst: Listing) -> Code:
    code = Code(lst.name, lst.kind, lst.file, lnames=list(lst.lnames), ntemps=lst.ntemps)
    addr = []
    pc = 0
    for name, ops, _ in lst.instrs:
        addr.append(pc)
        pc += 1 + len(ops)
    addr.append(pc)
    const_ix: dict = {}
    info_ix: dict = {}
    mix: dict = {}
    gix: dict = {}

    def const(v):
        k = const_key(v)
        i = const_ix.get(k)
        if i is None:
            i = const_ix[k] = len(code.consts)
            code.consts.append(v)
        return i

    def label(name):
        if name not in lst.labels:
            raise AsmError(f"undefined label {name}")
        return addr[lst.labels[name]]

    words = code.words
    regions = code.regions
    reg_cache: dict = {}
    for name, ops, reg in lst.instrs:
        info = O.BY_NAME[name]
        r = None
        if reg is not None:
            key = (reg.kind, reg.line, reg.end)
            r = reg_cache.get(key)
            if r is None:
                r = reg_cache[key] = Region(reg.kind, reg.line, label(reg.end) if reg.kind == "G" else -1)
        words.append(info.number)
        regions.append(r)
        for k, v in zip(info.operands, ops):
            if k in _POOLED:
                w = const(v)
            elif k in _LABELS:
                w = label(v)
            elif k == "m":
                w = mix.setdefault(v.upper(), len(mix))
                if w == len(code.mnames):
                    code.mnames.append(v)
            elif k == "g":
                w = gix.setdefault(v.upper(), len(gix))
                if w == len(code.gnames):
                    code.gnames.append(v)
            elif k == "x":
                w = info_ix.get(v)
                if w is None:
                    w = info_ix[v] = len(code.infos)
                    line, flags = v
                    code.infos.append(StmtInfo(lst.file, line, "S" in flags, "C" in flags))
            else:
                w = v
            words.append(w)
            regions.append(r)
    return code


def assemble(text: str) -> list[Code]:
    """Assemble every ``.routine`` block of ``text``."""
    return [encode(lst) for lst in parse_listings(text)]


def to_listing(code: Code) -> Listing:
    lst = Listing(code.name, code.kind, code.file, list(code.lnames), code.ntemps)
    words = code.words
    starts = O.instruction_starts(words)
    index_of = {a: i for i, a in enumerate(starts)}
    index_of[len(words)] = len(starts)
    for a in starts:
        info = O.OPS[words[a]]
        ops = []
        for j, k in enumerate(info.operands):
            w = words[a + 1 + j]
            if k in _POOLED:
                ops.append(code.consts[w])
            elif k in _LABELS:
                name = f"@{w}"
                lst.labels[name] = index_of[w]
                ops.append(name)
            elif k == "m":
                ops.append(code.mnames[w])
            elif k == "g":
                ops.append(code.gnames[w])
            elif k == "x":
                si = code.infos[w]
                ops.append((si.line, ("S" if si.stops else "") + ("C" if si.cond_stops else "")))
            else:
                ops.append(w)
        r = code.regions[a]
        reg = None
        if r is not None:
            if r.kind == "G":
                name = f"@{r.end}"
                lst.labels[name] = index_of[r.end]
                reg = Region("G", r.line, name)
            else:
                reg = Region("A", r.line)
        lst.instrs.append((info.name, ops, reg))
    return lst


def disassemble(code: Code) -> str:
    return format_listing(to_listing(code))
