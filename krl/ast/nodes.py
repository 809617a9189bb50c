"""The KRL abstract syntax tree: every node class, declared in one place.

All nodes are ``@dataclass(slots=True)`` classes deriving from :class:`Node`. Two
keyword-only fields exist on every node and are excluded from equality and repr:

* ``span`` -- a :class:`Span` (file, 1-based line, 1-based column) of the node's first token;
* ``ann``  -- ``None`` until the checker runs, then an :class:`Annotation` holding the
  expression's static type (``ann.type``, a :mod:`krl.semantics.types` type) and, for names
  and calls, the resolved symbol (``ann.symbol``, a :class:`krl.semantics.symbols.Symbol`).

Because spans and annotations are ignored by ``==``, ``parse(print(ast)) == ast`` compares
structure only. Names keep their source spelling (KRL is case-insensitive, reference 1.1);
compare them with ``.upper()``. Operators and keywords are stored upper-case.

Shapes (reference sections in brackets):

* :class:`Module` -- a file: ``routines`` (.src/.sub) or ``data`` (.dat) [2.1-2.5].
* :class:`Routine` -- DEF/DEFFCT with ``params``, ``decls`` (declaration section) and
  ``body`` (statements) [2.2-2.4].
* declarations: :class:`VarDecl`, :class:`ArrayInit`, :class:`StrucDecl`,
  :class:`EnumDecl`, :class:`SignalDecl`, :class:`ExtDecl`, :class:`ImportDecl`,
  :class:`ChannelDecl` [2.5, 2.6, 3].
* statements: :class:`Assign`, :class:`CallStmt`, :class:`If`, :class:`Switch`, :class:`For`,
  :class:`While`, :class:`Repeat`, :class:`Loop`, :class:`Exit`, :class:`Goto`,
  :class:`Label`, :class:`Halt`, :class:`WaitFor`, :class:`WaitSec`, :class:`Continue`,
  :class:`Return`, :class:`OnErrorProceed`, :class:`InterruptDecl`, :class:`InterruptCtl`,
  :class:`Brake`, :class:`Resume`, :class:`Trigger`, :class:`ConditionalStop`, :class:`AninOn`, :class:`AninOff`,
  :class:`AnoutOn`, :class:`AnoutOff`, :class:`Motion`, :class:`SplineBlock`,
  :class:`KeywordStmt` (CONFIRM, ASYPTP, ...), :class:`MoveEmi`,
  :class:`DeclStmt` (a declaration found among statements), :class:`Unsupported`
  (a construct the builder does not know; carries the source text), :class:`Unparsed` (a line
  the grammar does not accept, in its place; also among a data list's items) [5, 6].
* expressions: :class:`IntLit`, :class:`RealLit`, :class:`BoolLit`, :class:`StrLit`,
  :class:`EnumLit`, :class:`Aggregate`, :class:`Name`, :class:`Index`, :class:`Field`,
  :class:`Call`, :class:`Unary`, :class:`Binary` (the geometric operator is ``op == ":"``) [1.5, 4].
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterator


@dataclass(slots=True, frozen=True)
class Span:
    """Source position of a node's first token: file path, 1-based line, 1-based column."""

    file: str = ""
    line: int = 0
    column: int = 0

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


NO_SPAN = Span()


@dataclass(slots=True)
class Annotation:
    """The front end's results for one node (the checker's and the resolver's).

    type:    static type of an expression (krl.semantics.types.KrlType) or None;
    symbol:  resolved symbol of a Name/Call/For variable (krl.semantics.symbols.Symbol);
    extra:   notes of the checker for tools (``{"whole_array": True}``, ``{"conversion":
             "REAL->INT"}``, ``{"advance_stop": ...}``);
    info:    a statement's place and advance-run stops (krl/semantics/advance.py ``StmtInfo``).

    The resolver's typed facts (krl/semantics/resolve.py) live in the subclasses below, one
    per kind of node that has them; :meth:`Node.annotate` creates the one of its node."""

    type: Any = None
    symbol: Any = None
    extra: dict = field(default_factory=dict)
    info: Any = None


@dataclass(slots=True)
class PlaceFacts(Annotation):
    """A Name (and an ArrayInit's element): ``place``, where its variable lives (``Storage``)."""
    place: "Storage | None" = None


