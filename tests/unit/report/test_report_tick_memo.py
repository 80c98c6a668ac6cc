"""tick_memo: an axes' ticks worked out once per layout pass and draw, the figures' bytes unchanged."""

from __future__ import annotations

import subprocess
import sys

import pytest

from albot1.report.tick_memo import share_tick_updates

# Figures of the report's kinds that lean on the memo, each written as its PNG and SVG twin by the report's
# own save (one layout, two formats): shared axes in a grid with titles, a colour bar and a figure legend
# (the maps and APE figures), two log axes one above the other with math-text ticks (the RPE boxes), and a
# single axes whose tick count follows its size (the layout changes it between passes). Printed: each
# file's sha256 and how many times matplotlib's own tick update ran.
_DRAW = """
import hashlib, sys, tempfile
from pathlib import Path
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.axis import Axis
if sys.argv[1] == "plain":
    import albot1.report.tick_memo as memo
    memo.share_tick_updates = lambda: False  # the report's pyplot() installs nothing
from albot1.report import plots
update = Axis._update_ticks
calls = [0]
def counted(self):  # matplotlib's own tick update, counted (the memo, when installed, wraps this)
    calls[0] += 1
    return update(self)
Axis._update_ticks = counted
plots.pyplot()
rng = np.random.default_rng(3)
out = Path(tempfile.mkdtemp())
digests = []
fig, axes = plt.subplots(2, 3, figsize=(9, 5), sharex=True, sharey=True, squeeze=False, layout="constrained")
for k, ax in enumerate(axes.flat[:5]):
    xy = np.cumsum(rng.normal(size=(400, 2)), axis=0)
    lines = ax.scatter(xy[:, 0], xy[:, 1], c=np.hypot(*xy.T), s=2)
    ax.set_title(f"panel {k}: ATE {k * 0.1:.3g} m", fontsize=8)
    ax.tick_params(labelsize=7)
fig.colorbar(lines, ax=axes, location="right", shrink=0.85, label="APE (m)")
plots.label_grid(axes, 5)
fig.legend(["a", "b"], loc="outside lower center", ncols=2, frameon=False)
fig.suptitle("a grid of shared axes")
plots.save(fig, out / "grid.png")
fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 7), sharex=True, layout="constrained")
for ax in (top, bottom):
    ax.boxplot([rng.lognormal(-3, 1.5, 200) for _ in range(4)], positions=range(4), manage_ticks=False)
    ax.set_yscale("log")
    ax.grid(alpha=0.3, which="both")
bottom.set_xticks(range(4), ["1", "2", "5", "10"])
bottom.set_xlabel("segment length (m)")
plots.save(fig, out / "boxes.png")
fig, ax = plt.subplots(figsize=(9, 4.2), layout="constrained")
ax.plot(np.arange(5000) * 0.013, np.abs(rng.normal(size=5000)).cumsum() * 1e-3, label="a method")
ax.set_title("error along the route")
fig.legend(loc="outside right upper", frameon=False)
plots.save(fig, out / "line.png")
for name in ("grid", "boxes", "line"):
    for suffix in ("png", "svg"):
        digests.append(hashlib.sha256((out / f"{name}.{suffix}").read_bytes()).hexdigest())
print(" ".join(digests), calls[0])
"""


def _draw(mode: str) -> tuple[list[str], int]:
    out = subprocess.run([sys.executable, "-c", _DRAW, mode], check=True, capture_output=True, text=True)
    *digests, calls = out.stdout.split()
    return digests, int(calls)


@pytest.mark.slow
def test_figures_drawn_with_the_tick_memo_have_the_bytes_of_those_drawn_without() -> None:
    (plain, plain_calls), (memo, memo_calls) = _draw("plain"), _draw("memo")
    assert len(plain) == 6
    assert memo == plain  # every PNG and SVG twin, byte for byte
    assert memo_calls < plain_calls / 2  # and matplotlib's tick update ran less than half as often


def test_the_memo_is_installed_by_the_reports_pyplot_once_and_idle_outside_a_draw() -> None:
    from matplotlib.axes._base import _AxesBase
    from matplotlib.axis import Axis

    from albot1.report.plots import pyplot

    plt = pyplot()
    assert share_tick_updates() and share_tick_updates()  # idempotent: installed once, not nested
    assert getattr(Axis.__dict__["_update_ticks"], "_albot1_tick_memo", False)
    assert getattr(_AxesBase.__dict__["draw"], "_albot1_tick_memo", False)
    assert not hasattr(Axis.__dict__["_update_ticks"].__wrapped__, "_albot1_tick_memo")
    # outside a draw or layout nothing is kept: ticks follow the limits set between two calls
    fig, ax = plt.subplots()
    ax.set_xlim(0, 1)
    first = [t.get_loc() for t in ax.xaxis._update_ticks()]
    ax.set_xlim(0, 100)
    second = [t.get_loc() for t in ax.xaxis._update_ticks()]
    plt.close(fig)
    assert first != second
