"""The extension's language configuration (editors/vscode/language-configuration.json): its folding
markers and indentation rules compiled as VS Code compiles them (`new RegExp(pattern, flags)`, in
node), on KRL lines (most from the corpus files of the grammar snippets, lower case as written there);
the expected answers are read off each line by hand."""

from __future__ import annotations

import json
import subprocess

from tests.editors.npm import EXTENSION, node_or_fail

MATCH_JS = r"""
const fs = require('fs');
const conf = JSON.parse(fs.readFileSync(process.argv[1], 'utf8'));
const re = (r) => new RegExp(r.pattern, r.flags);
const rules = {
  foldStart: re(conf.folding.markers.start), foldEnd: re(conf.folding.markers.end),
  indent: re(conf.indentationRules.increaseIndentPattern), outdent: re(conf.indentationRules.decreaseIndentPattern),
};
const lines = JSON.parse(fs.readFileSync(0, 'utf8'));
const out = {};
for (const [name, r] of Object.entries(rules)) out[name] = lines.filter((l) => r.test(l));
process.stdout.write(JSON.stringify({ out, comment: conf.comments.lineComment }));
"""

LINES = [
    ";FOLD PTP HOME  Vel= 100 % DEFAULT;%{PE}%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:HOME",
    "  ;fold BASISTECH INI",
    "  ;ENDFOLD (BASISTECH INI)",
    "DEF  CELL ( )",
    "GLOBAL DEF UP_Place_R1_L1_S1( )",
    "deffct int eki_hw_iface_get(joint_pos_cmd :out)",
    "DEFDAT  $CONFIG",
    "DEF_GROUP[1]='B1111' ; complete",
    "  IF $MODE_OP==#EX THEN",
    "  ELSE",
    "  ENDIF",
    "   loop",
    "   endloop",
    "  SWITCH N_PROGRAMA",
    "  CASE 0",
    "  DEFAULT",
    "  ENDSWITCH",
    "  REPEAT",
    "  UNTIL n == 1",
    "  WAIT FOR $IN[1]",
    "  ; IF in a comment",
    "END",
    "ENDDAT",
    "END_POS = 1",
]


def test_folding_markers_and_indentation_rules():
    node_or_fail()
    run = subprocess.run(["node", "-e", MATCH_JS, str(EXTENSION / "language-configuration.json")],
                         input=json.dumps(LINES), capture_output=True, text=True, timeout=60, check=False)
    assert run.returncode == 0, run.stderr
    result = json.loads(run.stdout)
    out = result["out"]
    assert result["comment"] == ";"
    assert out["foldStart"] == [LINES[0], LINES[1], "DEF  CELL ( )", "GLOBAL DEF UP_Place_R1_L1_S1( )",
                                "deffct int eki_hw_iface_get(joint_pos_cmd :out)", "DEFDAT  $CONFIG",
                                "  IF $MODE_OP==#EX THEN", "   loop", "  SWITCH N_PROGRAMA", "  REPEAT"]
    assert out["foldEnd"] == ["  ;ENDFOLD (BASISTECH INI)", "  ENDIF", "   endloop", "  ENDSWITCH",
                              "  UNTIL n == 1", "END", "ENDDAT"]
    assert out["indent"] == ["DEF  CELL ( )", "GLOBAL DEF UP_Place_R1_L1_S1( )",
                             "deffct int eki_hw_iface_get(joint_pos_cmd :out)", "DEFDAT  $CONFIG",
                             "  IF $MODE_OP==#EX THEN", "  ELSE", "   loop", "  SWITCH N_PROGRAMA", "  CASE 0",
                             "  DEFAULT", "  REPEAT"]
    assert out["outdent"] == ["  ELSE", "  ENDIF", "   endloop", "  CASE 0", "  DEFAULT", "  ENDSWITCH",
                              "  UNTIL n == 1", "END", "ENDDAT"]
