"""Dataset references: names, loader options and slices in one string."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from albot1.data.errors import DatasetNotFoundError, SliceError
from albot1.data.open import canonical_reference, open_sequence, parse_options, split_slice
from albot1.data.transforms import head, stride


def test_parse_options_converts_numbers() -> None:
    assert parse_options("odometry=laser-pose&max_range=80&tol=0.5", "x") == {
        "odometry": "laser-pose",
        "max_range": 80,
        "tol": 0.5,
    }


def test_parse_options_leaves_grouped_and_unicode_digits_as_text() -> None:
    """``int()`` reads ``1_0`` and ``１０`` as 10; an option so written stays text for its loader to refuse."""
    assert parse_options("max_range=1_0&tol=\uff10.5&n=\u0663", "x") == {
        "max_range": "1_0",
        "tol": "\uff10.5",
        "n": "\u0663",
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
        ("synthetic-office-startstop[5:10]", r"slice START is 5, but only prefixes exist \(a START, if given, is 0\)"),
        # Python's ``\d`` and ``int()`` read full-width and Arabic-Indic digits; a slice is ASCII digits only
        ("synthetic-office-startstop[:\uff13\uff10]", r"slice \[:\uff13\uff10\] is not understood"),
        ("synthetic-office-startstop[::\u0662]", r"slice \[::\u0662\] is not understood"),
        ("synthetic-office-startstop[\uff10:5]", r"is not understood"),
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


_SLICES = st.lists(st.tuples(st.none() | st.integers(1, 40), st.none() | st.integers(1, 5)), max_size=4)


@given(_SLICES)
def test_split_slice_selects_what_the_slices_select_one_after_another(
    slices: list[tuple[int | None, int | None]],
) -> None:
    """One (STOP, STEP) keeps exactly the scans the slices keep applied left to right (as Python slices would)."""
    text = "world" + "".join(f"[:{stop or ''}{'' if step is None else f':{step}'}]" for stop, step in slices)
    expected = list(range(100))
    for stop, step in slices:
        expected = expected[:stop][::step]
    base, stop, step = split_slice(text)
    assert base == "world" and list(range(100))[:stop][::step] == expected
    assert step != 1  # a step of 1 is no step


@pytest.mark.parametrize(
    ("ref", "expected"),
    [
        ("intel", ("intel", None, None)),
        ("intel[:]", ("intel", None, None)),
        ("intel[:300:1]", ("intel", 300, None)),
        ("intel[:0300]", ("intel", 300, None)),
        ("intel[:300][::2]", ("intel", 300, 2)),
        ("intel[::2][:300]", ("intel", 600, 2)),
        ("intel-corrected?odometry=laser-pose[::3]", ("intel-corrected?odometry=laser-pose", None, 3)),
        ("a[b]c", ("a[b]c", None, None)),
        ("intel[0:300]", ("intel", 300, None)),
        ("intel[00::2]", ("intel", None, 2)),
    ],
)
def test_split_slice_examples(ref: str, expected: tuple[str, int | None, int | None]) -> None:
    assert split_slice(ref) == expected


def test_an_existing_path_with_brackets_is_not_sliced(tmp_path: Path) -> None:
    log = tmp_path / "log[:5]"
    log.write_text("")
    assert split_slice(str(log)) == (str(log), None, None)
    assert split_slice(f"{log}[:3]") == (str(log), 3, None)


def test_nested_slices_open_the_scans_of_the_one_slice_they_make() -> None:
    nested = open_sequence("synthetic-office-startstop[::2][:7]")
    single = open_sequence("synthetic-office-startstop[:14:2]")
    assert len(nested) == len(single) == 7 and (nested.timestamps == single.timestamps).all()


@pytest.mark.parametrize(
    ("ref", "canonical"),
    [
        ("intel", "intel"),
        ("intel[:]", "intel"),
        ("intel[::1]", "intel"),
        ("intel[:300]", "intel[:300]"),
        ("intel[:300:1]", "intel[:300]"),
        ("intel[0:300]", "intel[:300]"),
        ("intel[:0300:]", "intel[:300]"),
        ("intel[:600][:300]", "intel[:300]"),
        ("intel[::2]", "intel[::2]"),
        ("intel[:300:2]", "intel[:300:2]"),
        ("intel[::2][:150]", "intel[:300:2]"),
        ("intel-corrected?odometry=laser-pose[::3]", "intel-corrected?odometry=laser-pose[::3]"),
        # slices before the loader options select the same scans: one spelling, one run key (they were two)
        ("intel-corrected[::3]?odometry=laser-pose", "intel-corrected?odometry=laser-pose[::3]"),
        ("intel-corrected[:400]?odometry=laser-pose[:10]", "intel-corrected?odometry=laser-pose[:10]"),
        ("intel-corrected[:400][::2]?odometry=laser-pose", "intel-corrected?odometry=laser-pose[:400:2]"),
    ],
)
def test_canonical_reference_spells_each_slice_one_way(ref: str, canonical: str) -> None:
    assert canonical_reference(ref) == canonical


@given(_SLICES)
def test_the_canonical_spelling_is_a_fixed_point_that_selects_the_same_scans(
    slices: list[tuple[int | None, int | None]],
) -> None:
    text = "world" + "".join(f"[:{stop or ''}{'' if step is None else f':{step}'}]" for stop, step in slices)
    canonical = canonical_reference(text)
    assert canonical_reference(canonical) == canonical
    assert split_slice(canonical) == split_slice(text)


def test_a_stop_or_step_beyond_any_log_is_every_scan_or_the_first_not_a_crash() -> None:
    whole = open_sequence("synthetic-office-startstop").count_scans()
    assert sum(1 for _ in open_sequence("synthetic-office-startstop[:" + "9" * 30 + "]").frames()) == whole
    assert sum(1 for _ in open_sequence("synthetic-office-startstop[::" + "9" * 30 + "]").frames()) == 1


def test_slices_before_the_loader_options_open_the_same_scans_and_errors_quote_them_as_written() -> None:
    before = open_sequence("synthetic-office-startstop[:12:3]?odometry=reference")
    after = open_sequence("synthetic-office-startstop?odometry=reference[:12:3]")
    stamps = [[frame.scan.timestamp for frame in sequence.frames()] for sequence in (before, after)]
    assert len(stamps[0]) == 4 and stamps[0] == stamps[1]
    assert split_slice("aces[:400]?odometry=laser-pose") == ("aces?odometry=laser-pose", 400, None)
    with pytest.raises(SliceError) as caught:
        split_slice("aces[100:400]?odometry=laser-pose")
    assert str(caught.value).startswith("'aces[100:400]?odometry=laser-pose': slice START is 100, but only prefixes")


@pytest.mark.parametrize(
    "spelling",
    [
        "synthetic-office-startstop?views=2:30&odometry=reference[:6]",
        "synthetic-office-startstop? odometry = reference &&views=2:30&[:6]",
        "synthetic-office-startstop[:6]?views=2:30&odometry=reference",
    ],
)
def test_loader_options_in_another_order_or_spacing_are_one_spelling_of_the_same_scans(spelling: str) -> None:
    """The options are applied in one order whatever order they are written in: one run key, not one per spelling.

    ``albot1 run`` and a suite's label key a run by this spelling; ``?views=..&odometry=reference`` and
    ``?odometry=reference&views=..`` (or a trailing ``?``) were two run folders and two table rows of one run.
    """
    canonical = "synthetic-office-startstop?odometry=reference&views=2:30[:6]"
    assert canonical_reference(spelling) == canonical
    assert canonical_reference(canonical) == canonical
    stamps = [[f.scan.timestamp for f in open_sequence(ref).frames()] for ref in (spelling, canonical)]
    assert len(stamps[0]) == 6 and stamps[0] == stamps[1]
    assert canonical_reference("synthetic-office-startstop?") == "synthetic-office-startstop"
    assert canonical_reference("synthetic-office-startstop[:6]?") == "synthetic-office-startstop[:6]"
