"""Each statement and declaration form parses to the expected tree shape; near-misses fail.

The expected shapes are written from the grammar's design (reference §2-§6.1): the head of
each outline entry names the construct the line must become.
"""

from __future__ import annotations

import pytest

from krl.syntax.outline import outline
from krl.syntax.parse import parse_text


def routine(*lines: str, decls: tuple[str, ...] = ()) -> str:
    return "DEF t()\n" + "".join(d + "\n" for d in decls) + "".join(ln + "\n" for ln in lines) + "END\n"


def heads(text: str) -> list[str]:
    res = parse_text(text)
    assert res.ok, [e.message for e in res.errors]
    return [e.split(": ", 1)[1].split("(", 1)[0] for e in outline(res.tree)]


STATEMENTS = [
    ("x = 1", "assignmentStatement/assignment"),
    ("$OUT[3] = TRUE", "assignmentStatement/assignment"),
    ("s[] = \"abc\"", "assignmentStatement/assignment"),
    ("p.X = p.X + 10.5", "assignmentStatement/assignment"),
    ("BAS(#INITMOV, 0)", "callStatement/call"),
    ("MsgNotify(\"k\", \"m\", , par[], 35)", "callStatement/call"),
    ("EXIT", "exitStatement"),
    ("GOTO lbl", "gotoStatement/name"),
    ("HALT", "haltStatement"),
    ("WAIT FOR $IN[1]", "waitForStatement/primaryExpression/variablePrimary/variable"),
    ("WAIT SEC 0.5", "waitSecStatement/primaryExpression/literalPrimary/literal"),
    ("CONTINUE", "continueStatement"),
    ("RETURN", "returnStatement"),
    ("ON_ERROR_PROCEED", "onErrorProceedStatement"),
    ("INTERRUPT DECL 21 WHEN $IN[12] DO Touch()", "interruptDeclaration"),
    ("GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM()", "interruptDeclaration"),
    ("INTERRUPT ON 21", "interruptControl/priority"),
    ("INTERRUPT OFF", "interruptControl"),
    ("BRAKE", "brakeStatement"),
    ("BRAKE F", "brakeFStatement"),
    ("RESUME", "resumeStatement"),
    ("TRIGGER WHEN DISTANCE=0 DELAY=20 DO $OUT[2]=TRUE", "triggerStatementAlt/triggerStatement"),
    ("TRIGGER WHEN PATH=-20 ONSTART DELAY=0 DO Cb() PRIO=-1", "triggerStatementAlt/triggerStatement"),
    ("ANIN ON v = 1.0 * ai", "aninOnStatement"),
    ("ANOUT ON ao = 0.5 * $VEL_ACT DELAY=0.1", "anoutOnStatement"),
    ("ANOUT OFF ao", "anoutOffStatement/name"),
    ("PTP XHOME", "motionStatement/ptpMotion/primaryExpression/variablePrimary/variable/name"),
    ("PTP {A1 45} C_PTP", "motionStatement/ptpMotion"),
    ("LIN XP2 C_DIS C_DIS", "motionStatement/linMotion"),
    ("LIN P1 : {X 0, Y 0, Z 50, A 0, B 0, C 0}", "motionStatement/linMotion/geometricExpression"),
    ("CIRC XA, XB, CA 90 C_ORI", "motionStatement/circMotion"),
    ("LIN_REL {X 10} #TOOL",
     "motionStatement/linRelMotion/primaryExpression/aggregatePrimary/aggregate/aggregateComponent"),
    ("PTP_REL {A1 10}", "motionStatement/ptpRelMotion/primaryExpression/aggregatePrimary/aggregate/aggregateComponent"),
    ("SPTP XP1 WITH $VEL_AXIS[1] = SVEL_JOINT(100.0) C_SPL", "motionStatement/sptpMotion"),
    ("SLIN XP2 C_SPL", "motionStatement/slinMotion"),
    ("SCIRC XA, XB WITH $CIRC_TYPE = #PATH C_SPL", "motionStatement/scircMotion"),
]


@pytest.mark.parametrize(("line", "head"), STATEMENTS)
def test_statement_shape(line: str, head: str) -> None:
    assert heads(routine(line))[-1] == head


def test_block_statements_nest() -> None:
    text = routine("FOR i = 1 TO 10 STEP 2", "  IF i > 3 THEN", "    x = i", "  ELSE", "    EXIT",
                   "  ENDIF", "ENDFOR", "WHILE x < 5", "  x = x + 1", "ENDWHILE", "REPEAT", "  x = x - 1",
                   "UNTIL x == 0", "LOOP", "  EXIT", "ENDLOOP", "SWITCH x", "CASE 1, 2", "  x = 3",
                   "DEFAULT", "  x = 4", "ENDSWITCH", "lbl:")
    got = heads(text)
    assert got[:2] == ["procedureDefinition", "forStatement"]
    for expected in ("ifStatement", "whileStatement", "repeatStatement", "loopStatement", "switchStatement",
                     "label/name"):
        assert any(h.startswith(expected) for h in got), expected


