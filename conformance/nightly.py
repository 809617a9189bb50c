"""Index page of the nightly reports: ``python -m conformance.nightly reports/nightly``.

``make nightly`` writes ``reports/nightly/<date>/{recovery,growth,conformance}`` and then this
module writes ``reports/nightly/index.html`` (and ``index.md``) linking every dated run, with
the conformance summary numbers of each day.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from urllib.parse import quote

PARTS = (("recovery", ("report.html", "report.md")), ("growth", ("growth.png", "growth.csv")),
         ("conformance", ("report.html", "report.md")))


def write_index(root: Path) -> Path:
    root.mkdir(parents=True, exist_ok=True)
    days = sorted((p for p in root.iterdir() if p.is_dir()), reverse=True)
    rows, rows_md = [], []   # rows: for conformance/templates/nightly.html.j2
    for d in days:
        links = []
        for part, names in PARTS:
            for n in names:
                if (d / part / n).exists():
                    links.append((f"{part}", quote(f"{d.name}/{part}/{n}")))
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
        rows.append({"name": d.name, "links": links, "summary": summ})
        rows_md.append(f"| {d.name} | " + " ".join(f"[{t}]({h})" for t, h in links) + f" | {summ} |")
    from krl.render import render_html  # noqa: PLC0415

    (root / "index.html").write_text(render_html("conformance", "nightly.html.j2", days=rows), encoding="utf-8")
    (root / "index.md").write_text("# Nightly reports\n\n| date | reports | conformance |\n|---|---|---|\n"
                                   + "\n".join(rows_md) + "\n", encoding="utf-8")
    return root / "index.html"


if __name__ == "__main__":
    print(write_index(Path(sys.argv[1] if len(sys.argv) > 1 else "reports/nightly")))
