"""Parse tree -> AST.

This module and :mod:`krl.syntax` are the only code that touches ANTLR types. The
builder maps parse-tree contexts by their *rule and label names* (``assignmentStatement``,
``ptpMotion``, ``variableDeclaration``) and reads children generically (rule children by
rule name, tokens by symbolic name), so a grammar that grows new alternatives keeps
working: motions are recognised by their leading keyword, binary operators by their
shape (expression, operator token, expression), declarations by their modifier tokens.

:func:`build_module` never raises. A parse-tree node it cannot map becomes an
:class:`~krl.ast.nodes.Unsupported` statement (printed back verbatim) plus a W003
diagnostic. A tree that came from error recovery (the file has syntax errors, already
reported as E002) is built from what parsed (issue 63): each statement, declaration or
data-list line with a syntax error becomes an :class:`~krl.ast.nodes.Unparsed` node in its
place, and a block or routine whose own line parsed but whose closer did not is still built,
its routine marked ``broken`` at the first line not understood.
"""

from __future__ import annotations

from antlr4 import ParserRuleContext
from antlr4.tree.Tree import ErrorNode, TerminalNode

from krl.ast import nodes as N
from krl.diagnostics import DiagnosticSink
from krl.diagnostics.codes import E003, PROGRAM_SYNTAX_CODES, W003

_RULE_CACHE: dict[type, tuple[str, str]] = {}


def _names(ctx) -> tuple[str, str]:
    """(label-or-rule name, base rule name) of a context, e.g. ('ptpMotion', 'motion')."""
    cls = type(ctx)
    got = _RULE_CACHE.get(cls)
    if got is None:
        def low(name: str) -> str:
            if name.endswith("Context"):
                name = name[:-7]
            return name[:1].lower() + name[1:]
        own = low(cls.__name__)
        base = own
        for klass in cls.__mro__:
            parents = klass.__bases__
            if parents and parents[0] is ParserRuleContext:
                base = low(klass.__name__)
                break
        got = (own, base)
        _RULE_CACHE[cls] = got
    return got


_NAME_RULES = frozenset(("name", "contextKeyword", "keywordName", "componentName", "enumValue",
                         "identifier"))


def _matches(base: str, rule: str) -> bool:
    if base == rule:
        return True
    # every name-like rule (a name, or a keyword accepted as a name) answers to "name"
    return rule == "name" and (base in _NAME_RULES or base.endswith("Keyword"))


class BuildError(Exception):
    """Raised internally for a malformed (error-recovered) subtree; never escapes."""


