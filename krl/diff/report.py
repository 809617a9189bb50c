"""The change report (`krl report BACKUP [--since OLD]`): one HTML page with the check summary
of the backup, its program map (krl/programmap) and, given an older backup, the diff
(krl/diff/core.py). Rendered in the project's one Jinja environment (krl/render.py, autoescape
on): ``templates/report.html.j2`` here, the map section from krl/programmap's own template.
"""

from __future__ import annotations

from markupsafe import Markup

from krl.diff.core import Diff
from krl.diff.text import format_delta, html_helpers
from krl.programmap.graph import ProgramMap
from krl.programmap.render import context
from krl.render import render_html

__all__ = ["report_html", "MAX_REPORT_DIAGNOSTICS"]

# the diagnostics listed on the page (the counts are always complete)
MAX_REPORT_DIAGNOSTICS = 200


def report_html(backup: str, files: int, diagnostics: list, pm: ProgramMap, svg: str,
                diff: Diff | None = None) -> str:
    """The page: `diagnostics` (krl.diagnostics.Diagnostic, as krl check reports them for the
    backup's `files` files), the map `pm` with its drawing `svg` ("" for none), `diff` or None."""
    map_section = Markup(render_html("krl.programmap", "_map_body.html.j2", **context(pm, svg)))
    errors = sum(d.is_error for d in diagnostics)
    return render_html("krl.diff", "report.html.j2", title=f"Change report: {backup}", backup=backup,
                       files=files, errors=errors, warnings=len(diagnostics) - errors,
                       diagnostics=diagnostics[:MAX_REPORT_DIAGNOSTICS], more=max(0, len(diagnostics) - MAX_REPORT_DIAGNOSTICS),
                       map_section=map_section, diff=diff, format_delta=format_delta, **html_helpers())
