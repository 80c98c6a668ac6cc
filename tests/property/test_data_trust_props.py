"""Properties of what users' files may make the project do (hypothesis).

* Any manifest ``path`` either is refused with one DataError or, joined to
  a data root, stays inside it.
* Any store record document either reads back as a typed record or is one
  RecordError naming the file; a cell key read back is always a plain folder
  name.
* Any name written into a Markdown page carries no HTML and no line break.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.bench.store_records import parse_failure, parse_plan
from albot1.data.errors import DataError
from albot1.data.manifest import parse_manifest
from albot1.records import RecordError
from albot1.report.markdown import code, text

SHA = "a" * 64
PATH_TEXT = st.lists(st.sampled_from([*"ab./\\~ \0:", "..", "é"]), max_size=10).map("".join)
JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-5, 20) | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=12,
)


@settings(max_examples=300, deadline=None)
@given(PATH_TEXT)
def test_a_manifest_path_is_refused_or_stays_inside_the_data_root(value: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        manifest = Path(folder) / "t.toml"
        entry = json.dumps(value, ensure_ascii=False)
        manifest.write_text(f'name = "t"\n\n[[files]]\nrole = "log"\npath = {entry}\nsha256 = "{SHA}"\n')
        try:
            parsed = parse_manifest(manifest)
        except DataError as exc:
            assert str(exc).startswith(f"{manifest}")
            return
        root = Path(folder) / "root"
        joined = os.path.normpath(root / parsed.log.path)
        assert joined.startswith(str(root) + os.sep)


def _plan(cells: Any, extra: dict[str, Any]) -> dict[str, Any]:
    base = {
        "suite": "s",
        "suite_path": None,
        "description": "",
        "cells": cells,
        "skipped_datasets": [],
        "skipped_methods": [],
        "config_failures": {},
        "seeds": [0],
        "degradations": ["none"],
        "machine": {},
    }
    return {**base, **extra}


CELL_FIELDS = st.fixed_dictionaries(
    {
        "suite": st.just("s"),
        "dataset": st.text(max_size=6),
        "dataset_label": st.text(max_size=6),
        "method": st.just("odometry"),
        "method_label": st.text(max_size=6),
        "preset": st.just("default"),
        "degradation": st.just("none"),
        "seed": st.integers(0, 3) | st.text(max_size=3),
        "key": st.text("0123456789abcdef./", min_size=14, max_size=18),
        "code_version": st.just("v"),
        "time_s": st.floats(0, 100) | st.text(max_size=3),
        "memory_mb": st.floats(0, 100),
    }
)


@settings(max_examples=200, deadline=None)
@given(st.lists(CELL_FIELDS, max_size=3) | JSON, st.dictionaries(st.sampled_from(["machine", "seeds"]), JSON))
def test_a_grid_plan_reads_back_typed_or_is_one_error_naming_the_file(cells: Any, extra: dict[str, Any]) -> None:
    path = Path("/results/s/grid.json")
    try:
        plan = parse_plan(_plan(cells, extra), path)
    except RecordError as exc:
        assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc)
        return
    for cell in plan.cells:
        assert len(cell.key) == 16 and set(cell.key) <= set("0123456789abcdef")
        assert isinstance(cell.seed, int)


@settings(max_examples=200, deadline=None)
@given(st.dictionaries(st.sampled_from(["reason", "kind", "exit_code", "elapsed_s", "log", "host"]), JSON))
def test_a_failure_record_reads_back_typed_or_is_one_error_naming_the_file(data: dict[str, Any]) -> None:
    path = Path("/results/s/runs/0123456789abcdef/FAILED.json")
    try:
        record = parse_failure(data, path)
    except RecordError as exc:
        assert str(exc).startswith(f"{path}: ")
        return
    assert isinstance(record.reason, str) and record.elapsed_s >= 0
    assert record.log is None or Path(record.log).name == record.log


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=30))
def test_names_in_markdown_carry_no_html_and_no_line_break(value: str) -> None:
    written = text(value)
    assert "<" not in written and ">" not in written and "\n" not in written and "\r" not in written
    span = code(value)
    fence = span[: len(span) - len(span.lstrip("`"))]
    inner = span[len(fence) : len(span) - len(fence)]
    assert span.endswith(fence) and fence not in inner and "\n" not in span
