"""Differential fuzzing with hypothesis (issue 8): random, well-typed KRL programs.

The generator draws a program from a small typed grammar: INT/REAL/BOOL variables and an INT
array (all initialised first), assignments with arithmetic and comparisons, IF/ELSE, SWITCH
with value lists and DEFAULT, FOR (with STEP), WHILE/REPEAT/LOOP bounded by counters, EXIT,
forward GOTOs, calls of a procedure with :IN/:OUT parameters and of a function, $OUT writes
(with and without CONTINUE), PULSE, WAIT SEC, PTP/LIN/CIRC motions with C_PTP/C_DIS/C_VEL
approximation between reachable points near the start pose, TRIGGERs, an interrupt on an
input driven by generated stimuli, REAL<->INT conversions and statements that may fail at run
time (division by a variable, array index from a variable), sometimes after ON_ERROR_PROCEED.

Property:
* with the VM available: ``tree == vm`` (trace flow, I/O with times, motion/end events, TCP
  polyline) - :func:`conformance.harness.compare_runs`;
* until then: the tree interpreter runs the program without an internal error (exit code 2,
  an exception, a wall-clock timeout or a missing ``end`` event) - a smoke test.

A failure is shrunk by hypothesis to a minimal program, which is saved as a new case
``conformance/cases/9NN_fuzz_<hash>/`` (``expect.yaml`` with ``fuzz: true``; its
expectation is "runs cleanly, and tree == vm").
"""

from __future__ import annotations

import hashlib
import random
import tempfile
from pathlib import Path
from typing import Any

import yaml
from hypothesis import given, HealthCheck, Phase, seed, settings, strategies as st

from . import harness as H
from krl.pool import run_tasks

INT_VARS = ("a", "b", "c")
REAL_VARS = ("x", "y")
BOOL_VARS = ("f", "g")
# reachable Cartesian points around the start pose (flange down at (445, 0, 810))
POINTS = [(445, 0, 810), (485, 40, 790), (505, -30, 830), (465, 60, 770), (425, -50, 800),
          (525, 20, 780), (455, -70, 840)]
AXES = [(0, -90, 90, 0, 90, 0), (15, -85, 85, 5, 85, -10), (-20, -95, 95, -5, 95, 10),
        (10, -80, 95, 0, 80, 20)]

HEADER = """DEF program()
  DECL INT a, b, c, arr[5], i1, i2, i3, w1, w2, w3
  DECL REAL x, y
  DECL BOOL f, g
  BAS(#INITMOV, 0)
  $TOOL = $NULLFRAME
  $VEL.CP = 0.5
  $APO.CDIS = 15
  $APO.CPTP = 40
  $APO.CVEL = 60
  a = 1
  b = 2
  c = 3
  x = 0.5
  y = -1.5
  f = TRUE
  g = FALSE
  FOR i1 = 1 TO 5
    arr[i1] = i1
  ENDFOR
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}
"""

FOOTER = """END

DEF Sub1(p :IN, q :OUT)
  DECL INT p, q
  q = p * 2 - q
  IF q > 1000 THEN
    q = 7
  ENDIF
END

DEFFCT INT F1(v :IN)
  DECL INT v
  IF v < 0 THEN
    RETURN -v
  ENDIF
  RETURN v + 1
ENDFCT

DEF OnIn()
  irqs = irqs + 1
  $OUT[30] = NOT $OUT[30]
END

DEF Mark(k :IN)
  DECL INT k
  $OUT[20 + k] = TRUE
END
"""

DAT = """DEFDAT program
  DECL INT irqs=0
ENDDAT
"""


# ----------------------------------------------------------------------------- expressions
def int_atom():
    return st.one_of(st.integers(-9, 9).map(str), st.sampled_from(INT_VARS),
                     st.integers(1, 5).map(lambda k: f"arr[{k}]"))


def int_expr(depth: int = 2):
    if depth <= 0:
        return int_atom()
    sub = int_expr(depth - 1)
    return st.one_of(
        int_atom(),
        st.tuples(sub, st.sampled_from(["+", "-", "*"]), sub).map(lambda t: f"({t[0]} {t[1]} {t[2]})"),
        st.tuples(sub, st.integers(1, 7)).map(lambda t: f"({t[0]} / {t[1]})"),
        sub.map(lambda e: f"F1({e})"),
        st.tuples(sub, sub).map(lambda t: f"({t[0]} B_AND {t[1]})"),
    )


