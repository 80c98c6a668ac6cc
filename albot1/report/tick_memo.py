"""An axes' ticks worked out once per layout pass and per draw, instead of up to five times.

While matplotlib lays out or draws one axes, each of its axes (x, y) recomputes its ticks (the locator's
positions, the formatter's labels, every tick moved and relabelled) and measures its tick labels several
times over: its own bounding box does it, then again to place the axis label (``_update_label_position``
through ``_get_tick_boxes_siblings``, which with no aligned labels is the axis itself), and again for each
spine's extent (``Spine.get_window_extent``) and the title's placement. In a profile of the default report
these repeats were about a quarter of the figures' CPU (docs/benchmarking.md, "Session 21").

:func:`share_tick_updates` opens a window for each call of ``Axes.get_tightbbox`` (the constrained layout's
measure of one axes) and of ``Axes.draw``; inside it, the first ``Axis._update_ticks`` of an axis is kept and
returned again by the later ones, and so are its tick labels' boxes (``Axis._get_ticklabel_bboxes``, per
renderer and list of ticks). Nothing in the window changes what those depend on: the axes' size and limits
are settled before it (``apply_aspect`` runs first in both calls) and change only between two windows (the
layout moves the axes between its passes; the SVG twin is drawn at another resolution), and the recomputed
ticks would set the same positions and texts again. So every file keeps its bytes. The window closes with
the outermost call; where this matplotlib lacks the private names relied on, nothing is changed.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

#: Marks the wrappers installed here (installing twice would nest them).
_MARK = "_albot1_tick_memo"


class _Window:
    """The ticks and tick-label boxes computed since the outermost open call (empty when none is open)."""

    def __init__(self) -> None:
        self.depth = 0
        self.ticks: dict[int, tuple[Any, list[Any]]] = {}
        self.boxes: dict[tuple[int, int, tuple[int, ...]], tuple[Any, Any, Any]] = {}

    def open(self) -> None:
        self.depth += 1

    def close(self) -> None:
        self.depth -= 1
        if not self.depth:
            self.ticks.clear()
            self.boxes.clear()


def _windowed(window: _Window, method: Callable[..., Any]) -> Callable[..., Any]:
    """``method`` (``Axes.draw`` or ``Axes.get_tightbbox``) run inside a window (its attributes kept)."""

    @functools.wraps(method)
    def run(self: Any, *args: Any, **kwargs: Any) -> Any:
        window.open()
        try:
            return method(self, *args, **kwargs)
        finally:
            window.close()

    setattr(run, _MARK, True)
    return run


def share_tick_updates() -> bool:
    """Install the windows and the memo (idempotent); whether they are in place."""
    from matplotlib.axes._base import _AxesBase
    from matplotlib.axis import Axis

    update, measure = Axis.__dict__.get("_update_ticks"), Axis.__dict__.get("_get_ticklabel_bboxes")
    draw, tight = _AxesBase.__dict__.get("draw"), _AxesBase.__dict__.get("get_tightbbox")
    if any(getattr(f, _MARK, False) for f in (update, measure, draw, tight)):
        return True
    if not all(callable(f) for f in (update, measure, draw, tight)):
        return False
    assert update is not None and measure is not None and draw is not None and tight is not None
    window = _Window()

    def update_ticks(self: Any) -> list[Any]:
        if not window.depth:
            return update(self)  # type: ignore[no-any-return]
        kept = window.ticks.get(id(self))
        if kept is None or kept[0] is not self:
            kept = (self, list(update(self)))
            window.ticks[id(self)] = kept
        return list(kept[1])

    def ticklabel_bboxes(self: Any, ticks: list[Any], renderer: Any) -> tuple[list[Any], list[Any]]:
        if not window.depth:
            return measure(self, ticks, renderer)  # type: ignore[no-any-return]
        key = (id(self), id(renderer), tuple(id(t) for t in ticks))
        kept = window.boxes.get(key)
        if kept is None or kept[0] is not self:
            first, second = measure(self, ticks, renderer)
            kept = (self, first, second)
            window.boxes[key] = kept
        # copies: a caller may extend the lists or move a box, and the next one must see the boxes as measured
        return [b.frozen() for b in kept[1]], [b.frozen() for b in kept[2]]

    for function in (update_ticks, ticklabel_bboxes):
        setattr(function, _MARK, True)
    setattr(Axis, "_update_ticks", functools.wraps(update)(update_ticks))  # noqa: B010 (private names)
    setattr(Axis, "_get_ticklabel_bboxes", functools.wraps(measure)(ticklabel_bboxes))  # noqa: B010
    _AxesBase.draw = _windowed(window, draw)  # type: ignore[method-assign]
    _AxesBase.get_tightbbox = _windowed(window, tight)  # type: ignore[method-assign]
    return True