class Builder:
    """Builds one file's AST. Use :func:`build_module`."""

    def __init__(self, path: str, sink: DiagnosticSink, symbolic: list[str], recovered: bool,
                 error_lines: dict[int, str] | None = None, line_errors: dict[int, str] | None = None):
        self.path = path
        self.sink = sink
        self.symbolic = symbolic
        self.recovered = recovered
        # line -> its text, of each line with a syntax error (a recovered tree only)
        self.error_lines = error_lines or {}
        # line -> "CODE: message" of the error lines whose form KRL rejects (Unparsed.error)
        self.line_errors = line_errors or {}
        self._placed: set[int] = set()      # error lines already given their Unparsed node
        self._in_doubt = False              # a rule of the routine in hand recovered past its own line

    # ---------------------------------------------------------------- tree helpers

    def span(self, ctx) -> N.Span:
        tok = ctx.symbol if isinstance(ctx, TerminalNode) else getattr(ctx, "start", None)
        if tok is None:
            return N.Span(self.path, 0, 0)
        return N.Span(self.path, tok.line, tok.column + 1)

    def sym(self, tnode) -> str:
        ttype = tnode.symbol.type
        if 0 < ttype < len(self.symbolic):
            return self.symbolic[ttype]
        return "EOF" if ttype == -1 else str(ttype)

    @staticmethod
    def rules(ctx, rule: str | None = None) -> list:
        out = []
        for c in ctx.children or ():
            if isinstance(c, ParserRuleContext) and (rule is None or _matches(_names(c)[1], rule)):
                out.append(c)
        return out

    def rule(self, ctx, rule: str, required: bool = True):
        for c in ctx.children or ():
            if isinstance(c, ParserRuleContext) and _matches(_names(c)[1], rule):
                return c
        if required:
            raise BuildError(f"{_names(ctx)[0]} lacks {rule}")
        return None

    def toks(self, ctx) -> list[tuple[str, str, object]]:
        out = []
        for c in ctx.children or ():
            if isinstance(c, ErrorNode):
                if self._elsewhere(ctx, c.symbol.line):
                    continue        # a line of its own inside a block (its Unparsed node says so)
                raise BuildError("error node")
            if isinstance(c, TerminalNode):
                out.append((self.sym(c), c.getText(), c))
        return out

    def has(self, ctx, *symbols: str) -> bool:
        return any(s in symbols for s, _, _ in self.toks(ctx))

    def first_tok(self, ctx) -> str:
        tok = getattr(ctx, "start", None)
        return tok.text.upper() if tok is not None and tok.text else ""

    def source_text(self, ctx) -> str:
        try:
            stream = ctx.start.getInputStream()
            stop = ctx.stop if ctx.stop is not None and ctx.stop.stop >= ctx.start.start else ctx.start
            return stream.getText(ctx.start.start, stop.stop)
        except Exception:  # noqa: BLE001 - best effort only
            return ctx.getText()

    def check_ok(self, ctx) -> None:
        if getattr(ctx, "exception", None) is not None:
            tok = getattr(ctx, "start", None)
            if tok is not None and self._elsewhere(ctx, None):
                # a block (or routine, data list) whose own line parsed: the error is on a line
                # inside it or at its closer; built from what parsed, its routine in doubt
                self._in_doubt = True
                return
            raise BuildError("recovered subtree")

    def _elsewhere(self, ctx, line: int | None) -> bool:
        """In a recovered tree: True when `ctx` starts on a line that parsed and (with `line`)
        the error at `line` lies on another line."""
        if not self.recovered:
            return False
        tok = getattr(ctx, "start", None)
        start = tok.line if tok is not None else None
        return start is not None and start not in self.error_lines and line != start

    def unparsed(self, ctx_or_line) -> N.Unparsed | None:
        """The Unparsed node of an error line (once per line), or None when the line parsed
        or was placed already; `ctx_or_line`: a rule context (its first line) or a line."""
        if isinstance(ctx_or_line, int):
            line, col = ctx_or_line, 1
        else:
            tok = getattr(ctx_or_line, "start", None)
            if tok is None:
                return None
            line, col = tok.line, tok.column + 1
        if line not in self.error_lines or line in self._placed:
            return None
        self._placed.add(line)
        text = self.error_lines[line]
        col = len(text) - len(text.lstrip()) + 1 if text.strip() else col
        return N.Unparsed(text.strip(), self.line_errors.get(line, ""), span=N.Span(self.path, line, col))

    def _error_line_of(self, ctx) -> int | None:
        """The line of `ctx` when it is a line with a syntax error (a recovered tree), else None."""
        if not self.error_lines:
            return None
        tok = getattr(ctx, "start", None)
        return tok.line if tok is not None and tok.line in self.error_lines else None

    def unknown(self, ctx, what: str) -> None:
        if not self.recovered:
            sp = self.span(ctx)
            self.sink.add(self.path, sp.line, sp.column, *W003(what=what, name=_names(ctx)[0]))

    def guarded(self, fn, ctx, default=None):
        """Run fn(ctx); on a malformed subtree report (unless recovered) and return default."""
        try:
            self.check_ok(ctx)
            return fn(ctx)
        except RecursionError:
            sp = self.span(ctx)
            self.sink.add(self.path, sp.line, sp.column, *E003("too_deep"))
            return default
        except Exception as exc:  # noqa: BLE001 - the builder must never raise
            if not self.recovered:
                sp = self.span(ctx)
                self.sink.add(self.path, sp.line, sp.column, *E003(name=_names(ctx)[0], error=exc))
            return default

    # ---------------------------------------------------------------- module level

    def module(self, tree) -> N.Module:
        kind = "dat" if self.path.lower().endswith(".dat") else "src"
        mod = N.Module(self.path, kind, span=N.Span(self.path, 1, 1))
        for c in tree.children or ():
            if not isinstance(c, ParserRuleContext):
                continue
            own, base = _names(c)
            if base == "headerLine":
                for s, text, _ in self._safe_toks(c):
                    if s == "HEADER":
                        mod.headers.append(text)
            elif base == "routine":
                r = self.guarded(self.routine, c)
                if r is not None:
                    mod.routines.append(r)
            elif base == "dataList":
                mod.kind = "dat"
                mod.data = self.guarded(self.datalist, c)
            else:
                self.unknown(c, "module item")
        return mod

    def _safe_toks(self, ctx):
        try:
            return self.toks(ctx)
        except BuildError:
            return []

    def routine(self, ctx) -> N.Routine:
        doubt, self._in_doubt = self._in_doubt, False
        try:
            r = self._routine(ctx)
        finally:
            in_doubt, self._in_doubt = self._in_doubt, doubt
        if in_doubt:
            last = r.end_line or max(self.error_lines, default=r.span.line)
            r.broken = min((ln for ln in self.error_lines if r.span.line <= ln <= last), default=r.span.line)
        return r

    def _routine(self, ctx) -> N.Routine:
        inner = self.rules(ctx)
        if len(inner) == 1 and _names(inner[0])[1] in ("procedureDefinition", "functionDefinition"):
            ctx = inner[0]
        self.check_ok(ctx)
        tk = self.toks(ctx)
        syms = [s for s, _, _ in tk]
        kind = "DEFFCT" if "DEFFCT" in syms else "DEF"
        name = self.name(self.rule(ctx, "name"))
        params: list[N.Param] = []
        plist = self.rule(ctx, "parameterList", required=False)
        if plist is not None:
            for p in self.rules(plist, "parameter"):
                mode = None
                for s, _, _ in self.toks(p):
                    if s in ("IN", "OUT"):
                        mode = s
                dims = 0
                for od in self.rules(p):
                    if _names(od)[1].endswith("Dimensions"):
                        dims = len(self.dims_of(od))
                params.append(N.Param(self.name(self.rule(p, "name")), mode, dims, span=self.span(p)))
        rtype = None
        tref = self.rule(ctx, "typeRef", required=False)
        if tref is not None:
            rtype = self.typeref(tref)
        decls: list[N.Decl] = []
        body: list[N.Stmt] = []
        rbody = self.rule(ctx, "routineBody", required=False)
        if rbody is not None:
            self.body_items(rbody, decls, body)
        stop = getattr(ctx, "stop", None)
        return N.Routine(kind, name, params, decls, body, rtype, "GLOBAL" in syms, span=self.span(ctx),
                         end_line=stop.line if stop is not None else 0)

    def body_items(self, ctx, decls: list, body: list) -> None:
        """Fill decls/body from a routine body; declarations after a statement become DeclStmt."""
        for c in ctx.children or ():
            if not isinstance(c, ParserRuleContext):
                continue
            base = _names(c)[1]
            if base == "declarationLine":
                if self._error_line_of(c) is not None:
                    u = self.unparsed(c)
                    if u is not None:
                        (body if body else decls).append(u)
                    continue
                for d in self.rules(c):
                    decl = self.guarded(self.declaration, d)
                    if decl is None:
                        continue
                    if body:
                        body.append(N.DeclStmt(decl, span=decl.span))
                    else:
                        decls.append(decl)
            elif base == "statementList":
                body.extend(self.stmt_list(c))
            elif base == "statementLine":
                body.extend(self.stmt_line(c))
            elif base in ("declaration",):
                decl = self.guarded(self.declaration, c)
                if decl is not None:
                    (body.append(N.DeclStmt(decl, span=decl.span)) if body else decls.append(decl))
            else:
                self.body_items(c, decls, body)

    def datalist(self, ctx) -> N.DataList:
        name = self.name(self.rule(ctx, "name"))
        public = self.has(ctx, "PUBLIC")
        items: list[N.Decl] = []
        for line in self.rules(ctx):
            if self._error_line_of(line) is not None and not _matches(_names(line)[1], "name"):
                u = self.unparsed(line)
                if u is not None:
                    items.append(u)
                continue
            for it in self.rules(line) if _names(line)[1].endswith("Line") else [line]:
                if _matches(_names(it)[1], "name"):
                    continue
                d = self.guarded(self.declaration, it)
                if d is not None:
                    items.append(d)
        return N.DataList(name, items, public, span=self.span(ctx))

    # ---------------------------------------------------------------- declarations

    def declaration(self, ctx) -> N.Decl:
        own, base = _names(ctx)
        inner = self.rules(ctx)
        if base in ("declaration", "dataItem") and len(inner) == 1:
            self.check_ok(ctx)
            return self.declaration(inner[0])
        self.check_ok(ctx)
        method = {
            "variableDeclaration": self.var_decl,
            "dataVariableDeclaration": self.var_decl,
            "arrayElementInitialisation": self.array_init,
            "stringInitialisation": self.array_init,
            "structureDeclaration": self.struc_decl,
            "enumDeclaration": self.enum_decl,
            "signalDeclaration": self.signal_decl,
            "externalDeclaration": self.ext_decl,
            "importDeclaration": self.import_decl,
            "channelDeclaration": self.channel_decl,
        }.get(base) or {
            "variableDeclaration": self.var_decl,
        }.get(own)
        if method is None and own.endswith("Initialisation"):
            method = self.array_init
        if method is None:
            if "Declaration" in own or "Decl" in own:
                return self.var_decl(ctx)
            raise BuildError(f"unknown declaration kind {own}")
        return method(ctx)

    _TYPE_RULES = ("typeName", "simpleType", "geometricType")

    def var_decl(self, ctx) -> N.VarDecl:
        syms = [s for s, _, _ in self.toks(ctx)]
        tctx = None
        names: list[N.VarName] = []
        init = None
        seen_eq = False
        for c in ctx.children or ():
            if isinstance(c, TerminalNode):
                if c.getText() == "=":
                    seen_eq = True
                continue
            b = _names(c)[1]
            if seen_eq and b in ("constantValue", "expression", "constantAggregate", "aggregate", "literal"):
                init = self.value(c)
            elif tctx is None and (b in self._TYPE_RULES or b.endswith("Type")):
                tctx = c
            elif b in ("variableName", "openArrayName") or (b.endswith("Name") and b != "typeName"):
                names.append(self.var_name(c))
        if tctx is None:
            raise BuildError("declaration without type")
        if not names:
            raise BuildError("declaration without names")
        return N.VarDecl(N.TypeRef(self.type_name(tctx), span=self.span(tctx)), names, init,
                         "GLOBAL" in syms, "CONST" in syms, "DECL" in syms, span=self.span(ctx))

    def dims_of(self, ctx) -> list[int]:
        """Sizes from arrayDimensions ([3,4] -> [3, 4]) or open dimensions ([,] -> [0, 0])."""
        b = _names(ctx)[1]
        if b == "arrayDimensions":
            return [int(t) for s, t, _ in self.toks(ctx) if s == "INTLITERAL"]
        commas = sum(1 for _, t, _ in self.toks(ctx) if t == ",")
        return [0] * (commas + 1)

    def var_name(self, ctx) -> N.VarName:
        dims: list[int] = []
        nm = self.rule(ctx, "name", required=False)
        for c in self.rules(ctx):
            b = _names(c)[1]
            if b in ("arrayDimensions", "openDimensions") or b.endswith("Dimensions"):
                dims = self.dims_of(c)
        if nm is None:
            raise BuildError("declared name missing")
        return N.VarName(self.name(nm), dims, span=self.span(ctx))

    def array_init(self, ctx) -> N.ArrayInit:
        name = self.name(self.rule(ctx, "name"))
        indices: list[int | None] = []
        cur: int | None = None
        inside = False
        seen_eq = False
        value = None
        for c in ctx.children or ():
            if isinstance(c, TerminalNode):
                t = c.getText()
                if seen_eq:
                    value = self.literal_token(c)
                elif t == "[":
                    inside = True
                elif t == "," and inside:
                    indices.append(cur)
                    cur = None
                elif t == "]" and inside:
                    indices.append(cur)
                    inside = False
                elif t == "=":
                    seen_eq = True
                elif inside and self.sym(c) == "INTLITERAL":
                    cur = int(t)
            elif seen_eq:
                value = self.value(c)
            elif inside and _names(c)[1] in ("constantIndex", "expression"):
                cur = int(self.source_text(c).strip())
        if value is None:
            raise BuildError("array initialisation without value")
        return N.ArrayInit(name, indices, value, span=self.span(ctx))

    def struc_decl(self, ctx) -> N.StrucDecl:
        syms = [s for s, _, _ in self.toks(ctx)]
        name = self.name(self.rule(ctx, "name"))
        comps: list[N.StrucComp] = []
        cur_type = None
        for c in self.rules(ctx):
            b = _names(c)[1]
            if b in ("typeName", "simpleType"):
                cur_type = self.type_name(c)
            elif b == "structureComponent":
                if cur_type is None:
                    raise BuildError("component without type")
                dims = []
                for ad in self.rules(c):
                    if _names(ad)[1].endswith("Dimensions"):
                        dims = self.dims_of(ad)
                comps.append(N.StrucComp(cur_type, self.name(self.rule(c, "name")), dims, span=self.span(c)))
        return N.StrucDecl(name, comps, "GLOBAL" in syms, span=self.span(ctx))

    def enum_decl(self, ctx) -> N.EnumDecl:
        syms = [s for s, _, _ in self.toks(ctx)]
        names = [self.name(n) for n in self.rules(ctx, "name")]
        return N.EnumDecl(names[0], names[1:], "GLOBAL" in syms, span=self.span(ctx))

    def signal_decl(self, ctx) -> N.SignalDecl:
        syms = [s for s, _, _ in self.toks(ctx)]
        if not self.rules(ctx, "signalReference"):
            tk = self.toks(ctx)
            sysname = next((t for s, t, _ in tk if s in ("SYSNAME", "IDENTIFIER")), None)
            nm = self.rule(ctx, "name", required=False)
            if "FALSE" in [s for s, _, _ in tk] and (sysname or nm is not None):
                return N.SignalDecl(sysname or self.name(nm), None, None, "GLOBAL" in syms,
                                    span=self.span(ctx))
        name = self.name(self.rule(ctx, "name"))
        refs = []
        for r in self.rules(ctx, "signalReference"):
            tk = self.toks(r)
            sysname = next(t for s, t, _ in tk if s in ("SYSNAME", "IDENTIFIER"))
            idx = next(int(t) for s, t, _ in tk if s == "INTLITERAL")
            refs.append(N.SignalRef(sysname, idx, span=self.span(r)))
        if not refs:
            raise BuildError("SIGNAL without reference")
        return N.SignalDecl(name, refs[0], refs[1] if len(refs) > 1 else None, "GLOBAL" in syms,
                            span=self.span(ctx))

    def ext_decl(self, ctx) -> N.ExtDecl:
        kind = self.first_tok(ctx)
        name = self.name(self.rule(ctx, "name"))
        rtype = None
        tref = self.rule(ctx, "typeRef", required=False)
        if tref is not None:
            rtype = self.typeref(tref)
        params = []
        plist = self.rule(ctx, "externalParameterList", required=False)
        if plist is not None:
            for p in self.rules(plist, "externalParameter"):
                params.append(self.ext_param(p))
        return N.ExtDecl(kind, name, params, rtype, span=self.span(ctx))

    def ext_param(self, ctx) -> N.ExtParam:
        p = N.ExtParam("", span=self.span(ctx))
        after_name = False
        size: int | None = None
        in_br = False
        for c in ctx.children or ():
            if isinstance(c, TerminalNode):
                s, t = self.sym(c), c.getText()
                if t == "[":
                    in_br, size = True, 0
                elif t == "]":
                    in_br = False
                    if after_name:
                        p.name_size = size
                    else:
                        p.type_size = size
                elif s == "INTLITERAL" and in_br:
                    size = int(t)
                elif s in ("IN", "OUT"):
                    p.mode = s
            else:
                b = _names(c)[1]
                if b in self._TYPE_RULES or b.endswith("Type"):
                    p.type_name = self.type_name(c)
                elif _matches(b, "name"):
                    p.name = self.name(c)
                    after_name = True
        return p

    def import_decl(self, ctx) -> N.ImportDecl:
        tname = self.type_name(self.rule(ctx, "typeName"))
        names = [self.name(n) for n in self.rules(ctx, "name")]
        return N.ImportDecl(tname, names[0], names[1:], span=self.span(ctx))

    def channel_decl(self, ctx) -> N.ChannelDecl:
        names = [self.name(n) for n in self.rules(ctx, "name")] + ["", "", ""]
        return N.ChannelDecl(names[0], names[1], names[2], span=self.span(ctx))

    def typeref(self, ctx) -> N.TypeRef:
        tctx = next((c for c in self.rules(ctx) if _names(c)[1] in self._TYPE_RULES
                     or _names(c)[1].endswith("Type")), None)
        if tctx is None:
            raise BuildError("type missing")
        tname = self.type_name(tctx)
        size = None
        for s, t, _ in self.toks(ctx):
            if t == "[":
                size = 0
            elif s == "INTLITERAL":
                size = int(t)
        return N.TypeRef(tname, size, span=self.span(ctx))

    def type_name(self, ctx) -> str:
        return self.source_text(ctx).strip()

    def name(self, ctx) -> str:
        if ctx is None:
            raise BuildError("missing name")
        text = ctx.getText()
        if not text or "<missing" in text:
            raise BuildError("missing name")
        return text

    # ---------------------------------------------------------------- statements

    def stmt_list(self, ctx) -> list[N.Stmt]:
        out: list[N.Stmt] = []
        if ctx is None:
            return out
        for c in ctx.children or ():
            if isinstance(c, ErrorNode):
                u = self.unparsed(c.symbol.line)     # tokens skipped between statement lines
                if u is not None:
                    out.append(u)
                continue
            if isinstance(c, ParserRuleContext):
                base = _names(c)[1]
                if self._error_line_of(c) is not None and base in ("statementLine", "statement",
                                                                   "declarationLine", "declaration"):
                    u = self.unparsed(c)
                    if u is not None:
                        out.append(u)
                    continue
                if base == "statementLine":
                    out.extend(self.stmt_line(c))
                elif base == "statement":
                    s = self.guarded(self.statement, c)
                    if s is not None:
                        out.append(s)
                elif base in ("declarationLine", "declaration"):
                    for d in ([c] if base == "declaration" else self.rules(c)):
                        decl = self.guarded(self.declaration, d)
                        if decl is not None:
                            out.append(N.DeclStmt(decl, span=decl.span))
                else:
                    out.extend(self.stmt_list(c))
        return out

    def stmt_line(self, ctx) -> list[N.Stmt]:
        out = []
        for c in self.rules(ctx):
            base = _names(c)[1]
            if base == "label":
                lab = self.guarded(lambda x: N.Label(self.name(self.rule(x, "name")), span=self.span(x)), c)
                if lab is not None:
                    out.append(lab)
            elif base in ("declaration",):
                decl = self.guarded(self.declaration, c)
                if decl is not None:
                    out.append(N.DeclStmt(decl, span=decl.span))
            else:
                s = self.guarded(self.statement, c)
                if s is not None:
                    out.append(s)
        return out

    def statement(self, ctx) -> N.Stmt:
        own, base = _names(ctx)
        sp = self.span(ctx)
        method = _STATEMENTS.get(own)
        if method is not None:
            return method(self, ctx, sp)
        if base == "assignment":
            return self.assignment(ctx)
        if base == "call":
            return N.CallStmt(self.call(ctx), span=sp)
        if base == "triggerStatement":
            return self.trigger(ctx)
        inner = self.rules(ctx)
        first = self.first_tok(ctx)
        if first in ("SPLINE", "PTP_SPLINE"):
            return self.spline_block(ctx, sp)
        if base == "motion" or own.endswith("Motion"):
            return self.motion(ctx, sp)
        tk = self.toks(ctx)
        if not inner and len(tk) == 1 and tk[0][0] == "IDENTIFIER":
            # a parameterless call without parentheses (`Name`), however the grammar labels it
            return N.CallStmt(N.Call(tk[0][1], [], span=sp), span=sp)
        if own == "moveEmiStatement" or first == "MOVE_EMI":
            return self.move_emi(ctx, sp)
        if tk and tk[0][2] is (ctx.children or [None])[0] and all(
                _names(c)[1] == "expression" for c in inner) and all(
                s not in ("ASSIGN", "COMMA") and t not in ("=", ",") for s, t, _ in tk):
            # KEYWORD [KEYWORD...] expression...: CONFIRM n, ASYPTP {E1 90}, ...
            words = [t.upper() for s, t, _ in tk]
            return N.KeywordStmt(words, [self.expr(c) for c in inner], span=sp)
        if len(inner) == 1 and not tk:
            # a wrapper alternative (e.g. `splineBlock # splineStatement`): unwrap it
            return self.statement(inner[0])
        if base in ("declaration",) or own.endswith("Declaration") and first in ("DECL", "CONST", "GLOBAL"):
            return N.DeclStmt(self.declaration(ctx), span=sp)
        self.unknown(ctx, "statement")
        return N.Unsupported(own, self.source_text(ctx), span=sp)

    def move_emi(self, ctx, sp) -> N.MoveEmi:
        target = self.variable(self.rule(ctx, "variable"))
        text = next(t for s, t, _ in self.toks(ctx) if s == "STRINGLITERAL")[1:-1]
        key = self.rule(ctx, "name", required=False)
        value = self.rule(ctx, "expression", required=False)
        return N.MoveEmi(target, text, self.name(key) if key is not None else None,
                         self.expr(value) if value is not None else None, span=sp)

    def s_assign(self, ctx, sp):
        a = self.rule(ctx, "assignment")
        return self.assignment(a)

    def assignment(self, a) -> N.Assign:
        self.check_ok(a)
        target = self.variable(self.rule(a, "variable"))
        value = self.expr(self.rule(a, "expression"))
        return N.Assign(target, value, span=self.span(a))

    def s_call(self, ctx, sp):
        return N.CallStmt(self.call(self.rule(ctx, "call")), span=sp)

    def s_if(self, ctx, sp):
        lists = self.rules(ctx, "statementList")
        cond = self.expr(self.rule(ctx, "expression"))
        then = self.stmt_list(lists[0]) if lists else []
        orelse = self.stmt_list(lists[1]) if self.has(ctx, "ELSE") and len(lists) > 1 else (
            [] if self.has(ctx, "ELSE") else None)
        return N.If(cond, then, orelse, span=sp)

    def s_switch(self, ctx, sp):
        sel = self.expr(self.rule(ctx, "expression"))
        cases = []
        for c in self.rules(ctx, "switchCase"):
            self.check_ok(c)
            vals = [self.expr(e) for e in self.rules(c, "expression")]
            cases.append(N.Case(vals, self.stmt_list(self.rule(c, "statementList", required=False)),
                                span=self.span(c)))
        d = self.rule(ctx, "switchDefault", required=False)
        default = self.stmt_list(self.rule(d, "statementList", required=False)) if d is not None else None
        return N.Switch(sel, cases, default, span=sp)

    def s_for(self, ctx, sp):
        nm = self.rule(ctx, "name")
        exprs = [self.expr(e) for e in self.rules(ctx, "expression")]
        if len(exprs) < 2:
            raise BuildError("FOR without bounds")
        return N.For(N.Name(self.name(nm), span=self.span(nm)), exprs[0], exprs[1],
                     exprs[2] if len(exprs) > 2 else None,
                     self.stmt_list(self.rule(ctx, "statementList", required=False)), span=sp)

    def s_while(self, ctx, sp):
        return N.While(self.expr(self.rule(ctx, "expression")),
                       self.stmt_list(self.rule(ctx, "statementList", required=False)), span=sp)

    def s_repeat(self, ctx, sp):
        return N.Repeat(self.stmt_list(self.rule(ctx, "statementList", required=False)),
                        self.expr(self.rule(ctx, "expression")), span=sp)

    def s_loop(self, ctx, sp):
        return N.Loop(self.stmt_list(self.rule(ctx, "statementList", required=False)), span=sp)

    def s_goto(self, ctx, sp):
        return N.Goto(self.name(self.rule(ctx, "name")), span=sp)

    def s_wait_for(self, ctx, sp):
        return N.WaitFor(self.expr(self.rule(ctx, "expression")), span=sp)

    def s_wait_sec(self, ctx, sp):
        return N.WaitSec(self.expr(self.rule(ctx, "expression")), span=sp)

    def s_return(self, ctx, sp):
        e = self.rule(ctx, "expression", required=False)
        return N.Return(self.expr(e) if e is not None else None, span=sp)

    def priority(self, ctx) -> N.Expr:
        b = _names(ctx)[1]
        if b == "expression":
            return self.expr(ctx)
        nm = self.rule(ctx, "name", required=False)
        if nm is not None:
            return N.Name(self.name(nm), span=self.span(nm))
        e = self.rule(ctx, "expression", required=False)
        if e is not None:
            return self.expr(e)
        for s, t, tn in self.toks(ctx):
            if s == "INTLITERAL":
                return N.IntLit(int(t), span=self.span(tn))
        raise BuildError("bad priority")

    def s_int_decl(self, ctx, sp):
        pr = self.rule(ctx, "priority", required=False)
        exprs = self.rules(ctx, "expression")
        if pr is not None:
            prio = self.priority(pr)
            when = self.expr(exprs[0])
        else:
            prio, when = self.expr(exprs[0]), self.expr(exprs[1])
        call_ctx = self.rule(ctx, "call", required=False)
        if call_ctx is not None:
            return N.InterruptDecl(prio, when, self.call(call_ctx), self.has(ctx, "GLOBAL"), span=sp)
        syms = [s for s, _, _ in self.toks(ctx)]
        after_do = syms[syms.index("DO") + 1:] if "DO" in syms else []
        if "BRAKE_F" in after_do or "BRAKE" in after_do:
            fast = "BRAKE_F" in after_do
            brake = N.Brake(fast, span=sp)
            call = N.Call("BRAKE_F" if fast else "BRAKE", [], span=sp)
            return N.InterruptDecl(prio, when, call, self.has(ctx, "GLOBAL"), brake, span=sp)
        raise BuildError("interrupt declaration without action")

    def s_int_ctl(self, ctx, sp):
        action = next(s for s, _, _ in self.toks(ctx) if s in ("ON", "OFF", "ENABLE", "DISABLE"))
        pr = self.rule(ctx, "priority", required=False) or self.rule(ctx, "expression", required=False)
        return N.InterruptCtl(action, self.priority(pr) if pr is not None else None, span=sp)

    def s_trigger(self, ctx, sp):
        t = self.rule(ctx, "triggerStatement", required=False) or ctx
        return self.trigger(t)

    def keyed(self, ctx) -> dict[str, object]:
        """Children after `KEY =` pairs: {'DELAY': exprctx, 'DISTANCE': token, ...}."""
        out: dict[str, object] = {}
        key = None
        for c in ctx.children or ():
            if isinstance(c, TerminalNode):
                s = self.sym(c)
                if s in ("DISTANCE", "PATH", "DELAY", "PRIO", "MINIMUM", "MAXIMUM"):
                    key = s
                elif key and s in ("INTLITERAL", "REALLITERAL"):
                    out[key] = c
                    key = None
            elif key and _names(c)[1] == "expression":
                out[key] = c
                key = None
        return out

    def keyed_expr(self, item) -> N.Expr:
        if isinstance(item, TerminalNode):
            t = item.getText()
            if self.sym(item) == "INTLITERAL":
                return N.IntLit(int(t), span=self.span(item))
            return N.RealLit(float(t), span=self.span(item))
        return self.expr(item)

    def trigger(self, ctx) -> N.Trigger:
        self.check_ok(ctx)
        kv = self.keyed(ctx)
        kind = "PATH" if "PATH" in kv else "DISTANCE"
        act = self.rule(ctx, "triggerAction")
        inner = self.rules(act)
        if not inner:
            raise BuildError("trigger without action")
        a = inner[0]
        ab = _names(a)[1]
        if ab == "assignment":
            action: N.Stmt = self.assignment(a)
        elif ab == "call":
            action = N.CallStmt(self.call(a), span=self.span(a))
        else:
            action = self.statement(a)
        return N.Trigger(kind, self.keyed_expr(kv[kind]), self.keyed_expr(kv["DELAY"]), action,
                         self.keyed_expr(kv["PRIO"]) if "PRIO" in kv else None,
                         self.has(ctx, "ONSTART"), span=self.span(ctx))

    def s_cond_stop(self, ctx, sp):
        return self.cond_stop(self.rule(ctx, "conditionalStop", required=False) or ctx)

    def cond_stop(self, ctx) -> N.ConditionalStop:
        self.check_ok(ctx)
        exprs = self.rules(ctx, "expression")
        if len(exprs) != 2:
            raise BuildError("conditional stop without its distance or condition")
        return N.ConditionalStop(self.expr(exprs[0]), self.expr(exprs[1]), self.has(ctx, "ONSTART"),
                                 span=self.span(ctx))

    def s_anin_on(self, ctx, sp):
        return N.AninOn(self.variable(self.rule(ctx, "variable")),
                        self.expr(self.rule(ctx, "expression")), span=sp)

    def s_anin_off(self, ctx, sp):
        return N.AninOff(self.name(self.rule(ctx, "name")), span=sp)

    def s_anout_on(self, ctx, sp):
        kv = self.keyed(ctx)
        value = None
        for c in ctx.children or ():
            if isinstance(c, ParserRuleContext) and _names(c)[1] == "expression":
                value = self.expr(c)
                break
        opt = {k: self.keyed_expr(v) for k, v in kv.items()}
        return N.AnoutOn(self.name(self.rule(ctx, "name")), value, opt.get("DELAY"),
                         opt.get("MINIMUM"), opt.get("MAXIMUM"), span=sp)

    def s_anout_off(self, ctx, sp):
        return N.AnoutOff(self.name(self.rule(ctx, "name")), span=sp)

    def s_motion(self, ctx, sp):
        m = self.rule(ctx, "motion", required=False)
        if m is None:
            inner = self.rules(ctx)
            if len(inner) == 1:
                return self.statement(inner[0])
            raise BuildError("motion statement without motion")
        return self.motion(m, self.span(m))

    def motion(self, ctx, sp) -> N.Stmt:
        self.check_ok(ctx)
        kind = self.first_tok(ctx)
        if kind in ("SPLINE", "PTP_SPLINE"):
            return self.spline_block(ctx, sp)
        exprs: list[N.Expr] = []
        ca = None
        ca_next = False
        approx: list[str] = []
        with_: list[N.WithAssign] = []
        frame = None
        for c in ctx.children or ():
            if isinstance(c, TerminalNode):
                if isinstance(c, ErrorNode):
                    raise BuildError("error node")
                s = self.sym(c)
                if s == "CA":
                    ca_next = True
                elif s in ("C_PTP", "C_DIS", "C_VEL", "C_ORI", "C_SPL"):
                    approx.append(s)
                elif s == "ENUMLITERAL":
                    frame = c.getText()
                continue
            b = _names(c)[1]
            if b == "expression":
                e = self.expr(c)
                if ca_next:
                    ca, ca_next = e, False
                else:
                    exprs.append(e)
            elif b in ("approximation", "splineApproximation"):
                approx.append(self.first_tok(c))
            elif b == "withClause":
                with_.extend(self.with_clause(c))
            elif b == "motion":
                return self.motion(c, sp)
            else:
                # e.g. relativeFrame: an enum literal naming the frame; C_SPL-like tokens
                for s2, t2, _ in self.toks(c):
                    if s2 == "ENUMLITERAL":
                        frame = t2
                    elif s2 in ("C_PTP", "C_DIS", "C_VEL", "C_ORI", "C_SPL"):
                        approx.append(s2)
        if not exprs:
            raise BuildError("motion without target")
        aux = exprs[0] if len(exprs) > 1 else None
        return N.Motion(kind, exprs[-1], aux, ca, approx, with_, frame, span=sp)

    def with_clause(self, ctx) -> list[N.WithAssign]:
        out = []
        for w in self.rules(ctx, "withAssignment"):
            self.check_ok(w)
            tgt_ctx = self.rules(w)[0]
            target = self.variable(tgt_ctx)
            value = self.expr(self.rule(w, "expression"))
            out.append(N.WithAssign(target, value, span=self.span(w)))
        return out

    def spline_block(self, ctx, sp) -> N.SplineBlock:
        kind = self.first_tok(ctx)
        body: list[N.Stmt] = []
        with_: list[N.WithAssign] = []
        approx = None
        seen_end = False

        def collect(c) -> None:
            nonlocal approx, seen_end
            for ch in c.children or ():
                if isinstance(ch, TerminalNode):
                    s = self.sym(ch)
                    if s == "ENDSPLINE":
                        seen_end = True
                    elif s == "C_SPL" and seen_end:
                        approx = "C_SPL"
                    continue
                own, b = _names(ch)
                if b == "withClause" and not body and not seen_end:
                    with_.extend(self.with_clause(ch))
                elif b in ("motion", "triggerStatement", "conditionalStop") or own.endswith(("Motion", "Segment")) \
                        or b.endswith("Segment"):
                    if b == "triggerStatement":
                        st = self.guarded(self.trigger, ch)
                    elif b == "conditionalStop":
                        st = self.guarded(self.cond_stop, ch)
                    else:
                        st = self.guarded(lambda x: self.motion(x, self.span(x)), ch)
                    if st is not None:
                        body.append(st)
                elif b == "statement" and self.first_tok(ch) not in ("SPL", "SLIN", "SCIRC", "SPTP"):
                    st = self.guarded(self.statement, ch)
                    if st is not None:
                        body.append(st)
                elif b in ("splineApproximation", "approximation") and seen_end:
                    approx = self.first_tok(ch)
                else:
                    collect(ch)

        collect(ctx)
        return N.SplineBlock(kind, body, with_, approx, span=sp)

    # ---------------------------------------------------------------- expressions

    def value(self, ctx) -> N.Expr:
        """A data-list constantValue or an expression."""
        b = _names(ctx)[1]
        if b == "expression":
            return self.expr(ctx)
        if b == "constantAggregate" or b == "aggregate":
            return self.aggregate(ctx)
        self.check_ok(ctx)
        sub = self.rules(ctx)
        sign = None
        lit = None
        for c in ctx.children or ():
            if isinstance(c, TerminalNode):
                t = c.getText()
                if t in ("-", "+"):
                    sign = t
                else:
                    lit = self.literal_token(c)
        if sub:
            lit = self.value(sub[0]) if _names(sub[0])[1] != "literal" else self.literal(sub[0])
        if lit is None:
            raise BuildError("empty constant")
        if sign is not None:
            return N.Unary(sign, lit, span=self.span(ctx))
        return lit

    def expr(self, ctx) -> N.Expr:
        """The AST of an expression context. A left-nested chain of binary operators (one
        parse-tree level per operator, up to krl.limits.MAX_EXPRESSION_TERMS terms) is walked
        in a loop, not recursively; recursion is left for brackets and prefix operators, which
        krl.limits.MAX_NESTING bounds. Left before right, as the operators associate."""
        links: list[tuple[str, object, N.Span]] = []   # (op, right context, span), outermost first
        while True:
            if ctx is None:
                raise BuildError("missing expression")
            if getattr(ctx, "exception", None) is not None:
                raise BuildError("recovered expression")
            own, base = _names(ctx)
            if base in ("primary", "literal", "variable", "call", "aggregate", "constantAggregate"):
                break
            kids = ctx.children or []
            rule_kids = [c for c in kids if isinstance(c, ParserRuleContext)]
            term_kids = [c for c in kids if isinstance(c, TerminalNode)]
            if any(isinstance(c, ErrorNode) for c in term_kids):
                raise BuildError("error node in expression")
            if len(rule_kids) == 1 and not term_kids:
                ctx = rule_kids[0]
            elif len(rule_kids) == 1 and len(term_kids) == 1 and kids[0] is term_kids[0]:
                break
            elif len(rule_kids) == 2 and len(term_kids) == 1 and kids[1] is term_kids[0]:
                links.append((term_kids[0].getText().upper(), rule_kids[1], self.span(term_kids[0])))
                ctx = rule_kids[0]
            elif len(rule_kids) == 1 and [t.getText() for t in term_kids] == ["(", ")"]:
                ctx = rule_kids[0]
            else:
                raise BuildError(f"unknown expression form {own}")
        node = self._operand(ctx, base)
        for op, right, span in reversed(links):
            node = N.Binary(op, node, self.expr(right), span=span)
        return node

    def _operand(self, ctx, base: str) -> N.Expr:
        """An expression context that is no binary operator: a primary, literal, variable,
        call, aggregate or prefix operator."""
        if base == "primary":
            return self.primary(ctx)
        if base in ("literal",):
            return self.literal(ctx)
        if base in ("variable",):
            return self.variable(ctx)
        if base == "call":
            return self.call(ctx)
        if base in ("aggregate", "constantAggregate"):
            return self.aggregate(ctx)
        if base == "channelName":
            return N.ChannelName(self.name(self.rule(ctx, "name")), span=self.span(ctx))
        kids = ctx.children or []
        term = kids[0]
        return N.Unary(term.getText().upper(), self.expr(kids[1]), span=self.span(ctx))

    def primary(self, ctx) -> N.Expr:
        inner = self.rules(ctx)
        if len(inner) != 1:
            raise BuildError("bad primary")
        return self.expr(inner[0])

    def literal_token(self, tn) -> N.Expr:
        s, t, sp = self.sym(tn), tn.getText(), self.span(tn)
        if s == "INTLITERAL":
            return N.IntLit(int(t), span=sp)
        if s == "REALLITERAL":
            return N.RealLit(float(t), span=sp)
        if s == "HEXLITERAL":
            return N.IntLit(int(t[2:-1], 16), 16, span=sp)
        if s == "BINLITERAL":
            return N.IntLit(int(t[2:-1], 2), 2, span=sp)
        if s == "TRUE":
            return N.BoolLit(True, span=sp)
        if s == "FALSE":
            return N.BoolLit(False, span=sp)
        if s == "STRINGLITERAL":
            return N.StrLit(t[1:-1], span=sp)
        if s == "ENUMLITERAL":
            return N.EnumLit(t[1:], span=sp)
        raise BuildError(f"unknown literal token {s}")

    def literal(self, ctx) -> N.Expr:
        tk = [c for c in ctx.children or () if isinstance(c, TerminalNode)]
        if len(tk) != 1 or isinstance(tk[0], ErrorNode):
            raise BuildError("bad literal")
        return self.literal_token(tk[0])

    def variable(self, ctx) -> N.Expr:
        self.check_ok(ctx)
        kids = list(ctx.children or ())
        if not kids:
            raise BuildError("empty variable")
        head = kids[0]
        if isinstance(head, TerminalNode):
            node: N.Expr = N.Name(head.getText(), span=self.span(head))
        else:
            node = N.Name(self.name(head), span=self.span(head))
        for sel in kids[1:]:
            if isinstance(sel, TerminalNode) or _names(sel)[1] != "selector":
                raise BuildError("bad selector")
            node = self.selector(node, sel)
        return node

    def selector(self, base: N.Expr, ctx) -> N.Expr:
        self.check_ok(ctx)
        kids = list(ctx.children or ())
        first = kids[0].getText() if kids else ""
        if first == ".":
            return N.Field(base, self.name(self.rule(ctx, "name")), span=base.span)
        if first != "[":
            raise BuildError("bad selector")
        return N.Index(base, self.slots(kids[1:], "]"), span=base.span)

    def slots(self, kids, closer: str) -> list:
        """Comma-separated optional expressions up to `closer`: '[a,,b]' -> [a, None, b]."""
        out: list = []
        cur = None
        for c in kids:
            if isinstance(c, TerminalNode):
                t = c.getText()
                if isinstance(c, ErrorNode):
                    raise BuildError("error node")
                if t == ",":
                    out.append(cur)
                    cur = None
                elif t == closer:
                    out.append(cur)
                    return out
            else:
                b = _names(c)[1]
                if b == "argumentList":
                    return self.slots(list(c.children or ()), closer)
                inner = self.rules(c) if b == "argument" else [c]
                if b == "argument" and len(inner) != 1:
                    raise BuildError("bad argument")
                cur = self.expr(inner[0])
        out.append(cur)
        return out

    def call(self, ctx) -> N.Call:
        self.check_ok(ctx)
        name = self.name(self.rule(ctx, "name"))
        args_ctx = self.rule(ctx, "argumentList", required=False)
        args: list = []
        if args_ctx is not None:
            self.check_ok(args_ctx)
            args = self.slots(list(args_ctx.children or ()), "\0")
        return N.Call(name, args, span=self.span(ctx))

    def aggregate(self, ctx) -> N.Aggregate:
        self.check_ok(ctx)
        tn = self.rule(ctx, "typeName", required=False)
        items = []
        for comp in self.rules(ctx):
            b = _names(comp)[1]
            if b in ("aggregateComponent", "constantComponent"):
                self.check_ok(comp)
                nm = self.name(self.rule(comp, "name"))
                arr = self.has(comp, "LBRACK") or any(t == "[" for _, t, _ in self.toks(comp))
                vctx = [c for c in self.rules(comp) if not _matches(_names(c)[1], "name")]
                if not vctx:
                    raise BuildError("component without value")
                items.append(N.AggItem(nm, self.value(vctx[0]), arr, span=self.span(comp)))
        return N.Aggregate(self.type_name(tn) if tn is not None else None, items, span=self.span(ctx))


