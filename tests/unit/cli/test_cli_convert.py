"""``albot1 convert`` (and one `albot1 run --set`) as a user runs it, on synthetic worlds: what it did not carry
over, and the paths its errors name."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from albot1.cli.app import main


def run_cli(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    monkeypatch.setattr(sys, "argv", ["albot1", *args])
    try:
        main()
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def test_convert_says_which_ground_truth_the_output_cannot_hold(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    out_path = tmp_path / "dl.albotlog"
    code, out, err = run_cli(monkeypatch, capsys, "convert", "synthetic-places-double-loop[:20]", str(out_path))
    assert code == 0, err
    assert out == f"wrote 20 scans from synthetic:synthetic-places-double-loop to {out_path} (albot-log)\n"
    assert err == (
        "note: not carried over (albot-log cannot hold it): "
        "the floor plan (144 wall segments, 6 rooms, 7 doorways, 10 doorway crossings), licence\n"
    )


def test_the_format_help_lists_what_the_registry_reads_and_writes() -> None:
    from albot1.cli import convert as command
    from albot1.data.loaders.registry import FORMATS, WRITE_ONLY_FORMATS

    assert command.READ_FORMATS == tuple(FORMATS)
    assert command.WRITE_FORMATS == (*[n for n, (_, w) in FORMATS.items() if w], *WRITE_ONLY_FORMATS)
    assert command.FORMAT_HELP.startswith("carmen | ros1 | ros2-sqlite3 | ros2-mcap | albot-log | rawlog (")
    assert "rawlog is write-only" in command.FORMAT_HELP and "rawlog" not in command.FROM_HELP


def test_converting_a_rawlog_back_names_it_write_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    rawlog = tmp_path / "pl.rawlog"
    assert run_cli(monkeypatch, capsys, "convert", "synthetic-places-loop[:5]", str(rawlog))[0] == 0
    code, _, err = run_cli(monkeypatch, capsys, "convert", str(rawlog), str(tmp_path / "x.clf"))
    assert code == 1
    assert err.startswith(f"albot1: error: {rawlog}: an MRPT rawlog; albot1 writes rawlogs only as input for MRPT's")
    assert err.count("\n") == 1 and not (tmp_path / "x.clf").exists()


def test_a_rejected_override_repeats_the_value_found(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run_cli(monkeypatch, capsys, "run", "odometry", "synthetic-places-loop[:5]", "--set", "map_every=0")
    assert code == 1
    assert err == (
        "albot1: error: invalid config for method 'odometry' (preset 'default'): "
        "map_every: Input should be greater than or equal to 1, found 0 (from --set)\n"
    )
