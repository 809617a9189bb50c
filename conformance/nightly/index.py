"""``reports/nightly/index.html`` and ``index.md``: what changed last night, every figure over
time (matplotlib charts, as growth.png is drawn) and the list of nights with their reports.

Rendered in the project's one Jinja environment (krl/render.py, autoescape on): folder names
and item names come from the file system and the corpus and are escaped; links are quoted.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from urllib.parse import quote

from krl.render import render_html

from . import flags as F, history as H
from .figures import CORE, kind_of, read_night
from krl.durable import write_text
import matplotlib
import matplotlib.pyplot as plt

PARTS = (("recovery", ("report.html", "report.md")), ("growth", ("growth.png", "growth.csv")),
         ("conformance", ("report.html", "report.md")), ("check", ("check_report.md",)),
         ("fuzz", ("summary.json",)))
DATE = re.compile(r"\d{4}-\d{2}-\d{2}")
HISTORY = "history.sqlite"


def _days(root: Path) -> list[Path]:
    return sorted((p for p in root.iterdir() if p.is_dir() and p.name != "trends"), reverse=True)


def _summary_line(day: Path) -> str:
    s = day / "conformance" / "summary.json"
    if not s.exists():
        return ""
    try:
        j = json.loads(s.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return "summary.json unreadable"
    return (f"cases {j.get('passed')}/{j.get('cases')}, tree=vm {j.get('tree_vm_agree')}, "
            f"fuzz {j.get('fuzz_programs')}, real {j.get('real_programs')}")


def _chart_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)[:120] + ".png"


def draw_charts(series: dict[str, list[tuple[str, float]]], out: Path) -> list[dict]:
    """One PNG per figure under ``out`` (the core figures first); returns [{name, png, kind}]."""

    matplotlib.use("Agg")

    out.mkdir(parents=True, exist_ok=True)
    names = [n for n in CORE if n in series] + sorted(n for n in series if n not in CORE)
    charts = []
    for name in names:
        points = series[name]
        fig, ax = plt.subplots(figsize=(4.2, 2.2), dpi=90)
        ax.plot([d for d, _ in points], [v for _, v in points], marker="o", color="#1f5fa8")
        band = F.noise_band([v for _, v in points[:-1]]) if kind_of(name) == "ratio" else None
        if band:
            ax.axhspan(band[0], band[1], color="#1f5fa8", alpha=0.12, label="noise band")
        ax.set_title(name, fontsize=9)
        ax.tick_params(labelsize=7)
        fig.autofmt_xdate()
        fig.tight_layout()
        png = out / _chart_name(name)
        fig.savefig(png)
        plt.close(fig)
        charts.append({"name": name, "png": f"{out.name}/{quote(png.name)}", "kind": kind_of(name)})
    return charts


def update_history(root: Path) -> list[str]:
    """Record every dated folder of ``root`` not yet in the history (and the newest again);
    returns the recorded dates."""
    hist = root / HISTORY
    known = set(H.nights(hist))
    days = [d for d in _days(root) if DATE.fullmatch(d.name)]
    for i, day in enumerate(sorted(days, reverse=True)):
        if i == 0 or day.name not in known:
            H.record(hist, read_night(day))
    return H.nights(hist)


def write_index(root: Path, charts: bool = True) -> Path:
    """Update the history from the dated folders of ``root`` and write ``index.html`` and
    ``index.md``; returns the index.html path. Raises history.HistoryError on a history
    file that is no SQLite database of this nightly."""
    root.mkdir(parents=True, exist_ok=True)
    dates = update_history(root)
    hist = root / HISTORY
    series = H.series(hist)
    flag_list: list[F.Flag] = []
    if len(dates) >= 2:
        last, prev = dates[-1], dates[-2]
        flag_list = F.item_flags(H.items(hist, prev), H.items(hist, last), last) + F.figure_flags(series, last)
    order = {"regression": 0, "change": 1, "improvement": 2}
    flag_list.sort(key=lambda f: (order[f.severity], f.subject))
    rows = []
    for d in _days(root):
        links = []
        for part, names in PARTS:
            for n in names:
                if (d / part / n).exists():
                    links.append((part, quote(f"{d.name}/{part}/{n}")))
                    break
        rows.append({"name": d.name, "links": links, "summary": _summary_line(d)})
    chart_rows = draw_charts(series, root / "trends") if charts and series else []

    html = render_html("conformance", "nightly.html.j2", days=rows, flags=flag_list, charts=chart_rows,
                       last=dates[-1] if dates else None, prev=dates[-2] if len(dates) > 1 else None,
                       nights=len(dates))
    write_text(root / "index.html", html)
    md = ["# Nightly reports", ""]
    if flag_list:
        md += [f"## Changes since {dates[-2]}", ""] + [f"- **{f.severity}** [{f.text}]({f.link})" for f in flag_list] + [""]
    md += ["| date | reports | conformance |", "|---|---|---|"]
    md += [f"| {r['name']} | " + " ".join(f"[{t}]({h})" for t, h in r["links"]) + f" | {r['summary']} |" for r in rows]
    write_text(root / "index.md", "\n".join(md) + "\n")
    return root / "index.html"