def real_expr(depth: int = 2):
    atom = st.one_of(st.sampled_from(["0.5", "1.25", "-2.0", "3.0"]), st.sampled_from(REAL_VARS),
                     st.sampled_from(INT_VARS))
    if depth <= 0:
        return atom
    sub = real_expr(depth - 1)
    return st.one_of(atom,
                     st.tuples(sub, st.sampled_from(["+", "-", "*"]), sub).map(lambda t: f"({t[0]} {t[1]} {t[2]})"),
                     sub.map(lambda e: f"ABS({e})"), sub.map(lambda e: f"SIN({e} * 10)"))


def bool_expr(depth: int = 2):
    atom = st.one_of(st.sampled_from(BOOL_VARS + ("TRUE", "FALSE")),
                     st.tuples(int_expr(1), st.sampled_from(["==", "<>", "<", ">", "<=", ">="]), int_expr(1))
                     .map(lambda t: f"({t[0]} {t[1]} {t[2]})"),
                     st.tuples(real_expr(1), st.sampled_from(["<", ">"]), real_expr(1))
                     .map(lambda t: f"({t[0]} {t[1]} {t[2]})"))
    if depth <= 0:
        return atom
    sub = bool_expr(depth - 1)
    return st.one_of(atom, sub.map(lambda e: f"NOT {e}" if not e.startswith("NOT") else f"NOT ({e})"),
                     st.tuples(sub, st.sampled_from(["AND", "OR", "EXOR"]), sub)
                     .map(lambda t: f"({t[0]} {t[1]} {t[2]})"))


def _pt(p):
    return f"{{X {p[0]}, Y {p[1]}, Z {p[2]}, A 180, B 0, C 180}}"


def _ax(q):
    return "{" + ", ".join(f"A{i + 1} {v}" for i, v in enumerate(q)) + "}"


