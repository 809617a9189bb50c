#!/usr/bin/env python3
"""Generate the negative corpus: invalid KRL programs, one syntax mutation each.

Every program starts from one of a few small valid base programs (below) and applies exactly
one named mutation that makes it invalid at the *syntax* level according to
../shared/docs/krl-reference.md (type errors and other semantic errors are deliberately left
out). The first line of each generated file names the mutation and the reference section:

    ; NEGATIVE: IF without ENDIF (reference 5.2)

Usage:  python tests/negative/generate.py          (rewrites tests/negative/neg_*.src|.dat)
        python tests/negative/generate.py --check  (exit 1 if the files on disk differ)

The generated files are committed; re-run this script after editing the table and commit both.
Numbers are assigned in table order, so append new mutations at the end to keep names stable.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

HERE = Path(__file__).resolve().parent
MAX_NAME = 24          # KRL identifier limit (reference 1.2); the main routine is named like the file

# --------------------------------------------------------------------------- base programs
# "@NAME@" is replaced by the module name (= the file stem), so the main routine matches the file.

MAIN = """\
DEF @NAME@( )
  DECL INT nCount, i
  DECL REAL rSpeed
  DECL BOOL bReady
  DECL E6POS pTarget
  ;FOLD INI
  GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )
  INTERRUPT ON 3
  BAS (#INITMOV,0 )
  ;ENDFOLD (INI)
  nCount = 0
  rSpeed = 0.5
  bReady = $IN[1]
  PTP XHOME
  IF bReady THEN
    $OUT[5] = TRUE
  ELSE
    $OUT[5] = FALSE
  ENDIF
  FOR i = 1 TO 5
    nCount = nCount + i
  ENDFOR
  WHILE nCount > 0
    nCount = nCount - 1
  ENDWHILE
  REPEAT
    nCount = nCount + 1
  UNTIL nCount >= 3
  LOOP
    EXIT
  ENDLOOP
  SWITCH nCount
    CASE 1
      rSpeed = 0.1
    CASE 2, 3
      rSpeed = 0.2
    DEFAULT
      rSpeed = 0.3
  ENDSWITCH
  pTarget = {X 500.0, Y 0.0, Z 300.0, A 0.0, B 90.0, C 0.0}
  WAIT FOR $IN[2]
  WAIT SEC 0.5
  LIN pTarget C_DIS
  CIRC XP2, XP3
  PTP XHOME
END
"""

FUNC = """\
DEF @NAME@( )
  DECL REAL rOut
  rOut = Clamp(12.5, 0.0, 10.0)
END

DEFFCT REAL Clamp(rVal :IN, rLow :IN, rHigh :IN)
  DECL REAL rVal, rLow, rHigh
  IF rVal < rLow THEN
    RETURN rLow
  ENDIF
  IF rVal > rHigh THEN
    RETURN rHigh
  ENDIF
  RETURN rVal
ENDFCT
"""

IRQ = """\
DEF @NAME@( )
  DECL INT nHits
  INTERRUPT DECL 21 WHEN $IN[12] DO Touch( )
  nHits = 0
  INTERRUPT ON 21
  TRIGGER WHEN DISTANCE=1 DELAY=0 DO $OUT[7]=TRUE
  LIN XP1
  TRIGGER WHEN PATH=-10.0 ONSTART DELAY=5 DO Mark(nHits) PRIO=-1
  LIN XP2
  INTERRUPT OFF 21
END

DEF Touch( )
  BRAKE
  RESUME
END

DEF Mark(n :IN)
  DECL INT n
  $OUT[8] = TRUE
END
"""

SPLINE = """\
DEF @NAME@( )
  SPTP XHOME WITH $VEL_AXIS[1] = SVEL_JOINT(100.0)
  SPLINE WITH $VEL = {CP 0.2}
    SPL XP1
    SLIN XP2
    SCIRC XP3, XP4
  ENDSPLINE
  SLIN XP5 WITH $VEL = {CP 0.1} C_SPL
  SPTP XHOME
END
"""

SMOVE = """\
DEF @NAME@( )
  SPTP XHOME WITH $VEL_AXIS[1] = SVEL_JOINT(100.0)
  SLIN XP5 WITH $VEL = {CP 0.1} C_SPL
  SCIRC XP6, XP7 C_SPL
  SPTP XHOME
END
"""

DAT = """\
DEFDAT @NAME@
DECL INT nCount=0
DECL REAL rSpeed=0.5
DECL E6POS XP1={X 100.0,Y 0.0,Z 200.0,A 0.0,B 90.0,C 0.0,S 2,T 35}
DECL FDAT FP1={TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE}
DECL LOAD LGRIP={M 2.5,CM {X 0.0,Y 0.0,Z 80.0,A 0.0,B 0.0,C 0.0},J {X 0.0,Y 0.0,Z 0.0}}
DECL INT nTable[3]
nTable[1]=10
ENUM COLOR_T RED,GREEN,BLUE
STRUC PART_T INT NR,REAL WEIGHT
SIGNAL Gripper $OUT[17]
ENDDAT
"""

BASES = {"main": (MAIN, ".src"), "func": (FUNC, ".src"), "irq": (IRQ, ".src"),
         "spline": (SPLINE, ".src"),
         "smove": (SMOVE, ".src"), "dat": (DAT, ".dat")}


# --------------------------------------------------------------------------- mutations

@dataclass(frozen=True)
class Mutation:
    slug: str                       # short name, part of the file name
    what: str                       # the mutation, as written in the first-line comment
    section: str                    # reference section(s)
    base: str                       # key of BASES
    edits: tuple                    # ((old, new), ...) each old must occur exactly once


def M(slug: str, what: str, section: str, base: str, *edits: tuple[str, str]) -> Mutation:
    return Mutation(slug, what, section, base, tuple(edits))


MUTATIONS: list[Mutation] = [
    # ---- missing or wrong block ends (2.2, 5.x)
    M("missing_endif", "IF without ENDIF", "5.2", "main",
      ("    $OUT[5] = FALSE\n  ENDIF\n", "    $OUT[5] = FALSE\n")),
    M("missing_endfor", "FOR without ENDFOR", "5.4", "main",
      ("    nCount = nCount + i\n  ENDFOR\n", "    nCount = nCount + i\n")),
    M("missing_endwhile", "WHILE without ENDWHILE", "5.5", "main",
      ("    nCount = nCount - 1\n  ENDWHILE\n", "    nCount = nCount - 1\n")),
    M("missing_until", "REPEAT without UNTIL", "5.5", "main", ("  UNTIL nCount >= 3\n", "")),
    M("until_no_cond", "UNTIL without a condition", "5.5", "main",
      ("  UNTIL nCount >= 3\n", "  UNTIL\n")),
    M("missing_endloop", "LOOP without ENDLOOP", "5.5", "main", ("    EXIT\n  ENDLOOP\n", "    EXIT\n")),
    M("no_endswitch", "SWITCH without ENDSWITCH", "5.3", "main",
      ("      rSpeed = 0.3\n  ENDSWITCH\n", "      rSpeed = 0.3\n")),
    M("missing_end", "DEF without END", "2.2", "main", ("  PTP XHOME\nEND\n", "  PTP XHOME\n")),
    M("missing_endfct", "DEFFCT without ENDFCT", "2.2, 2.4", "func", ("  RETURN rVal\nENDFCT\n", "  RETURN rVal\n")),
    M("deffct_end", "DEFFCT closed by END", "2.2, 2.4", "func", ("  RETURN rVal\nENDFCT\n", "  RETURN rVal\nEND\n")),
    M("def_endfct", "DEF closed by ENDFCT", "2.2", "func",
      ("  rOut = Clamp(12.5, 0.0, 10.0)\nEND\n", "  rOut = Clamp(12.5, 0.0, 10.0)\nENDFCT\n")),
    M("missing_enddat", "DEFDAT without ENDDAT", "2.5", "dat", ("SIGNAL Gripper $OUT[17]\nENDDAT\n", "SIGNAL Gripper $OUT[17]\n")),
    M("def_enddat", "DEF closed by ENDDAT", "2.2", "main", ("  PTP XHOME\nEND\n", "  PTP XHOME\nENDDAT\n")),
    M("endif_twice", "ENDIF without IF (second ENDIF)", "5.2", "main",
      ("    $OUT[5] = FALSE\n  ENDIF\n", "    $OUT[5] = FALSE\n  ENDIF\n  ENDIF\n")),
    M("while_endfor", "WHILE closed by ENDFOR", "5.5", "main",
      ("    nCount = nCount - 1\n  ENDWHILE\n", "    nCount = nCount - 1\n  ENDFOR\n")),
    M("for_endwhile", "FOR closed by ENDWHILE", "5.4", "main",
      ("    nCount = nCount + i\n  ENDFOR\n", "    nCount = nCount + i\n  ENDWHILE\n")),
    M("end_if_two_words", "END IF written as two words", "5.2", "main",
      ("    $OUT[5] = FALSE\n  ENDIF\n", "    $OUT[5] = FALSE\n  END IF\n")),
    M("repeat_endloop", "REPEAT closed by ENDLOOP instead of UNTIL", "5.5", "main",
      ("  UNTIL nCount >= 3\n", "  ENDLOOP\n")),
    M("loop_endwhile", "LOOP closed by ENDWHILE", "5.5", "main", ("    EXIT\n  ENDLOOP\n", "    EXIT\n  ENDWHILE\n")),
    M("else_twice", "two ELSE branches in one IF", "5.2", "main",
      ("    $OUT[5] = FALSE\n  ENDIF\n", "    $OUT[5] = FALSE\n  ELSE\n    nCount = 1\n  ENDIF\n")),
    M("elsif", "ELSIF (there is no ELSIF in KRL)", "5.2", "main",
      ("  ELSE\n    $OUT[5] = FALSE\n", "  ELSIF nCount > 1 THEN\n    $OUT[5] = FALSE\n")),
    M("else_if_one_line", "ELSE IF on one line (ELSE must stand alone)", "1.4, 5.2", "main",
      ("  ELSE\n    $OUT[5] = FALSE\n  ENDIF\n", "  ELSE IF nCount > 1 THEN\n    $OUT[5] = FALSE\n  ENDIF\n  ENDIF\n")),
    M("missing_then", "IF without THEN", "5.2", "main", ("  IF bReady THEN\n", "  IF bReady\n")),
    M("then_next_line", "THEN on the line after IF", "1.4, 5.2", "main", ("  IF bReady THEN\n", "  IF bReady\n  THEN\n")),
    M("single_line_if", "single-line IF ... THEN ... ENDIF", "1.4, 5.2", "main",
      ("  IF bReady THEN\n    $OUT[5] = TRUE\n  ELSE\n    $OUT[5] = FALSE\n  ENDIF\n",
       "  IF bReady THEN $OUT[5] = TRUE ENDIF\n")),
    M("if_then_stmt", "statement after THEN on the IF line", "1.4, 5.2", "main",
      ("  IF bReady THEN\n    $OUT[5] = TRUE\n", "  IF bReady THEN $OUT[5] = TRUE\n")),
    M("if_no_cond", "IF without a condition", "5.2", "main", ("  IF bReady THEN\n", "  IF THEN\n")),
    M("if_assign_cond", "assignment used as IF condition (IF x = 1 THEN)", "5.1, 5.2", "main",
      ("  IF bReady THEN\n", "  IF nCount = 1 THEN\n")),
    M("while_assign", "assignment used as WHILE condition", "5.1, 5.5", "main",
      ("  WHILE nCount > 0\n", "  WHILE nCount = 0\n")),
    M("until_assign", "assignment used as UNTIL condition", "5.1, 5.5", "main",
      ("  UNTIL nCount >= 3\n", "  UNTIL nCount = 3\n")),
    M("wait_for_assign", "assignment used as WAIT FOR condition", "5.1, 5.8", "main",
      ("  WAIT FOR $IN[2]\n", "  WAIT FOR nCount = 3\n")),
    M("while_no_cond", "WHILE without a condition", "5.5", "main", ("  WHILE nCount > 0\n", "  WHILE\n")),
    M("while_do", "WHILE cond DO (no DO in KRL loops)", "5.5", "main", ("  WHILE nCount > 0\n", "  WHILE nCount > 0 DO\n")),
    M("for_without_to", "FOR without TO", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR i = 1 5\n")),
    M("for_colon_eq", "FOR with := instead of =", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR i := 1 TO 5\n")),
    M("for_no_start", "FOR without a start value", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR i TO 5\n")),
    M("for_downto", "FOR ... DOWNTO (use STEP -1)", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR i = 5 DOWNTO 1\n")),
    M("for_step_empty", "STEP without an increment", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR i = 1 TO 5 STEP\n")),
    M("for_do", "FOR ... TO ... DO", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR i = 1 TO 5 DO\n")),
    M("for_no_counter", "FOR without a counter variable", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR = 1 TO 5\n")),
    M("for_no_end_value", "FOR ... TO without an end value", "5.4", "main", ("  FOR i = 1 TO 5\n", "  FOR i = 1 TO\n")),
    M("endfor_counter", "ENDFOR followed by the counter (NEXT style)", "5.4", "main",
      ("    nCount = nCount + i\n  ENDFOR\n", "    nCount = nCount + i\n  ENDFOR i\n")),
    M("next_for_endfor", "NEXT instead of ENDFOR", "5.4", "main",
      ("    nCount = nCount + i\n  ENDFOR\n", "    nCount = nCount + i\n  NEXT i\n")),
    M("endwhile_cond", "ENDWHILE followed by a condition", "5.5", "main",
      ("  ENDWHILE\n", "  ENDWHILE nCount > 0\n")),
    M("loop_with_cond", "LOOP with a condition", "5.5", "main", ("  LOOP\n", "  LOOP nCount < 3\n")),
    M("exit_with_value", "EXIT with an argument", "5.5", "main", ("    EXIT\n", "    EXIT 1\n")),
    M("exit_when", "EXIT WHEN condition", "5.5", "main", ("    EXIT\n", "    EXIT WHEN nCount > 3\n")),
    M("switch_no_case", "SWITCH without any CASE", "5.3", "main",
      ("    CASE 1\n      rSpeed = 0.1\n    CASE 2, 3\n      rSpeed = 0.2\n", "")),
    M("case_after_dflt", "CASE after DEFAULT", "5.3", "main",
      ("    DEFAULT\n      rSpeed = 0.3\n", "    DEFAULT\n      rSpeed = 0.3\n    CASE 4\n      rSpeed = 0.4\n")),
    M("two_defaults", "two DEFAULT branches", "5.3", "main",
      ("    DEFAULT\n      rSpeed = 0.3\n", "    DEFAULT\n      rSpeed = 0.3\n    DEFAULT\n      rSpeed = 0.4\n")),
    M("case_no_value", "CASE without a value", "5.3", "main", ("    CASE 1\n", "    CASE\n")),
    M("case_colon", "CASE value followed by ':' (C style)", "5.3", "main", ("    CASE 1\n", "    CASE 1:\n")),
    M("case_trail_comma", "CASE value list with a trailing comma", "5.3", "main", ("    CASE 2, 3\n", "    CASE 2, 3,\n")),
    M("case_range", "CASE range with TO", "5.3", "main", ("    CASE 2, 3\n", "    CASE 2 TO 3\n")),
    M("case_else", "CASE ELSE instead of DEFAULT", "5.3", "main", ("    DEFAULT\n", "    CASE ELSE\n")),
    M("switch_no_expr", "SWITCH without a selector", "5.3", "main", ("  SWITCH nCount\n", "  SWITCH\n")),
    M("case_no_switch", "CASE outside a SWITCH", "5.3", "main",
      ("  WAIT SEC 0.5\n", "  CASE 1\n  WAIT SEC 0.5\n")),
    M("default_value", "DEFAULT with a value", "5.3", "main", ("    DEFAULT\n", "    DEFAULT 4\n")),
    M("case_stmt_line", "statement on the CASE line", "1.4, 5.3", "main",
      ("    CASE 1\n      rSpeed = 0.1\n", "    CASE 1 rSpeed = 0.1\n")),
    M("else_without_if", "ELSE without IF", "5.2", "main", ("  WAIT SEC 0.5\n", "  ELSE\n  WAIT SEC 0.5\n")),
    M("endif_without_if", "ENDIF without IF", "5.2", "main", ("  WAIT SEC 0.5\n", "  WAIT SEC 0.5\n  ENDIF\n")),
    M("until_no_repeat", "UNTIL without REPEAT", "5.5", "main", ("  WAIT SEC 0.5\n", "  UNTIL bReady\n  WAIT SEC 0.5\n")),
    M("endloop_no_loop", "ENDLOOP without LOOP", "5.5", "main", ("  WAIT SEC 0.5\n", "  WAIT SEC 0.5\n  ENDLOOP\n")),
    # ---- GOTO and labels (1.4, 5.6)
    M("goto_no_label", "GOTO without a label name", "5.6", "main", ("  WAIT SEC 0.5\n", "  GOTO\n  WAIT SEC 0.5\n")),
    M("goto_number", "GOTO with a line number", "5.6", "main", ("  WAIT SEC 0.5\n", "  GOTO 10\n  WAIT SEC 0.5\n")),
    M("goto_keyword", "GOTO to a keyword (GOTO END)", "1.6, 5.6", "main", ("  WAIT SEC 0.5\n", "  GOTO END\n  WAIT SEC 0.5\n")),
    M("label_with_stmt", "label followed by a statement on the same line", "1.4", "main",
      ("  WAIT SEC 0.5\n", "  again: WAIT SEC 0.5\n")),
    M("label_keyword", "keyword used as a label (LOOP:)", "1.4, 1.6", "main", ("  WAIT SEC 0.5\n", "  LOOP:\n  WAIT SEC 0.5\n")),
    # ---- line structure (1.4)
    M("two_stmts_line", "two statements on one line", "1.4", "main", ("  nCount = 0\n  rSpeed = 0.5\n", "  nCount = 0 rSpeed = 0.5\n")),
    M("two_motions_line", "two motions on one line", "1.4", "main", ("  PTP XHOME\n  IF", "  PTP XHOME LIN pTarget\n  IF")),
    M("continue_stmt", "CONTINUE and its statement on one line", "1.4, 5.9", "main",
      ("    $OUT[5] = TRUE\n", "    CONTINUE $OUT[5] = TRUE\n")),
    M("on_error_stmt", "ON_ERROR_PROCEED and its statement on one line", "1.4, 5.19", "main",
      ("  bReady = $IN[1]\n", "  ON_ERROR_PROCEED bReady = $IN[1]\n")),
    M("halt_argument", "HALT with an argument", "5.7", "main", ("  WAIT SEC 0.5\n", "  HALT 1\n")),
    M("brace_block", "C-style braces around an IF body", "5.2", "main",
      ("  IF bReady THEN\n    $OUT[5] = TRUE\n", "  IF bReady THEN {\n    $OUT[5] = TRUE\n  }\n")),
    # ---- routine structure (2.1-2.4)
    M("code_after_end", "statement outside any routine (after END)", "2.1", "main",
      ("  PTP XHOME\nEND\n", "  PTP XHOME\nEND\nnCount = 1\n")),
    M("code_before_def", "statement before the first DEF", "2.1", "main",
      ("DEF @NAME@( )\n", "$OUT[1] = TRUE\nDEF @NAME@( )\n")),
    M("header_in_middle", "&ACCESS header line in the middle of the file", "1.3", "main",
      ("  WAIT SEC 0.5\n", "&ACCESS RVP\n  WAIT SEC 0.5\n")),
    M("header_after_end", "&REL header line after the routine", "1.3", "func",
      ("  rOut = Clamp(12.5, 0.0, 10.0)\nEND\n", "  rOut = Clamp(12.5, 0.0, 10.0)\nEND\n&REL 2\n")),
    M("nested_def", "DEF inside a DEF", "2.2", "func",
      ("  rOut = Clamp(12.5, 0.0, 10.0)\n", "  rOut = Clamp(12.5, 0.0, 10.0)\n  DEF Inner( )\n  END\n")),
    M("def_no_parens", "DEF without a parameter list", "2.2", "main", ("DEF @NAME@( )\n", "DEF @NAME@\n")),
    M("def_with_type", "DEF with a return type", "2.2", "main", ("DEF @NAME@( )\n", "DEF INT @NAME@( )\n")),
    M("def_keyword_name", "keyword used as a routine name (DEF WAIT)", "1.6, 2.2", "irq", ("DEF Touch( )\n", "DEF WAIT( )\n")),
    M("deffct_no_type", "DEFFCT without a return type", "2.2, 2.4", "func",
      ("DEFFCT REAL Clamp(", "DEFFCT Clamp(")),
    M("deffct_no_name", "DEFFCT without a name", "2.2, 2.4", "func",
      ("DEFFCT REAL Clamp(rVal :IN, rLow :IN, rHigh :IN)\n", "DEFFCT REAL (rVal :IN, rLow :IN, rHigh :IN)\n")),
    M("param_typed", "typed parameters in the routine header", "2.3", "func",
      ("DEFFCT REAL Clamp(rVal :IN, rLow :IN, rHigh :IN)\n", "DEFFCT REAL Clamp(REAL rVal :IN, REAL rLow :IN, REAL rHigh :IN)\n")),
    M("param_in_colon", "parameter mode IN without ':'", "2.3", "func", ("Clamp(rVal :IN,", "Clamp(rVal IN,")),
    M("param_inout", "parameter mode :INOUT", "2.3", "func", ("Clamp(rVal :IN,", "Clamp(rVal :INOUT,")),
    M("param_colon_only", "':' without IN or OUT", "2.3", "func", ("Clamp(rVal :IN,", "Clamp(rVal :,")),
    M("param_trail_com", "trailing comma in a parameter list", "2.3", "func",
      ("rHigh :IN)\n", "rHigh :IN,)\n")),
    M("param_keyword", "keyword used as a parameter name", "1.6, 2.3", "irq", ("DEF Mark(n :IN)\n  DECL INT n\n", "DEF Mark(if :IN)\n  DECL INT if\n")),
    M("param_default", "default value in a parameter list", "2.3", "func", ("rHigh :IN)\n", "rHigh :IN = 10.0)\n")),
    M("end_with_name", "END followed by the routine name", "2.2", "main", ("  PTP XHOME\nEND\n", "  PTP XHOME\nEND @NAME@\n")),
    M("endfct_value", "ENDFCT followed by a value", "2.4", "func", ("  RETURN rVal\nENDFCT\n", "  RETURN rVal\nENDFCT rVal\n")),
    M("return_two", "RETURN with two values", "5.10", "func", ("    RETURN rLow\n", "    RETURN rLow rHigh\n")),
    M("public_on_def", "PUBLIC on a DEF line", "2.2, 2.5", "main", ("DEF @NAME@( )\n", "DEF @NAME@( ) PUBLIC\n")),
    M("global_defdat", "GLOBAL on DEFDAT", "2.5", "dat", ("DEFDAT @NAME@\n", "GLOBAL DEFDAT @NAME@\n")),
    # ---- declarations (2.2, 3.2-3.8)
    M("decl_after_stmt", "DECL after a statement", "2.2", "main", ("  nCount = 0\n", "  nCount = 0\n  DECL INT nLate\n")),
    M("decl_after_irq", "DECL after INTERRUPT DECL (a statement)", "2.2, 5.16", "irq",
      ("  INTERRUPT DECL 21 WHEN $IN[12] DO Touch( )\n", "  INTERRUPT DECL 21 WHEN $IN[12] DO Touch( )\n  DECL INT nLate\n")),
    M("decl_after_label", "DECL after a label", "2.2", "main", ("  DECL E6POS pTarget\n", "  DECL E6POS pTarget\nstart:\n  DECL INT nLate\n")),
    M("decl_inside_if", "DECL inside an IF block", "2.2", "main", ("    $OUT[5] = TRUE\n", "    DECL INT nLocal\n    $OUT[5] = TRUE\n")),
    M("decl_after_fct", "DECL after a statement in a DEFFCT", "2.2", "func",
      ("  IF rVal < rLow THEN\n", "  rVal = rVal + 0.0\n  DECL REAL rTmp\n  IF rVal < rLow THEN\n")),
    M("decl_in_spline", "DECL inside a SPLINE block", "2.2, 6.2", "spline", ("    SLIN XP2\n", "    DECL INT n\n    SLIN XP2\n")),
    M("decl_init_in_src", "DECL with an initial value inside a routine", "2.2", "main", ("  DECL INT nCount, i\n", "  DECL INT nCount = 0, i\n")),
    M("decl_init_in_fct", "DECL with an initial value inside a DEFFCT", "2.2", "func",
      ("  DECL REAL rVal, rLow, rHigh\n", "  DECL REAL rVal, rLow, rHigh\n  DECL REAL rTmp = 0.0\n")),
    M("decl_init_agg", "DECL E6POS with an aggregate initialiser in a routine", "2.2", "main",
      ("  DECL E6POS pTarget\n", "  DECL E6POS pTarget = {X 500.0}\n")),
    M("decl_no_name", "DECL without a variable name", "3.2", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT\n")),
    M("decl_no_type", "DECL without a type", "3.2", "main", ("  DECL REAL rSpeed\n", "  DECL REAL rSpeed\n  DECL nOther\n")),
    M("decl_kw_end", "keyword used as a variable name (DECL INT END)", "1.2, 1.6", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT END\n")),
    M("decl_kw_if", "keyword used as a variable name (DECL INT if)", "1.2, 1.6", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT if\n")),
    M("decl_kw_for", "keyword used as a variable name (DECL REAL For)", "1.2, 1.6", "main", ("  DECL REAL rSpeed\n", "  DECL REAL rSpeed, For\n")),
    M("decl_kw_wait", "keyword used as a variable name (DECL BOOL WAIT)", "1.2, 1.6", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady, WAIT\n")),
    M("decl_kw_to", "keyword used as a variable name (INT to)", "1.2, 1.6", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  INT to\n")),
    M("decl_kw_lin", "motion keyword used as a variable name (DECL E6POS LIN)", "1.2, 1.6", "main",
      ("  DECL E6POS pTarget\n", "  DECL E6POS pTarget, LIN\n")),
    M("decl_kw_type", "type keyword used as a name (DECL INT REAL)", "1.2, 1.6", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT REAL\n")),
    M("decl_digit_name", "identifier starting with a digit", "1.2", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT 2ndCount\n")),
    M("decl_dash_name", "'-' inside an identifier", "1.2", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT n-Count\n")),
    M("decl_neg_dim", "negative array dimension", "3.2, 3.3", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT nTab[-3]\n")),
    M("decl_four_dims", "array with four dimensions", "3.2, 3.3", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT nTab[2,2,2,2]\n")),
    M("decl_real_dim", "REAL array dimension", "3.2, 3.3", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT nTab[2.5]\n")),
    M("decl_trail_comma", "trailing comma in a declaration", "3.2", "main", ("  DECL INT nCount, i\n", "  DECL INT nCount, i,\n")),
    M("decl_paren_dims", "array dimensions in parentheses", "3.2, 3.3", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL INT nTab(10)\n")),
    M("decl_colon_type", "Pascal-style declaration (name : type)", "3.2", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  DECL nOther : INT\n")),
    M("struc_no_type", "STRUC component without a type", "3.5", "dat", ("STRUC PART_T INT NR,REAL WEIGHT\n", "STRUC PART_T NR,WEIGHT\n")),
    M("struc_braces", "STRUC body in braces", "3.5", "dat", ("STRUC PART_T INT NR,REAL WEIGHT\n", "STRUC PART_T {INT NR,REAL WEIGHT}\n")),
    M("struc_multiline", "STRUC spread over several lines", "3.5", "dat", ("STRUC PART_T INT NR,REAL WEIGHT\n", "STRUC PART_T INT NR,\n  REAL WEIGHT\n")),
    M("enum_braces", "ENUM values in braces", "3.6", "dat", ("ENUM COLOR_T RED,GREEN,BLUE\n", "ENUM COLOR_T {RED,GREEN,BLUE}\n")),
    M("enum_values_eq", "ENUM values with explicit numbers", "3.6", "dat", ("ENUM COLOR_T RED,GREEN,BLUE\n", "ENUM COLOR_T RED=1,GREEN=2,BLUE=3\n")),
    M("enum_no_values", "ENUM without values", "3.6", "dat", ("ENUM COLOR_T RED,GREEN,BLUE\n", "ENUM COLOR_T\n")),
    M("enum_hash_values", "ENUM declaration with #-prefixed values", "3.6", "dat", ("ENUM COLOR_T RED,GREEN,BLUE\n", "ENUM COLOR_T #RED,#GREEN,#BLUE\n")),
    M("signal_no_target", "SIGNAL without an I/O reference", "3.8", "dat", ("SIGNAL Gripper $OUT[17]\n", "SIGNAL Gripper\n")),
    M("signal_to_open", "SIGNAL ... TO without the last signal", "3.8", "dat", ("SIGNAL Gripper $OUT[17]\n", "SIGNAL Gripper $OUT[17] TO\n")),
    M("signal_eq", "SIGNAL with '='", "3.8", "dat", ("SIGNAL Gripper $OUT[17]\n", "SIGNAL Gripper = $OUT[17]\n")),
    M("signal_no_index", "SIGNAL on $OUT without an index", "3.8", "dat", ("SIGNAL Gripper $OUT[17]\n", "SIGNAL Gripper $OUT\n")),
    M("ext_no_parens", "EXT declaration without a parameter list", "2.6", "main", ("  DECL BOOL bReady\n", "  DECL BOOL bReady\n  EXT BAS\n")),
    # ---- data lists (2.5)
    M("dat_statement", ".dat with an executable statement", "2.5", "dat", ("nTable[1]=10\n", "nTable[1]=10\nnCount = nCount + 1\n")),
    M("dat_motion", ".dat with a motion statement", "2.5", "dat", ("nTable[1]=10\n", "nTable[1]=10\nPTP XP1\n")),
    M("dat_if_block", ".dat with an IF block", "2.5", "dat", ("nTable[1]=10\n", "nTable[1]=10\nIF nCount > 0 THEN\nnCount = 0\nENDIF\n")),
    M("dat_def_inside", ".dat with a DEF routine inside DEFDAT", "2.5", "dat",
      ("nTable[1]=10\n", "nTable[1]=10\nDEF Helper( )\n  nCount = 1\nEND\n")),
    M("dat_nested_dat", "DEFDAT inside DEFDAT", "2.5", "dat", ("nTable[1]=10\n", "nTable[1]=10\nDEFDAT inner\nENDDAT\n")),
    M("dat_init_expr", ".dat initial value with an expression", "1.5, 2.5", "dat", ("DECL INT nCount=0\n", "DECL INT nCount=1+2\n")),
    M("dat_init_var", ".dat initial value from another variable", "1.5, 2.5", "dat", ("DECL REAL rSpeed=0.5\n", "DECL REAL rSpeed=nCount\n")),
    M("dat_agg_expr", ".dat aggregate component with an expression", "1.5, 2.5", "dat", ("{X 100.0,Y 0.0,", "{X 100.0+5.0,Y 0.0,")),
    M("dat_agg_call", ".dat initial value from a function call", "1.5, 2.5", "dat", ("DECL REAL rSpeed=0.5\n", "DECL REAL rSpeed=SQRT(2.0)\n")),
    M("dat_decl_no_type", ".dat DECL without a type", "2.5, 3.2", "dat", ("DECL INT nCount=0\n", "DECL nCount=0\n")),
    M("dat_no_index", ".dat assignment to a variable without a declaration", "2.5", "dat", ("nTable[1]=10\n", "nTable=10\n")),
    M("dat_var_index", ".dat array element initialised with a variable index", "2.5", "dat", ("nTable[1]=10\n", "nTable[nCount]=10\n")),
    M("dat_no_name", "DEFDAT without a name", "2.5", "dat", ("DEFDAT @NAME@\n", "DEFDAT\n")),
    M("dat_public_first", "PUBLIC before the DEFDAT name", "2.5", "dat", ("DEFDAT @NAME@\n", "DEFDAT PUBLIC @NAME@\n")),
    M("dat_header_mid", "&PARAM header line inside the DEFDAT", "1.3", "dat", ("nTable[1]=10\n", "&PARAM EDITMASK = *\nnTable[1]=10\n")),
    M("dat_after_enddat", "declaration after ENDDAT", "2.5", "dat", ("SIGNAL Gripper $OUT[17]\nENDDAT\n", "SIGNAL Gripper $OUT[17]\nENDDAT\nDECL INT nLate=0\n")),
    M("dat_two_decls", "two declarations on one line", "1.4, 2.5", "dat", ("DECL INT nCount=0\nDECL REAL rSpeed=0.5\n", "DECL INT nCount=0 DECL REAL rSpeed=0.5\n")),
    M("dat_const_noval", "CONST without an initial value", "2.5", "dat", ("DECL INT nCount=0\n", "DECL CONST INT nCount\n")),
    M("dat_agg_open", "nested aggregate not closed", "1.5", "dat", ("CM {X 0.0,Y 0.0,Z 80.0,A 0.0,B 0.0,C 0.0},", "CM {X 0.0,Y 0.0,Z 80.0,A 0.0,B 0.0,C 0.0,")),
    M("dat_string_open", "unterminated string in a .dat aggregate", "1.5", "dat", ("{TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE}", "{TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE,POINT2[] \"P1}")),
    # ---- aggregates (1.5)
    M("agg_no_rbrace", "aggregate without its closing brace", "1.5", "main", ("A 0.0, B 90.0, C 0.0}\n", "A 0.0, B 90.0, C 0.0\n")),
    M("agg_no_braces", "aggregate without braces", "1.5", "main",
      ("  pTarget = {X 500.0, Y 0.0, Z 300.0, A 0.0, B 90.0, C 0.0}\n", "  pTarget = X 500.0, Y 0.0, Z 300.0, A 0.0, B 90.0, C 0.0\n")),
    M("agg_no_value", "aggregate component without a value", "1.5", "main", ("{X 500.0, Y 0.0,", "{X 500.0, Y,")),
    M("agg_trail_comma", "aggregate with a trailing comma", "1.5", "main", ("B 90.0, C 0.0}\n", "B 90.0, C 0.0,}\n")),
    M("agg_lead_comma", "aggregate with a leading comma", "1.5", "main", ("{X 500.0,", "{, X 500.0,")),
    M("agg_double_comma", "aggregate with an empty slot", "1.5", "main", ("{X 500.0, Y 0.0,", "{X 500.0,, Y 0.0,")),
    M("agg_equals", "'=' inside an aggregate", "1.5", "main", ("{X 500.0, Y 0.0, Z 300.0,", "{X=500.0, Y=0.0, Z=300.0,")),
    M("agg_colons", "':' between component and value", "1.5", "main", ("{X 500.0, Y 0.0, Z 300.0,", "{X: 500.0, Y: 0.0, Z: 300.0,")),
    M("agg_semicolon", "';' as aggregate separator (starts a comment)", "1.3, 1.5", "main", ("{X 500.0, Y 0.0,", "{X 500.0; Y 0.0,")),
    M("agg_square", "aggregate in square brackets", "1.5", "main",
      ("{X 500.0, Y 0.0, Z 300.0, A 0.0, B 90.0, C 0.0}", "[X 500.0, Y 0.0, Z 300.0, A 0.0, B 90.0, C 0.0]")),
    M("agg_type_colon", "typed aggregate without ':' after the type", "1.5", "main", ("{X 500.0,", "{E6POS X 500.0,")),
    M("agg_value_only", "aggregate of bare values without component names", "1.5", "main",
      ("{X 500.0, Y 0.0, Z 300.0, A 0.0, B 90.0, C 0.0}", "{500.0, 0.0, 300.0, 0.0, 90.0, 0.0}")),
    M("agg_multiline", "aggregate broken over two lines", "1.4, 1.5", "main", ("Z 300.0, A 0.0,", "Z 300.0,\n    A 0.0,")),
    # ---- assignments and operators (4.1, 5.1)
    M("eq_eq_statement", "comparison x == 1 used as a statement", "5.1", "main", ("  nCount = 0\n", "  nCount == 0\n")),
    M("ne_statement", "comparison x <> 1 used as a statement", "5.1", "main", ("  nCount = 0\n", "  nCount <> 0\n")),
    M("chained_assign", "chained assignment a = b = c", "5.1", "main", ("  nCount = 0\n", "  nCount = i = 0\n")),
    M("colon_eq_assign", "':=' assignment", "5.1", "main", ("  nCount = 0\n", "  nCount := 0\n")),
    M("plus_plus", "'++' increment", "4.1, 5.1", "main", ("    nCount = nCount + i\n", "    nCount++\n")),
    M("plus_equals", "'+=' compound assignment", "4.1, 5.1", "main", ("    nCount = nCount + i\n", "    nCount += i\n")),
    M("bang_equals", "'!=' instead of '<>'", "4.1", "main", ("  WHILE nCount > 0\n", "  WHILE nCount != 0\n")),
    M("amp_amp", "'&&' instead of AND", "4.1", "main", ("  IF bReady THEN\n", "  IF bReady && $IN[3] THEN\n")),
    M("pipe_pipe", "'||' instead of OR", "4.1", "main", ("  IF bReady THEN\n", "  IF bReady || $IN[3] THEN\n")),
    M("bang_not", "'!' instead of NOT", "4.1", "main", ("  IF bReady THEN\n", "  IF !bReady THEN\n")),
    M("percent_mod", "'%' modulo operator", "4.1", "main", ("    nCount = nCount + i\n", "    nCount = nCount % i\n")),
    M("star_star_power", "'**' power operator", "4.1", "main", ("  rSpeed = 0.5\n", "  rSpeed = 0.5 ** 2\n")),
    M("caret_power", "'^' power operator", "4.1", "main", ("  rSpeed = 0.5\n", "  rSpeed = 0.5 ^ 2\n")),
    M("triple_equals", "'===' comparison", "4.1", "main", ("  IF bReady THEN\n", "  IF nCount === 1 THEN\n")),
    M("ge_reversed", "'=>' instead of '>='", "4.1", "main", ("  UNTIL nCount >= 3\n", "  UNTIL nCount => 3\n")),
    M("le_reversed", "'=<' instead of '<='", "4.1", "main", ("  UNTIL nCount >= 3\n", "  UNTIL nCount =< 3\n")),
    M("ne_split", "'< >' with a space", "4.1", "main", ("  WHILE nCount > 0\n", "  WHILE nCount < > 0\n")),
    M("assign_no_rhs", "assignment without a right-hand side", "5.1", "main", ("  rSpeed = 0.5\n", "  rSpeed =\n")),
    M("assign_no_lhs", "assignment without a target", "5.1", "main", ("  rSpeed = 0.5\n", "  = 0.5\n")),
    M("assign_to_lit", "assignment to a literal", "5.1", "main", ("  nCount = 0\n", "  0 = nCount\n")),
    M("assign_to_call", "assignment to a call", "5.1", "func", ("  rOut = Clamp(12.5, 0.0, 10.0)\n", "  Clamp(12.5, 0.0, 10.0) = rOut\n")),
    M("dangling_op", "binary operator without a right operand", "4.1", "main", ("    nCount = nCount + i\n", "    nCount = nCount + \n")),
    M("double_operator", "two binary operators in a row", "4.1", "main", ("    nCount = nCount + i\n", "    nCount = nCount * / i\n")),
    M("not_postfix", "NOT after its operand", "4.1", "main", ("  bReady = $IN[1]\n", "  bReady = $IN[1] NOT\n")),
    M("compare_no_rhs", "comparison without a right operand", "4.1", "main", ("  WHILE nCount > 0\n", "  WHILE nCount >\n")),
    M("paren_unclosed", "unbalanced parentheses (missing ')')", "4.2", "main", ("  IF bReady THEN\n", "  IF (bReady AND $IN[3] THEN\n")),
    M("paren_extra", "unbalanced parentheses (extra ')')", "4.2", "main", ("    nCount = nCount + i\n", "    nCount = (nCount + i))\n")),
    M("bracket_unclosed", "unbalanced brackets in an index", "4.2", "main", ("    $OUT[5] = TRUE\n", "    $OUT[5 = TRUE\n")),
    M("index_parens", "array index in parentheses", "4.2", "main", ("    $OUT[5] = TRUE\n", "    $OUT(5) = TRUE\n")),
    M("call_unclosed", "call without its closing parenthesis", "4.2", "main", ("  BAS (#INITMOV,0 )\n", "  BAS (#INITMOV,0 \n")),
    M("call_brackets", "call with square brackets", "4.2", "main", ("  BAS (#INITMOV,0 )\n", "  BAS [#INITMOV,0]\n")),
    M("member_dotdot", "structure access with '..'", "4.2", "main", ("  pTarget = {X", "  pTarget..X = 1.0\n  pTarget = {X")),
    # ---- literals and comments (1.3, 1.5)
    M("slash_comment", "C++ comment '//'", "1.3", "main", ("  nCount = 0\n", "  nCount = 0 // reset the counter\n")),
    M("block_comment", "C comment '/* */'", "1.3", "main", ("  nCount = 0\n", "  /* reset the counter */\n  nCount = 0\n")),
    M("hash_comment", "'#' comment", "1.3", "main", ("  nCount = 0\n", "  # reset the counter\n  nCount = 0\n")),
    M("string_newline", "string literal with a line break", "1.5", "main",
      ("  WAIT SEC 0.5\n", "  MsgText(\"first line\nsecond line\")\n  WAIT SEC 0.5\n")),
    M("string_open", "unterminated string literal", "1.5", "main", ("  WAIT SEC 0.5\n", "  MsgText(\"waiting)\n  WAIT SEC 0.5\n")),
    M("string_escape", "escaped quote inside a string (no escapes in KRL)", "1.5", "main",
      ("  WAIT SEC 0.5\n", "  MsgText(\"say \\\"hi\\\"\")\n  WAIT SEC 0.5\n")),
    M("string_squote", "string in single quotes", "1.5", "main", ("  WAIT SEC 0.5\n", "  MsgText('waiting')\n  WAIT SEC 0.5\n")),
    M("real_two_points", "REAL literal with two decimal points", "1.5", "main", ("  rSpeed = 0.5\n", "  rSpeed = 0.5.1\n")),
    M("real_exp_empty", "REAL literal with an empty exponent", "1.5", "main", ("  rSpeed = 0.5\n", "  rSpeed = 0.5E\n")),
    M("hex_bad_digit", "hex literal with a non-hex digit", "1.5", "main", ("  nCount = 0\n", "  nCount = 'HFG'\n")),
    M("hex_unterminated", "hex literal without its closing quote", "1.5", "main", ("  nCount = 0\n", "  nCount = 'H1F\n")),
    M("bin_bad_digit", "binary literal with a digit 2", "1.5", "main", ("  nCount = 0\n", "  nCount = 'B0120'\n")),
    M("hex_c_style", "C-style hex literal 0x1F", "1.5", "main", ("  nCount = 0\n", "  nCount = 0x1F\n")),
    M("enum_space", "'#' separated from the enum value", "1.5", "main", ("  BAS (#INITMOV,0 )\n", "  BAS (# INITMOV,0 )\n")),
    # ---- WAIT, CONTINUE, interrupts, BRAKE/RESUME (5.8, 5.16, 5.17)
    M("wait_without_for", "WAIT without FOR or SEC", "5.8", "main", ("  WAIT FOR $IN[2]\n", "  WAIT $IN[2]\n")),
    M("wait_sec_no_time", "WAIT SEC without a time", "5.8", "main", ("  WAIT SEC 0.5\n", "  WAIT SEC\n")),
    M("wait_for_no_cond", "WAIT FOR without a condition", "5.8", "main", ("  WAIT FOR $IN[2]\n", "  WAIT FOR\n")),
    M("wait_until", "WAIT UNTIL instead of WAIT FOR", "5.8", "main", ("  WAIT FOR $IN[2]\n", "  WAIT UNTIL $IN[2]\n")),
    M("wait_for_timeout", "WAIT FOR with a trailing time-out", "5.8", "main", ("  WAIT FOR $IN[2]\n", "  WAIT FOR $IN[2] SEC 5\n")),
    M("irq_number_first", "INTERRUPT 3 ON (number before keyword)", "5.16", "main", ("  INTERRUPT ON 3\n", "  INTERRUPT 3 ON\n")),
    M("irq_decl_no_when", "INTERRUPT DECL without WHEN", "5.16", "irq", ("DECL 21 WHEN $IN[12]", "DECL 21 $IN[12]")),
    M("irq_decl_no_do", "INTERRUPT DECL without DO", "5.16", "irq", ("$IN[12] DO Touch( )", "$IN[12] Touch( )")),
    M("irq_decl_no_prio", "INTERRUPT DECL without a priority", "5.16", "irq", ("DECL 21 WHEN", "DECL WHEN")),
    M("irq_then_not_do", "INTERRUPT DECL ... THEN instead of DO", "5.16", "irq", ("$IN[12] DO Touch( )", "$IN[12] THEN Touch( )")),
    M("irq_decl_assign", "INTERRUPT DECL with an assignment as handler", "5.16", "irq", ("DO Touch( )", "DO $OUT[3] = TRUE")),
    M("irq_bad_action", "INTERRUPT START (unknown action)", "5.16", "irq", ("  INTERRUPT ON 21\n", "  INTERRUPT START 21\n")),
    M("irq_two_numbers", "INTERRUPT ON with two numbers", "5.16", "irq", ("  INTERRUPT ON 21\n", "  INTERRUPT ON 21 22\n")),
    M("irq_glob_nodecl", "GLOBAL INTERRUPT without DECL", "5.16", "main", ("GLOBAL INTERRUPT DECL 3", "GLOBAL INTERRUPT 3")),
    M("irq_no_condition", "INTERRUPT DECL WHEN without a condition", "5.16", "irq", ("WHEN $IN[12] DO", "WHEN DO")),
    M("brake_bad_flag", "BRAKE with an unknown option", "5.17", "irq", ("  BRAKE\n", "  BRAKE FAST\n")),
    M("resume_argument", "RESUME with an argument", "5.17", "irq", ("  RESUME\n", "  RESUME Touch\n")),
    # ---- TRIGGER (5.18)
    M("trigger_no_do", "TRIGGER without DO", "5.18", "irq", ("DELAY=0 DO $OUT[7]=TRUE", "DELAY=0 $OUT[7]=TRUE")),
    M("trigger_no_when", "TRIGGER without WHEN", "5.18", "irq", ("TRIGGER WHEN DISTANCE=1", "TRIGGER DISTANCE=1")),
    M("trigger_no_delay", "TRIGGER without DELAY", "5.18", "irq", ("DISTANCE=1 DELAY=0 DO", "DISTANCE=1 DO")),
    M("trigger_no_act", "TRIGGER DO without an action", "5.18", "irq", ("DO $OUT[7]=TRUE", "DO")),
    M("trigger_wait", "TRIGGER with WAIT as action", "5.18", "irq", ("DO $OUT[7]=TRUE", "DO WAIT SEC 1")),
    M("trigger_dist_2", "TRIGGER WHEN DISTANCE=2 (only 0 or 1)", "5.18", "irq", ("DISTANCE=1", "DISTANCE=2")),
    M("trigger_onstart", "ONSTART with DISTANCE (only with PATH)", "5.18", "irq", ("DISTANCE=1 DELAY", "DISTANCE=1 ONSTART DELAY")),
    M("trigger_prio_eq", "PRIO without '='", "5.18", "irq", ("PRIO=-1", "PRIO -1")),
    M("trigger_path_eq", "PATH without '='", "5.18", "irq", ("PATH=-10.0", "PATH -10.0")),
    M("trigger_time", "TRIGGER WHEN TIME (no such trigger)", "5.18", "irq", ("TRIGGER WHEN DISTANCE=1", "TRIGGER WHEN TIME=1")),
    # ---- motions (6.1, 6.2)
    M("ptp_no_target", "PTP with no target", "6.1", "main", ("  PTP XHOME\n  IF", "  PTP\n  IF")),
    M("lin_no_target", "LIN with an approximation keyword but no target", "6.1", "main", ("  LIN pTarget C_DIS\n", "  LIN C_DIS\n")),
    M("lin_three_approx", "LIN with three approximation keywords", "6.1", "main", ("  LIN pTarget C_DIS\n", "  LIN pTarget C_DIS C_DIS C_DIS\n")),
    M("ptp_three_approx", "PTP with three approximation keywords", "6.1", "main", ("  PTP XHOME\n  IF", "  PTP XHOME C_PTP C_DIS C_DIS\n  IF")),
    M("circ_one_point", "CIRC with one point", "6.1", "main", ("  CIRC XP2, XP3\n", "  CIRC XP3\n")),
    M("circ_no_comma", "CIRC points without a comma", "6.1", "main", ("  CIRC XP2, XP3\n", "  CIRC XP2 XP3\n")),
    M("circ_three_pts", "CIRC with three points", "6.1", "main", ("  CIRC XP2, XP3\n", "  CIRC XP2, XP3, XP4\n")),
    M("circ_ca_no_angle", "CA without an angle", "6.1", "main", ("  CIRC XP2, XP3\n", "  CIRC XP2, XP3, CA\n")),
    M("circ_ca_no_comma", "CA without its comma", "6.1", "main", ("  CIRC XP2, XP3\n", "  CIRC XP2, XP3 CA 90.0\n")),
    M("lin_with_clause", "WITH on a classic LIN (spline motions only)", "6.1", "main", ("  LIN pTarget C_DIS\n", "  LIN pTarget WITH $VEL = {CP 0.2} C_DIS\n")),
    M("ptp_c_spl", "C_SPL on a classic PTP", "6.1, 6.8", "main", ("  PTP XHOME\n  IF", "  PTP XHOME C_SPL\n  IF")),
    M("lin_comma_approx", "comma before the approximation keyword", "6.1", "main", ("  LIN pTarget C_DIS\n", "  LIN pTarget, C_DIS\n")),
    M("lin_rel_world", "LIN_REL with #WORLD (only #BASE or #TOOL)", "6.1", "main", ("  LIN pTarget C_DIS\n", "  LIN_REL {Z 10.0} #WORLD\n")),
    M("lin_rel_two_enum", "LIN_REL with both #BASE and #TOOL", "6.1", "main", ("  LIN pTarget C_DIS\n", "  LIN_REL {Z 10.0} #BASE #TOOL\n")),
    M("ptp_two_targets", "PTP with two targets", "6.1", "main", ("  PTP XHOME\n  IF", "  PTP XHOME XP2\n  IF")),
    M("approx_first", "approximation keyword before the target", "6.1", "main", ("  LIN pTarget C_DIS\n", "  LIN C_DIS pTarget\n")),
    M("sptp_alone", "SPTP alone (no target)", "6.1", "smove", ("  SLIN XP5 WITH $VEL = {CP 0.1} C_SPL\n", "  SPTP\n")),
    M("sptp_with_only", "SPTP target WITH without assignments", "6.1", "smove", ("  SPTP XHOME WITH $VEL_AXIS[1] = SVEL_JOINT(100.0)\n", "  SPTP XHOME WITH\n")),
    M("with_trail_comma", "WITH list with a trailing comma", "6.1", "smove", ("WITH $VEL = {CP 0.1} C_SPL", "WITH $VEL = {CP 0.1}, C_SPL")),
    M("with_user_var", "WITH assigning a user variable (system variables only)", "6.1", "smove",
      ("WITH $VEL = {CP 0.1} C_SPL", "WITH rSpeed = 0.1 C_SPL")),
    M("with_no_equals", "WITH assignment without '='", "6.1", "smove", ("WITH $VEL = {CP 0.1} C_SPL", "WITH $VEL {CP 0.1} C_SPL")),
    M("slin_c_vel", "C_VEL on a spline motion", "6.1", "smove", ("{CP 0.1} C_SPL", "{CP 0.1} C_VEL")),
    M("no_endspline", "SPLINE without ENDSPLINE", "6.2", "spline", ("    SCIRC XP3, XP4\n  ENDSPLINE\n", "    SCIRC XP3, XP4\n")),
    M("spl_no_block", "SPL outside a spline block", "6.2", "smove", ("  SLIN XP5 WITH $VEL = {CP 0.1} C_SPL\n", "  SPL XP5\n")),
    M("nested_spline", "SPLINE block inside a SPLINE block", "6.2", "spline", ("    SLIN XP2\n", "    SPLINE\n      SPL XP2\n    ENDSPLINE\n")),
    M("ptp_in_spline", "classic PTP inside a SPLINE block", "6.2", "spline", ("    SLIN XP2\n", "    PTP XP2\n")),
    M("wait_in_spline", "WAIT inside a SPLINE block", "6.2", "spline", ("    SLIN XP2\n", "    WAIT SEC 0.1\n    SLIN XP2\n")),
    M("out_in_spline", "$OUT assignment inside a SPLINE block", "6.2", "spline", ("    SLIN XP2\n", "    $OUT[3] = TRUE\n    SLIN XP2\n")),
    M("sptp_in_spline", "SPTP inside a SPLINE block (only in PTP_SPLINE)", "6.2", "spline", ("    SLIN XP2\n", "    SPTP XP2\n")),
    M("endspline_c_dis", "ENDSPLINE with C_DIS (only C_SPL)", "6.2", "spline", ("  ENDSPLINE\n", "  ENDSPLINE C_DIS\n")),
    M("endspline_alone", "ENDSPLINE without SPLINE", "6.2", "smove", ("  SPTP XHOME\nEND\n", "  SPTP XHOME\n  ENDSPLINE\nEND\n")),
    M("spl_two_approx", "SPL with two approximation keywords", "6.2", "spline", ("    SPL XP1\n", "    SPL XP1 C_SPL C_SPL\n")),
    # ---- analog I/O (5.14)
    M("anout_no_on", "ANOUT without ON/OFF", "5.14", "main", ("  WAIT SEC 0.5\n", "  ANOUT $ANOUT[1] = 0.5\n  WAIT SEC 0.5\n")),
    M("anin_on_no_eq", "ANIN ON without '='", "5.14", "main", ("  WAIT SEC 0.5\n", "  ANIN ON rSpeed 1.0 * $ANIN[1]\n  WAIT SEC 0.5\n")),
]


# --------------------------------------------------------------------------- generation

def file_name(number: int, m: Mutation) -> str:
    return f"neg_{number:03d}_{m.slug}"


def render(number: int, m: Mutation) -> tuple[str, str]:
    template, suffix = BASES[m.base]
    name = file_name(number, m)
    text = template
    for old, new in m.edits:
        count = text.count(old)
        if count != 1:
            raise SystemExit(f"{name}: edit anchor occurs {count} times: {old!r}")
        text = text.replace(old, new)
    text = text.replace("@NAME@", name)
    header = f"; NEGATIVE: {m.what} (reference {m.section})\n"
    return name + suffix, header + text


def generate() -> dict[str, str]:
    out: dict[str, str] = {}
    slugs = set()
    for number, m in enumerate(MUTATIONS, start=1):
        if m.slug in slugs:
            raise SystemExit(f"duplicate slug {m.slug}")
        slugs.add(m.slug)
        if len(file_name(number, m)) > MAX_NAME:
            raise SystemExit(f"{file_name(number, m)}: longer than {MAX_NAME} characters")
        fname, text = render(number, m)
        out[fname] = text
    return out


def main(argv: list[str]) -> int:
    files = generate()
    if "--check" in argv:
        stale = [f for f, t in files.items() if not (HERE / f).exists() or (HERE / f).read_text() != t]
        extra = [p.name for p in HERE.glob("neg_*") if p.name not in files]
        for f in stale + extra:
            print(f"out of date: {f}")
        return 1 if stale or extra else 0
    for p in HERE.glob("neg_*"):
        if p.name not in files:
            p.unlink()
    for f, t in files.items():
        (HERE / f).write_text(t)
    print(f"wrote {len(files)} negative programs to {HERE}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