@dataclass(slots=True)
class CallFacts(Annotation):
    """A Call: ``callee``, what it runs (``Callee``: a routine, a built-in, or a stub)."""
    callee: "Callee | None" = None


@dataclass(slots=True)
class LayoutFacts(Annotation):
    """A Routine or DataList: ``layout``, its slots (``Layout``)."""
    layout: "Layout | None" = None


@dataclass(slots=True)
class AggregateFacts(Annotation):
    """An Aggregate: ``struc``, the STRUC its TYPE prefix names (a ``types.Struc``), else None."""
    struc: "Struc | None" = None


@dataclass(slots=True)
class GotoFacts(Annotation):
    """A Goto: ``target``, the Label it jumps to (the nearest enclosing block's), else None."""
    target: "Label | None" = None


@dataclass(slots=True)
class AssignFacts(Annotation):
    """An Assign: ``cyclic``, True when it assigns a cyclic flag (re-evaluated every IPO cycle)."""
    cyclic: bool = False


@dataclass(slots=True)
class ComponentFacts(Annotation):
    """A Field or an aggregate's item (AggItem): ``component``, the structure component it names
    (``Component``: its key and declared type)."""
    component: "Component | None" = None


@dataclass(slots=True)
class ChannelFacts(Annotation):
    """ANIN ON/OFF, ANOUT ON/OFF: ``channel``, the analog signal's place (``Storage``)."""
    channel: "Storage | None" = None


@dataclass(slots=True)
class Node:
    span: Span = field(default=NO_SPAN, compare=False, repr=False, kw_only=True)
    ann: Annotation | None = field(default=None, compare=False, repr=False, kw_only=True)

    def annotate(self) -> Annotation:
        """The node's Annotation (the one of its kind: :data:`FACTS`), created on first use."""
        if self.ann is None:
            self.ann = FACTS.get(self.__class__, Annotation)()
        return self.ann

    def children(self) -> Iterator["Node"]:
        """Direct child nodes in field order (lists flattened, None skipped)."""
        for name in self.__dataclass_fields__:
            if name in ("span", "ann"):
                continue
            value = getattr(self, name)
            if isinstance(value, Node):
                yield value
            elif isinstance(value, (list, tuple)):
                for item in value:
                    if isinstance(item, Node):
                        yield item
                    elif isinstance(item, (list, tuple)):
                        yield from (x for x in item if isinstance(x, Node))

    def walk(self) -> Iterator["Node"]:
        """This node and all descendants, pre-order."""
        stack = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(list(node.children())))


# ------------------------------------------------------------------ expressions (1.5, 4)

@dataclass(slots=True)
class Expr(Node):
    pass


@dataclass(slots=True)
class IntLit(Expr):
    """INT literal; base is 10, 16 ('H1F') or 2 ('B101')."""
    value: int
    base: int = 10


@dataclass(slots=True)
class RealLit(Expr):
    value: float


@dataclass(slots=True)
class BoolLit(Expr):
    value: bool


@dataclass(slots=True)
class StrLit(Expr):
    """String literal without the quotes; one character is a CHAR constant (1.5)."""
    value: str


@dataclass(slots=True)
class ChannelName(Expr):
    """``:SER_3`` as a call argument (``COPEN(:SER_3, HANDLE)``): a channel of the controller;
    ``name`` without the ':' (4.7, the CREAD/CWRITE channels)."""
    name: str


@dataclass(slots=True)
class EnumLit(Expr):
    """``#NAME``; ``name`` without the '#'. Its enum type comes from the context (3.6)."""
    name: str


@dataclass(slots=True)
class AggItem(Node):
    """One ``NAME value`` component; ``array`` for ``NAME[] "text"``."""
    name: str
    value: Expr
    array: bool = False


@dataclass(slots=True)
class Aggregate(Expr):
    """``{[TYPE:] NAME value, ...}`` (1.5); partial aggregates allowed (3.9)."""
    type_name: str | None
    items: list[AggItem]


@dataclass(slots=True)
class Name(Expr):
    """A variable, constant, signal, system variable or parameter name."""
    name: str


@dataclass(slots=True)
class Index(Expr):
    """``base[i, j]``; an omitted index is None: ``s[]`` is ``[None]``, ``t[2,]`` ``[2, None]``."""
    base: Expr
    indices: list[Expr | None]


