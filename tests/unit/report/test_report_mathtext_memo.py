"""mathtext_memo: math text parsed once per process, the figures' bytes unchanged."""

from __future__ import annotations

import subprocess
import sys

from albot1.report.mathtext_memo import share_parsed_math

# Two log-axis figures (math-text tick labels) written as PNG and SVG; the second one's files are hashed.
# With the memo, the second figure's labels are all memo hits, parsed by the first figure's renderers.
_DRAW = """
import hashlib, io, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
if sys.argv[1] == "shared":
    from albot1.report.mathtext_memo import share_parsed_math
    assert share_parsed_math()
digests = []
# the third figure under another math-text setting: a label parsed before must be parsed again under it
for settings in ({}, {}, {"mathtext.default": "rm"}):
    fig, ax = plt.subplots(figsize=(4, 3), layout="constrained")
    ax.semilogy([1, 2, 3], [1e-3, 1e-1, 1e2])
    ax.set_title(r"$\\alpha^2$ and a fraction $\\frac{1}{2}$ of $x$")
    for fmt in ("png", "svg"):
        out = io.BytesIO()
        with matplotlib.rc_context({"svg.hashsalt": "x", **settings}):
            fig.savefig(out, format=fmt, dpi=120, metadata={"Date": None} if fmt == "svg" else None)
        digests.append(hashlib.sha256(out.getvalue()).hexdigest())
    plt.close(fig)
print(" ".join(digests))
"""


def _digests(mode: str) -> list[str]:
    out = subprocess.run([sys.executable, "-c", _DRAW, mode], check=True, capture_output=True, text=True)
    return out.stdout.split()


def test_figures_drawn_with_the_shared_memo_have_the_bytes_of_those_drawn_without() -> None:
    plain, shared = _digests("plain"), _digests("shared")
    assert len(plain) == 6
    assert plain[4:] != plain[:2]  # the setting changes the drawing
    # both formats: the first figure (memo filled), the second (memo hits), the third (parsed again: other setting)
    assert shared == plain


def test_two_parsers_of_one_kind_share_a_parse_and_kinds_stay_apart() -> None:
    from matplotlib.font_manager import FontProperties
    from matplotlib.mathtext import MathTextParser

    assert share_parsed_math() and share_parsed_math()  # idempotent: installed once
    prop = FontProperties(size=9)
    first = MathTextParser("agg").parse(r"$10^{-3}$", 120, prop)
    assert MathTextParser("agg").parse(r"$10^{-3}$", 120, prop) is first
    assert MathTextParser("path").parse(r"$10^{-3}$", 120, prop) is not first  # a vector parse, not a raster one
    assert MathTextParser("agg").parse(r"$10^{-3}$", 72, prop) is not first  # the resolution is in the key


def test_the_memo_is_installed_by_the_reports_pyplot() -> None:
    from matplotlib.mathtext import MathTextParser

    from albot1.report.plots import pyplot

    pyplot()
    assert getattr(MathTextParser.__dict__["_parse_cached"], "_albot1_shared", False)