# ----------------------------------------------------------------------------- statements
@st.composite
def statement(draw, depth: int, ctx: dict[str, Any]):
    kinds = ["assign_int", "assign_real", "assign_bool", "assign_arr", "out", "call", "motion",
             "motion", "wait", "trigger", "convert", "risky"]
    if depth > 0:
        kinds += ["if", "switch", "for", "while", "repeat", "loop", "goto"]
    k = draw(st.sampled_from(kinds))
    ind = "  " * (ctx["level"] + 1)
    if k == "assign_int":
        return [f"{ind}{draw(st.sampled_from(INT_VARS))} = {draw(int_expr())}"]
    if k == "assign_real":
        return [f"{ind}{draw(st.sampled_from(REAL_VARS))} = {draw(real_expr())}"]
    if k == "assign_bool":
        return [f"{ind}{draw(st.sampled_from(BOOL_VARS))} = {draw(bool_expr())}"]
    if k == "convert":  # REAL -> INT (rounding), INT -> REAL
        if draw(st.booleans()):
            return [f"{ind}{draw(st.sampled_from(INT_VARS))} = {draw(real_expr(1))}"]
        return [f"{ind}{draw(st.sampled_from(REAL_VARS))} = {draw(int_expr(1))} / 4"]
    if k == "risky":  # may raise a run-time error (division by zero, index out of range)
        v = draw(st.sampled_from(INT_VARS))
        stmt = draw(st.sampled_from([f"{v} = {draw(int_expr(1))} / {draw(st.sampled_from(INT_VARS))}",
                                     f"{v} = arr[{draw(st.sampled_from(INT_VARS))}]",
                                     f"arr[{draw(st.sampled_from(INT_VARS))}] = {draw(int_expr(1))}"]))
        if draw(st.booleans()):
            return [f"{ind}ON_ERROR_PROCEED", f"{ind}{stmt}"]
        return [f"{ind}{stmt}"]
    if k == "assign_arr":
        return [f"{ind}arr[{draw(st.integers(1, 5))}] = {draw(int_expr(1))}"]
    if k == "out":
        n = draw(st.integers(1, 8))
        v = draw(bool_expr(1))
        form = draw(st.sampled_from(["plain", "continue", "pulse"]))
        if form == "continue":
            return [f"{ind}CONTINUE", f"{ind}$OUT[{n}] = {v}"]
        if form == "pulse":
            return [f"{ind}PULSE($OUT[{n}], TRUE, {draw(st.sampled_from(['0.05', '0.1', '0.3']))})"]
        return [f"{ind}$OUT[{n}] = {v}"]
    if k == "call":
        if draw(st.booleans()):
            return [f"{ind}Sub1({draw(int_expr(1))}, {draw(st.sampled_from(INT_VARS))})"]
        return [f"{ind}{draw(st.sampled_from(INT_VARS))} = F1({draw(int_expr(1))})"]
    if k == "motion":
        ctx["motions"] += 1
        kind = draw(st.sampled_from(["PTP_AX", "PTP", "LIN", "LIN", "CIRC"]))
        approx = draw(st.sampled_from(["", "", " C_DIS", " C_PTP", " C_VEL"]))
        if kind == "PTP_AX":
            return [f"{ind}PTP {_ax(draw(st.sampled_from(AXES)))}{approx}"]
        p = draw(st.sampled_from(POINTS))
        if kind == "PTP":
            return [f"{ind}PTP {_pt(p)}{approx}"]
        if kind == "LIN":
            return [f"{ind}LIN {_pt(p)}{approx if approx != ' C_PTP' else ' C_DIS'}"]
        aux = draw(st.sampled_from([q for q in POINTS if q != p]))
        end = draw(st.sampled_from([q for q in POINTS if q not in (p, aux)]))
        # a CIRC starts where the previous motion ended: make that p first
        return [f"{ind}LIN {_pt(p)}", f"{ind}CIRC {_pt(aux)}, {_pt(end)}{approx if approx != ' C_PTP' else ''}"]
    if k == "wait":
        return [f"{ind}WAIT SEC {draw(st.sampled_from(['0', '0.012', '0.05', '0.2']))}"]
    if k == "trigger":
        ctx["motions"] += 1
        p = draw(st.sampled_from(POINTS))
        trig = draw(st.sampled_from([
            "TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT[11]=TRUE",
            "TRIGGER WHEN DISTANCE=1 DELAY=-20 DO $OUT[12]=NOT $OUT[12]",
            "TRIGGER WHEN PATH=-5 DELAY=0 DO Mark(3) PRIO=-1",
            "TRIGGER WHEN DISTANCE=1 DELAY=0 DO PULSE($OUT[13], TRUE, 0.05)"]))
        return [f"{ind}{trig}", f"{ind}LIN {_pt(p)}"]
    # compound statements
    ctx["level"] += 1
    try:
        body = draw(block(depth - 1, ctx))
        if k == "if":
            cond = draw(bool_expr())
            out = [f"{ind}IF {cond} THEN", *body]
            if draw(st.booleans()):
                out += [f"{ind}ELSE", *draw(block(depth - 1, ctx))]
            return out + [f"{ind}ENDIF"]
        if k == "switch":
            vals = draw(st.lists(st.integers(-3, 6), min_size=1, max_size=4, unique=True))
            out = [f"{ind}SWITCH {draw(int_expr(1))}"]
            first = True
            rest = list(vals)
            while rest:
                take = rest[:draw(st.integers(1, len(rest)))]
                rest = rest[len(take):]
                out += [f"{ind}  CASE {', '.join(map(str, take))}", *(body if first else draw(block(depth - 1, ctx)))]
                first = False
            if draw(st.booleans()):
                out += [f"{ind}  DEFAULT", *draw(block(depth - 1, ctx))]
            return out + [f"{ind}ENDSWITCH"]
        lv = ctx["level"]
        cnt = f"i{min(lv, 3)}" if k == "for" else f"w{min(lv, 3)}"
        if k == "for":
            lo, hi = draw(st.integers(-2, 3)), draw(st.integers(-2, 4))
            step = draw(st.sampled_from(["", " STEP 2", " STEP -1", " STEP -2"]))
            if step.strip().startswith("STEP -"):
                lo, hi = hi, lo
            return [f"{ind}FOR {cnt} = {lo} TO {hi}{step}", *body, f"{ind}ENDFOR"]
        n = draw(st.integers(0, 3))
        if k == "while":
            return [f"{ind}{cnt} = 0", f"{ind}WHILE ({cnt} < {n}) AND (a > -100000)",
                    f"{ind}  {cnt} = {cnt} + 1", *body, f"{ind}ENDWHILE"]
        if k == "repeat":
            return [f"{ind}{cnt} = 0", f"{ind}REPEAT", f"{ind}  {cnt} = {cnt} + 1", *body,
                    f"{ind}UNTIL {cnt} >= {n}"]
        if k == "loop":
            return [f"{ind}{cnt} = 0", f"{ind}LOOP", f"{ind}  {cnt} = {cnt} + 1",
                    f"{ind}  IF {cnt} > {n} THEN", f"{ind}    EXIT", f"{ind}  ENDIF", *body, f"{ind}ENDLOOP"]
        if k == "goto":
            ctx["labels"] += 1
            lab = f"skip{ctx['labels']}"
            return [f"{ind}IF {draw(bool_expr(1))} THEN", f"{ind}  GOTO {lab}", f"{ind}ENDIF", *body, f"{lab}:"]
        raise AssertionError(k)
    finally:
        ctx["level"] -= 1


