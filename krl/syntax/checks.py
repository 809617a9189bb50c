"""Post-parse checks: restrictions that the grammar states as data, not as target code.

Some restrictions of the reference are on a token's value, not on the token kind:
`TRIGGER WHEN DISTANCE` takes 0 or 1 (reference 5.18); a relative motion takes the frame
#BASE or #TOOL (6.1, 6.3); a conditional stop starts with the word STOP, no reserved word
(KSS 8.3, grammar/CHANGES.md). The grammar used to state them as semantic predicates written in
Python, which tied it to the Python target. Now the grammar accepts any INTLITERAL /
ENUMLITERAL there, under a label (`point=`, `frame=`), and this module checks the labelled
token after the parse, on the parse tree, whatever ANTLR target produced it
(docs/architecture.md, "Parse engines").

`may_fail(text)` is a conservative pre-filter on the source text: a check can only fail on
a line it matches, so a file it does not match needs no tree walk (and the fast engine,
which returns no tree, needs no fallback for it).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from antlr4 import ParserRuleContext


@dataclass(frozen=True, slots=True)
class TokenCheck:
    """The token under label `label` of a `context` node must be one of `allowed`
    (compared in upper case: KRL is case-insensitive, reference 1.2)."""

    rule: str             # the parser rule
    context: str          # generated context class name, e.g. "TriggerStatementContext"
    label: str            # the grammar label of the token
    allowed: tuple[str, ...]
    message: str          # what the rule says, in KRL words
    section: str          # the reference section


_REL = "a relative motion takes #BASE or #TOOL"
CHECKS: tuple[TokenCheck, ...] = (
    TokenCheck("triggerStatement", "TriggerStatementContext", "point", ("0", "1"), "TRIGGER WHEN DISTANCE takes 0 or 1", "5.18"),
    *(TokenCheck("motion", f"{kind}RelMotionContext", "frame", ("#BASE", "#TOOL"), _REL, "6.1")
      for kind in ("Ptp", "Lin", "Circ", "Sptp", "Slin", "Scirc")),
    TokenCheck("conditionalStop", "ConditionalStopContext", "word", ("STOP",),
               "a conditional stop takes STOP before WHEN PATH", "KSS 8.3"),
)

# A check can fail only on a line that matches: DISTANCE '=' followed by anything but a lone
# 0 or 1, a *_REL motion keyword followed on its line by '#' and not #BASE / #TOOL, or a name
# other than STOP (or TRIGGER) before WHEN PATH.
_MAY_FAIL = re.compile(
    r"DISTANCE[ \t\f]*=[ \t\f]*(?![01](?![0-9A-Z_]))"
    r"|(?:PTP|LIN|CIRC|SPTP|SLIN|SCIRC)_REL(?![0-9A-Z_$])[^\r\n]*#(?!(?:BASE|TOOL)(?![0-9A-Z_$]))"
    r"|(?<![0-9A-Z_$])(?!(?:STOP|TRIGGER)(?![0-9A-Z_$]))[A-Z_$][0-9A-Z_$]*[ \t\f]+WHEN[ \t\f]+PATH(?![0-9A-Z_$])",
    re.IGNORECASE)


def may_fail(text: str) -> bool:
    """True when some check could fail on `text` (a superset: False means none can)."""
    upper = text.upper()  # a cheap pre-test: each pattern needs one of these words
    if "DISTANCE" not in upper and "_REL" not in upper and "PATH" not in upper:
        return False
    return _MAY_FAIL.search(text) is not None


@dataclass(slots=True)
class CheckFailure:
    token: object          # the offending ANTLR token
    check: TokenCheck
    rule_stack: list[str]  # outermost rule first


def _checks_for(parser_cls: type) -> dict[type, TokenCheck]:
    """The checks whose context class exists in this generated parser (older grammar
    versions lack some rules; a version that still states a check as a semantic predicate
    of its rule, `<rule>_sempred`, needs no post-parse check for it)."""
    out = {}
    for check in CHECKS:
        cls = getattr(parser_cls, check.context, None)
        if cls is not None and not hasattr(parser_cls, f"{check.rule}_sempred"):
            out[cls] = check
    return out


_CACHE: dict[type, dict[type, TokenCheck]] = {}


def run_checks(tree, parser_cls: type) -> list[CheckFailure]:
    """Every failed token check in a parse tree (iterative walk; no recursion limit)."""
    table = _CACHE.get(parser_cls)
    if table is None:
        table = _CACHE[parser_cls] = _checks_for(parser_cls)
    if not table or tree is None:
        return []
    failures = []
    stack = [tree]
    while stack:
        node = stack.pop()
        check = table.get(type(node))
        if check is not None:
            token = getattr(node, check.label, None)
            if token is not None and (token.text or "").upper() not in check.allowed:
                failures.append(CheckFailure(token, check, _rule_stack(node, parser_cls)))
        children = node.children
        if children:
            stack.extend(c for c in reversed(children) if isinstance(c, ParserRuleContext))
    failures.sort(key=lambda f: (f.token.line, f.token.column))
    return failures


def _rule_stack(node, parser_cls: type) -> list[str]:
    names = parser_cls.ruleNames
    out = []
    while node is not None:
        out.append(names[node.getRuleIndex()])
        node = node.parentCtx
    return list(reversed(out))
