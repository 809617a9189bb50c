"""`krl run`'s progress on a terminal (issue 86): a status line while the run goes on, and at
the end how fast it ran.

While the run goes on, standard error shows one transient line (rich's live display,
refreshed twice a second by rich's own thread, which reads the run's figures as they stand:
the simulated time, the motions started, the run's rate against real time); at the end the
line is erased and, after the summary, one line says how fast the run went::

    krl run: 300.0 s simulated in 21.4 s (20.9 s CPU): 14.0x real time, 14.4x per CPU second

Both only when standard error is a terminal (krl/terminal.py ``progress_shown``): piped or
redirected, `krl run` writes exactly what it wrote before (its summary on standard output is
the same either way, so scripts and tests that read it see no difference). The rate is what
a user waits for, simulated seconds per wall-clock second; the CPU figure is the one the
benchmarks use (tools/whole_run_bench.py: simulated seconds per CPU second of the process).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from rich.console import Console
from rich.progress import Progress, ProgressColumn, Task, TextColumn, TimeElapsedColumn
from rich.text import Text

from krl.terminal import progress_shown

__all__ = ["RunProgress", "speed_line"]

#: redraws of the status line per second
REFRESH_PER_S = 2.0


def speed_line(sim_s: float, wall_s: float, cpu_s: float) -> str:
    """The line that says how fast a run went: `sim_s` simulated seconds in `wall_s` seconds of
    wall-clock time and `cpu_s` of the process's CPU time, each ratio ("-" for no time)."""
    def ratio(d: float) -> str:
        return f"{sim_s / d:.1f}x" if d > 0 else "-"
    return (f"krl run: {sim_s:.1f} s simulated in {wall_s:.1f} s ({cpu_s:.1f} s CPU): "
            f"{ratio(wall_s)} real time, {ratio(cpu_s)} per CPU second")


class _Figures(ProgressColumn):
    """The run's figures, read at each redraw from `read` (``(simulated s, motions)``)."""

    def __init__(self, read: Callable[[], tuple[float, int]], limit_s: float | None, started: float) -> None:
        super().__init__()
        self.read, self.limit_s, self.started = read, limit_s, started

    def render(self, task: Task) -> Text:
        sim_s, motions = self.read()
        wall = time.perf_counter() - self.started
        of = f" of {self.limit_s:g}" if self.limit_s else ""
        rate = f", {sim_s / wall:.1f}x real time" if wall > 0 else ""
        return Text(f"{sim_s:.1f}{of} s simulated, {motions} motion(s){rate}")


class RunProgress:
    """The progress of one run on `stream` (a text stream, standard error): a context manager
    around the run. `read` gives the run's ``(simulated s, motions started)`` (called from
    rich's refresh thread: it must only read); `limit_s` the run's simulated-time limit (s) or
    None. Nothing is shown, and nothing is started, when `stream` is not a terminal
    (``shown`` is then False)."""

    def __init__(self, stream: Any, read: Callable[[], tuple[float, int]], limit_s: float | None = None) -> None:
        self.stream, self.read, self.limit_s = stream, read, limit_s
        self.shown = progress_shown(stream)
        self._live: Progress | None = None
        self._wall0 = self._cpu0 = 0.0
        self._spent: tuple[float, float] | None = None     # (wall s, CPU s) of the run

    def __enter__(self) -> "RunProgress":
        self._wall0, self._cpu0 = time.perf_counter(), time.process_time()
        if self.shown:
            console = Console(file=self.stream, stderr=True)
            self._live = Progress(TextColumn("running"), _Figures(self.read, self.limit_s, self._wall0),
                                  TimeElapsedColumn(), console=console, transient=True,
                                  refresh_per_second=REFRESH_PER_S)
            self._live.add_task("run", total=None)
            self._live.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        self._spent = (time.perf_counter() - self._wall0, time.process_time() - self._cpu0)
        if self._live is not None:
            self._live.stop()           # transient: the line is erased
            self._live = None

    def done(self) -> None:
        """Write :func:`speed_line` of the run (the time spent inside the ``with``) on a terminal;
        call it after the summary, so that the line is the last one."""
        if self.shown and self._spent is not None:
            sim_s, _ = self.read()
            self.stream.write(speed_line(sim_s, *self._spent) + "\n")
            self.stream.flush()
