"""The software packages a corpus's lines reveal: every KUKA inline form and template fold of
the KRL files below some folders, by the module or provider it names (issue 46; docs/robot.md,
"Technology packages the lines reveal").

KUKA's form providers write their name into the lines they write: a KSS 5 to 8 inline form's
opening comment ``;FOLD PTP P1 ...;%{PE}%R 8.3.31,%MKUKATPBASIS,%CMOVE,%VPTP,%P ...`` names its
module (``%M``), command (``%C``) and variant (``%V``); a KSS 8 form names its provider in a
hidden parameter fold (``;Params IlfProvider=kukaroboter.basistech.inlineforms.movement.spline``);
the template names each technology package's INI fold (``;FOLD SPOTTECH INI``). The checker
reads the same markers (krl/semantics/outside.py ``template_lines``) as evidence that a name
used there is declared by installed software.

Usage: ``python -m krl.survey.forms FOLDER...`` prints one row per module, provider and INI
fold: how many folds, their commands, and where they were seen (repository folders: the first
folder below each FOLDER, then the pair folder for ../shared/krl-history's ``OWNER/NN-SHA``).
"""

from __future__ import annotations

import re
import sys
from collections import Counter, defaultdict
from pathlib import Path

from krl.files import walk
from krl.semantics.outside import FOLD_MODULE, FOLD_PROVIDER, fold_opening
from krl.source import is_krl_file, read_source
from krl.terminal import printable


def folds(text: str):
    """(kind, label, command) of each fold opening of `text` that names its writer: ``module``
    (``KUKATPBASIS``, with the form's ``%C`` command), ``provider`` (a KSS 8 form's
    ``IlfProvider``), ``ini`` (a template INI fold's title other than ``USER INI``)."""
    for line in text.splitlines():
        if ";" not in line:
            continue
        rest = fold_opening(line)
        if rest is not None:
            m = FOLD_MODULE.search(rest)
            if m is not None:
                c = re.search(r"%C([A-Z0-9_]+)", rest, re.IGNORECASE)
                yield "module", m.group(1).upper(), c.group(1).upper() if c else ""
            t = rest.split(";", 1)[0].strip().upper()
            if (t.endswith((" INI", " INIT")) or t in ("INI", "INIT")) and not t.startswith("USER"):
                yield "ini", t, ""
            continue
        p = FOLD_PROVIDER.match(line)
        if p is not None:
            yield "provider", p.group(1), ""


def survey(folders: list[Path]) -> dict:
    """(kind, label) -> {"folds": n, "commands": Counter, "where": Counter of repository
    folders} over every KRL file below `folders`."""
    out: dict = defaultdict(lambda: {"folds": 0, "commands": Counter(), "where": Counter()})
    for folder in folders:
        for entry in walk(folder):
            if entry.kind != "file" or not is_krl_file(entry.path):
                continue
            rel = entry.path.relative_to(folder).parts
            where = "/".join(rel[:2]) if (folder / rel[0]).is_dir() and len(rel) > 2 and \
                rel[1][:2].isdigit() else rel[0]
            try:
                text = read_source(entry.path).text
            except (OSError, ValueError):
                continue
            for kind, label, cmd in folds(text):
                row = out[(kind, label)]
                row["folds"] += 1
                if cmd:
                    row["commands"][cmd] += 1
                row["where"][f"{folder.name}/{where}"] += 1
    return dict(out)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if not args:
        print("usage: python -m krl.survey.forms FOLDER...", file=sys.stderr)
        return 2
    rows = survey([Path(a) for a in args])
    for (kind, label), row in sorted(rows.items(), key=lambda kv: (kv[0][0], -kv[1]["folds"])):
        cmds = ", ".join(f"{c} {n}" for c, n in row["commands"].most_common(8))
        where = ", ".join(f"{w} ({n})" for w, n in row["where"].most_common())
        print(f"{kind:8s} {printable(label):45s} {row['folds']:6d}  {printable(cmds)}\n         seen in: {printable(where)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
