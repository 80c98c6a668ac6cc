"""Relations files (Kuemmerle et al. 2009): exact parsing, round trip, errors with file:line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.data.errors import ParseError
from albot1.data.model import Relations
from albot1.data.relations import read_relations, write_relations


def test_read_keeps_the_planar_part(tmp_path: Path) -> None:
    path = tmp_path / "r.relations"
    path.write_text("# comment\n\n90.2 90.7 0.42 -0.00075 0 0 0 0.01726\n1 2 3 4 0.000000 0 0 -0.5\n")
    rel = read_relations(path)
    np.testing.assert_array_equal(rel.t1, [90.2, 1.0])
    np.testing.assert_array_equal(rel.poses, [[0.42, -0.00075, 0.01726], [3.0, 4.0, -0.5]])


def test_round_trip(tmp_path: Path) -> None:
    rel = Relations(np.array([1.5, 2.25]), np.array([3.0, 9.125]), np.array([[0.1, -0.2, 0.3], [4.0, 5.0, -3.0]]))
    write_relations(tmp_path / "x.txt", rel)
    back = read_relations(tmp_path / "x.txt")
    np.testing.assert_allclose(back.poses, rel.poses, atol=1e-9)
    np.testing.assert_allclose(back.t2, rel.t2, atol=1e-9)
    assert not list(tmp_path.glob(".*tmp"))


def test_an_empty_copy_this_project_wrote_is_zero_relations(tmp_path: Path) -> None:
    write_relations(tmp_path / "e.txt", Relations(np.zeros(0), np.zeros(0), np.zeros((0, 3))))
    assert len(read_relations(tmp_path / "e.txt", empty_ok=True)) == 0


@pytest.mark.parametrize(
    ("text", "found"),
    [("", "the file is empty"), ("# relations\n\n   \n", "its 3 line(s) are all blank or '#' comments")],
)
def test_a_relations_file_without_a_relation_is_refused_in_one_line(tmp_path: Path, text: str, found: str) -> None:
    path = tmp_path / "e.relations"
    path.write_text(text)
    with pytest.raises(ParseError) as refused:
        read_relations(path)
    assert str(refused.value) == (
        f"{path}: no relation: {found}; expected one relation per line (t1 t2 x y z roll pitch yaw)"
    )


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("1 2 3", r"r\.txt:2: 3 fields, expected 8"),
        ("1 2 3 4 0 0 0 x", r"r\.txt:2: field 'x' is not a number"),
        ("1 2 3 4 0 0 0 nan", r"r\.txt:2: non-finite value"),
        ("1 2 3 4 0.5 0 0 0", r"r\.txt:2: z, roll and pitch must be 0"),
    ],
)
def test_bad_lines(tmp_path: Path, line: str, message: str) -> None:
    path = tmp_path / "r.txt"
    path.write_text("1 2 3 4 0 0 0 0\n" + line + "\n")
    with pytest.raises(ParseError, match=message):
        read_relations(path)