def test_declarations_and_precedence() -> None:
    res = parse_text(routine("x = a + b * c", decls=("DECL INT a, b, c, x", "REAL m[3,4]",
                                                     "DECL E6POS P1", "STRUC S REAL A, B, INT C",
                                                     "ENUM COLOR red, green", "SIGNAL Grip $OUT[17]")))
    assert res.ok
    entries = outline(res.tree)
    assert any("variableDeclaration(typeName/simpleType variableName/name variableName/name" in e for e in entries)
    assert any(": declaration/structureDeclaration(" in e for e in entries)
    # '*' binds tighter than '+': the top node is the addition.
    assign = [e for e in entries if "assignmentStatement" in e][0]
    assert "additiveExpression(primaryExpression" in assign and "multiplicativeExpression" in assign


def test_comparison_binds_weaker_than_and() -> None:
    # Reference 4.1: `a == 1 AND b` is `a == (1 AND b)`.
    res = parse_text(routine("IF a == 1 AND b THEN", "ENDIF"))
    entry = [e for e in outline(res.tree) if "ifStatement" in e][0]
    assert entry.startswith(entry.split(":")[0] + ": ifStatement(relationalExpression(")
    assert "andExpression" in entry


def test_dat_file_shapes() -> None:
    text = ("&ACCESS RVP\n&REL 3\nDEFDAT demo PUBLIC\nDECL E6POS XP1={X 10.5,Y -2,Z 3,A 0,B 90,C 0,S 2,T 10}\n"
            "INT count=0\nDECL GLOBAL CONST INT LIMIT=3\nDECL FRAME TD[4]\nTD[1]={X 0,Y 0,Z 225,A 0,B 0,C 0}\n"
            "ENDDAT\n")
    got = heads(text)
    assert got[0] == "dataList"
    assert got.count("dataItem/dataVariableDeclaration") == 4
    assert got.count("dataItem/arrayElementInitialisation") == 1


NEAR_MISSES = [
    ("IF without ENDIF", routine("IF x THEN", "x = 1")),
    ("FOR without TO", routine("FOR i = 1 10", "ENDFOR")),
    ("comparison as a statement", routine("x == 1")),
    ("DECL after a statement", routine("x = 1", "DECL INT y")),
    ("initial value in a routine", routine(decls=("DECL INT x = 1",))),
    ("assignment as a condition", routine("IF x = 1 THEN", "ENDIF")),
    ("chained assignment", routine("a = b = c")),
    ("DEFFCT closed by END", "DEFFCT INT f()\nRETURN 1\nEND\n"),
    ("keyword as a name", routine(decls=("DECL INT END",))),
    ("INTERRUPT number before the keyword", routine("INTERRUPT 3 ON")),
    ("single-line IF", routine("IF a THEN b = 1 ENDIF")),
    ("TRIGGER without DELAY", routine("TRIGGER WHEN DISTANCE=0 DO x=1")),
    ("motion without target", routine("PTP")),
    ("CIRC with one point", routine("CIRC P1")),
    ("three approximation keywords", routine("LIN P1 C_DIS C_DIS C_DIS")),
    ("statement in a data list", "DEFDAT d\nx = 1\nENDDAT\n"),
    ("code outside a routine", "x = 1\nDEF t()\nEND\n"),
    ("unknown header", "&FOO bar\nDEF t()\nEND\n"),
    ("lexer error", routine("x = 1 ? 2")),
]


@pytest.mark.parametrize(("why", "text"), NEAR_MISSES, ids=[w for w, _ in NEAR_MISSES])
def test_near_miss_rejected(why: str, text: str) -> None:
    assert not parse_text(text).ok, why


def test_case_insensitive_and_comments_hidden() -> None:
    text = ("&ACCESS RVP\n;FOLD header\n\ndef t( )\n  ; a comment\n  decl int i ;trailing\n\n"
            "  ;FOLD PTP P1;%{PE}\n  ptp xhome c_ptp\n  ;ENDFOLD\nend\n")
    assert heads(text)[-1] == "motionStatement/ptpMotion"


def test_unterminated_last_line_and_crlf() -> None:
    assert parse_text("DEF t()\r\nx = 1\r\nEND").ok
    assert parse_text("DEF t()\rx = 1\nEND\r\n").ok
