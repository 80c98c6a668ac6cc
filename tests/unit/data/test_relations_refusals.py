"""What the relations reader refuses (with the line) and how it counts identical repeated lines."""

from __future__ import annotations

import logging
import warnings
from pathlib import Path
from typing import Literal

import numpy as np
import pytest

from albot1.data.errors import DataError
from albot1.data.relations import read_relations, repeat_policy, write_relations


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0.2 0.2 1 0 0 0 0 0\n", ":1: t1 and t2 are both 0.2: a relation from a pose to itself"),
        ("0.2 0.2 0 0 0 0 0 0\n", ":1: t1 and t2 are both 0.2"),
        ("0 0.2 1e308 0 0 0 0 0\n", ":1: motion (1e+308, 0) m is beyond 1e+08 m"),
        ("0 1e300 1 0 0 0 0 0\n", ":1: timestamp beyond 1e+11"),
        ("0 0.2 1e400 0 0 0 0 0\n", ":1: non-finite value"),
        (  # a file in degrees: 90 deg read as 90 rad would score a wrong heading, silently
            "0 0.2 1 0 0 0 0 0\n0.2 0.4 1 1 0 0 0 90.0\n",
            ":2: yaw 90 is beyond pi; expected radians in [-pi, pi] (a file written in degrees?)",
        ),
        ("0 0.2 1 0 0 0 0 -3.15\n", ":1: yaw -3.15 is beyond pi"),
        (
            "0 0.2 1 0 0 0 0 0\n# x\n0 0.2 2 0 0 0 0 0\n",
            ":3: the relation t1=0.0 t2=0.2 is listed twice with different",
        ),
    ],
)
def test_bad_relations_are_refused_with_the_line(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "r.relations"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy warning leaks
        warnings.simplefilter("ignore", ResourceWarning)  # another test's garbage, freed here by chance
        with pytest.raises(DataError) as caught:
            read_relations(path)
    assert str(caught.value).startswith(f"{path}{message}")


_REPEATED = "0 0.2 1 0 0 0 0 0\n0.2 0.4 1 0 0 0 0 0\n0 0.2 1 0 0 0 0 0\n0.2 0.4 1 0 0 0 0 0\n"


def test_identical_repeated_lines_are_counted_once_by_default_and_said(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "r.relations"
    path.write_text(_REPEATED)
    with caplog.at_level(logging.WARNING):
        relations = read_relations(path)
    assert len(relations) == 2 and relations.repeats == 2 and not relations.repeats_counted
    assert relations.t1.tolist() == [0.0, 0.2] and relations.t2.tolist() == [0.2, 0.4]
    assert "2 relation line(s) repeat an earlier line identically; each relation is counted once" in caplog.text
    assert "line 3 (= 1), 4 (= 2)" in caplog.text


def test_keep_counts_identical_repeated_lines_as_listed_and_says_so(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "r.relations"
    path.write_text(_REPEATED)
    with caplog.at_level(logging.WARNING):
        relations = read_relations(path, repeats="keep")
    assert len(relations) == 4 and relations.repeats == 2 and relations.repeats_counted
    assert relations.t1.tolist() == [0.0, 0.2, 0.0, 0.2]
    assert "each is counted as listed (relations_repeats=keep)" in caplog.text


@pytest.mark.parametrize("policy", ["drop", "keep"])
def test_a_written_copy_reads_back_with_its_sources_reading_and_count(
    tmp_path: Path, policy: Literal["drop", "keep"], caplog: pytest.LogCaptureFixture
) -> None:
    source = tmp_path / "r.relations"
    source.write_text(_REPEATED)
    relations = read_relations(source, repeats=policy)
    copy = tmp_path / "copy.txt"
    write_relations(copy, relations)
    caplog.clear()
    assert copy.read_text().splitlines()[0] == f"# albot1: relations_repeats={policy} repeated_lines=2"
    with caplog.at_level(logging.WARNING):
        back = read_relations(copy, warn_repeats=False)  # the default (drop) does not override the copy's note
    assert caplog.text == ""
    assert (len(back), back.repeats, back.repeats_counted) == (len(relations), 2, policy == "keep")
    assert np.array_equal(back.poses, relations.poses)


def test_a_copy_without_repeats_has_no_note(tmp_path: Path) -> None:
    source = tmp_path / "r.relations"
    source.write_text("0 0.2 1 0 0 0 0 0\n")
    copy = tmp_path / "copy.txt"
    write_relations(copy, read_relations(source))
    assert not copy.read_text().startswith("#")


@pytest.mark.parametrize(
    "note",
    [
        "# albot1: relations_repeats=twice repeated_lines=2",
        "# albot1: relations_repeats=drop repeated_lines=x",
        "# albot1: relations_repeats=drop",
    ],
)
def test_a_broken_note_is_refused_with_its_line(tmp_path: Path, note: str) -> None:
    path = tmp_path / "r.relations"
    path.write_text(note + "\n0 0.2 1 0 0 0 0 0\n")
    with pytest.raises(DataError) as caught:
        read_relations(path)
    assert str(caught.value).startswith(f"{path}:1:")


def test_an_unknown_reading_is_refused_in_one_line() -> None:
    with pytest.raises(DataError) as caught:
        repeat_policy("twice", "x.clf")
    assert str(caught.value) == (
        "x.clf: relations_repeats='twice'; expected drop (count each relation once) or keep (as listed)"
    )


@pytest.mark.parametrize("yaw", ["3.141593", "-3.141593", "3.1416", "3.14159265358979", "-3.141592654", "0"])
def test_a_yaw_of_pi_as_printed_is_read(tmp_path: Path, yaw: str) -> None:
    """pi printed with 4 or 6 decimals rounds up past pi (3.1416, 3.141593): still radians, still read."""
    path = tmp_path / "r.relations"
    path.write_text(f"0 0.2 1 0 0 0 0 {yaw}\n")
    assert read_relations(path).poses[0, 2] == float(yaw)


# line 3 gives line 1's relation (a 90 deg left turn ending 2 m ahead, 1 m left) from t2 back to t1: its inverse
_BOTH_WAYS = "0 0.2 2 1 0 0 0 1.5707963\n0.2 0.4 1 0 0 0 0 0\n0.2 0 -1 2 0 0 0 -1.5707963\n"


def test_a_relation_given_in_both_directions_is_one_relation_counted_as_repeats_are(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Both directions were read as two relations: that pair weighted double, with two different translation errors
    (the error of inv(d) against inv(d*) is not that of d against d*), whichever way the file's author wrote it."""
    path = tmp_path / "r.relations"
    path.write_text(_BOTH_WAYS)
    with caplog.at_level(logging.WARNING):
        relations = read_relations(path)
    assert len(relations) == 2 and relations.repeats == 1 and not relations.repeats_counted
    assert relations.t1.tolist() == [0.0, 0.2] and relations.t2.tolist() == [0.2, 0.4]
    assert "1 relation line(s) repeat an earlier line identically or in the other direction" in caplog.text
    assert "line 3 (= 1 reversed)" in caplog.text
    kept = read_relations(path, repeats="keep", warn_repeats=False)  # the published evaluator's reading: as listed
    assert len(kept) == 3 and kept.repeats == 1 and kept.repeats_counted


def test_a_relation_given_in_both_directions_with_motions_that_disagree_is_refused_with_the_line(
    tmp_path: Path,
) -> None:
    path = tmp_path / "r.relations"
    path.write_text(_BOTH_WAYS.replace("0.2 0 -1 2", "0.2 0 -1 2.5"))
    with pytest.raises(DataError) as caught:
        read_relations(path)
    assert str(caught.value).startswith(
        f"{path}:3: the relation t1=0.0 t2=0.2 of line 1 is listed again in the other direction with a motion that "
        "is not its inverse (composed they move 0.5 m"
    )
