"""Folder trees deeper than MAX_FOLDER_DEPTH for tests, made and removed without recursion
(pytest's own clean-up of its tmp folder would hit RecursionError on them)."""

from __future__ import annotations

from pathlib import Path


def deep_chain(root: Path, levels: int, made: list[Path]) -> Path:
    """`levels` folders d/d/... below `root`, each appended to `made` (deepest last); returns
    the deepest."""
    p = root
    for _ in range(levels):
        p = p / "d"
        p.mkdir()
        made.append(p)
    return p


def remove_bottom_up(folders: list[Path]) -> None:
    """Remove `folders` (as deep_chain lists them) and the files in them, deepest first."""
    for folder in reversed(folders):
        for f in folder.iterdir():
            if not f.is_dir() or f.is_symlink():
                f.unlink()
        folder.rmdir()
