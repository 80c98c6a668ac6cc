"""A build is skipped exactly when nothing it reads changed and what it wrote is untouched (albot1.report.build_stamp).

Synthetic folders stand for a store and a report: every rule of the stamp is
checked on its own (content, not time, for inputs; size and time for
outputs; options, code version, stamp damage; files added or removed).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

import pytest

from albot1 import versions
from albot1.report import build_stamp
from albot1.report.build_stamp import (
    STAMP,
    BuildStamp,
    Fingerprints,
    Source,
    folder_files,
    forget_all,
    unsettled,
)
from albot1.report.collect import CellRecord, as_of
from albot1.report.figure_cache import STAMPS, FigureCache

OPTIONS = {"plots": True, "map_style": "grid"}


def _store(root: Path) -> Path:
    (root / "runs" / "a").mkdir(parents=True)
    (root / "grid.json").write_text('{"suite": "s"}')
    (root / "runs" / "a" / "metrics.json").write_text('{"ate": 1.0}')
    (root / "runs" / "a" / "result.json").write_text('{"scans": 3}')
    return root


def _build(store: Path, out: Path, options: dict[str, Any] = OPTIONS) -> None:
    """What a build does here: write two outputs, then stamp them."""
    out.mkdir(exist_ok=True)
    (out / "README.md").write_text("report")
    (out / "plots").mkdir(exist_ok=True)
    (out / "plots" / "a.png").write_bytes(b"png")
    stamp = BuildStamp(out)
    stamp.record([Source(store)], stamp.digest([Source(store)], options), folder_files(out), "README.md")


@pytest.fixture()
def built(tmp_path: Path) -> tuple[Path, Path]:
    store, out = _store(tmp_path / "store"), tmp_path / "report"
    _build(store, out)
    return store, out


def _later(path: Path) -> None:
    """Move a file's modification time one second on (a rewrite that a stat can see)."""
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))


def test_an_untouched_build_is_fresh_and_gives_its_payload(built: tuple[Path, Path]) -> None:
    _, out = built
    assert BuildStamp(out).fresh(OPTIONS) == "README.md"
    assert folder_files(out) == [out / "README.md", out / STAMP, out / "plots" / "a.png"]


def test_an_input_rewritten_with_the_same_bytes_changes_nothing(built: tuple[Path, Path]) -> None:
    store, out = built
    grid = store / "grid.json"
    grid.write_text(grid.read_text())  # `albot1 bench` rewrites grid.json on every run
    _later(grid)
    stamp = BuildStamp(out)
    assert stamp.fresh(OPTIONS) == "README.md"
    assert stamp.fingerprints.read == 1  # only the file whose time changed was read again


def test_a_changed_added_or_removed_input_invalidates(built: tuple[Path, Path]) -> None:
    store, out = built
    metrics = store / "runs" / "a" / "metrics.json"
    metrics.write_text('{"ate": 2.0}')  # same size, other bytes
    _later(metrics)
    assert BuildStamp(out).fresh(OPTIONS) is None
    metrics.write_text('{"ate": 1.0}')  # back to what the build read
    assert BuildStamp(out).fresh(OPTIONS) == "README.md"
    (store / "runs" / "b").mkdir()
    (store / "runs" / "b" / "DONE").write_text("b")
    assert BuildStamp(out).fresh(OPTIONS) is None
    (store / "runs" / "b" / "DONE").unlink()
    assert BuildStamp(out).fresh(OPTIONS) == "README.md"
    (store / "runs" / "a" / "result.json").unlink()
    assert BuildStamp(out).fresh(OPTIONS) is None


def _rewrite_keeping_time(path: Path, text: str) -> None:
    """Rewrite ``path`` with ``text`` and put its modification time back (``touch -r``, ``cp -p``, ``rsync -t``)."""
    st = path.stat()
    assert len(text.encode()) == st.st_size  # the same size: size and time alone cannot tell
    path.write_text(text)
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))


def test_an_input_rewritten_with_its_size_and_time_kept_invalidates(built: tuple[Path, Path]) -> None:
    store, out = built
    _rewrite_keeping_time(store / "runs" / "a" / "metrics.json", '{"ate": 9.0}')
    stamp = BuildStamp(out)
    assert stamp.fresh(OPTIONS) is None  # the tables would show the old ATE
    assert stamp.fingerprints.read == 1


def test_an_output_rewritten_with_its_size_and_time_kept_invalidates(built: tuple[Path, Path]) -> None:
    _, out = built
    _rewrite_keeping_time(out / "README.md", "REPORT")
    assert BuildStamp(out).fresh(OPTIONS) is None