@st.composite
def block(draw, depth: int, ctx: dict[str, Any]):
    n = draw(st.integers(1, 3))
    out: list[str] = []
    for _ in range(n):
        out += draw(statement(depth, ctx))
    return out


@st.composite
def programs(draw, max_depth: int = 2):
    """(program.src text, stimuli yaml text or None)."""
    ctx = {"level": 0, "motions": 0, "labels": 0}
    lines: list[str] = []
    use_irq = draw(st.booleans())
    if use_irq:
        lines += ["  INTERRUPT DECL 12 WHEN $IN[5] DO OnIn()", "  INTERRUPT ON 12"]
    for _ in range(draw(st.integers(1, 5))):
        lines += draw(statement(max_depth, ctx))
    src = HEADER + "\n".join(lines) + "\n" + FOOTER
    stim = None
    if use_irq:
        times = sorted(draw(st.lists(st.sampled_from([0.05, 0.1, 0.2, 0.35, 0.5, 0.8]), min_size=1, max_size=4,
                                     unique=True)))
        items = [{"at": t, "set": {"$IN[5]": i % 2 == 0}} for i, t in enumerate(times)]
        stim = yaml.safe_dump({"stimuli": items}, sort_keys=False)
    return src, stim


# ----------------------------------------------------------------------------- running
def run_text(src: str, stim: str | None, interp: str | list[str], *,
             max_sim_time: float = 20.0) -> H.RunResult | dict[str, H.RunResult]:
    """Run the program on one interpreter (a RunResult) or on several, in the same folder
    (a dict interp -> RunResult)."""
    many = not isinstance(interp, str)
    with tempfile.TemporaryDirectory(prefix="krl-fuzz-") as tmp:
        d = Path(tmp)
        (d / "program.src").write_text(src, encoding="utf-8")
        (d / "program.dat").write_text(DAT, encoding="utf-8")
        stim_path = None
        if stim:
            stim_path = d / "stimuli.yaml"
            stim_path.write_text(stim, encoding="utf-8")
        out = {it: H.run_program(d / "program.src", it, stimuli=stim_path, workspace=d,
                                 max_sim_time=max_sim_time, max_steps=200_000, wall_timeout=60.0)
               for it in ([interp] if not many else interp)}
    return out if many else out[interp]


clean_run_problem = H.clean_run_problem


def _check_program(src: str, stim: str | None, interps: list[str]) -> str | None:
    """None if the program passes the fuzz property, else a description."""
    runs = run_text(src, stim, list(interps))
    for it, r in runs.items():
        prob = clean_run_problem(r)
        if prob:
            return f"{it}: {prob}"
    if "tree" in runs and "vm" in runs:
        bad = [c for c in H.compare_runs(runs["tree"], runs["vm"]) if not c.ok]
        if bad:
            return "tree != vm\n" + "\n".join(f"[{c.name}] {c.detail}" for c in bad)
    return None


#: the fuzz property's check of one program (run_fuzz's property calls a local of this name)
check_program = _check_program


def save_case(src: str, stim: str | None, problem: str, root: Path = H.CASES_DIR) -> Path:
    """Save a (shrunk) failing program as a new case directory."""
    h = hashlib.sha1((src + (stim or "")).encode()).hexdigest()[:8]
    existing = [p.name for p in root.iterdir() if p.name[:3].isdigit() and p.name.startswith("9")]
    nums = [int(p[:3]) for p in existing] or [899]
    d = root / f"{max(nums) + 1:03d}_fuzz_{h}"
    if any(p.endswith(h) for p in existing):
        return root / next(p for p in existing if p.endswith(h))
    d.mkdir(parents=True)
    (d / "program.src").write_text(src, encoding="utf-8")
    (d / "program.dat").write_text(DAT, encoding="utf-8")
    if stim:
        (d / "stimuli.yaml").write_text(stim, encoding="utf-8")
    first = problem.splitlines()[0][:300].replace('"', "'")
    (d / "expect.yaml").write_text(
        "title: minimal program found by the differential fuzzer (conformance/fuzz.py)\n"
        "fuzz: true\nmax_sim_time: 20\n"
        "covers: [fuzz]\n"
        f"status: pending\nreason: \"found by fuzzing: {first}\"\n", encoding="utf-8")
    return d


