"""The 4-axis palletizer solutions (robot/kinematics/pal4rows.py, compiled where built) against
the selection through numpy's forward kinematics on the corpus programs (issue 39, "Real
programs"): every call of robot/kinematics/palletizer4.py ``Palletizer4.solutions`` in the runs is
answered by both (``Palletizer4.numpy_rows``), and the rows must be the same bytes.

pal4rows.py keeps a row when its own forward kinematics (Rodrigues' formula per joint) puts the
flange within 1e-6 mm of the target; ``numpy_rows`` asks ``Kinematics.forward`` (numpy and
scipy). The two forwards may differ in the last bits, so the test could only part where a
candidate's flange error is near 1e-6 mm. For every candidate row the Python code tests, this
prints the accepted rows' largest error, the rejected rows' smallest, the error nearest to 1e-6
(its distance from 1e-6 is the margin) and the largest difference between the two forwards'
positions: where the margin exceeds that difference, no candidate lies where the two could part.

Usage::

    python tools/palletizer_rows_check.py [CORPUS_OR_BACKUP ...]   (default: ../shared/krl-corpus)

Each entry point runs as the real-programs report runs it with its cell file (VM); robots other
than the 4-axis palletizer are not touched. Exit status 0 when the rows agree on every call,
1 otherwise.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from interp import realprograms as rp
from robot.kinematics import Kinematics
from robot.kinematics.palletizer4 import Palletizer4

_orig_rows = Palletizer4.solutions
_orig_forward = Kinematics.forward
stats = {"calls": 0, "differ": 0, "accepted": 0, "rejected": 0,
         "acc_err": 0.0, "rej_err": math.inf, "fk_diff": 0.0, "margin": math.inf}
_target: list = []   # (p, compiled) of the Python call being checked


def _forward(self, axes_deg):
    T = _orig_forward(self, axes_deg)
    if _target:
        p, c = _target[-1]
        e_np = float(np.abs(T[:3, 3] - p).max())
        cp = np.array(c.flange_position(np.asarray(axes_deg, dtype=float).tolist()))
        e_c = float(np.abs(cp - p).max())
        stats["fk_diff"] = max(stats["fk_diff"], float(np.abs(cp - T[:3, 3]).max()))
        for e in (e_np, e_c):
            stats["margin"] = min(stats["margin"], abs(e - 1e-6))
            if e < 1e-6:
                stats["acc_err"] = max(stats["acc_err"], e)
            else:
                stats["rej_err"] = min(stats["rej_err"], e)
        stats["accepted" if e_np < 1e-6 else "rejected"] += 1
    return T


def _rows(self, flange_T, ref_deg):
    got = _orig_rows(self, flange_T, ref_deg)
    _target.append((np.asarray(flange_T, dtype=float)[:3, 3].copy(), self._rows))
    try:
        want = self.numpy_rows(flange_T, ref_deg)
    finally:
        _target.pop()
    stats["calls"] += 1
    if len(got) != len(want) or np.array(got).tobytes() != np.array(want).tobytes():
        stats["differ"] += 1
    return got


def main(argv: list[str]) -> int:
    roots = [Path(a) for a in argv] or [rp.DEFAULT_CORPUS]
    Palletizer4.solutions = _rows
    Kinematics.forward = _forward
    for root in roots:
        corpus = rp.DEFAULT_CORPUS if root.resolve().is_relative_to(rp.DEFAULT_CORPUS.resolve()) else root
        for backup in rp.find_backups(root):
            for path in rp.entries_of(backup):
                before = stats["calls"]
                row = rp.run_one(path, rp.REPORT_SIM_TIME_S, rp.REPORT_STEPS, rp.cell_of(path, corpus), False, "vm")
                if stats["calls"] > before:
                    print(f"{stats['calls'] - before:7d} calls  {row['cause']:<16} {path}")
    s = stats
    print(f"calls {s['calls']}, rows differing {s['differ']}; candidate rows accepted {s['accepted']}, "
          f"rejected {s['rejected']}")
    print(f"largest error of an accepted row {s['acc_err']:.3g} mm, smallest of a rejected row {s['rej_err']:.3g} mm")
    print(f"margin (nearest error's distance from 1e-6 mm) {s['margin']:.3g} mm; largest difference "
          f"between the two forward kinematics {s['fk_diff']:.3g} mm")
    return 1 if s["differ"] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
