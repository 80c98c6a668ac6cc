"""Text from results and suite files written safely into the report's Markdown pages.

Dataset and method names, reasons, descriptions and paths come from files a
user (or someone who sent them the results folder) wrote. Markdown passes raw
HTML through, so such text is written as text: HTML-escaped (as ``index.html``
does, :func:`html.escape`), table pipes and line breaks neutralised, and a
code span delimited so that no backtick inside it can end it. Backslashes and
the emphasis marks ``* _ ~`` are backslash-escaped too: a name ``a\\|b`` became
``a\\\\|b`` (an escaped backslash, then a pipe that split the table cell), and
``a*b*c`` was shown as "a", an italic "b", "c".
"""

from __future__ import annotations

import html
import re


def text(value: object) -> str:
    """``value`` as Markdown text: no HTML, no table cell break, one line."""
    flat = " ".join(str(value).split()).replace("\\", "\\\\")
    # Quotes stay as written ("odometry's", not "odometry&#x27;s" in the raw page): with < and > escaped no HTML
    # element, hence no attribute a quote could end, can start in the text.
    escaped = html.escape(flat, quote=False)
    for mark in "*_~":
        escaped = escaped.replace(mark, "\\" + mark)
    return escaped.replace("|", "\\|").replace("`", "&#96;").replace("[", "\\[").replace("]", "\\]")


def code(value: object) -> str:
    """``value`` as a Markdown code span (shown as written, never interpreted), one line."""
    content = " ".join(str(value).split()).replace("|", "\\|")
    longest = max((len(run) for run in re.findall(r"`+", content)), default=0)
    fence = "`" * (longest + 1)
    pad = " " if content.startswith("`") or content.endswith("`") or not content.strip() else ""
    return f"{fence}{pad}{content}{pad}{fence}"