def test_a_copied_store_is_read_again_and_changes_nothing(built: tuple[Path, Path], tmp_path: Path) -> None:
    store, out = built
    stamp = BuildStamp(out)
    digest = stamp.digest([Source(store)], OPTIONS)
    copy = tmp_path / "copy"
    shutil.copytree(store, copy, copy_function=shutil.copy2)  # times kept, new inodes
    shutil.rmtree(store)
    copy.rename(store)
    again = BuildStamp(out)
    assert again.digest([Source(store)], OPTIONS) == digest
    assert again.fingerprints.read == 3  # other inodes: every file read again, none trusted by its time


def test_hidden_files_are_not_inputs(built: tuple[Path, Path]) -> None:
    store, out = built
    (store / ".lock").write_text("host pid 1\n")  # the runner's lock, rewritten by every `albot1 bench`
    assert BuildStamp(out).fresh(OPTIONS) == "README.md"


def test_a_deleted_or_modified_output_invalidates(built: tuple[Path, Path]) -> None:
    _, out = built
    (out / "plots" / "a.png").unlink()
    assert BuildStamp(out).fresh(OPTIONS) is None
    (out / "plots" / "a.png").write_bytes(b"png")  # recreated: another modification time
    _later(out / "plots" / "a.png")
    assert BuildStamp(out).fresh(OPTIONS) is None


def test_an_output_edited_in_place_invalidates(built: tuple[Path, Path]) -> None:
    _, out = built
    (out / "README.md").write_text("report, edited by hand")
    assert BuildStamp(out).fresh(OPTIONS) is None


def test_other_options_or_code_invalidate(built: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch) -> None:
    _, out = built
    assert BuildStamp(out).fresh({**OPTIONS, "map_style": "points"}) is None
    monkeypatch.setattr(versions, "code_version", lambda: "0.0.0+other")
    assert BuildStamp(out).fresh(OPTIONS) is None


def test_a_changed_project_toml_invalidates(built: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch) -> None:
    _, out = built
    monkeypatch.setattr(build_stamp, "resources_digest", lambda: [["datasets", "x.toml", "other"]])
    assert BuildStamp(out).fresh(OPTIONS) is None


@pytest.mark.parametrize(
    "text", ["", "{", "[]", json.dumps({"version": 0}), json.dumps({"version": build_stamp.STAMP_VERSION})]
)
def test_a_damaged_or_foreign_stamp_is_not_trusted(built: tuple[Path, Path], text: str) -> None:
    _, out = built
    (out / STAMP).write_text(text)
    assert BuildStamp(out).fresh(OPTIONS) is None


def test_forget_removes_the_stamp(built: tuple[Path, Path]) -> None:
    _, out = built
    BuildStamp(out).forget()
    assert not (out / STAMP).exists()
    assert BuildStamp(out).fresh(OPTIONS) is None


def test_fingerprints_read_a_file_again_only_when_its_stat_changed(tmp_path: Path) -> None:
    path = tmp_path / "f"
    path.write_bytes(b"abc")
    prints = Fingerprints()
    first = prints.sha256(path)
    assert first == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    assert prints.sha256(path) == first and prints.read == 1
    again = Fingerprints(prints.known)  # as a stamp stores them
    assert again.sha256(path) == first and again.read == 0
    path.write_bytes(b"abd")
    _later(path)
    assert again.sha256(path) != first and again.read == 1
    assert again.sha256(tmp_path / "absent") == "absent"


def test_a_source_lists_matching_files_and_an_absent_root_lists_none(tmp_path: Path) -> None:
    (tmp_path / "plots").mkdir()
    for name in ("a-maps.png", "a-ape.png", ".b-maps.png"):
        (tmp_path / "plots" / name).write_bytes(b"")
    assert Source(tmp_path / "plots", "*-maps.png").files() == [tmp_path / "plots" / "a-maps.png"]
    assert Source(tmp_path / "absent").files() == []
    assert Source(Path("relative")).root == Path(os.path.abspath("relative"))


