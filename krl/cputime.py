"""CPU time of a process tree, the one measure the benchmarks share (``krl.lsp.bench``,
``interp.debug.bench``, ``pendant.bench``).

The figure is user + system seconds (``psutil.Process.cpu_times``; Linux ``/proc/PID/stat``
utime, stime, cutime, cstime) of a process and of every live descendant, plus what their
children that already ended and were waited for used (cutime, cstime), so a worker that came
and went between two readings is still counted. A benchmark reads it twice and prints the
difference; it is never used to decide anything.
"""

from __future__ import annotations

import psutil


def tree_cpu_s(pid: int | None = None, *, name: str | None = None) -> float:
    """CPU seconds (user + system, ended children included) of process ``pid`` (default: this
    process) and its descendants; with ``name``, only of those whose process name contains it
    (case-insensitive; e.g. ``"chrom"``: Playwright's Chromium among this process's
    descendants). A process that is gone, or cannot be read, counts 0 (never an error): the
    tree changes while it is walked."""

    try:
        root = psutil.Process(pid)
        procs = [root, *root.children(recursive=True)]
    except psutil.Error:
        return 0.0
    total = 0.0
    for p in procs:
        try:
            if name is not None and name.lower() not in p.name().lower():
                continue
            t = p.cpu_times()
            total += t.user + t.system + t.children_user + t.children_system
        except psutil.Error:
            pass
    return total
