"""Run the conformance suites and write ``reports/conformance/`` (issue 8).

* the hand-written cases (``conformance/cases``) on every available interpreter, each against
  its expectations, and tree vs VM when both exist;
* the differential fuzzer (``conformance/fuzz.py``);
* the runnable programs of the KRC backups in ``../shared/krl-corpus`` (tree vs VM).

Outputs: ``summary.json`` (``cases, passed, tree_vm_agree, fuzz_programs, fuzz_agree,
real_programs, real_agree`` plus explanatory keys, ``case_status`` case -> pass/pending/FAIL and
``real_status`` program -> how the tree run ended, which the nightly history compares), ``report.md``, ``report.html`` (jinja2) and
one PNG per case with motion (programmed points, approximation zones, the interpreters' TCP
paths; matplotlib Agg). Without a VM the agreement fields are ``null`` and ``vm`` says why.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from krl.durable import write_text
from krl.files import SHARED_CORPUS as DEFAULT_CORPUS
from interp import realprograms as R
from krl.cluster import run_batches
from krl.render import markdown_code as md, render_html

from . import fuzz as F, harness as H
import matplotlib
import matplotlib.pyplot as plt
from matplotlib.patches import Circle
from krl.pool import run_tasks

REPO = H.REPO


# ============================================================================ cases
@dataclass
class CaseOutcome:
    case: H.Case
    results: dict[str, H.CaseResult] = field(default_factory=dict)
    runs: dict[str, H.RunResult] = field(default_factory=dict)
    tree_vm: list[H.Check] | None = None
    plot: str | None = None

    @property
    def passed(self) -> bool:
        return bool(self.results) and all(r.passed for r in self.results.values())

    @property
    def agree(self) -> bool | None:
        if self.tree_vm is None:
            return None
        return all(c.ok for c in self.tree_vm)

    @property
    def ok_or_pending(self) -> bool:
        """Every interpreter passes or is marked pending for this case, and tree == vm (or the
        VM is marked pending)."""
        for it, r in self.results.items():
            if not r.passed and self.case.pending_for(it) is None:
                return False
        return self.agree is not False or self.case.pending_for("vm") is not None


def case_outcome(case: H.Case, interps: list[str]) -> CaseOutcome:
    """One case run and checked on each of `interps`, and the interpreters compared."""
    co = CaseOutcome(case)
    for it in interps:
        res = H.run_case(case, it)
        co.runs[it] = res
        co.results[it] = H.check_case(case, res)
    if "tree" in co.runs and "vm" in co.runs:
        co.tree_vm = H.compare_runs(co.runs["tree"], co.runs["vm"])
    return co


def _elsewhere(fn, tasks: list[tuple[int, tuple]], name: str, progress, failed, *,
               scheduler: str | None = None, jobs: int = 1, group=None) -> list:
    """``fn(*args)`` of each task in `jobs` worker processes of this machine (krl/pool.py), or,
    with `scheduler`, on that Dask cluster (krl/cluster.py); the results in the tasks' order,
    `progress(result)` as each arrives (in completion order). A task whose worker fails (it
    died, or the cluster lost it: not a failure of the interpreters, which the results hold
    themselves) is ``failed(*args, detail)``, a result that says so. Each task is independent
    (a fresh runtime per run), so the results are those of a run one after the other. Raises
    krl.cluster.SchedulerError."""

    if scheduler is not None:
        outcomes = run_batches(scheduler, fn, tasks, batch_files=1, name=name)
        where = "on the Dask cluster"
    else:

        # no pool timeout: each run has its own wall-clock guard (harness.run_program)
        outcomes = run_tasks(fn, tasks, jobs=jobs, timeout=None, group=group)
        where = "in its worker process"
    got = {}
    for o in outcomes:
        got[o.key] = o.value if o.status == "done" else failed(*tasks[o.key][1], f"{where}: {o.status}: {o.detail}")
        if progress:
            progress(got[o.key])
    return [got[i] for i in range(len(tasks))]


def _case_failed(case: H.Case, interps: list[str], detail: str) -> CaseOutcome:
    co = CaseOutcome(case)
    for it in interps:
        co.runs[it] = H.RunResult(it, [], None, crash=detail)
        co.results[it] = H.check_case(case, co.runs[it])
    return co


def _real_failed(prog: Path, corpus: Path, interps: list[str], _t: float, _steps: int, detail: str) -> RealOutcome:
    ro = RealOutcome(str(prog.relative_to(corpus)) if prog.is_relative_to(corpus) else str(prog))
    ro.crash = {it: detail[:300] for it in interps}
    ro.reasons = {it: "crash" for it in interps}
    ro.cause = "interpreter gap"
    return ro


def run_cases(cases: list[H.Case] | None = None, interps: list[str] | None = None,
              *, progress=None, scheduler: str | None = None, jobs: int = 1) -> list[CaseOutcome]:
    """:func:`case_outcome` of every case (default the whole suite), in this process (`jobs`
    1), in `jobs` worker processes of this machine, or, with `scheduler`
    (``tcp://HOST:8786``), on that Dask cluster's workers: the same outcomes."""
    cases = H.load_cases() if cases is None else cases
    interps = H.available_interpreters() if interps is None else interps
    if scheduler is not None or jobs > 1:
        return _elsewhere(case_outcome, [(i, (c, interps)) for i, c in enumerate(cases)],
                          "krl-conformance-cases", progress, _case_failed, scheduler=scheduler, jobs=jobs)
    out = []
    for case in cases:
        out.append(case_outcome(case, interps))
        if progress:
            progress(out[-1])
    return out


# ============================================================================ real programs
@dataclass
class RealOutcome:
    program: str
    reasons: dict[str, str] = field(default_factory=dict)   # interp -> end reason / crash
    crash: dict[str, str] = field(default_factory=dict)
    tree_vm: list[H.Check] | None = None
    cause: str = ""          # the one cause of the tree run's stop (interp/realprograms.py cause_of)
    where: str = ""          # file:line of the stop (file name only)
    cell: str = ""           # the committed cell file used (corpus/cells), or ""

    @property
    def agree(self) -> bool | None:
        if self.tree_vm is None:
            return None
        return all(c.ok for c in self.tree_vm)


def real_programs(corpus: Path = DEFAULT_CORPUS) -> list[tuple[Path, Path]]:
    """(program, backup root) for every runnable program of the corpus backups (the
    definition of issue 6: ``interp.realprograms``). Empty when the corpus is absent."""
    if not corpus.is_dir():
        return []

    out = []
    for root in R.find_backups(corpus):
        for prog in R.programs_of(root):
            out.append((prog, root))
    return out


def run_real(corpus: Path = DEFAULT_CORPUS, interps: list[str] | None = None, *, limit: int | None = None,
             max_sim_time: float | None = None, max_steps: int | None = None, progress=None,
             scheduler: str | None = None, jobs: int = 1) -> list[RealOutcome]:
    """Run the corpus programs on every interpreter with the real-programs report's limits
    (interp/realprograms.py: 60 s or the cell's ``sim_time``, the step budget with the
    submit's), so that the causes shown here are that report's. `jobs` > 1: in that many worker
    processes of this machine; `scheduler`: on that Dask cluster's workers (they see the corpus
    at the same paths). The same outcomes every way."""

    interps = H.available_interpreters() if interps is None else interps
    max_sim_time = R.REPORT_SIM_TIME_S if max_sim_time is None else max_sim_time
    max_steps = R.REPORT_STEPS if max_steps is None else max_steps
    progs = real_programs(corpus)
    if limit is not None:
        progs = progs[:limit]
    tasks = [(i, (prog, corpus, interps, max_sim_time, max_steps)) for i, (prog, _root) in enumerate(progs)]
    if scheduler is not None or jobs > 1:
        # a backup's programs in one worker after the other: it loads the backup once
        return _elsewhere(real_outcome, tasks, "krl-conformance-real", progress, _real_failed,
                          scheduler=scheduler, jobs=jobs, group=lambda i: progs[i][1])
    out = []
    for _i, args in tasks:
        out.append(real_outcome(*args))
        if progress:
            progress(out[-1])
    return out


def real_outcome(prog: Path, corpus: Path, interps: list[str], max_sim_time: float,
                 max_steps: int) -> RealOutcome:
    """One corpus program run on each of `interps` with the real-programs report's limits."""

    ro = RealOutcome(str(prog.relative_to(corpus)) if prog.is_relative_to(corpus) else str(prog))
    cell = R.cell_of(prog, corpus)
    ro.cell = str(cell.relative_to(R.CELLS.parent.parent)) if cell is not None else ""
    runs = {}
    try:
        _robot, subs, t, steps = R.report_run(prog, cell, max_sim_time, max_steps)
    except Exception as exc:  # noqa: BLE001 - a robot or cell file that cannot be read: this row says so
        ro.crash = {it: f"{type(exc).__name__}: {exc}"[:300] for it in interps}
        ro.reasons = {it: "crash" for it in interps}
        ro.cause = "interpreter gap"
        return ro
    for it in interps:
        res = H.run_program(prog, it, workspace=None, max_sim_time=t, stimuli=cell,
                            max_steps=steps, submit=subs[0] if subs else None,
                            wall_timeout=300.0, check=False)
        runs[it] = res
        if res.crash:
            ro.crash[it] = res.crash.splitlines()[0][:300]
            ro.reasons[it] = "crash"
        else:
            ends = [e for e in res.events if e.get("kind") == "end"]
            ro.reasons[it] = ends[-1].get("reason", "?") if ends else "no end event"
    if "tree" in runs and "vm" in runs:
        ro.tree_vm = H.compare_runs(runs["tree"], runs["vm"], path_tol_mm=1e-6)
    first = runs.get("tree") or next(iter(runs.values()), None)
    if first is not None:
        if first.crash:
            ro.cause = "interpreter gap"
        else:
            row = R.row_from_trace(prog, first.events)
            ro.cause = row["cause"]
            ro.where = f"{Path(row['file']).name}:{row['line']}" if row.get("file") and row.get("line") else ""
    return ro


# ============================================================================ plots
def plot_case(co: CaseOutcome, png: Path) -> bool:
    """TCP paths (top view X-Y and side view X-Z): programmed points, approximation zones,
    each interpreter's path. Returns False when the case has no motion."""
    runs = {k: r for k, r in co.runs.items() if r.events and any(e.get("kind") == "motion" for e in r.events)}
    if not runs:
        return False

    matplotlib.use("Agg")

    first = next(iter(runs.values()))
    mt = H.motion_times(first.events)
    zones = {}
    for spec in co.case.expect.get("motion") or []:
        if spec.get("check") == "blend":
            mid = int(spec["id"])
            if "zone_mm" in spec:
                zones[mid] = float(spec["zone_mm"])
    for mid, d in mt.items():
        if "blend_start" in d and mid not in zones:
            p = H._pose_at(H.poses(first.events), d["blend_start"])
            zones[mid] = H._norm(H._sub(p, d["point"][:3]))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    styles = {"tree": dict(color="tab:blue", lw=1.6, ls="-"), "vm": dict(color="tab:orange", lw=1.2, ls="--")}
    for ax, (i, j, lab) in zip(axes, ((0, 1, "top view: X-Y"), (0, 2, "side view: X-Z"))):
        for name, r in runs.items():
            ps = [p for _, p in H.poses(r.events)]
            ax.plot([p[i] for p in ps], [p[j] for p in ps], label=f"{name} TCP path", **styles.get(name, {}))
        pts = [(mid, d["point"]) for mid, d in sorted(mt.items()) if "point" in d]
        ax.plot([p[i] for _, p in pts], [p[j] for _, p in pts], "k+", ms=9, mew=1.5, label="programmed points")
        for mid, p in pts:
            ax.annotate(str(mid), (p[i], p[j]), textcoords="offset points", xytext=(4, 4), fontsize=8)
            if mid in zones:
                ax.add_patch(Circle((p[i], p[j]), zones[mid], fill=False, ls=":", color="tab:red",
                                    label="approximation zone" if mid == min(zones) else None))
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(lab, fontsize=9)
        ax.set_xlabel("X mm" if i == 0 else "")
        ax.set_ylabel("Y mm" if j == 1 else "Z mm")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, loc="best")
    fig.suptitle(co.case.name, fontsize=10)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=90)
    plt.close(fig)
    return True


