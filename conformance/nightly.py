"""Index page of the nightly reports: ``python -m conformance.nightly reports/nightly``.

``make nightly`` writes ``reports/nightly/<date>/{recovery,growth,conformance}`` and then this
module writes ``reports/nightly/index.html`` (and ``index.md``) linking every dated run, with
the conformance summary numbers of each day.
"""

from __future__ import annotations

import html
import json
import sys
from pathlib import Path

PARTS = (("recovery", ("report.html", "report.md")), ("growth", ("growth.png", "growth.csv")),
         ("conformance", ("report.html", "report.md")))


def write_index(root: Path) -> Path:
    root.mkdir(parents=True, exist_ok=True)
    days = sorted((p for p in root.iterdir() if p.is_dir()), reverse=True)
    rows_html, rows_md = [], []
    for d in days:
        links = []
        for part, names in PARTS:
            for n in names:
                if (d / part / n).exists():
                    links.append((f"{part}", f"{d.name}/{part}/{n}"))
                    break
        s = d / "conformance" / "summary.json"
        summ = ""
        if s.exists():
            try:
                j = json.loads(s.read_text(encoding="utf-8"))
                summ = (f"cases {j.get('passed')}/{j.get('cases')}, tree=vm {j.get('tree_vm_agree')}, "
                        f"fuzz {j.get('fuzz_programs')}, real {j.get('real_programs')}")
            except (OSError, ValueError):
                summ = "summary.json unreadable"
        rows_html.append(f"<tr><td>{html.escape(d.name)}</td><td>"
                         + " ".join(f'<a href="{html.escape(h)}">{html.escape(t)}</a>' for t, h in links)
                         + f"</td><td>{html.escape(summ)}</td></tr>")
        rows_md.append(f"| {d.name} | " + " ".join(f"[{t}]({h})" for t, h in links) + f" | {summ} |")
    (root / "index.html").write_text(
        "<!doctype html><html><head><meta charset='utf-8'><title>Nightly reports</title></head><body>"
        "<h1>Nightly reports</h1><table border=1 cellpadding=4><tr><th>date</th><th>reports</th>"
        "<th>conformance</th></tr>" + "".join(rows_html) + "</table></body></html>\n", encoding="utf-8")
    (root / "index.md").write_text("# Nightly reports\n\n| date | reports | conformance |\n|---|---|---|\n"
                                   + "\n".join(rows_md) + "\n", encoding="utf-8")
    return root / "index.html"


if __name__ == "__main__":
    print(write_index(Path(sys.argv[1] if len(sys.argv) > 1 else "reports/nightly")))
