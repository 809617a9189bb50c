"""A project's listing kept while its folders are as listed (krl/project.py ``_kept_entries``,
used by ``list_entries`` and so ``project_of`` at each run's start): listed again, and equal to
a fresh walk, after a file is added, removed or rewritten in place with another size, or a
folder is made unreadable; an unchanged project is not walked again."""

from __future__ import annotations

import os

import pytest

from krl import files, project
from krl.project import collect_entries, list_entries


@pytest.fixture
def tree(tmp_path, monkeypatch):
    """A program folder with a sub-folder; every listing settled at once (its folders' times
    are not within a clock tick of the listing: krl/files.py ``_settled``), the walks counted."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "prog.src").write_text("DEF prog()\nEND\n")
    (tmp_path / "sub" / "lib.src").write_text("DEF lib()\nEND\n")
    (tmp_path / "sub" / "lib.dat").write_text("DEFDAT lib\nENDDAT\n")
    monkeypatch.setattr(files, "_settled", lambda st, listed_at: True)
    walks = []
    walk = files.walk

    def counted(*a, **k):
        walks.append(a[0])
        return walk(*a, **k)
    monkeypatch.setattr(files, "walk", counted)
    monkeypatch.setattr(project, "_KEPT", {})
    return tmp_path, walks


def _same(folder) -> None:
    got, fresh = list_entries(folder), collect_entries(folder)
    assert [(e.path, e.rel, e.kind, e.detail, e.size) for e in got] == \
        [(e.path, e.rel, e.kind, e.detail, e.size) for e in fresh]


def test_an_unchanged_project_is_listed_once(tree):
    folder, walks = tree
    first = list_entries(folder)
    assert [e.rel for e in first] == ["prog.src", "sub/lib.dat", "sub/lib.src"]
    assert list_entries(folder) == first and len(walks) == 1
    list_entries(folder).clear()
    assert list_entries(folder) == first and len(walks) == 1


def test_a_changed_project_is_listed_again(tree):
    folder, walks = tree
    list_entries(folder)
    (folder / "sub" / "more.src").write_text("DEF more()\nEND\n")
    _same(folder)
    assert "sub/more.src" in [e.rel for e in list_entries(folder)]
    (folder / "sub" / "more.src").unlink()
    _same(folder)
    with open(folder / "sub" / "lib.dat", "a") as f:      # in place: its folder's times stay
        f.write("; more\n")
    _same(folder)
    assert next(e.size for e in list_entries(folder) if e.rel == "sub/lib.dat") == len("DEFDAT lib\nENDDAT\n; more\n")
    os.chmod(folder / "sub", 0)         # (its own change time: listed again)
    try:
        _same(folder)
        readable = os.access(folder / "sub", os.R_OK)       # (root reads any folder)
        assert [e.kind for e in list_entries(folder)][-1] == ("file" if readable else "unreadable_folder")
    finally:
        os.chmod(folder / "sub", 0o755)
    _same(folder)
    assert len(walks) > 1