def run_fuzz(n: int = 200, *, reproducible: bool = True, interps: list[str] | None = None,
             save_failures: Path | None = None, save_cases: bool = True, jobs: int = 1) -> dict[str, Any]:
    """Run ``n`` generated programs (the same ones every time with ``reproducible``; fresh
    ones otherwise, as in the nightly run). Returns ``{"programs", "mode", "tree_ok", "agree",
    "failures": [...], "saved": [...]}``; ``programs`` counts every run of the property,
    including hypothesis' shrinking runs after a failure.

    `jobs` > 1: the programs run in that many worker processes of this machine (krl/pool.py),
    with the same result as one after the other: hypothesis first draws the ``n`` programs (a
    property that only records them), the workers check them all, then hypothesis runs the
    property again over the same draws, taking each verdict from the workers' results; a
    failure is shrunk as before, in this process (the shrunk programs are new draws)."""
    interps = H.available_interpreters() if interps is None else interps
    mode = "tree == vm" if ("tree" in interps and "vm" in interps) else (
        "tree smoke test (no VM): runs without internal errors" if "tree" in interps else "no interpreter")
    stats = {"programs": 0, "tree_ok": 0, "agree": 0 if "vm" in interps else None, "mode": mode,
             "failures": [], "saved": []}
    if not interps:
        return stats
    last: dict[str, Any] = {}
    # the property below calls this name, not the module's function: with workers, the first
    # pass records the draws and the second answers from the workers' verdicts. The property's
    # source stays as it was, because with `reproducible` hypothesis seeds its draws from it.
    verdicts: dict[tuple[str, str | None], str | None] = {}
    drawn: list[tuple[str, str | None]] = []
    recording = False

    def check_program(src: str, stim: str | None, interps: list[str]) -> str | None:
        if recording:
            drawn.append((src, stim))
            return None
        if (src, stim) in verdicts:
            return verdicts[(src, stim)]
        return _check_program(src, stim, interps)

    # report_multiple_bugs=False: after the first failure hypothesis goes straight to shrinking it.
    # With its default it goes on drawing for up to 10 s of wall time, so how many programs
    # ran depended on the machine's load (74 against 71 in one run under load 20), and two
    # failures would end in an exception group, not the AssertionError caught below.
    @settings(max_examples=n, deadline=None, database=None, derandomize=reproducible,
              report_multiple_bugs=False, suppress_health_check=list(HealthCheck),
              phases=[Phase.generate, Phase.shrink] if n > 0 else [Phase.generate])
    @given(programs())
    def prop(prog):
        src, stim = prog
        stats["programs"] += 1
        prob = check_program(src, stim, interps)
        if prob is None:
            stats["tree_ok"] += 1
            if stats["agree"] is not None:
                stats["agree"] += 1
            return
        if prob.startswith("tree != vm") and stats["agree"] is not None:
            stats["tree_ok"] += 1
        last["src"], last["stim"], last["problem"] = src, stim, prob
        raise AssertionError(prob)

    if not reproducible:
        # fresh programs, but the same fresh ones in both passes
        prop = seed(random.getrandbits(64))(prop)
    if jobs > 1:
        recording = True
        prop()
        recording = False
        stats.update(programs=0, tree_ok=0, agree=0 if "vm" in interps else None)

        order = list(dict.fromkeys(drawn))
        tasks = ((i, (src, stim, interps)) for i, (src, stim) in enumerate(order))
        # no pool timeout: each run has its own wall-clock guard (harness.run_program)
        for o in run_tasks(_check_program, tasks, jobs=jobs, timeout=None):
            # a worker that died checked nothing: that program is checked again here
            if o.status == "done":
                verdicts[order[o.key]] = o.value
    try:
        prop()
    except AssertionError:
        # hypothesis re-raises with the shrunk example last: `last` holds the minimal program
        stats["failures"].append(f"{last.get('problem')}\n--- minimal program ---\n{last.get('src')}")
        if save_cases and last.get("src"):
            stats["saved"].append(str(save_case(last["src"], last.get("stim"), last["problem"])))
        if save_failures is not None:
            save_failures.mkdir(parents=True, exist_ok=True)
            (save_failures / "minimal.src").write_text(last["src"], encoding="utf-8")
    return stats


__all__ = ["programs", "run_fuzz", "check_program", "run_text", "save_case", "clean_run_problem"]
