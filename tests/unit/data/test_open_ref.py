"""Dataset references: names, loader options and slices in one string."""

from __future__ import annotations

import pytest

from albot1.data.errors import DatasetNotFoundError, SliceError
from albot1.data.open import open_sequence, parse_options
from albot1.data.transforms import head, stride


def test_parse_options_converts_numbers() -> None:
    assert parse_options("odometry=laser-pose&max_range=80&tol=0.5", "x") == {
        "odometry": "laser-pose",
        "max_range": 80,
        "tol": 0.5,
    }


def test_bad_option_names_the_ref() -> None:
    with pytest.raises(DatasetNotFoundError, match="'x': loader option 'novalue' is not of the form KEY=VALUE"):
        parse_options("novalue", "x")


def test_slice_of_a_world() -> None:
    full = open_sequence("synthetic-office-startstop")
    part = open_sequence("synthetic-office-startstop[:20:2]")
    assert len(part) == 10
    assert part.timestamps[1] == full.timestamps[2]


def test_world_rejects_loader_options() -> None:
    with pytest.raises(DatasetNotFoundError, match="unknown loader option.s. laps2; expected start or laps"):
        open_sequence("synthetic-office-startstop?laps2=1")
    # odometry is an option of every dataset, with the values its source has: a world's is `reference` only
    with pytest.raises(DatasetNotFoundError, match="odometry='laser-pose'; a synthetic world takes odometry=reference"):
        open_sequence("synthetic-office-startstop?odometry=laser-pose")


def test_unknown_name_points_to_the_listing() -> None:
    with pytest.raises(DatasetNotFoundError, match=r"'no-such-dataset' is neither .*`albot1 datasets list` lists all"):
        open_sequence("no-such-dataset")


def test_corrected_log_with_clean_odometry(data_file) -> None:  # type: ignore[no-untyped-def]
    data_file("radish-corrected/intel-corrected.log.gz")
    seq = open_sequence("intel-corrected?odometry=laser-pose[:50]")
    assert seq.count_scans() == 50 and seq.reference is not None
    assert (seq.odometry == seq.reference).all()


@pytest.mark.parametrize(
    ("ref", "message"),
    [
        ("synthetic-office-startstop[:0]", r"'synthetic-office-startstop\[:0\]': slice STOP is 0, expected a positive"),
        ("synthetic-office-startstop[::0]", r"slice STEP is 0, expected a positive integer"),
        ("synthetic-office-startstop[:5:0]", r"slice STEP is 0"),
        ("synthetic-office-startstop[5]", r"slice \[5\] is not understood; expected \[:STOP\], \[:STOP:STEP\]"),
        ("synthetic-office-startstop[-5:]", r"slice \[-5:\] is not understood"),
        ("synthetic-office-startstop[:-5]", r"slice \[:-5\] is not understood"),
        ("synthetic-office-startstop[:" + "9" * 5000 + "]", r"is not understood"),
    ],
)
def test_bad_slices_are_one_line_errors_naming_the_reference(ref: str, message: str) -> None:
    with pytest.raises(SliceError, match=message):
        open_sequence(ref)


def test_zero_limits_and_strides_are_data_errors() -> None:
    seq = open_sequence("synthetic-office-startstop")
    with pytest.raises(SliceError, match="expected a positive number of scans .* got 0"):
        head(seq, 0)
    with pytest.raises(SliceError, match="expected a positive stride .* got -1"):
        stride(seq, -1)
    assert sum(1 for _ in open_sequence("synthetic-office-startstop[:]").frames()) == seq.count_scans()
