"""Progress of the long recovery commands (`krl validate`, `krl growth`) with rich.

Shown on standard error only when it is a terminal; piped or redirected, the commands stay
quiet (no bar, no control sequences in logs). The bar is transient: what the command prints
afterwards is the same with or without it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import TypeVar
from krl.terminal import progress_shown
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

T = TypeVar("T")


def shown(stream=None) -> bool:
    """True when a progress bar goes to `stream` (default stderr): krl/terminal.py ``progress_shown``."""
    return progress_shown(stream)


@contextlib.contextmanager
def bar(what: str, total: int | None) -> Iterator:
    """A transient progress bar on stderr showing `what` (`total` steps, None: unknown); yields
    ``advance(label)``: one step done, the bar then showing "`what` `label`"."""
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=Console(stderr=True), transient=True) as shown_bar:
        task = shown_bar.add_task(escape(what), total=total)

        def advance(label: str) -> None:
            shown_bar.update(task, advance=1, description=escape(f"{what} {label}"))
        yield advance


def steps(items: list[T], what: str, label=str) -> Iterator[T]:
    """Yield `items`, showing "`what` i/n: label(item)" and a bar on a terminal."""
    if not shown() or not items:
        yield from items
        return

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(escape(what), total=len(items))
        for item in items:
            bar.update(task, description=escape(f"{what}: {label(item)}"))
            yield item
            bar.advance(task)
