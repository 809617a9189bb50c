"""`krl cache path` and `krl cache clear`: the store of parses and checks in the user cache
folder (krl/store.py; docs/security.md "The store" and "Faults").

The store heals by itself (a damaged database is rebuilt once, with one warning); ``krl cache
clear`` is the user's own reset: it removes the databases of ``front-end/`` (every front-end
version's, with their journal files) and the folders earlier versions left, nothing else, and
never follows a symbolic link. A process that has a database open keeps reading its own copy
until it ends (POSIX unlink); the next command starts a new one. Exit 0; 2 when the cache folder
cannot be read.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from krl import store
from krl.terminal import printable, printable_path


@click.group("cache")
def cache() -> None:
    """The store of parses and checks in the user cache folder (krl/store.py): where it is, clear it."""


@cache.command("path")
def cache_path() -> None:
    """Print the cache folder ($KRL_CACHE_DIR, else the platform's user cache folder)."""
    click.echo(printable_path(_root()))


@cache.command("clear")
def cache_clear() -> None:
    """Remove the parse and check store (every front-end version's database) from the cache folder."""
    root = _root()
    try:
        removed, size = clear(root)
    except OSError as exc:
        click.echo(f"error: the cache folder cannot be read: {printable(exc.strerror or exc)}", err=True)
        sys.exit(2)
    click.echo(f"removed {removed} file(s), {size} bytes, from {printable_path(root / 'front-end')}")


def _root() -> Path:
    try:
        return store.cache_dir()
    except OSError as exc:
        click.echo(f"error: the cache folder cannot be made: {exc.strerror or exc}", err=True)
        sys.exit(2)


def clear(root: Path) -> tuple[int, int]:
    """Remove the databases ``root/front-end/*.sqlite*`` (:func:`krl.store.databases`: regular
    files only) and the obsolete folders (:func:`krl.store.remove_obsolete`); (files removed,
    their bytes). A file that cannot be removed is left. Raises OSError when the folder cannot
    be listed."""
    removed = size = 0
    for e in store.databases(root):
        n = e.stat(follow_symlinks=False).st_size
        try:
            os.unlink(e.path)
        except OSError:
            continue
        removed, size = removed + 1, size + n
    store.remove_obsolete(root)
    return removed, size


commands = [cache]
