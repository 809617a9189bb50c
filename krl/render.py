"""The one HTML environment of the project: every HTML report is rendered here.

Reports show text taken from untrusted input — KRL lines, file names from a corpus or a
backup, run-time messages — so every HTML output goes through the single Jinja environment
of :func:`html_env`, with autoescape on for every template whatever its name (docs/security.md).
Each package keeps its own report templates in its ``templates`` folder (``recovery.html.j2`` in
recovery/, ``conformance.html.j2`` and ``nightly.html.j2`` in conformance/); they extend
``_base.html.j2``, the shared page of ``krl/templates``. This module imports nothing of the
project: the packages above it name themselves when they render.

Markdown produced by the project (e.g. the static-check section of the recovery report) is
turned into HTML by markdown-it-py with raw HTML disabled (:func:`markdown_html`), never by
hand: a ``<script>`` inside that Markdown comes out as text.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

from jinja2 import ChoiceLoader, Environment, PackageLoader, StrictUndefined
from markupsafe import Markup
from markdown_it import MarkdownIt

__all__ = ["html_env", "markdown_code", "markdown_html", "render_html"]


@lru_cache(maxsize=1)
def _markdown():

    # CommonMark with tables; "html": False renders raw HTML in the source as text, and
    # markdown-it's link validation refuses javascript:, vbscript:, file: and data: links.
    return MarkdownIt("commonmark", {"html": False}).enable("table")


def markdown_html(text: str) -> Markup:
    """Markdown ``text`` as HTML (CommonMark + tables, raw HTML shown as text)."""
    return Markup(_markdown().render(text or ""))


def markdown_code(text: object) -> str:
    """`text` as a Markdown code span for the Markdown reports: fenced by one more backtick
    than its longest backtick run, line breaks as spaces, ``|`` escaped for tables. Nothing
    inside can close the span, and raw HTML inside a code span is shown as text."""
    s = " ".join(str(text).splitlines()).replace("|", "\\|")
    longest = run = 0
    for ch in s:
        run = run + 1 if ch == "`" else 0
        longest = max(longest, run)
    fence = "`" * (longest + 1)
    pad = " " if s.startswith("`") or s.endswith("`") or not s else ""
    return f"{fence}{pad}{s}{pad}{fence}"


@lru_cache(maxsize=None)
def html_env(package: str) -> Environment:
    """The Jinja environment of `package`'s HTML output: its ``templates`` folder, then
    ``krl/templates`` (the shared base page); autoescape on for all templates (not chosen by
    file name), undefined names are errors, filter ``markdown`` (:func:`markdown_html`)."""
    loader = ChoiceLoader([PackageLoader(package, "templates"), PackageLoader("krl", "templates")])
    env = Environment(loader=loader, autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    env.filters["markdown"] = markdown_html
    return env


def render_html(package: str, template: str, **context: Any) -> str:
    """Render ``<package>/templates/<template>`` with `context`; every value is escaped unless it
    is already :class:`markupsafe.Markup`."""
    return html_env(package).get_template(template).render(**context)
