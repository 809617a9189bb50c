"""The split of the reference's keyword list (1.6) into reserved words and soft keywords.

Every word of the list is either structurally reserved (never a name) or a soft keyword,
usable as a name exactly where real code uses it so. The evidence (grammar/CHANGES.md,
"keyword split"): KUKA's system data lists use IN OUT ON OFF PATH SEC DISTANCE as structure
components, enum values and `.` selectors; no file of the corpus outside
corpus/known-invalid.csv uses any of those or a reserved word as a declared variable or a
parameter. STEP is a name (grammar/CHANGES.md, "STEP as a name", issue 50): published programs
name variables and parameters `step` (the corpus's motion_eki.src, three files of an RSI
project), and the keyword stands only after FOR's `TO expression`, where no name can follow.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from krl.syntax import parse as P
from krl.syntax.parse import parse_text
from krl.survey.report import known_invalid

REFERENCE = Path(__file__).resolve().parents[2].parent / "shared" / "docs" / "krl-reference.md"

# reference 1.6, in its order; PULSE is listed there as a built-in procedure name, not a keyword
KEYWORDS = """DEF END DEFFCT ENDFCT DEFDAT ENDDAT PUBLIC GLOBAL DECL CONST STRUC ENUM SIGNAL
CHANNEL EXT EXTFCT EXTP EXTFCTP IMPORT IS IN OUT INT REAL BOOL CHAR
IF THEN ELSE ENDIF SWITCH CASE DEFAULT ENDSWITCH FOR TO STEP ENDFOR WHILE ENDWHILE
REPEAT UNTIL LOOP ENDLOOP EXIT GOTO HALT RETURN CONTINUE WAIT SEC ON_ERROR_PROCEED
INTERRUPT WHEN DO ON OFF ENABLE DISABLE BRAKE RESUME TRIGGER DISTANCE PATH ONSTART DELAY PRIO
ANIN ANOUT DIGIN MINIMUM MAXIMUM PULSE
PTP PTP_REL LIN LIN_REL CIRC CIRC_REL SPTP SPTP_REL SLIN SLIN_REL SCIRC SCIRC_REL
SPL SPLINE PTP_SPLINE ENDSPLINE WITH CA C_PTP C_DIS C_VEL C_ORI C_SPL ASYPTP ASYCONT ASYSTOP
ASYCANCEL MOVE_EMI TIME_BLOCK CONST_VEL
NOT AND OR EXOR B_NOT B_AND B_OR B_EXOR TRUE FALSE""".split()

# soft keywords: names in structure components, enum values and `.` selectors only
SOFT_COMPONENT = {"IN", "OUT", "ON", "OFF", "PATH", "SEC", "DISTANCE"}
# FOR's STEP: a name wherever a name may stand, the keyword only after FOR ... TO expression
STEP_NAME = {"STEP"}
# listed, but a name: "PULSE is a built-in procedure name" (1.6)
NOT_RESERVED = {"PULSE"}
# attribute words of INTERRUPT / TRIGGER / ANOUT statements: names wherever a name may stand
# (grammar/CHANGES.md, "attribute keywords as names"; real backups name parameters `ENABLE`)
ATTRIBUTE_NAMES = {"ENABLE", "DISABLE", "ONSTART", "DELAY", "PRIO", "MINIMUM", "MAXIMUM"}
RESERVED = [k for k in KEYWORDS if k not in SOFT_COMPONENT | NOT_RESERVED | ATTRIBUTE_NAMES | STEP_NAME]


def parses(text: str, path: str = "t.src") -> bool:
    return parse_text(text, path).ok


@pytest.mark.may_skip("the shared reference ../shared/docs/krl-reference.md is absent")
def test_list_is_the_references():
    if not REFERENCE.exists():
        pytest.skip("no reference")
    text = REFERENCE.read_text(encoding="utf-8")
    section = text[text.index("### 1.6 Keywords"):text.index("(Source: antlr krl.g4 token list")]
    words = [w for w in re.findall(r"`([^`]+)`", section)]
    listed = [t for w in words for t in w.split() if re.fullmatch(r"[A-Z_]+", t)]
    listed = [t for t in listed if t not in ("FRAME", "E6POS")]    # named as non-keywords there
    assert list(dict.fromkeys(listed)) == KEYWORDS


@pytest.mark.parametrize("word", RESERVED)
def test_reserved_word_is_no_name(word):
    """A reserved word is neither a variable, a parameter nor a structure component."""
    assert not parses(f"DEF t()\n  DECL INT {word}\nEND\n"), word
    assert not parses(f"DEF t({word} :IN)\n  DECL INT n\nEND\n"), word
    assert not parses(f"DEFDAT d\n  STRUC S_T INT A, {word}\nENDDAT\n", "d.dat"), word


@pytest.mark.parametrize("word", sorted(SOFT_COMPONENT))
def test_soft_keyword_is_a_component_but_no_variable(word):
    assert parses(f"DEFDAT d\n  STRUC S_T INT A, {word}\n  ENUM E_T {word}, OTHER\n  DECL S_T s = {{{word} 1}}\nENDDAT\n",
                  "d.dat"), word
    assert parses(f"DEF t()\n  DECL S_T s\n  DECL INT n\n  n = s.{word}\nEND\n"), word
    assert not parses(f"DEF t()\n  DECL INT {word}\nEND\n"), word
    assert not parses(f"DEF t({word} :IN)\n  DECL INT n\nEND\n"), word


@pytest.mark.parametrize("word", sorted(ATTRIBUTE_NAMES))
def test_attribute_word_is_a_name(word):
    """An attribute word is a variable, a parameter, a component, a routine and a data-list
    name, in any letter case, and the statements that use it as a keyword still parse."""
    low = word.lower()
    assert parses(f"DEF t({word} :IN)\n  DECL INT {word}\n  DECL INT n\n  n = {low} + 1\n  {low} = n\nEND\n"), word
    assert parses(f"DEF {word}()\nEND\nDEF t()\n  {low}()\nEND\n"), word
    assert parses(f"DEFDAT d\n  STRUC S_T INT A, {word}\n  DECL S_T s = {{A 1, {word} 2}}\n"
                  f"  DECL INT {word} = 3\nENDDAT\n", "d.dat"), word
    assert parses(f"DEF t()\n  DECL INT {low}\n  INTERRUPT DECL 3 WHEN $IN[1] DO t()\n  INTERRUPT ENABLE {low}\n"
                  f"  INTERRUPT DISABLE 3\n  TRIGGER WHEN PATH={low} ONSTART DELAY={low} DO $OUT[1]=TRUE PRIO={low}\n"
                  f"  LIN {{X 1}}\nEND\n"), word


def test_attribute_words_stay_keywords_where_they_are_keywords():
    """A name spelled like an attribute word does not replace the keyword: DELAY is still
    required after TRIGGER WHEN DISTANCE, and ENABLE after INTERRUPT is the action."""
    assert not parses("DEF t()\n  DECL INT delay\n  TRIGGER WHEN DISTANCE=0 delay DO $OUT[1]=TRUE\n  LIN {X 1}\nEND\n")
    assert not parses("DEF t()\n  DECL INT enable\n  INTERRUPT 3 enable\nEND\n")


def test_step_is_a_name_and_for_keeps_its_step():
    """`step` as a variable, parameter, component and argument (published RSI programs pass it to
    RSI_SETPUBLICPAR), and FOR ... TO ... STEP still reads its increment, also with a variable
    named step as the bound; `STEP = 2` and a STEP without its increment stay errors."""
    assert parses("DEF t(step :IN)\n  DECL INT step\n  DECL INT i, ret\n  step = 1\n"
                  "  ret = RSI_SETPUBLICPAR(1, \"POSCORR1\", \"MaxTrans\", step)\n"
                  "  FOR i = step TO 10 STEP 2\n  ENDFOR\n  FOR step = 1 TO step STEP -1\n  ENDFOR\nEND\n")
    assert parses("DEFDAT d\n  STRUC S_T INT A, STEP\n  DECL S_T s = {STEP 1}\n  DECL INT STEP = 2\nENDDAT\n", "d.dat")
    assert not parses("DEF t()\n  DECL INT i\n  FOR i = 1 TO 5 STEP = 2\n  ENDFOR\nEND\n")
    assert not parses("DEF t()\n  DECL INT i\n  FOR i = 1 TO 5 STEP\n  ENDFOR\nEND\n")
    assert not parses("DEF t()\n  DECL INT i\n  FOR i = 1 TO 5 STEP 2 STEP 3\n  ENDFOR\nEND\n")


def test_pulse_is_a_routine_name():
    assert parses("DEF t()\n  PULSE($OUT[1], TRUE, 0.5)\nEND\n")


@pytest.mark.corpus
def test_no_valid_file_declares_a_keyword(shared_corpus):
    """The evidence for the split: no file outside corpus/known-invalid.csv declares a listed
    word (other than PULSE and the attribute words) as a variable or parameter name."""
    invalid = known_invalid()
    words = set(KEYWORDS) - NOT_RESERVED - ATTRIBUTE_NAMES - STEP_NAME
    header = re.compile(r"^\s*(?:GLOBAL\s+)?DEF(?:FCT\s+\S+)?\s+\w+\s*\((.*)\)", re.IGNORECASE)
    decl = re.compile(r"^\s*DECL\s+(?:GLOBAL\s+)?(?:CONST\s+)?\w+\s+(.*)$", re.IGNORECASE)
    found, in_invalid = [], []
    for p in sorted(shared_corpus.rglob("*")):
        if not p.is_file() or p.suffix.lower() not in (".src", ".dat", ".sub"):
            continue
        rel = p.relative_to(shared_corpus).as_posix()
        for no, line in enumerate(p.read_text(encoding="latin-1").splitlines(), 1):
            code = line.split(";")[0]
            names = []
            m = header.match(code)
            if m:
                names += [part.split(":")[0].strip() for part in m.group(1).split(",")]
            m = decl.match(code)
            if m:
                rest = re.sub(r"\{.*?\}|=[^,]*", "", m.group(1))
                names += [re.split(r"[\[\s]", part.strip())[0] for part in rest.split(",")]
            for n in names:
                if n.upper() in words:
                    (in_invalid if rel in invalid else found).append(f"{rel}:{no} {n}")
    assert found == []


@pytest.mark.parametrize("word", ["AXIS", "E3AXIS", "E6AXIS", "FRAME", "POS", "E3POS", "E6POS"])
def test_geometric_type_names_are_names(word):
    """1.6: FRAME, E6POS, ... are "ordinary type identifiers, not keywords": a variable, a
    parameter, a component and an assignment target may carry the name."""
    assert parses(f"DEF t({word} :IN)\n  DECL FRAME {word}\n  DECL REAL r\n  r = {word}.X\nEND\n"), word
    assert parses(f"DEFDAT d\n  STRUC S_T REAL {word}\n  DECL INT {word} = 1\nENDDAT\n", "d.dat"), word
    assert not parses(f"DEF t()\n  DECL {word} {word} x\nEND\n"), word


def test_the_keyword_cache_answers_only_for_the_same_bundle(monkeypatch):
    """keyword_types caches by the bundle's id; an id another bundle had before it was freed
    (krl growth loads one parser bundle per grammar version) gives that bundle's own keywords,
    not the cached ones."""
    bundle = P.default_bundle()
    own = P._keyword_types(bundle)
    monkeypatch.setitem(P._KW_CACHE, id(bundle), (object(), frozenset({-1})))   # a freed bundle's entry
    assert P.keyword_types(bundle) == own and -1 not in own
    assert P.keyword_types(bundle) is P.keyword_types(bundle)
