"""Parse work is linear in the input whatever the layout (issue 17, the quadratic corner).

A run of blank or comment lines at the start of a routine body used to make the parser look
ahead over the whole run at every line (declaration or statement?): n lines cost n^2 token
lookups. The measure here is an operation count, not wall-clock time: the number of LA()
calls the parser makes on its token stream (prediction and matching alike), counted for
n and 10 n lines; 10x the lines may cost at most 12x the lookups.
"""

from __future__ import annotations

import pytest
from antlr4 import CommonTokenStream

import krl.syntax.parse as parse_mod


class CountingTokenStream(CommonTokenStream):
    calls = 0

    def LA(self, i):  # noqa: N802 - ANTLR's name
        CountingTokenStream.calls += 1
        return super().LA(i)


LAYOUTS = {
    "comment lines at the top of a body": lambda n: "DEF t()\n" + "; note\n" * n + "x = 1\nEND\n",
    "blank lines at the top of a body": lambda n: "DEF t()\n" + "\n" * n + "x = 1\nEND\n",
    "blank lines before a declaration": lambda n: "DEF t()\n" + "\n" * n + "DECL INT x\nx = 1\nEND\n",
    "blank lines between declarations": lambda n: "DEF t()\nDECL INT y\n" + "  \n" * n + "DECL INT x\nEND\n",
    "a body of blank lines only": lambda n: "DEF t()\n" + "\n" * n + "END\n",
    "blank lines after a header": lambda n: "&ACCESS RVP\n" + "\n" * n + "DEF t()\nx=1\nEND\n",
    "blank lines at the top of a file": lambda n: "\n" * n + "DEF t()\nx=1\nEND\n",
    "blank lines between routines": lambda n: "DEF t()\nEND\n" + "\n" * n + "DEF u()\nEND\n",
    "blank lines in an IF": lambda n: "DEF t()\nIF a THEN\n" + "\n" * n + "x=1\nENDIF\nEND\n",
    "blank lines in a data list": lambda n: "DEFDAT d\n" + "\n" * n + "INT x\nENDDAT\n",
    "statements and comments interleaved": lambda n: "DEF t()\n" + "x = 1\n; c\n" * (n // 2) + "END\n",
    "blank lines before a syntax error (LL stage)": lambda n: "DEF t()\n" + "\n" * n + "x = = 1\nEND\n",
}


def lookups(text: str, monkeypatch) -> int:
    monkeypatch.setattr(parse_mod, "CommonTokenStream", CountingTokenStream)
    CountingTokenStream.calls = 0
    parse_mod.parse_text(text, keep_tree=False)
    return CountingTokenStream.calls


@pytest.mark.parametrize("layout", LAYOUTS)
def test_ten_times_the_lines_at_most_twelve_times_the_work(layout, monkeypatch):
    make = LAYOUTS[layout]
    small, large = lookups(make(300), monkeypatch), lookups(make(3000), monkeypatch)
    assert large <= 12 * small, f"{layout}: {small} -> {large} lookups ({large / small:.1f}x)"