# ============================================================================ report
def summary(outcomes: list[CaseOutcome], fuzz: dict[str, Any] | None, real: list[RealOutcome] | None,
            status: dict[str, str | None]) -> dict[str, Any]:
    vm_ok = status.get("vm") is None and status.get("tree") is None
    s: dict[str, Any] = {
        "cases": len(outcomes),
        "passed": sum(1 for o in outcomes if o.passed),
        "tree_vm_agree": sum(1 for o in outcomes if o.agree) if vm_ok else None,
        "fuzz_programs": (fuzz or {}).get("programs", 0),
        "fuzz_agree": (fuzz or {}).get("agree") if vm_ok else None,
        "real_programs": len(real or []),
        "real_agree": sum(1 for r in (real or []) if r.agree) if vm_ok else None,
    }
    s["pending"] = sorted(o.case.name for o in outcomes if o.case.pending)
    s["pending_passing"] = sorted(o.case.name for o in outcomes if o.case.pending and o.passed
                                  and o.agree is not False)
    s["failed_not_pending"] = sorted(o.case.name for o in outcomes if not o.ok_or_pending)
    s["interpreters"] = {k: ("available" if v is None else v) for k, v in status.items()}
    s["vm"] = "available" if vm_ok else (status.get("vm") or "not available")
    if fuzz:
        s["fuzz_tree_ok"] = fuzz.get("tree_ok")
        s["fuzz_mode"] = fuzz.get("mode")
    if real is not None:
        s["real_tree_crashes"] = sum(1 for r in real if "tree" in r.crash)
        s["real_tree_reasons"] = _count(r.reasons.get("tree", "-") for r in real)
        s["real_causes"] = _count(r.cause or "-" for r in real)
        s["real_completed_or_intended"] = sum(1 for r in real if r.cause in ("completed", "intended end"))
        s["real_status"] = {r.program: (r.cause or r.reasons.get("tree", "-")) for r in real}
    s["case_status"] = {o.case.name: _status(o) for o in outcomes}
    return s


