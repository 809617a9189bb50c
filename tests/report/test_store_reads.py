"""`krl graph` and `krl report` read a backup's files from the one store (krl/store.py), as
`krl check` and `krl diff` do (app/changes.py ``load_map``). Outside tests/programmap, whose
conftest loads every map through the store itself (and so hid that `krl graph` parsed every
file again at each call)."""

from __future__ import annotations

from pathlib import Path

import krl.parsecache as parsecache
import krl.workspace as workspace
from app.changes import load_map
from krl.store import Store

FIXTURE = Path(__file__).resolve().parents[1] / "programmap" / "fixtures" / "KRC"


def test_the_map_takes_its_parses_from_the_store(tmp_path, monkeypatch):
    """`krl graph` and `krl report` read a backup's files as `krl check` and `krl diff` do, from
    the one store (krl/store.py) when it holds their parses: the second map of the same backup
    parses no file (before, every `krl graph` parsed the whole backup in worker processes: the
    palletizer 4.8 s of CPU, 1.0 s with the store)."""
    store = Store(tmp_path / "store")
    monkeypatch.setattr(parsecache, "shared_store", lambda: store)
    first = load_map(str(FIXTURE))[0]

    def no_parse(*_args, **_kw):
        raise AssertionError("a file was parsed, not read from the store")
    for module in (parsecache, workspace):
        monkeypatch.setattr(module, "load_batch", no_parse)
        monkeypatch.setattr(module, "load_here", no_parse)
    again = load_map(str(FIXTURE))[0]
    assert sorted(again.nodes) == sorted(first.nodes) and len(again.nodes) > 3
    assert sorted(again.edges, key=repr) == sorted(first.edges, key=repr)