@dataclass(slots=True)
class Field(Expr):
    """``base.name`` (structure component)."""
    base: Expr
    name: str


@dataclass(slots=True)
class Call(Expr):
    """``name(args)``; an omitted argument is None (2.3)."""
    name: str
    args: list[Expr | None]


@dataclass(slots=True)
class Unary(Expr):
    """op is '-', '+', 'NOT' or 'B_NOT'."""
    op: str
    operand: Expr


@dataclass(slots=True)
class Binary(Expr):
    """op is ':', '*', '/', '+', '-', 'AND', 'B_AND', 'EXOR', 'B_EXOR', 'OR', 'B_OR',
    '==', '<>', '<', '>', '<=', '>=' (4.1).

    Binary operators associate to the left, so ``1 + 1 + ... + 1`` (up to
    krl.limits.MAX_EXPRESSION_TERMS terms) is a chain nested one level per operator in
    ``left``. Code that descends into ``left`` walks such a chain with :func:`left_chain`
    instead of recursing, and pickling (worker processes) and copying store it flat."""
    op: str
    left: Expr
    right: Expr

    def __eq__(self, other):
        if other.__class__ is not self.__class__:
            return NotImplemented
        a, b = self, other
        while a.op == b.op and a.right == b.right:
            a, b = a.left, b.left
            if a.__class__ is not Binary or b.__class__ is not Binary:
                return a == b
        return False

    def __reduce__(self):
        leftmost, chain = left_chain(self)
        return _rebuild_chain, (leftmost, [(b.op, b.right, b.span, b.ann) for b in chain])


def left_chain(e: Binary) -> tuple[Expr, list[Binary]]:
    """``(leftmost, chain)`` of a left-nested chain of binary operators, without recursion:
    ``chain`` is the Binary nodes from the innermost (whose ``left`` is ``leftmost``, not a
    Binary) out to `e` itself. ``a - b + c`` -> ``(a, [a - b, (a - b) + c])``."""
    chain = []
    node: Expr = e
    while isinstance(node, Binary):
        chain.append(node)
        node = node.left
    chain.reverse()
    return node, chain


def _rebuild_chain(leftmost: Expr, links: list) -> Binary:
    node = leftmost
    for op, right, span, ann in links:
        node = Binary(op, node, right, span=span, ann=ann)
    return node


# ------------------------------------------------------------------ declarations (2.5, 2.6, 3)

@dataclass(slots=True)
class Decl(Node):
    pass


@dataclass(slots=True)
class TypeRef(Node):
    """A type name with an optional CHAR-array size: ``CHAR[128]`` (size 128), ``CHAR[]`` (size 0)."""
    name: str
    size: int | None = None


@dataclass(slots=True)
class VarName(Node):
    """A declared name with its array dimensions (1 to 3 INT sizes; empty for scalars;
    0 for an open dimension of an array parameter, ``buf[]`` -> [0], ``m[,]`` -> [0, 0])."""
    name: str
    dims: list[int] = field(default_factory=list)


@dataclass(slots=True)
class VarDecl(Decl):
    """``[DECL] [GLOBAL] [CONST] type name[dims], ... [= init]`` (3.2; init only in .dat files)."""
    type: TypeRef
    names: list[VarName]
    init: Expr | None = None
    is_global: bool = False
    is_const: bool = False
    decl_keyword: bool = True


@dataclass(slots=True)
class ArrayInit(Decl):
    """``NAME[1,2] = value`` or ``NAME[3,] = "row"`` in a data list (2.5)."""
    name: str
    indices: list[int | None]
    value: Expr


@dataclass(slots=True)
class StrucComp(Node):
    type_name: str
    name: str
    dims: list[int] = field(default_factory=list)


@dataclass(slots=True)
class StrucDecl(Decl):
    """``[GLOBAL] STRUC NAME type comp, ...`` (3.5)."""
    name: str
    components: list[StrucComp]
    is_global: bool = False


@dataclass(slots=True)
class EnumDecl(Decl):
    """``[GLOBAL] ENUM NAME v1, v2, ...`` (3.6)."""
    name: str
    values: list[str]
    is_global: bool = False


@dataclass(slots=True)
class SignalRef(Node):
    """``$IN[17]`` in a SIGNAL declaration."""
    sysvar: str
    index: int