def _status(o: CaseOutcome) -> str:
    """pass, pending or FAIL: a case's one status in the report and the nightly history."""
    return "pass" if o.passed and o.agree is not False else ("pending" if o.ok_or_pending else "FAIL")


def _count(items) -> dict[str, int]:
    out: dict[str, int] = {}
    for x in items:
        out[x] = out.get(x, 0) + 1
    return dict(sorted(out.items()))


def _row(o: CaseOutcome) -> dict[str, Any]:
    per = {k: ("pass" if r.passed else "FAIL") for k, r in o.results.items()}
    return {"name": o.case.name, "title": o.case.expect.get("title", ""),
            "covers": ", ".join(o.case.expect.get("covers", [])),
            "per": per, "agree": {None: "n/a", True: "yes", False: "NO"}[o.agree],
            "pending": o.case.pending or "", "plot": o.plot,
            "status": _status(o),
            "diffs": {k: r.diff_text() for k, r in o.results.items() if not r.passed},
            "tree_vm_diff": "\n".join(f"[{c.name}] {c.detail}" for c in (o.tree_vm or []) if not c.ok)}


def write_report(out: Path, outcomes: list[CaseOutcome], fuzz: dict[str, Any] | None = None,
                 real: list[RealOutcome] | None = None, *, plots: bool = True) -> dict[str, Any]:
    out.mkdir(parents=True, exist_ok=True)
    status = H.interpreter_status()
    if plots:
        for o in outcomes:
            png = out / "plots" / f"{o.case.name}.png"
            try:
                if plot_case(o, png):
                    o.plot = f"plots/{png.name}"
            except Exception as exc:  # noqa: BLE001 - a broken plot must not lose the report
                o.plot = None
                print(f"plot {o.case.name}: {exc}")
    s = summary(outcomes, fuzz, real, status)
    write_text(out / "summary.json", json.dumps(s, indent=2) + "\n")
    rows = [_row(o) for o in outcomes]
    interps = sorted({k for o in outcomes for k in o.results})
    write_text(out / "report.md", _markdown(s, rows, interps, fuzz, real))
    write_text(out / "report.html", _html(s, rows, interps, fuzz, real))
    return s


