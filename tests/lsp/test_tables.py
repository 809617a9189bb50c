"""sysvar_meanings.yaml (the hover text of system variables) names only system variables the
checker knows, with a section of the reference."""

from __future__ import annotations

import re

from krl.lsp.hover import meanings
from krl.semantics.builtins import load_builtins


def test_every_meaning_names_a_known_system_variable():
    b = load_builtins()
    got = meanings()
    assert len(got) >= 60
    for name, (meaning, ref) in got.items():
        assert name in b.sysvars or name in b.kss_variables, name
        assert meaning and re.fullmatch(r"\d+(\.\d+)?", ref), name     # 9: a section without subsections
