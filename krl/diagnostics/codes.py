"""Every diagnostic code, declared once: its severity, its kind (the short name reports use) and
its message templates. An emit site names the code's constant and fills a template; nothing
else spells a code (tests/frontend/test_diagnostics_doc.py: every code here has its section in
docs/diagnostics.md and every section a code here; no code is written as a bare string outside
this module; every code is emitted somewhere).

A :class:`Code` *is* its code's text (``E102 == "E102"``), so it compares, sorts and
serialises as a plain string. Calling it gives the ``(code, message)`` pair of a diagnostic:
``E102(name="X", where="")`` -> ``("E102", "'X' is declared more than once")``; a code with
several messages names the one: ``E109("dims", name="a", have=1, given=2)``. The pair is
spread into a sink or a Diagnostic: ``sink.at(span, *E102(name=..., where=...))``.

Adding a code: declare it here (in its group, with its templates), add its ``## CODE`` section
to docs/diagnostics.md (what it means, an example that produces it, the fix), emit it.
Codes are stable: tests, reports, ``krl.toml`` and users refer to them.
"""

from __future__ import annotations

ERROR = "error"
WARNING = "warning"


class Code(str):
    """A diagnostic code (module docstring): the string ``"E102"`` with ``severity`` ('error'
    or 'warning'), ``kind`` (the short name of the rule) and ``messages`` (variant name ->
    ``str.format`` template; the default variant is ``""``)."""

    severity: str
    kind: str
    messages: dict[str, str]

    def __new__(cls, code: str, severity: str, kind: str, message: str = "{detail}", **variants: str) -> "Code":
        self = super().__new__(cls, code)
        self.severity = severity
        self.kind = kind
        self.messages = {"": message, **variants}
        return self

    def __call__(self, variant: str = "", /, **fields) -> tuple[str, str]:
        """(code, message): the template `variant` filled with `fields` (the code as a plain
        str). Raises KeyError for a variant or a field the template does not have."""
        return str(self), self.messages[variant].format(**fields)

    def __reduce__(self):
        return str, (str(self),)


# ---------------------------------------------------------------------- input and syntax (E0xx)
E001 = Code("E001", ERROR, "unreadable or binary input", "file not parsed: {why}",
            not_checked="file not checked: {why}", missing="no such file or folder")
W002 = Code("W002", WARNING, "entry of a folder not read (symbolic link, FIFO/socket/device, folder unreadable or "
                             "too deep)", "not read: {why}")
E002 = Code("E002", ERROR, "syntax error", "{detail}",
            glued="{text} is read as one name; write {fix}",
            ends_early="the line ends too early{expected}",
            unexpected="unexpected {token}{after}{expected}",
            open_array="{name} has no size ({example}): the controller rejects an open dimension outside a "
                       "parameter list and does not declare {name} (reference 3.3)")
W003 = Code("W003", WARNING, "construct not understood by the AST builder", "{what} '{name}' is not mapped to the AST yet")
E003 = Code("E003", ERROR, "construct that cannot be built (too large or malformed)",
            "cannot build '{name}': {error}", too_deep="construct nested too deeply to build",
            failed="AST builder failed: {error}")
E004 = Code("E004", ERROR, "backup archive refused (unsafe entry or past a limit)", "{detail}")
E005 = Code("E005", ERROR, "file not parsed within the time limit (--timeout)",
            "file not parsed within {timeout:g} s (--timeout; the parse was stopped)",
            not_checked="file not checked: not parsed within {timeout:g} s (--timeout; the parse was stopped)")
E010 = Code("E010", ERROR, "block not closed", "missing {closer} for the {opener} at line {line}")
E011 = Code("E011", ERROR, "block closer without its opener", "{kw} without an open {opener}",
            wrong="{kw} does not close the {opener} at line {line}; use {closer}",
            two_words="`END {word}` is written {kw}, in one word",
            outside="{kw} outside {article} {opener} block",
            second_else="second ELSE in the IF at line {line}")
E012 = Code("E012", ERROR, "statement missing a keyword or a part", "{detail}",
            second_word="{kw} needs {listed}, found {found}",
            wait="WAIT needs FOR and a condition, or SEC and a time",
            keyword="{kw} needs {keyword}{what}{found}",
            bare_name="{name} alone is not a statement; to call the routine write {call}",
            expression_after="an expression is missing after {after}",
            expression="an expression is missing here")
E013 = Code("E013", ERROR, "`==` where an assignment `=` is meant", "`==` compares; to assign use `=`",
            comparison="{op} compares; a statement cannot be a comparison (to assign use `=`)",
            condition="`=` assigns; to compare use `==`",
            pascal="`:=` is not KRL; to assign use `=`",
            increment="`++` and `+=` are not KRL; write `n = n + 1`")
E014 = Code("E014", ERROR, "declaration after the first statement (syntax)",
            "declarations must come before the first statement")
E015 = Code("E015", ERROR, "bracket or string not closed", "{detail}",
            no_opening="{bracket} without an opening {opening}",
            not_closed="this {bracket} is not closed; expected {closing} before {token}")