def _markdown(s, rows, interps, fuzz, real) -> str:
    L = ["# Conformance report", "",
         f"Generated {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}.", "",
         "| metric | value |", "|---|---|"]
    for k in ("cases", "passed", "tree_vm_agree", "fuzz_programs", "fuzz_agree", "real_programs", "real_agree", "vm"):
        L.append(f"| {k} | {s.get(k) if s.get(k) is not None else 'n/a (no VM)'} |")
    L += ["", "## Cases", "", "| case | " + " | ".join(interps) + " | tree = vm | status | covers |",
          "|---|" + "---|" * len(interps) + "---|---|---|"]
    for r in rows:
        L.append(f"| {r['name']} | " + " | ".join(r["per"].get(i, "-") for i in interps)
                 + f" | {r['agree']} | {r['status']} | {r['covers']} |")
    pend = [r for r in rows if r["pending"]]
    if pend:
        L += ["", "## Pending cases", ""]
        L += [f"- **{r['name']}** ({r['status']}): {r['pending']}" for r in pend]
    fails = [r for r in rows if r["diffs"] or r["tree_vm_diff"]]
    if fails:
        L += ["", "## Differences", ""]
        for r in fails:
            L += [f"### {r['name']}" + (" (pending)" if r["pending"] else ""), ""]
            for k, d in r["diffs"].items():
                L += [f"{k}:", "", "```", d, "```", ""]
            if r["tree_vm_diff"]:
                L += ["tree vs vm:", "", "```", r["tree_vm_diff"], "```", ""]
    if fuzz:
        L += ["", "## Differential fuzzing", "", f"mode: {fuzz.get('mode')}; programs: {fuzz.get('programs')}; "
              f"tree ran cleanly: {fuzz.get('tree_ok')}; tree = vm: {fuzz.get('agree')}"]
        for f in fuzz.get("failures", [])[:20]:
            L += ["", "```", str(f)[:2000], "```"]
    if real is not None:
        L += ["", "## Real programs (../shared/krl-corpus)", "", f"{len(real)} runnable programs of the KRC backups.", ""]
        causes = s.get("real_causes") or {}
        if causes:
            L += ["Every stop explained (interp/realprograms.py `cause_of`): completed; intended end (the "
                  "program's own HALT, or a cycle loop stopped by the limit with its cell answering); "
                  "program error (at its file:line); interpreter gap; limit. Cell files: corpus/cells.", "",
                  "| cause | programs |", "|---|---:|"]
            L += [f"| {md(k)} | {v} |" for k, v in causes.items()]
            L += ["", f"Completed or intended end: {s.get('real_completed_or_intended')} of {len(real)}.", ""]
        reasons = s.get("real_tree_reasons") or {}
        if reasons:
            L += ["| end reason (tree) | programs |", "|---|---:|"]
            L += [f"| {md(k)} | {v} |" for k, v in reasons.items()]
        its = sorted({k for r in real for k in r.reasons})
        if real:
            L += ["", "| program | cause | stop at | cell | " + " | ".join(its) + " | tree = vm | crash |",
                  "|---|---|---|---|" + "---|" * len(its) + "---|---|"]
            for r in real:
                agree = {None: "n/a", True: "yes", False: "NO"}[r.agree]
                crash = "; ".join(r.crash.values())
                L.append(f"| {md(r.program)} | {md(r.cause) if r.cause else ''} | {md(r.where) if r.where else ''} | "
                         f"{md(r.cell) if r.cell else ''} | "
                         + " | ".join(md(r.reasons.get(i, "-")) for i in its)
                         + f" | {agree} | {md(crash) if crash else ''} |")
    return "\n".join(L) + "\n"