_STATEMENTS = {
    "assignmentStatement": Builder.s_assign,
    "callStatement": Builder.s_call,
    "ifStatement": Builder.s_if,
    "switchStatement": Builder.s_switch,
    "forStatement": Builder.s_for,
    "whileStatement": Builder.s_while,
    "repeatStatement": Builder.s_repeat,
    "loopStatement": Builder.s_loop,
    "exitStatement": lambda self, ctx, sp: N.Exit(span=sp),
    "gotoStatement": Builder.s_goto,
    "haltStatement": lambda self, ctx, sp: N.Halt(span=sp),
    "waitForStatement": Builder.s_wait_for,
    "waitSecStatement": Builder.s_wait_sec,
    "continueStatement": lambda self, ctx, sp: N.Continue(span=sp),
    "returnStatement": Builder.s_return,
    "onErrorProceedStatement": lambda self, ctx, sp: N.OnErrorProceed(span=sp),
    "interruptDeclaration": Builder.s_int_decl,
    "interruptControl": Builder.s_int_ctl,
    "brakeStatement": lambda self, ctx, sp: N.Brake(False, span=sp),
    "brakeFStatement": lambda self, ctx, sp: N.Brake(True, span=sp),
    "resumeStatement": lambda self, ctx, sp: N.Resume(span=sp),
    "triggerStatementAlt": Builder.s_trigger,
    "triggerStatement": Builder.s_trigger,
    "conditionalStopStatement": Builder.s_cond_stop,
    "aninOnStatement": Builder.s_anin_on,
    "aninOffStatement": Builder.s_anin_off,
    "anoutOnStatement": Builder.s_anout_on,
    "anoutOffStatement": Builder.s_anout_off,
    "motionStatement": Builder.s_motion,
}