def test_an_unsettled_figure_group_is_seen_and_force_forgets_every_stamp(tmp_path: Path) -> None:
    out = tmp_path / "report"
    figures = out / "figures"
    figures.mkdir(parents=True)
    (figures / "x.png").write_bytes(b"png")
    cache = FigureCache(figures)
    cache.store("ok", "d1", [figures / "x.png"])
    cache.unsettled("failed")
    cache.save()
    assert json.loads((figures / STAMPS).read_text())["unsettled"] == ["failed"]
    assert unsettled(out)
    again = FigureCache(figures)
    again.store("failed", "d2", [figures / "x.png"])  # drawn at last
    again.save()
    assert json.loads((figures / STAMPS).read_text())["unsettled"] == []
    assert not unsettled(out)
    (out / STAMP).write_text("{}")
    forget_all(out)
    assert not (out / STAMP).exists() and not (figures / STAMPS).exists()
    assert (figures / "x.png").exists()


def _record(finished: str | None) -> CellRecord:
    attempt = None if finished is None else SimpleNamespace(finished=finished)
    return cast(CellRecord, SimpleNamespace(attempt=attempt))


def test_a_report_is_dated_by_its_newest_cell_not_by_the_clock() -> None:
    records = [_record("2026-11-27T02:34:33Z"), _record(None), _record("2026-11-28T00:01:59Z")]
    assert as_of(records) == "newest cell finished 2026-11-28 00:01 UTC"
    assert as_of([_record(None)]) == "no cell has finished"


def test_a_store_changed_during_the_build_is_built_again(tmp_path: Path) -> None:
    store, out = _store(tmp_path / "store"), tmp_path / "report"
    out.mkdir()
    stamp = BuildStamp(out)
    digest = stamp.digest([Source(store)], OPTIONS)  # taken before the build reads the store
    (store / "runs" / "a" / "metrics.json").write_text('{"ate": 3.5}')  # a cell finished meanwhile
    (out / "README.md").write_text("report")
    stamp.record([Source(store)], digest, folder_files(out), "README.md")
    assert BuildStamp(out).fresh(OPTIONS) is None


def test_the_results_page_is_written_again_only_when_a_store_or_a_written_file_changed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from albot1.report import rebuild, results_data, results_page

    default, thesis = _store(tmp_path / "results" / "default"), _store(tmp_path / "results" / "thesis")
    page, readme = tmp_path / "docs" / "results.md", tmp_path / "README.md"
    readme.write_text("before")
    runs: list[str] = []

    def write(data: object, page_: Path, readme_: Path | None) -> list[Path]:
        runs.append(str(data))
        (page_.parent / "results").mkdir(parents=True, exist_ok=True)  # as the real one: its figures' folder
        page_.write_text("page")
        assert readme_ is not None
        readme_.write_text("block")
        return [page_, readme_]

    monkeypatch.setattr(results_data, "build_data", lambda d, t, command: command)
    monkeypatch.setattr(results_page, "write_results", write)
    assert rebuild.current_results_page(default, thesis, page, readme) is None
    assert rebuild.results_page(default, thesis, page, readme) == [page, readme]
    assert runs == [f"albot1 results-page {default.as_posix()} --thesis {thesis.as_posix()}"]
    assert rebuild.current_results_page(default, thesis, page, readme) == [page, readme]
    assert rebuild.current_results_page(default, None, page, readme) is None  # other options
    readme.write_text("edited by hand")
    assert rebuild.current_results_page(default, thesis, page, readme) is None
    rebuild.results_page(default, thesis, page, readme)
    (thesis / "runs" / "a" / "metrics.json").write_text('{"ate": 0.5}')
    assert rebuild.current_results_page(default, thesis, page, readme) is None


def test_every_option_that_changes_a_report_is_in_its_digest_and_jobs_is_not(tmp_path: Path) -> None:
    from albot1.report.rebuild import report_options

    base = report_options(tmp_path / "results", tmp_path / "out", plots=True, map_style="grid")
    assert base == {
        "kind": "report",
        "results": str(tmp_path / "results"),
        "out": str(tmp_path / "out"),
        "plots": True,
        "map_style": "grid",
        "columns": None,
    }
    assert report_options(tmp_path / "results", tmp_path / "out", plots=True, map_style="grid", columns="a") != base


def test_a_file_known_from_a_stamp_is_not_read_again_by_the_figure_cache(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "trajectory.tum"
    path.write_bytes(b"0 0 0 0 0 0 0 1\n")
    known = Fingerprints()
    first = known.sha256(path)
    monkeypatch.setattr(build_stamp, "_SEEN", {})  # a new process: only the stamp's memory
    Fingerprints(known.known).sha256(path)  # the build stamp's check
    figure_cache = Fingerprints()
    assert figure_cache.sha256(path) == first and figure_cache.read == 0