E016 = Code("E016", ERROR, "unexpected text after a complete statement",
            "{token} after the end of the statement; KRL has one statement per line",
            alone="{token} after {kw}: {kw} stands alone on its line")
E017 = Code("E017", ERROR, "character that is not KRL", "{char} is not a KRL character here", hint="{detail}")
E018 = Code("E018", ERROR, "nesting too deep", "nesting too deep: more than {limit} levels of blocks and brackets")
E019 = Code("E019", ERROR, "expression too long", "expression too long: more than {limit} terms in one statement")
E020 = Code("E020", ERROR, "unexpected end of file", "unexpected end of file{expected}")
W021 = Code("W021", WARNING, "unbalanced ;FOLD / ;ENDFOLD", "`;ENDFOLD` without an open `;FOLD`",
            after_end="`;FOLD` closed by the `;ENDFOLD` at line {line}, after the end of {routine} (line {end})",
            into_routine="`;FOLD` outside any routine closed by the `;ENDFOLD` at line {line}, inside a routine",
            unclosed="`;FOLD` never closed (it opens in {routine}, which ends at line {end})",
            unclosed_file="`;FOLD` never closed before the end of the file (line {line})")

# ---------------------------------------------------------------------- names and declarations (E1xx)
E101 = Code("E101", ERROR, "undeclared name", "'{name}' is not declared",
            parameter="parameter '{name}' of {routine} has no declaration")
W101 = Code("W101", WARNING, "name not in the backup, declared by installed software (once per backup)",
            "{noun} '{name}' is not declared in this backup ({times}; first here): {why}", soft="'{name}' is not declared")
E102 = Code("E102", ERROR, "duplicate declaration", "'{name}' is declared more than once{where}",
            component="component '{name}' appears twice in {struc}")
E103 = Code("E103", ERROR, "identifier longer than 24 characters",
            "identifier '{name}' has {length} characters (at most {limit})")
E104 = Code("E104", ERROR, "declaration after the first statement", "declaration after the first statement of the routine")
E105 = Code("E105", ERROR, "unknown type", "unknown type '{name}'")
W105 = Code("W105", WARNING, "type not in the backup, declared by installed software (once per backup)",
            "{noun} '{name}' is not declared in this backup ({times}; first here): {why}", soft="unknown type '{name}'")
E106 = Code("E106", ERROR, "undeclared routine", "routine '{name}' is not declared")
W106 = Code("W106", WARNING, "routine not in the backup, provided by installed software (once per backup)",
            "{noun} '{name}' is not declared in this backup ({times}; first here): {why}",
            soft="routine '{name}' is not declared",
            ext="{noun} '{name}' is declared EXT but not defined in this backup ({times}; first here): {why}")
W107 = Code("W107", WARNING, "system variable the platform tables do not list (once per backup)",
            "{noun} '{name}' is not declared in this backup ({times}; first here): {why}",
            soft="unknown system variable '{name}'")
E108 = Code("E108", ERROR, "unknown structure component", "{struc} has no component '{name}'",
            not_struc="'.{name}' applied to {type}, which is not a structure")
W108 = Code("W108", WARNING, "component not in the built-in structure table", "{struc} has no component '{name}'")
E109 = Code("E109", ERROR, "not an array / wrong number of indices", "'{name}' is not an array",
            not_array_type="'{name}' is {type}, not an array",
            dims="'{name}' has {have} dimension(s), {given} given",
            last_only="only the last index may be left out")
E110 = Code("E110", ERROR, "array index out of range", "index {index} is outside 1..{size}",
            named="index {index} of '{name}' is outside 1..{size}")
W111 = Code("W111", WARNING, "main routine name differs from the file name",
            "main routine '{name}' differs from the file name '{file}'")

# ---------------------------------------------------------------------- types (E2xx)
E201 = Code("E201", ERROR, "incompatible types in assignment", "{reason}", assign="{what}: {reason}",
            aggregate="an aggregate cannot be assigned to {type}")
W201 = Code("W201", WARNING, "aggregate for a built-in type that the tables do not describe as a structure",
            "an aggregate cannot be assigned to {type}")
W202 = Code("W202", WARNING, "lossy conversion (REAL to INT rounds)", "{what}: {reason}")
E203 = Code("E203", ERROR, "operator applied to wrong operand types", "'{op}' cannot be applied to {left} and {right}",
            number="{what} needs a number, not {type}", integer="{what} must be INT, not {type}",
            unary="{op} cannot be applied to {type}", geometric="':' needs FRAME, POS or E6POS operands, not {type}")
E204 = Code("E204", ERROR, "condition is not BOOL", "{what} condition is {type}, not BOOL")
E205 = Code("E205", ERROR, "ENUM literal not of the expected type", "#{name} is not a value of {enum}",
            assign="{what}: {reason}")
W205 = Code("W205", WARNING, "ENUM literal not in the built-in enum table", "#{name} is not a value of {enum}",
            assign="{what}: {reason}")
E206 = Code("E206", ERROR, "unknown aggregate component", "{struc} has no component '{name}'",
            twice="component '{name}' given twice")
