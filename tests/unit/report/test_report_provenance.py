"""Data checksums per dataset on the report, runs on different data kept apart, names written as text."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

from albot1.bench.grid import Cell
from albot1.report.collect import CellRecord
from albot1.report.markdown import code, text
from albot1.report.provenance import data_by_dataset, data_identity, data_lines, describe_data, separate_data

A, B = "a" * 64, "b" * 64


def record(label: str, checksums: dict[str, str] | None) -> CellRecord:
    cell = Cell("s", label, label, "odometry", "odometry", "default", "none", 0, "0" * 16, "v", 1.0, 1.0)
    result = None if checksums is None else SimpleNamespace(dataset_info=SimpleNamespace(data_sha256=checksums))
    return CellRecord(cell, "done" if result else "failed", Path("."), cast(Any, result), None, None)


def test_runs_of_one_dataset_on_different_data_never_share_a_label() -> None:
    records = [record("aces", {"aces.clf": A}), record("aces", {"aces.clf": B}), record("aces", None)]
    labels = [r.cell.dataset_label for r in separate_data(records)]
    assert labels == ["aces @aaaaaaaaaaaa", "aces @bbbbbbbbbbbb", "aces"]
    same = [record("intel", {"intel.clf": A}), record("intel", {"intel.clf": A}), record("w", {})]
    assert [r.cell.dataset_label for r in separate_data(same)] == ["intel", "intel", "w"]


def test_the_identity_of_several_files_covers_all_of_them() -> None:
    one = data_identity(record("x", {"log": A, "rel": A}))
    other = data_identity(record("x", {"log": A, "rel": B}))
    assert len(one) == 12 and one != other and data_identity(record("x", {})) == ""


def test_each_dataset_names_its_short_checksums() -> None:
    data = data_by_dataset([record("aces", {"aces.clf": A, "aces.rel": B}), record("w", {}), record("x", None)])
    assert data == {"aces": {"aces.clf": "a" * 12, "aces.rel": "b" * 12}, "w": {}}
    assert describe_data(data["aces"]) == "aces.clf sha256 aaaaaaaaaaaa, aces.rel sha256 bbbbbbbbbbbb"
    assert describe_data({}).startswith("no data file recorded (a synthetic world, named by the code version, or")


def test_markdown_text_and_code_never_carry_html_or_break_out() -> None:
    assert text('<script>alert("x")</script> | a\nb') == ('&lt;script&gt;alert("x")&lt;/script&gt; \\| a b')
    assert text("the odometry's prediction") == "the odometry's prediction"  # not &#x27;: no element can start
    assert text("[link](javascript:x) `c`") == "\\[link\\](javascript:x) &#96;c&#96;"
    assert code("a`b") == "``a`b``"
    assert code("`x") == "`` `x ``"
    assert code("<b>") == "`<b>`"  # a code span shows its content as written, it never renders HTML


def test_pages_of_several_stores_list_each_data_identity_of_a_label() -> None:
    records = [record("aces", {"aces.clf": A}), record("aces", {"aces.clf": A}), record("aces", {"aces.clf": B})]
    assert data_lines([*records, record("aces", None)]) == [
        "aces: aces.clf sha256 aaaaaaaaaaaa",
        "aces: aces.clf sha256 bbbbbbbbbbbb",
    ]