@dataclass(slots=True)
class SignalDecl(Decl):
    """``[GLOBAL] SIGNAL NAME $OUT[n] [TO $OUT[m]]`` (3.8); start None for a system signal
    declared ``SIGNAL $NAME FALSE`` (not wired)."""
    name: str
    start: SignalRef | None
    end: SignalRef | None = None
    is_global: bool = False


@dataclass(slots=True)
class ExtParam(Node):
    """A parameter of an EXT declaration: type, optional array brackets on the type or the
    name (``None`` = no brackets, ``0`` = ``[]``, n = ``[n]``), optional name, mode."""
    type_name: str
    type_size: int | None = None
    name: str | None = None
    name_size: int | None = None
    mode: str | None = None


@dataclass(slots=True)
class ExtDecl(Decl):
    """``EXT/EXTP name(params)`` or ``EXTFCT/EXTFCTP type name(params)`` (2.6)."""
    kind: str
    name: str
    params: list[ExtParam]
    return_type: TypeRef | None = None


@dataclass(slots=True)
class ImportDecl(Decl):
    """``IMPORT type name IS /R1/module..var`` (2.5)."""
    type_name: str
    name: str
    path: list[str]


@dataclass(slots=True)
class ChannelDecl(Decl):
    """``CHANNEL :NAME :DEVICE PARAM`` (2.5); accepted and ignored."""
    name: str
    device: str
    param: str


# ------------------------------------------------------------------ statements (5, 6)

@dataclass(slots=True)
class Stmt(Node):
    pass


@dataclass(slots=True)
class Assign(Stmt):
    target: Expr
    value: Expr


@dataclass(slots=True)
class CallStmt(Stmt):
    call: Call


@dataclass(slots=True)
class If(Stmt):
    cond: Expr
    then: list[Stmt]
    orelse: list[Stmt] | None = None


@dataclass(slots=True)
class Case(Node):
    values: list[Expr]
    body: list[Stmt]


@dataclass(slots=True)
class Switch(Stmt):
    selector: Expr
    cases: list[Case]
    default: list[Stmt] | None = None


@dataclass(slots=True)
class For(Stmt):
    var: Name
    start: Expr
    end: Expr
    step: Expr | None
    body: list[Stmt]


@dataclass(slots=True)
class While(Stmt):
    cond: Expr
    body: list[Stmt]


@dataclass(slots=True)
class Repeat(Stmt):
    body: list[Stmt]
    cond: Expr


@dataclass(slots=True)
class Loop(Stmt):
    body: list[Stmt]


@dataclass(slots=True)
class Exit(Stmt):
    pass


@dataclass(slots=True)
class Goto(Stmt):
    label: str


@dataclass(slots=True)
class Label(Stmt):
    name: str


@dataclass(slots=True)
class Halt(Stmt):
    pass


@dataclass(slots=True)
class WaitFor(Stmt):
    cond: Expr


@dataclass(slots=True)
class WaitSec(Stmt):
    time: Expr


@dataclass(slots=True)
class Continue(Stmt):
    pass


@dataclass(slots=True)
class Return(Stmt):
    value: Expr | None = None


@dataclass(slots=True)
class OnErrorProceed(Stmt):
    pass


@dataclass(slots=True)
class InterruptDecl(Stmt):
    """``[GLOBAL] INTERRUPT DECL prio WHEN cond DO call`` (5.16). For ``DO BRAKE`` /
    ``DO BRAKE F``, ``brake`` is the Brake node and ``call`` is ``Call('BRAKE', [])`` /
    ``Call('BRAKE_F', [])`` (the form the interpreters dispatch on)."""
    prio: Expr
    when: Expr
    call: Call
    is_global: bool = False
    brake: "Brake | None" = None


@dataclass(slots=True)
class InterruptCtl(Stmt):
    """``INTERRUPT ON|OFF|ENABLE|DISABLE [prio]`` (5.16)."""
    action: str
    prio: Expr | None = None


@dataclass(slots=True)
class Brake(Stmt):
    """``BRAKE`` or ``BRAKE F`` (fast=True) (5.17)."""
    fast: bool = False


@dataclass(slots=True)
class Resume(Stmt):
    pass