W206 = Code("W206", WARNING, "aggregate component not in the built-in structure table", "{struc} has no component '{name}'")
E207 = Code("E207", ERROR, "invalid SWITCH selector or CASE value", "SWITCH selector must be INT, CHAR or ENUM, not {type}",
            case="CASE value of type {type} for a {selector} selector")
E208 = Code("E208", ERROR, "FOR counter must be an INT variable", "FOR counter '{name}' is {type}, not INT",
            not_variable="FOR counter '{name}' is not a variable")
E209 = Code("E209", ERROR, "invalid motion target", "motion target of type {type}; expected a position or axis type",
            mixed="aggregate target mixes or misses axis and Cartesian components")
W210 = Code("W210", WARNING, "string longer than the CHAR array", "{what}: {reason}")
E211 = Code("E211", ERROR, "invalid array index type", "array index of type {type}; indices are INT")
E212 = Code("E212", ERROR, "FOR STEP is not a non-zero INT constant", "FOR STEP must be an INT constant (a literal or a CONST)",
            zero="FOR STEP must not be 0")

# ---------------------------------------------------------------------- calls (E3xx)
E301 = Code("E301", ERROR, "too many arguments", "'{name}' takes {params} argument(s), {given} given")
E302 = Code("E302", ERROR, ":OUT argument is not a variable", "argument {n} of '{name}' is :OUT and must be a variable")
E303 = Code("E303", ERROR, "argument type mismatch", "argument {n} of '{name}': {reason}")
E304 = Code("E304", ERROR, "procedure used as a function or function as a statement", "procedure '{name}' has no value",
            statement="function '{name}' called as a statement; use its value (x = {name}(...))")

# ---------------------------------------------------------------------- control flow (E4xx)
E401 = Code("E401", ERROR, "GOTO target not found in the routine", "GOTO target '{label}' is not a label of {routine}")
E402 = Code("E402", ERROR, "GOTO into a block", "GOTO {label} jumps into a block")
E403 = Code("E403", ERROR, "EXIT outside a loop", "EXIT outside a loop")
E404 = Code("E404", ERROR, "RETURN value mismatch", "RETURN in function {routine} needs a value",
            procedure="RETURN with a value in procedure {routine}")
E405 = Code("E405", ERROR, "duplicate label", "label '{label}' is defined more than once")
E406 = Code("E406", ERROR, "motion statement in a submit program",
            "{what} in a submit program (.sub): the submit interpreter has no motion")
E408 = Code("E408", ERROR, "interrupt priority outside 1..128", "interrupt priority {prio} is outside 1..128")
E409 = Code("E409", ERROR, "TRIGGER calling a routine without PRIO",
            "a TRIGGER that calls a routine needs PRIO (-1 lets the system choose)")

# ---------------------------------------------------------------------- system variables and write protection (E5xx)
E501 = Code("E501", ERROR, "write to a write-protected variable or an input", "'{name}' is write-protected",
            input="'{name}' is an input; programs cannot write inputs (5.13)")
W501 = Code("W501", WARNING, "write to a SIGNAL name of an input",
            "'{name}' is an input; programs can only write simulated inputs")
E502 = Code("E502", ERROR, "assignment to a constant", "'{name}' is a constant")
E503 = Code("E503", ERROR, "not an assignable variable", "the left side of an assignment must be a variable",
            routine="'{name}' is a routine, not a variable")

# ---------------------------------------------------------------------- internal (E9xx)
E901 = Code("E901", ERROR, "internal checker error", "internal checker error: {error}",
            datalist="internal checker error in data list: {error}",
            too_deep="routine nested too deeply to check",
            cluster="not checked on the Dask cluster: {status}: {detail}")

#: every code, in the order of docs/diagnostics.md
ALL: tuple[Code, ...] = tuple(v for v in list(globals().values()) if isinstance(v, Code))

#: code -> (severity, kind): the form reports and SARIF read
CODES: dict[str, tuple[str, str]] = {str(c): (c.severity, c.kind) for c in ALL}

#: the codes of syntax errors (the file does not parse; krl/syntax/messages.py); E001 and E003
#: are input and build errors of the same group
SYNTAX_CODES = frozenset({E002, E010, E011, E012, E013, E014, E015, E016, E017, E018, E019, E020})

#: the syntax findings that are the program's error whatever the controller's full grammar holds:
#: a closer without its opener, a statement missing its keyword or part (a name alone on its
#: line: calls need parentheses, grammar/CHANGES.md), `==` for `=`, a declaration after the
#: first statement, a bracket or string not closed, a character that is not KRL: the compile
#: errors of the reference, 8.1. A run that reaches such a line stops on the program's error
#: (interp/runtime/errors.py ``not_understood``). The others (E002, E016: a construct the
#: recovered grammar may lack; E010: the routine is not entered; E018-E020: the tool's limits,
#: a file cut short) stay the simulator's gap.
PROGRAM_SYNTAX_CODES = frozenset({E011, E012, E013, E014, E015, E017})

__all__ = ["ALL", "CODES", "Code", "ERROR", "PROGRAM_SYNTAX_CODES", "SYNTAX_CODES", "WARNING", *(str(c) for c in ALL)]
