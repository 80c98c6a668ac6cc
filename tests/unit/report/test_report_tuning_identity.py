"""Held-in marks follow the data, not its spelling, and travel with every table format (albot1.report.tuning).

A number on ``my-aces`` (a user's manifest of the ``aces`` file), on ``aces-corrected`` (the same drive,
corrected) or on a log given by path used to be unmarked for a method tuned on ``aces``; a LaTeX row, a
``cells-cost.csv`` row and a method without a recorded tuning lost or misreported the mark.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from albot1.bench.grid import Cell
from albot1.data import catalog
from albot1.errors import ConfigError
from albot1.report import tuning
from albot1.report.collect import METRIC_COLUMNS
from albot1.report.tables import aggregate, cells_frame, latex, write_tables
from albot1.report.tuning import LEGEND, MARK, held_in


def _cell(dataset: str, method: str, preset: str = "default") -> Cell:
    return Cell(
        suite="t",
        dataset=dataset,
        dataset_label=dataset,
        method=method,
        method_label=method,
        preset=preset,
        degradation="gauss:0.1:1",  # a degraded cell is measured on the same data
        seed=0,
        key=f"{dataset}-{method}",
        code_version="v",
        time_s=1.0,
        memory_mb=1.0,
    )


@pytest.fixture
def own_manifests(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A user's config folder whose ``datasets/`` adds to the catalog; the caches that read it cleared around."""
    folder = tmp_path / "project" / "datasets"
    folder.mkdir(parents=True)
    monkeypatch.setenv("ALBOT1_CONFIG_DIR", str(tmp_path / "project"))
    names = ("_identities", "_held_in_identities", "tuned_datasets")
    caches = [catalog._manifests, *(getattr(tuning, n) for n in names if hasattr(tuning, n))]
    for cache in caches:
        cache.cache_clear()
    yield folder
    for cache in caches:
        cache.cache_clear()


def test_a_corrected_copy_of_a_tuned_drive_is_held_in_both_ways() -> None:
    assert held_in(_cell("aces-corrected?odometry=laser-pose[:150]", "albot1", "thesis")) is True  # tuned on aces
    assert held_in(_cell("intel-corrected", "mrpt-icp")) is True  # tuned on intel
    assert held_in(_cell("freiburg-079-corrected", "albot1", "thesis")) is True  # tuned on fr079
    assert held_in(_cell("aces-corrected", "kiss-icp")) is False  # tuned on intel only
    assert held_in(_cell("fhw-corrected?odometry=laser-pose", "albot1", "thesis")) is False  # another drive
    assert catalog.get("aces-corrected").recording == "aces"


def test_a_users_manifest_of_a_tuned_log_is_held_in(own_manifests: Path) -> None:
    aces = catalog.get("aces")
    (own_manifests / "my-aces.toml").write_text(
        f'name = "my-aces"\nformat = "carmen"\n\n[[files]]\nrole = "log"\npath = "{aces.log.path}"\n'
        f'sha256 = "{aces.log.sha256}"\n'
    )
    catalog._manifests.cache_clear()  # read again, with the new manifest
    assert held_in(_cell("my-aces[:300]", "albot1", "thesis")) is True
    assert held_in(_cell("my-aces[:300]", "kiss-icp")) is False


def test_a_log_given_by_path_is_known_by_the_checksum_its_run_recorded() -> None:
    aces, corrected = catalog.get("aces").log.sha256, catalog.get("aces-corrected").log.sha256
    cell = _cell("/data/robot/aces.clf.bz2?relations=x.relations", "albot1", "thesis")
    assert held_in(cell) is False  # a path alone names nothing the tuned-on lists name
    assert held_in(cell, [aces]) is True
    assert held_in(cell, [corrected]) is True  # the corrected drive of aces, read by path
    assert held_in(_cell("/data/robot/aces.clf.bz2", "kiss-icp"), [aces]) is False


def test_a_tuned_on_name_that_is_no_dataset_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """A typo (``acess``) matched no cell, so every number on the dataset meant went unmarked without a word."""
    monkeypatch.setattr(tuning, "tuned_on", lambda owner, preset: ("acess", "intel"))
    tuning.tuned_datasets.cache_clear()
    try:
        with pytest.raises(ConfigError, match=r"kiss-icp\.toml: \[tuned_on\] of preset 'default': .*'acess'.*aces"):
            held_in(_cell("aces", "kiss-icp"))
    finally:
        tuning.tuned_datasets.cache_clear()


def _row(method: str, held: bool | None) -> dict[str, object]:
    row: dict[str, object] = {"dataset": "aces", "method": method, "degradation": "none", "seeds": 1, "status": "ok"}
    row |= {"ate_rmse_m_n": 1, "ate_rmse_m_na": None, "held_in": held}
    return row | {f"ate_rmse_m_{stat}": 0.5 for stat in ("mean", "std", "median", "min", "max")}


def test_a_latex_row_keeps_the_mark_and_the_file_its_legend() -> None:
    import pandas as pd  # here, not at collection: pandas costs every test run's collection

    table = pd.DataFrame([_row("gtsam-graph", True), _row("odometry", False)])
    text = latex(table, {"ate_rmse_m": METRIC_COLUMNS["ate_rmse_m"]}, "T")
    assert "gtsam-graph $^\\dagger$ & none &" in text and "odometry & none &" in text
    assert LEGEND.removeprefix(MARK).strip() in text
    unmarked = latex(pd.DataFrame([_row("odometry", False)]), {"ate_rmse_m": METRIC_COLUMNS["ate_rmse_m"]}, "T")
    assert "dagger" not in unmarked


def test_an_unknown_tuning_stays_unknown_in_the_aggregated_tables() -> None:
    """A plugin or external system records no tuning: its row must not read "not held-in" (False) in a CSV."""
    import pandas as pd

    cells = cells_frame([])
    base = {c: None for c in cells.columns} | {"dataset": "aces", "degradation": "none", "seed": 0, "status": "done"}
    rows = [base | {"method": "ext", "held_in": None}, base | {"method": "odo", "held_in": False}]
    rows += [base | {"method": "mine", "held_in": True}]
    frame = pd.DataFrame(rows, columns=[*cells.columns, "held_in"]).astype({"ate_rmse_m": float})
    table = aggregate(frame, METRIC_COLUMNS)
    assert dict(zip(table["method"], table["held_in"], strict=True)) == {"ext": None, "odo": False, "mine": True}


def test_every_cost_cell_row_says_whether_it_is_held_in(tmp_path: Path) -> None:
    write_tables([], tmp_path)
    header = (tmp_path / "cells-cost.csv").read_text().splitlines()[0].split(",")
    assert "held_in" in header


def test_every_recording_a_manifest_names_is_a_catalog_dataset_and_not_itself(tmp_path: Path) -> None:
    """A typo in ``recording`` would link nothing, leaving the corrected copy's tuned numbers unmarked."""
    from albot1.data.errors import DataError
    from albot1.data.manifest import parse_manifest

    linked = {name: catalog.get(name).recording for name in catalog.names() if catalog.get(name).recording}
    assert linked == {
        "aces-corrected": "aces",
        "intel-corrected": "intel",
        "freiburg-079-corrected": "fr079",
        "csail-corrected": "mit-csail",
    }
    assert set(linked.values()) <= set(catalog.names())
    own = tmp_path / "loop.toml"
    own.write_text(f'name = "loop"\nrecording = "loop"\n[[files]]\nrole = "log"\npath = "a/b"\nsha256 = "{"0" * 64}"\n')
    with pytest.raises(DataError, match=r"loop\.toml:2: recording names the dataset itself"):
        parse_manifest(own)
