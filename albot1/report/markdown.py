"""Text from results and suite files written safely into the report's Markdown pages.

Dataset and method names, reasons, descriptions and paths come from files a
user (or someone who sent them the results folder) wrote. Markdown passes raw
HTML through, so such text is written as text: HTML-escaped (as ``index.html``
does, :func:`html.escape`), table pipes and line breaks neutralised, and a
code span delimited so that no backtick inside it can end it.
"""

from __future__ import annotations

import html
import re


def text(value: object) -> str:
    """``value`` as Markdown text: no HTML, no table cell break, one line."""
    escaped = html.escape(" ".join(str(value).split()), quote=True)
    return escaped.replace("|", "\\|").replace("`", "&#96;").replace("[", "\\[").replace("]", "\\]")


def code(value: object) -> str:
    """``value`` as a Markdown code span (shown as written, never interpreted), one line."""
    content = " ".join(str(value).split()).replace("|", "\\|")
    longest = max((len(run) for run in re.findall(r"`+", content)), default=0)
    fence = "`" * (longest + 1)
    pad = " " if content.startswith("`") or content.endswith("`") or not content.strip() else ""
    return f"{fence}{pad}{content}{pad}{fence}"
