"""The KRL natives ``INVERSE`` and ``FORWARD`` per call on the five-axis palletizer (issue 86 item 1):
the whole native path (the E6POS/E6AXIS/FRAME structures read, the frames to matrices, the
kinematics, the result back to an E6AXIS/E6POS), called as the interpreters call it, in
microseconds per call, with a digest of every result (components as reprs, STATUS) so that two
checkouts' answers can be compared bit for bit.

The calls: a ``Find_Optimal_ST``-style search of one E6POS (a TOOLPOS made by ``FORWARD`` in a
non-null $TOOL and $BASE) through ``INVERSE`` with each of 8 S x 64 T (most answer STATUS
"not reachable" or "soft limit"), and ``FORWARD`` of 300 drawn axis sets. The natives are called
with the run's ``NativeContext``; ``inverse_us`` is the search asked for the first time in the run
(a fresh INVERSE memo each round, interp/runtime/natives/invmemo.py, where the checkout has one),
``inverse_again_us`` the same search asked again (a palletizer's next pallet: the memo's answers). The robot is the
library's KR 180 R3200 PA5 (robot/data/kr180_r3200_pa5.dat).

Usage::

    python tools/native_geometry_bench.py [--against DIR] [--rounds N]

Each checkout runs in its own child process (``--against DIR``: also the checkout in DIR, e.g.
main's), interleaved round by round; the figure of each is its best round's, the ratios come
from the same run, and the digests must agree.
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

#: the child: one checkout's figures and digests, printed as one JSON line (argv: repo)
CHILD = r'''
import copy, hashlib, json, sys, tempfile, time
from pathlib import Path
sys.path.insert(0, sys.argv[1])
import numpy as np
from interp.run import RunSinks, make_runtime, run_spec
from interp.runtime.natives import geometry
from interp.runtime.natives.args import ValueRef
from interp.runtime.sysvars import axis_struct
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_mada
d = Path(tempfile.mkdtemp())
(d / "s.src").write_text("""DEF s()
  INT st
  $TOOL = {X 10, Y 20, Z 300, A 0, B 0, C 0}
  $BASE = {X 1000, Y 0, Z 0, A 30, B 0, C 0}
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  target = FORWARD({A1 -40, A2 -80, A3 100, A4 0, A5 30, A6 10}, st)
END
""")
(d / "s.dat").write_text("DEFDAT s\n  DECL E6POS target\nENDDAT\n")
rt, _ = make_runtime(run_spec(d / "s.src", max_sim_time=30.0, mujoco=False, check=False, interp="vm",
                              robot=load_mada(ROBOT_LIBRARY / "kr180_r3200_pa5.dat")), RunSinks())
from tests.interp.helpers import Run
target = Run(rt, rt.run(), None).var("s", "target")
class Out:
    v = None
    def set(self, v):
        self.v = v
start = axis_struct(rt.controller.actual.axis_act())
calls = []
for s in range(8):
    for t in range(64):
        p = copy.deepcopy(target)
        p.f["S"], p.f["T"] = s, t
        calls.append([ValueRef(p), ValueRef(start), Out()])
rng = np.random.default_rng(86)
fcalls = [[ValueRef(axis_struct(list(rng.uniform(-90.0, 90.0, 6)) + [0.0] * 6)), Out()] for _ in range(300)]
def digest(results):
    return hashlib.sha256(repr([(sorted((k, repr(v)) for k, v in r.f.items()), o.v) for r, o in results]).encode()).hexdigest()
ctx = getattr(rt, "natives", rt)    # the run's NativeContext (a checkout before it: the run)
def fresh():
    """A new run-owned INVERSE memo where the checkout has one (natives/invmemo.py): the search asked first."""
    if hasattr(ctx, "inverse_memo"):
        ctx.inverse_memo = type(ctx.inverse_memo)()
fresh()
inv = digest([(geometry._inverse(ctx, a), a[2]) for a in calls])
again = digest([(geometry._inverse(ctx, a), a[2]) for a in calls])
fwd = digest([(geometry._forward(ctx, a), a[1]) for a in fcalls])
def best(fn, args, first=False):
    b = 1e9
    for _ in range(5):
        if first:
            fresh()
        t0 = time.process_time()
        for a in args:
            fn(ctx, a)
        b = min(b, (time.process_time() - t0) / len(args))
    return round(b * 1e6, 2)
assert again == inv
print(json.dumps({"inverse_us": best(geometry._inverse, calls, True), "inverse_again_us": best(geometry._inverse, calls),
                  "forward_us": best(geometry._forward, fcalls),
                  "reachable": sum(1 for a in calls if a[2].v == 0), "inverse_digest": inv[:16], "forward_digest": fwd[:16]}))
'''


def child(repo: str) -> dict:
    """One checkout's figures (a child process that imports only `repo`'s files)."""
    env = dict(os.environ, PYTHONPATH=repo)
    res = subprocess.run([sys.executable, "-c", OTHER_CHECKOUT_PRELUDE + CHILD, repo],
                         capture_output=True, text=True, cwd=repo, env=env, check=False)
    if res.returncode != 0:
        raise SystemExit(f"the benchmark in {repo} failed:\n{res.stderr[-3000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python tools/native_geometry_bench.py")
    ap.add_argument("--against", metavar="DIR", help="also measure the checkout in DIR")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    runs = {"this": str(HERE)}
    if args.against:
        runs["against"] = os.path.abspath(args.against)
    got: dict[str, list[dict]] = {k: [] for k in runs}
    for _ in range(max(1, args.rounds)):
        for key, repo in runs.items():
            got[key].append(child(repo))
    for fig in ("inverse_us", "inverse_again_us", "forward_us"):
        vals = {k: min(r[fig] for r in rounds) for k, rounds in got.items()}
        line = f"{fig:<17}" + "".join(f"{k:>9} {v:>8}" for k, v in vals.items())
        if "against" in vals:
            line += f"   against/this {vals['against'] / vals['this']:.2f}x"
        print(line)
    for fig in ("reachable", "inverse_digest", "forward_digest"):
        vals = {k: rounds[0][fig] for k, rounds in got.items()}
        print(f"{fig:<16}" + "  ".join(f"{k} {v}" for k, v in vals.items())
              + ("   (the same)" if len(set(vals.values())) == 1 else "   (DIFFERENT)"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
