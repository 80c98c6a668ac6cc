"""What the relations reader refuses (with the line) and how it counts identical repeated lines."""

from __future__ import annotations

import logging
import warnings
from pathlib import Path

import pytest

from albot1.data.errors import DataError
from albot1.data.relations import read_relations


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0.2 0.2 1 0 0 0 0 0\n", ":1: t1 and t2 are both 0.2: a relation from a pose to itself"),
        ("0.2 0.2 0 0 0 0 0 0\n", ":1: t1 and t2 are both 0.2"),
        ("0 0.2 1e308 0 0 0 0 0\n", ":1: motion (1e+308, 0) m is beyond 1e+08 m"),
        ("0 1e300 1 0 0 0 0 0\n", ":1: timestamp beyond 1e+11"),
        ("0 0.2 1e400 0 0 0 0 0\n", ":1: non-finite value"),
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
        with pytest.raises(DataError) as caught:
            read_relations(path)
    assert str(caught.value).startswith(f"{path}{message}")


def test_identical_repeated_lines_are_counted_as_listed_and_said(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "r.relations"
    path.write_text("0 0.2 1 0 0 0 0 0\n0.2 0.4 1 0 0 0 0 0\n0 0.2 1 0 0 0 0 0\n0.2 0.4 1 0 0 0 0 0\n")
    with caplog.at_level(logging.WARNING):
        relations = read_relations(path)
    assert len(relations) == 4 and relations.repeats == 2
    assert "2 relation line(s) repeat an earlier line identically" in caplog.text
    assert "line 3 (= 1), 4 (= 2)" in caplog.text
