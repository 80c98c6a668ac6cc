"""Progress bars: on a terminal with a total and an ETA, nothing when stderr is not a terminal."""

from __future__ import annotations

import io
import sys

import pytest

from albot1.cli import progress
from albot1.data.open import open_sequence


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_slice_bound_is_the_most_scans_a_slice_yields() -> None:
    assert progress.slice_bound("intel[:3000]") == 3000
    assert progress.slice_bound("intel[:3000:7]") == 429
    assert progress.slice_bound("intel[::7]") is None
    assert progress.slice_bound("intel") is None


def test_quiet_when_stderr_is_not_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    captured = io.StringIO()
    monkeypatch.setattr(sys, "stderr", captured)
    sequence = open_sequence("synthetic-corridor[:30]")
    assert progress.with_progress(sequence, "x") is sequence
    assert sum(1 for _ in progress.with_progress(sequence, "x", at_most=30).frames()) == 30
    assert captured.getvalue() == ""


@pytest.mark.parametrize(("known", "at_most"), [(True, None), (False, 30)])
def test_on_a_terminal_the_bar_has_a_total_and_an_eta(
    monkeypatch: pytest.MonkeyPatch, known: bool, at_most: int | None
) -> None:
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    sequence = open_sequence("synthetic-corridor[:30]")
    if not known:  # a log whose length is unknown until decoded (a CARMEN file): the slice bounds it
        sequence = sequence.with_frames(lambda frames: frames, scan_count=None)
        assert sequence.known_scan_count is None
    wrapped = progress.with_progress(sequence, "odometry on it", at_most=at_most)
    assert sum(1 for _ in wrapped.frames()) == 30
    shown = terminal.getvalue()
    assert "odometry on it" in shown and "/30 [" in shown and "<" in shown  # n/total [elapsed<remaining


def test_report_bar_counts_datasets_drawn_on_a_terminal_only(monkeypatch: pytest.MonkeyPatch) -> None:
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    bar = progress.FigureBar()
    for done in range(4):
        bar.update(done, 3)
    bar.close()
    assert "report: drawing" in terminal.getvalue() and "3/3 [" in terminal.getvalue()
    quiet = io.StringIO()
    monkeypatch.setattr(sys, "stderr", quiet)
    bar = progress.FigureBar()
    bar.update(0, 3)
    bar.update(3, 3)
    bar.close()
    assert quiet.getvalue() == ""