@dataclass(slots=True)
class Trigger(Stmt):
    """``TRIGGER WHEN DISTANCE=d|PATH=p [ONSTART] DELAY=t DO action [PRIO=p]`` (5.18).
    kind is 'DISTANCE' or 'PATH'; action is an Assign or a CallStmt."""
    kind: str
    at: Expr
    delay: Expr
    action: Stmt
    prio: Expr | None = None
    onstart: bool = False


@dataclass(slots=True)
class ConditionalStop(Stmt):
    """``STOP WHEN PATH = path [ONSTART] IF cond`` (KSS 8.3 and later, grammar/CHANGES.md): the
    next motion (or spline segment) stops on its path `path` mm from its end point (from its
    start point with ONSTART) when `cond` holds at the braking point, and goes on when it no
    longer holds (robot/controller.py ``Controller._conditional_stops``)."""
    path: Expr
    cond: Expr
    onstart: bool = False


@dataclass(slots=True)
class AninOn(Stmt):
    target: Expr
    value: Expr


@dataclass(slots=True)
class AninOff(Stmt):
    name: str


@dataclass(slots=True)
class AnoutOn(Stmt):
    name: str
    value: Expr
    delay: Expr | None = None
    minimum: Expr | None = None
    maximum: Expr | None = None


@dataclass(slots=True)
class AnoutOff(Stmt):
    name: str


@dataclass(slots=True)
class WithAssign(Node):
    """One ``$SYSVAR[...] = expr`` of a WITH clause; target is a Name/Index/Field chain."""
    target: Expr
    value: Expr


@dataclass(slots=True)
class Motion(Stmt):
    """A motion statement (6.1).

    kind:     'PTP', 'PTP_REL', 'LIN', 'LIN_REL', 'CIRC', 'CIRC_REL', 'SPTP', 'SLIN', 'SCIRC',
              their _REL forms, and 'SPL' inside spline blocks;
    target:   the target expression; aux: the CIRC auxiliary point (else None);
    ca:       the circular angle expression after CA (else None);
    approx:   approximation keywords in order ('C_PTP', 'C_DIS', 'C_VEL', 'C_ORI', 'C_SPL');
    with_:    the WITH assignments; frame: '#BASE'/'#TOOL' of a relative motion, else None.
    """
    kind: str
    target: Expr
    aux: Expr | None = None
    ca: Expr | None = None
    approx: list[str] = field(default_factory=list)
    with_: list[WithAssign] = field(default_factory=list)
    frame: str | None = None


@dataclass(slots=True)
class SplineBlock(Stmt):
    """``SPLINE|PTP_SPLINE [WITH ...] ... ENDSPLINE [C_SPL]`` (6.2); body holds Motion
    (SPL/SLIN/SCIRC/SPTP) and Trigger statements."""
    kind: str
    body: list[Stmt]
    with_: list[WithAssign] = field(default_factory=list)
    approx: str | None = None


@dataclass(slots=True)
class KeywordStmt(Stmt):
    """A statement made of keywords followed by expressions, e.g. ``CONFIRM n``,
    ``ASYPTP {E1 90}`` (5.20); ``words`` are the upper-case keywords."""
    words: list[str]
    args: list[Expr] = field(default_factory=list)


@dataclass(slots=True)
class MoveEmi(Stmt):
    """``MOVE_EMI device[] "file.emily" [KEY value]`` (5.20)."""
    target: Expr
    file: str
    key: str | None = None
    value: Expr | None = None


@dataclass(slots=True)
class DeclStmt(Stmt):
    """A declaration that appears after the first statement (a checker error, 2.2)."""
    decl: Decl


@dataclass(slots=True)
class Unparsed(Stmt):
    """A line the grammar does not accept (a syntax error of the file, E002 and its kin), kept
    in its place among the statements, the declaration section or a data list's items, so
    that every tool uses what parsed around it (issue 63). ``text`` is the line's source text,
    stripped; the parser's message is the file's diagnostic at the same line. A run that
    reaches it stops there (interp/runtime ``not_understood``); ``krl diff`` compares it by its
    text. ``error``: the checker's finding on the line when KRL rejects its form whatever the
    controller's grammar holds (``"E012: `TODO` alone is not a statement; ..."``,
    krl/diagnostics ``PROGRAM_SYNTAX_CODES``): the run stops on the program's error; "" when the
    line may be a construct the grammar lacks (the simulator's gap)."""
    text: str
    error: str = ""