def _html(s, rows, interps, fuzz, real) -> str:
    keys = ("cases", "passed", "tree_vm_agree", "fuzz_programs", "fuzz_agree", "real_programs", "real_agree", "vm")
    return render_html("conformance", "conformance.html.j2", when=time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
                       summary_rows=[(k, s.get(k) if s.get(k) is not None else "n/a (no VM)") for k in keys],
                       rows=rows, interps=interps, pending=[r for r in rows if r["pending"]],
                       fuzz=fuzz, real=real, real_reasons=s.get("real_tree_reasons") or {},
                       real_causes=s.get("real_causes") or {},
                       real_good=s.get("real_completed_or_intended"),
                       real_interps=sorted({k for r in (real or []) for k in r.reasons}))


def run_all(out: Path, *, fuzz_n: int = 200, real: bool = True, corpus: Path = DEFAULT_CORPUS,
            real_limit: int | None = None, fuzz_random: bool = False, echo=print,
            scheduler: str | None = None, cases: list[H.Case] | None = None, jobs: int = 1) -> dict[str, Any]:
    """Everything `krl conformance` / `make conformance` does. `jobs`: worker processes of this
    machine for the cases, the fuzzer's programs and the real programs (1: in this process);
    `scheduler`: the cases and the real programs run on that Dask cluster instead (the
    fuzzer's programs run on this machine, in `jobs` workers); `cases`: these instead of the
    whole suite. The same report every way."""
    status = H.interpreter_status()
    for k, v in status.items():
        echo(f"{k}: {'available' if v is None else v}")
    t0 = time.monotonic()

    def prog(co):
        st = "pass" if co.passed and co.agree is not False else ("pending" if co.ok_or_pending else "FAIL")
        echo(f"  {st:7s} {co.case.name}")
    outcomes = run_cases(cases, progress=prog, scheduler=scheduler, jobs=jobs)
    echo(f"cases: {sum(o.passed for o in outcomes)}/{len(outcomes)} pass ({time.monotonic() - t0:.0f} s)")
    fz = None
    if fuzz_n > 0:

        fz = F.run_fuzz(fuzz_n, reproducible=not fuzz_random, save_failures=out / "fuzz_failures", jobs=jobs)
        echo(f"fuzz: {fz['programs']} programs, mode {fz['mode']}, tree clean {fz['tree_ok']}, agree {fz['agree']}")
    rl = None
    if real:
        if corpus.is_dir():
            rl = run_real(corpus, limit=real_limit, scheduler=scheduler, jobs=jobs,
                          progress=lambda r: echo(f"  real {r.reasons} {r.program}"))
            echo(f"real programs: {len(rl)}")
        else:
            echo(f"real programs: skipped ({corpus} not found)")
    s = write_report(out, outcomes, fz, rl)
    echo(f"report: {out / 'report.md'}")
    return s


__all__ = ["case_outcome", "real_outcome", "run_cases", "run_real", "write_report", "run_all", "plot_case", "summary", "CaseOutcome",
           "RealOutcome", "real_programs"]
