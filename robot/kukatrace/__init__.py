"""KUKA Trace recordings as a format of the project (issue 60): read, show, compare with a run.

A KR C4's KUKA Trace writes, per recording NAME, ``<prefix>_NAME_KRCIpo.csv`` (the interpolator's
12 ms samples: actual axes and TCP, torques, path speed) and ``<prefix>_NAME_PROG.TXT`` (the
controller's motion log: start, planned end and end of each motion, with its line, point, speeds,
frames and load). Modules:

* :mod:`robot.kukatrace.recording`: :func:`read_recording` reads the two files into a
  :class:`Recording` (the file formats and their traps: radians under a degree header, mm/s
  under an m/s header, Latin-1, a first row of garbage);
* :mod:`robot.kukatrace.model`: one view of a run of either kind, a recording or a simulated
  run's JSON Lines trace (robot/trace.py): its segments (TraceStart .. TraceStop), motions and
  samples; a recording's events in the project's trace model;
* :mod:`robot.kukatrace.compare`: ``krl trace compare RUN REC``: motions matched by program line
  and order within a segment; per motion and in total the motion time error, the exact-stop
  pause and the path deviation (text, JSON, plot);
* :mod:`robot.kukatrace.show`: ``krl trace show``: a recording's or run's motions, and a plot
  of the axes, the TCP path and its speed with the motion boundaries.

The binary ``.r64/.trc/.dat`` trace files are not read (their format is not documented
publicly; the public dataset of the project does not hold them). docs/trace.md describes the
commands.
"""