@dataclass(slots=True)
class Unsupported(Stmt):
    """A parse-tree construct the builder does not map (yet); ``rule`` is the parse-tree
    node name, ``text`` its source text (printed back verbatim)."""
    rule: str
    text: str


# ------------------------------------------------------------------ routines and modules (2)

@dataclass(slots=True)
class Param(Node):
    """A routine parameter; mode is 'IN', 'OUT' or None (unspecified, treated as OUT, 2.3);
    dims is the number of open array dimensions written in the header (``buf[]`` 1, ``m[,]`` 2)."""
    name: str
    mode: str | None = None
    dims: int = 0


@dataclass(slots=True)
class Routine(Node):
    """``[GLOBAL] DEF name(params)`` / ``[GLOBAL] DEFFCT type name(params)`` (2.2-2.4)."""
    kind: str                    # 'DEF' or 'DEFFCT'
    name: str
    params: list[Param]
    decls: list[Decl]
    body: list[Stmt]
    return_type: TypeRef | None = None
    is_global: bool = False
    end_line: int = field(default=0, compare=False, repr=False, kw_only=True)   # END/ENDFCT line
    # the first line not understood that leaves the routine's blocks in doubt (a block's opener
    # or closer, END itself: the statements after it may belong elsewhere), else 0; a run does
    # not enter such a routine (interp/runtime ``not_understood``)
    broken: int = field(default=0, compare=False, repr=False, kw_only=True)

    @property
    def is_function(self) -> bool:
        """True for a DEFFCT (it returns a value, reference 2.4)."""
        return self.kind == "DEFFCT"


@dataclass(slots=True)
class DataList(Node):
    """``DEFDAT name [PUBLIC]`` ... ``ENDDAT`` (2.5)."""
    name: str
    items: list[Decl]
    public: bool = False


@dataclass(slots=True)
class Module(Node):
    """One file. kind is 'src' (also .sub) or 'dat'; headers are the '&' lines verbatim.
    ``path`` is not part of equality (like spans)."""
    path: str = field(compare=False)
    kind: str
    headers: list[str] = field(default_factory=list)
    routines: list[Routine] = field(default_factory=list)
    data: DataList | None = None
    # a file with syntax errors: the lines its AST does not hold (krl/ast/coverage.py) and the
    # code lines counted, so that a tool says "N of M understood"; both empty for a file that parses
    unparsed: list[int] = field(default_factory=list, compare=False, repr=False, kw_only=True)
    code_lines: int = field(default=0, compare=False, repr=False, kw_only=True)

    @property
    def name(self) -> str:
        """Module name: the data list's name, else the first routine's, else the file stem."""
        if self.data is not None:
            return self.data.name
        if self.routines:
            return self.routines[0].name
        stem = self.path.replace("\\", "/").rsplit("/", 1)[-1]
        return stem.rsplit(".", 1)[0]


#: the Annotation class of each node kind that has typed facts (:meth:`Node.annotate`)
FACTS: dict[type, type] = {
    Name: PlaceFacts, ArrayInit: PlaceFacts, Call: CallFacts, Routine: LayoutFacts, DataList: LayoutFacts,
    Aggregate: AggregateFacts, Goto: GotoFacts, Assign: AssignFacts, AninOn: ChannelFacts,
    AninOff: ChannelFacts, AnoutOn: ChannelFacts, AnoutOff: ChannelFacts, Field: ComponentFacts,
    AggItem: ComponentFacts,
}


def type_of(expr: Node):
    """The static type the checker gave `expr` (krl.semantics.types.KrlType), or None."""
    return expr.ann.type if expr.ann is not None else None


def symbol_of(node: Node):
    """The symbol the checker resolved for a Name/Call/For/Goto node, or None."""
    return node.ann.symbol if node.ann is not None else None


def is_lvalue(expr: Node | None) -> bool:
    """True for a variable reference: a Name with any chain of Index/Field selectors."""
    while isinstance(expr, (Index, Field)):
        expr = expr.base
    return isinstance(expr, Name)


def root_name(expr: Node | None) -> Name | None:
    """The Name at the root of a Name/Index/Field chain, or None."""
    while isinstance(expr, (Index, Field)):
        expr = expr.base
    return expr if isinstance(expr, Name) else None
