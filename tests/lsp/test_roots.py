"""The workspace of an opened file is the one `krl check` forms (krl/lsp/roots.py against
krl/workspace.py find_backups)."""

from __future__ import annotations

from pathlib import Path

from krl.lsp.roots import list_krl_files, workspace_of
from krl.project import backup_of as backup_root
from krl.project import find_backups


def touch(path: Path, text: str = "") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_backup_layouts(tmp_path: Path):
    krc = tmp_path / "KRC"
    cfg = touch(krc / "R1" / "SYSTEM" / "$CONFIG.DAT")          # any letter case
    prog = touch(krc / "R1" / "Program" / "a" / "b.src")
    steu = touch(krc / "STEU" / "Mada" / "$machine.dat")
    assert backup_root(prog) == krc and backup_root(cfg) == krc and backup_root(steu) == krc
    flat = tmp_path / "export"
    touch(flat / "System" / "$config.dat")
    assert backup_root(touch(flat / "Program" / "x.src")) == flat
    assert backup_root(touch(tmp_path / "loose" / "y.src")) is None
    root, files, _ = workspace_of(prog, [])
    assert root == krc and sorted(f.name for f in files) == ["$CONFIG.DAT", "$machine.dat", "b.src"]


def test_file_outside_backups_takes_its_folder(tmp_path: Path):
    """krl/project.py rule 3: outside a backup, the files of the program's folder (the
    editor's folder when one is open), as krl run and krl check FILE read them."""
    a = touch(tmp_path / "proj" / "sub" / "a.src")
    touch(tmp_path / "proj" / "sub" / "A.DAT")
    touch(tmp_path / "proj" / "sub" / "other.src")
    touch(tmp_path / "proj" / "top.src")
    root, files, _ = workspace_of(a, [])                           # no folder open: its folder
    assert root == a.parent and sorted(f.name for f in files) == ["A.DAT", "a.src", "other.src"]
    root, files, _ = workspace_of(a, [tmp_path / "proj"])          # the opened folder, no backup in it
    assert root == tmp_path / "proj" and sorted(f.name for f in files) == ["A.DAT", "a.src", "other.src", "top.src"]
    touch(tmp_path / "proj" / "KRC" / "R1" / "System" / "$config.dat")
    root, files, _ = workspace_of(a, [tmp_path / "proj"])          # a backup in it: by top-level folder
    assert root == tmp_path / "proj" / "sub" and sorted(f.name for f in files) == ["A.DAT", "a.src", "other.src"]


def test_every_corpus_backup_file_finds_its_backup(shared_corpus: Path):
    backups = find_backups(shared_corpus)
    assert backups
    for b in backups:
        for f in b.rglob("*"):
            if f.suffix.lower() in (".src", ".dat", ".sub") and f.is_file():
                assert backup_root(f) == b, f


def test_listing_stops_at_its_limits(tmp_path: Path):
    for i in range(5):
        touch(tmp_path / f"d{i}" / f"f{i}.src")
    assert len(list_krl_files(tmp_path)) == 5
    assert len(list_krl_files(tmp_path, limit=3)) == 3
    assert len(list_krl_files(tmp_path, max_entries=3)) == 3     # files looked at
