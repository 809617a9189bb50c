"""The one history file of the nightly: ``reports/nightly/history.sqlite`` (stdlib sqlite3).

Tables: ``nights(date PRIMARY KEY, recorded)``, ``figures(date, name, value)`` and
``items(date, kind, name, status)``. Recording a night again replaces its rows, so running
the index twice on one day changes nothing. The CI workflow carries this one file from run to
run (.github/workflows/nightly.yml); the dated folders are the reports the flags link to.
"""

from __future__ import annotations

import sqlite3
import time
from contextlib import closing
from pathlib import Path

from .figures import Night

SCHEMA = """
CREATE TABLE IF NOT EXISTS nights (date TEXT PRIMARY KEY, recorded REAL NOT NULL);
CREATE TABLE IF NOT EXISTS figures (date TEXT NOT NULL, name TEXT NOT NULL, value REAL NOT NULL,
                                    PRIMARY KEY (date, name));
CREATE TABLE IF NOT EXISTS items (date TEXT NOT NULL, kind TEXT NOT NULL, name TEXT NOT NULL,
                                  status TEXT NOT NULL, PRIMARY KEY (date, kind, name));
"""


class HistoryError(Exception):
    """The history file exists but is no history of this nightly (message says why)."""


def _connect(path: Path) -> sqlite3.Connection:
    try:
        con = sqlite3.connect(path)
        con.executescript(SCHEMA)
    except sqlite3.DatabaseError as exc:
        raise HistoryError(f"{path}: not a nightly history ({exc})") from exc
    return con


def record(path: Path, night: Night) -> None:
    """Add (or replace) ``night`` in the history at ``path``; raises HistoryError."""
    with closing(_connect(path)) as con, con:
        con.execute("DELETE FROM figures WHERE date = ?", (night.date,))
        con.execute("DELETE FROM items WHERE date = ?", (night.date,))
        con.execute("INSERT OR REPLACE INTO nights VALUES (?, ?)", (night.date, time.time()))
        con.executemany("INSERT INTO figures VALUES (?, ?, ?)",
                        [(night.date, k, v) for k, v in sorted(night.figures.items())])
        con.executemany("INSERT INTO items VALUES (?, ?, ?, ?)",
                        [(night.date, k, n, s) for (k, n), s in sorted(night.items.items())])


def nights(path: Path) -> list[str]:
    """The recorded dates, oldest first."""
    with closing(_connect(path)) as con:
        return [r[0] for r in con.execute("SELECT date FROM nights ORDER BY date")]


def series(path: Path) -> dict[str, list[tuple[str, float]]]:
    """figure name -> [(date, value)], oldest first."""
    out: dict[str, list[tuple[str, float]]] = {}
    with closing(_connect(path)) as con:
        for date, name, value in con.execute("SELECT date, name, value FROM figures ORDER BY date, name"):
            out.setdefault(name, []).append((date, value))
    return out


def items(path: Path, date: str) -> dict[tuple[str, str], str]:
    """(kind, name) -> status of the night ``date``."""
    with closing(_connect(path)) as con:
        return {(k, n): s for k, n, s in con.execute("SELECT kind, name, status FROM items WHERE date = ?", (date,))}