def build_module(result, sink: DiagnosticSink | None = None) -> N.Module:
    """Build the AST of one parsed file.

    `result` is a krl.syntax.parse.ParseResult (its `.tree` must be kept); `sink` holds the
    file's syntax findings when the caller made them first (krl/workspace.py): a line whose
    finding is one of ``PROGRAM_SYNTAX_CODES`` gets it as its ``Unparsed.error``. Returns a
    Module (possibly empty, for a file that was not parsed or lost its tree). Never raises;
    a construct that cannot be built is an E003 error (the program does not start), one the
    builder does not map yet a W003 warning (it is kept as an Unsupported statement). Reference: sections 2-6 for the shapes.
    """
    sink = sink if sink is not None else DiagnosticSink()
    path = result.path
    tree = getattr(result, "tree", None)
    if tree is None:
        return N.Module(path, "dat" if path.lower().endswith(".dat") else "src", span=N.Span(path, 1, 1))
    try:
        parser = getattr(tree, "parser", None)
        symbolic = list(type(parser).symbolicNames) if parser is not None else []
        lines: dict[int, str] = {}
        for e in getattr(result, "errors", None) or ():
            lines.setdefault(e.line, e.line_text)
        rejected = {d.line: f"{d.code}: {d.message}" for d in reversed(sink.items)
                    if d.code in PROGRAM_SYNTAX_CODES and d.path == path and d.line in lines}
        b = Builder(path, sink, symbolic, recovered=not result.ok, error_lines=lines, line_errors=rejected)
        return b.module(tree)
    except Exception as exc:  # noqa: BLE001 - never raise on any parse tree
        sink.add(path, 1, 1, *E003("failed", error=f"{type(exc).__name__}: {exc}"))
        return N.Module(path, "src", span=N.Span(path, 1, 1))


def build_expression(tree, path: str, symbolic: list[str]) -> N.Expr | None:
    """The AST of an expression parse tree (:func:`krl.syntax.parse.parse_expression`), or None
    when the tree is malformed or holds a construct the builder cannot build. `symbolic`: the
    parser's token names. Never raises."""
    sink = DiagnosticSink()
    try:
        expr = Builder(path, sink, symbolic, recovered=False).expr(tree)
    except BuildError:
        return None
    return None if sink.items else expr
