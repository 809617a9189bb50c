"""The kinematic families' ``INVERSE`` and ``FORWARD`` per call (issue 86 item 1): for a robot of
each family, ``Kinematics.inverse`` with the pose's own S and T (as a taught point asks it),
``Kinematics.inverse`` of a ``Find_Optimal_ST``-style search (the eight statuses and eight turns
of a pose, as the KR 470 PA-2's program tries them through ``INVERSE``) and ``Kinematics.forward``
(the memo bypassed), in microseconds per call; a PTP motion's path-length table (robot/segments.py
``JointSegment``: 65 TCP points, its C_DIS zone's and path triggers' lengths) in microseconds per
table; an external kinematic's ``ETn(E)`` (robot/external.py: the KR 16-2 track's ``$ROBROOT_C``,
the turntable's chain) in microseconds per call.

Usage::

    python tools/kinematics_bench.py [--against DIR] [--rounds N] [--calls N]

Without ``--against``: this checkout, compiled (where built) and as Python
(``robot.kinematics.compiled.USE_COMPILED`` off; ``--no-python`` leaves it out), each in a child
process, interleaved round by round. With ``--against DIR``: also the checkout in DIR (e.g. main's), compiled, in alternation.
The figure of each is the best round's (the least disturbed by the machine's load); the ratios
come from the same run. The robots: the library's (robot/data) and, for the seven-axis arm, the
LBR iiwa of ../shared/robots/descriptions (left out when it is not there).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

from krl.cbuild import OTHER_CHECKOUT_PRELUDE

HERE = Path(__file__).resolve().parents[1]
#: family -> robot (robot/mada.py ``load_robot`` name or path); the numeric family's is made below
ROBOTS = {"opw": "kr16_2_krc2", "palletizer4": "kr180_r3200_pa", "palletizer5": "kr180_r3200_pa5",
          "scara": "kr6_r500_z200", "numeric": "numeric", "redundant": str(
              HERE.parent / "shared" / "robots" / "descriptions" / "kuka_experimental" / "kuka_lbr_iiwa_support"
              / "urdf" / "lbr_iiwa_14_r820.urdf")}

#: the child: one checkout's figures, printed as one JSON line (argv: repo, calls, compiled 0/1)
CHILD = r'''
import json, math, os, sys, tempfile, time
sys.path.insert(0, sys.argv[1])
import numpy as np
from robot.kinematics import compiled
compiled.USE_COMPILED = sys.argv[3] == "1"
from robot.errors import RobotError
from robot.kinematics import Kinematics
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_robot
from robot.controller import Controller
from robot.motion import MotionParams, MotionRequest
from robot.robotmodel import RobotModel
robots = json.loads(sys.argv[4])
calls = int(sys.argv[2])
out = {}


def ptp_table(m, home, n):
    """A PTP motion's path-length table (robot/segments.py ``JointSegment._table``: 65 TCP
    points), made afresh: seconds per table."""
    ctl = Controller(m, mujoco=False)
    keys = [f"A{i + 1}" for i in range(n)] if n == 6 else list(ctl.model.axes.robot_keys)
    target = home + np.where(np.arange(n) < 3, 20.0, 10.0)
    if m.a4fix:
        target[3] = home[3]
    if m.a5link:
        target[4] = home[4] + home[1] + home[2] - target[1] - target[2]
    ctl.queue.enqueue(MotionRequest("PTP", dict(zip(keys, target.tolist())), MotionParams()))
    seg = ctl.queue.pending[-1]
    reps = max(1, calls // 64)
    t0 = time.process_time()
    for _ in range(reps):
        seg._len_table = None
        seg._table()
    return (time.process_time() - t0) / reps
for fam, name in robots.items():
    if name == "numeric":
        text = (ROBOT_LIBRARY / "kr16_2_krc2.dat").read_text(encoding="utf-8")
        d = tempfile.mkdtemp()
        name = os.path.join(d, "$machine.dat")
        with open(name, "w", encoding="utf-8") as f:
            f.write(text.replace("$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 0.0,B 90.0000",
                                 "$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 20.0,B 90.0000"))
    elif name.endswith(".urdf") and not os.path.exists(name):
        continue
    m = load_robot(name)
    k = Kinematics(m)
    n = k.n_axes
    few = fam in ("numeric", "redundant")
    rng = np.random.default_rng(86)
    home = np.array(m.home_deg, dtype=float)[:n]
    poses = []
    while len(poses) < (8 if few else 64):
        q = np.clip(home + rng.uniform(-40.0, 40.0, n), k._lo, k._hi)
        if m.a4fix:
            q[3] = 0.0
        if m.a5link:
            q[4] = home[4] + home[1] + home[2] - q[1] - q[2]
        s, t = k.status_turn(q)
        T = k.forward(q)
        try:
            k.inverse(T, s, t, q)
        except RobotError:
            continue
        poses.append((T, s, t, q))
    reps = max(1, (calls // 8 if few else calls) // len(poses))
    k.inverse(poses[0][0], poses[0][1], poses[0][2], poses[0][3])
    t0 = time.process_time()
    for _ in range(reps):
        for T, s, t, q in poses:
            k.inverse(T, s, t, q)
    inv = (time.process_time() - t0) / (reps * len(poses))
    # Find_Optimal_ST: every S (8) and T (8 of 64) through INVERSE, errors included
    st = [(s_, t_) for s_ in range(8) for t_ in range(0, 64, 8)]
    picks = poses[:2] if few else poses[:8]
    t0 = time.process_time()
    for T, _, _, q in picks:
        for s_, t_ in st:
            try:
                k.inverse(T, s_, t_, q)
            except RobotError:
                pass
    search = (time.process_time() - t0) / (len(picks) * len(st))
    fk = k.impl.forward
    t0 = time.process_time()
    for _ in range(reps):
        for T, s, t, q in poses:
            fk(q)
    fwd = (time.process_time() - t0) / (reps * len(poses))
    out[fam] = {"inverse_us": round(inv * 1e6, 1), "st_search_us": round(search * 1e6, 1),
                "forward_us": round(fwd * 1e6, 1), "ptp_table_us": round(ptp_table(m, home, n) * 1e6, 1)}
for label, name in (("track", "kr16_2_kl1500"), ("turntable", "kr16_2_turntable")):
    ext = RobotModel(load_robot(name)).ext
    kin = ext.robroot_kin or next(iter(ext.base_kins.values()))
    es = [np.array([v]) for v in np.random.default_rng(86).uniform(-100.0, 100.0, 64)]
    reps = max(1, calls // 64)
    t0 = time.process_time()
    for _ in range(reps):
        for e in es:
            ext.chain(kin, e)
    out[label] = {"ETn_us": round((time.process_time() - t0) / (reps * 64) * 1e6, 1)}
print(json.dumps(out))
'''


def child(repo: str, calls: int, compiled: bool) -> dict:
    """One checkout's figures (a child process that imports only `repo`'s files)."""
    env = dict(os.environ, PYTHONPATH=repo)
    res = subprocess.run([sys.executable, "-c", OTHER_CHECKOUT_PRELUDE + CHILD, repo, str(calls),
                          "1" if compiled else "0", json.dumps(ROBOTS)],
                         capture_output=True, text=True, cwd=repo, env=env, check=False)
    if res.returncode != 0:
        raise SystemExit(f"the benchmark in {repo} failed:\n{res.stderr[-3000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python tools/kinematics_bench.py")
    ap.add_argument("--against", metavar="DIR", help="also measure the checkout in DIR (compiled)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--calls", type=int, default=2048, help="inverse calls per family and round")
    ap.add_argument("--no-python", action="store_true", help="leave out this checkout as Python")
    args = ap.parse_args(argv)
    runs = {"this": (str(HERE), True)}
    if not args.no_python:
        runs["python"] = (str(HERE), False)
    if args.against:
        runs["against"] = (os.path.abspath(args.against), True)
    got: dict[str, list[dict]] = {k: [] for k in runs}
    for _ in range(max(1, args.rounds)):
        for key, (repo, comp) in runs.items():
            got[key].append(child(repo, args.calls, comp))
    best = {key: {fam: {m: min(r[fam][m] for r in rounds if fam in r) for m in rounds[0][fam]}
                  for fam in rounds[0]} for key, rounds in got.items()}
    print(f"{'family':<12} {'figure':<13}" + "".join(f"{k:>12}" for k in runs)
          + "".join(f"  {k}/this" for k in runs if k != "this"))
    for fam in best["this"]:
        for m in best["this"][fam]:
            vals = [best[k].get(fam, {}).get(m) for k in runs]
            line = f"{fam:<12} {m:<13}" + "".join(f"{v:>12}" if v is not None else f"{'-':>12}" for v in vals)
            ratios = [v / best["this"][fam][m] for v in vals[1:] if v is not None and best["this"][fam][m] > 0]
            print(line + "".join(f"{r:>13.1f}x" for r in ratios))
    print(json.dumps(best))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
