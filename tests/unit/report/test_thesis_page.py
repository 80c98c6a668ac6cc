"""The thesis page from a tiny results store made by the real planner, cell executor and evaluation.

The store holds the thesis suite's Experiment 3 cells on the 106-view square world (dead reckoning and
the three Albot1 variants, clean and with the thesis's induced error), one of them failed on purpose; the
other experiments have no runs. The page must render, link only figures that exist, give a computed verdict
where the numbers exist and "not comparable" with the reason where they do not, and the report of a
``thesis`` results folder must make it its README.md.
"""

from __future__ import annotations

import re
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from albot1.bench.cells import execute_cell
from albot1.bench.plan import plan_suite
from albot1.bench.store import ResultsStore
from albot1.bench.suite import parse_suite
from albot1.report.errors import ReportError
from albot1.report.index import build_report
from albot1.report.thesis import figures
from albot1.report.thesis.evidence import open_stores
from albot1.report.thesis.experiments import (
    section_error_tolerance,
    section_places,
    section_public,
    section_spacing,
    thesis_datasets,
)
from albot1.report.thesis.experiments.common import RELATIONS_USED
from albot1.report.thesis.experiments.exp6_public import Scoring
from albot1.report.thesis.figures import MAX_GIF_BYTES
from albot1.report.thesis.page import write_thesis_page
from albot1.report.thesis.replay import replay_run
from albot1.report.thesis.verdicts import HOLDS, NOT_COMPARABLE
from albot1.settings import get_settings

LINK = re.compile(r"\]\(([^)#\s]+)\)")
FAILED_METHOD = "albot1:plus"
#: Experiment 3's square world, as the thesis suite file names it.
SQUARE = thesis_datasets().square


def _suite(name: str, datasets: list[dict[str, object]]) -> dict[str, object]:
    return {
        "description": "tiny",
        "grid": {"degradations": ["thesis"], "seeds": [0]},
        "methods": [
            {"name": "odometry"},
            {"name": "albot1", "preset": "literal"},
            {"name": "albot1", "preset": "thesis"},
            {"name": "albot1", "preset": "plus"},
        ],
        "datasets": datasets,
    }


def _store(root: Path, name: str, data: dict[str, object], *, fail: str | None = None) -> Path:
    suite = parse_suite(data, name=name, source=f"{name}.toml")
    plan = plan_suite(suite, get_settings())
    store = ResultsStore(root / name)
    store.write_plan(plan)
    for cell in plan.cells:
        if cell.method_label == fail and cell.degradation == "thesis":
            store.prepare(cell)
            store.record_failure(cell, "the mapper diverged (a test failure)", "exception")
            continue
        execute_cell(cell, store.runs)
    return root / name


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("results")
    return _store(root, "thesis", _suite("thesis", [{"name": SQUARE, "sweep": True}]), fail=FAILED_METHOD)


@dataclass(frozen=True)
class Written:
    """The page written once for the module, and the figure requests it drew (by stem, in order)."""

    page: Path
    drawn: list[str]


def _fewer_panels(patch: pytest.MonkeyPatch) -> None:
    """Fewer panels and frames: the same code, drawn faster."""
    patch.setattr(figures, "MAX_TRACE_PANELS", 4)
    patch.setattr(figures, "MAX_FRAMES", 6)


def _spy_on_drawing(patch: pytest.MonkeyPatch, drawn: list[str]) -> None:
    """Record the stem of every figure request the page draws (not those its figure cache serves)."""
    from albot1.report.thesis import page as page_module

    original = page_module._Figures.draw

    def spy(self: Any, request: Any) -> Any:
        drawn.append(request.stem)
        return original(self, request)

    patch.setattr(page_module._Figures, "draw", spy)


@pytest.fixture(scope="module")
def written(results: Path, tmp_path_factory: pytest.TempPathFactory) -> Written:
    """The page of ``results``, written once: rendered, linked and written again by the tests below."""
    drawn: list[str] = []
    with pytest.MonkeyPatch.context() as patch:
        _fewer_panels(patch)
        _spy_on_drawing(patch, drawn)
        return Written(write_thesis_page(results, tmp_path_factory.mktemp("report")), drawn)


@pytest.fixture(scope="module")
def page(written: Written) -> Path:
    return written.page


def test_experiment_3_verdicts_are_computed_from_the_stored_loop_gaps(results: Path) -> None:
    ev = open_stores(results)
    section = section_error_tolerance(ev)
    setup_clean = section.claims[0].verdicts[""]
    assert setup_clean.word == HOLDS  # the square world's odometry gap is the thesis's 4.6 m
    assert "odometry loop gap 4.61 m" in setup_clean.reason
    clean, induced = section.claims[2], section.claims[3]
    for row in (clean, induced):
        assert set(row.verdicts) == {"albot1:literal", "albot1:thesis", "albot1:plus"}
        for label, verdict in row.verdicts.items():
            if label == FAILED_METHOD and row is induced:
                continue
            assert verdict.word in ("holds", "does not hold")
            assert f"{label} loop gap" in verdict.reason and "vs odometry" in verdict.reason
    failed = induced.verdicts[FAILED_METHOD]
    assert failed.word == NOT_COMPARABLE
    assert "failed in" in failed.reason and "the mapper diverged" in failed.reason


def test_experiments_without_runs_are_not_comparable_with_the_reason(results: Path) -> None:
    ev = open_stores(results)
    assert any("results" in note and "default" in note for note in ev.notes)  # no companion store: said so
    spacing = section_spacing(ev)
    for row in spacing.claims:
        for verdict in row.verdicts.values():
            assert verdict.word == NOT_COMPARABLE
            assert "no " in verdict.reason and "synthetic-office-loop" in verdict.reason
    places = section_places(ev)
    assert all(v.word == NOT_COMPARABLE for row in places.claims for v in row.verdicts.values())


@pytest.mark.slow
def test_the_page_renders_and_every_linked_figure_exists(page: Path) -> None:
    text = page.read_text(encoding="utf-8")
    assert page.name == "README.md"
    for heading in ("Experiment 1", "Experiment 2", "Experiment 3", "Experiments 4-5", "Experiment 6", "Chapter 4"):
        assert f"## {heading}" in text
    links = LINK.findall(text)
    assert links, "the page links its figures"
    for link in links:
        assert (page.parent / link).exists(), link
    figures = [page.parent / link for link in links if link.startswith("figures/")]
    names = {f.name for f in figures}
    assert any(n.startswith("exp1-trace-albot1_thesis") and n.endswith(".png") for n in names)
    assert any(n.endswith("-strip.png") for n in names)
    assert "exp3-gap-maps.png" in names
    gif = page.parent / "figures" / "exp1-animation.gif"
    assert gif.is_file() and 0 < gif.stat().st_size <= MAX_GIF_BYTES
    assert gif.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    assert "**holds**" in text or "**does not hold**" in text
    assert "**not comparable**" in text
    assert "4.6 m (3.2.3, Figure 3.21a)" in text  # the thesis's number, labelled with its source


def test_report_of_a_thesis_store_makes_the_page_its_readme(results: Path, tmp_path: Path) -> None:
    index = build_report(results, tmp_path / "report", plots=False)
    assert index == tmp_path / "report" / "README.md"
    assert index.read_text(encoding="utf-8").startswith("# The thesis's experiments, reproduced")
    # written (while the figures are drawn) before the benchmark index, into an empty folder, it still links it
    assert "full benchmark report (every table and plot): [benchmark.md](benchmark.md)" in index.read_text("utf-8")
    assert (tmp_path / "report" / "benchmark.md").read_text(encoding="utf-8").startswith("# Benchmark report")
    html = (tmp_path / "report" / "index.html").read_text(encoding="utf-8")
    assert 'href="README.md"' in html and 'href="benchmark.md"' in html


def test_a_replay_that_does_not_reproduce_the_stored_run_is_refused(results: Path, tmp_path: Path) -> None:
    """The update trace is drawn from a replay only when it reproduces the stored trajectory."""
    found = open_stores(results).find(SQUARE, "albot1:thesis")
    assert found.record is not None
    replay = replay_run(found.record.run_dir)
    assert [s.view for s in replay.states][0] == "initial" and len(replay.states) > 10
    copy = tmp_path / "run"
    shutil.copytree(found.record.run_dir, copy)
    lines = (copy / "trajectory.tum").read_text().splitlines()
    last = lines[-1].split()
    last[1] = f"{float(last[1]) + 0.5:.9f}"  # the stored end pose moved by 0.5 m: not what this code computes
    (copy / "trajectory.tum").write_text("\n".join([*lines[:-1], " ".join(last)]) + "\n")
    with pytest.raises(ReportError, match="does not reproduce the stored trajectory"):
        replay_run(copy)


def test_experiment_6_says_why_a_relation_cell_is_missing(results: Path) -> None:
    """A failed baseline's n/a in the relation table is explained by its recorded reason, not left bare.

    The synthetic world has no ground-truth relations, so the section scores it by its ATE and RPE at the
    thesis error level the tiny store ran; the rows, n/a cells and notes are the section's own.
    """
    scoring = Scoring("ate.rmse_m", "rpe.rotation_deg.rmse", RELATIONS_USED, degradation="thesis")
    section = section_public(open_stores(results), scoring, candidates=[SQUARE])
    assert section.tables and "n/a" in section.tables[0] and f"`{SQUARE}`" in section.tables[0]
    why = [note for note in section.notes if note.startswith("Why a cell of the relation table reads n/a")]
    assert len(why) == 1
    assert f"`{FAILED_METHOD}` on `{SQUARE}`: failed in" in why[0] and "the mapper diverged" in why[0]
    assert f"`mrpt-rbpf` on `{SQUARE}`: no mrpt-rbpf run" in why[0]  # planned nowhere here: said so, too
    assert "`odometry` on" not in why[0] and "`albot1:literal` on" not in why[0]  # measured: no note
    verdicts = [v for claim in section.claims for v in claim.verdicts.values() if v.word != "not comparable"]
    assert verdicts and all("paired ratio" in v.reason for v in verdicts)  # "below the odometry's": with its test


@pytest.mark.slow
def test_a_page_written_again_draws_no_figure_whose_runs_did_not_change(
    results: Path, written: Written, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The first writing is the module's page (the same settings, its drawing recorded); it is written again in a
    # copy of its folder, so the page the other tests read stays as it was written. The figure stamps name the
    # files relative to the folder and the digests hold no output path, so the copy is what a second run finds.
    # The copy is tmp_path itself: like the page's folder, a child of pytest's base temporary folder, so the
    # page's relative links to the results are the same.
    assert tmp_path.parent == written.page.parent.parent
    out = tmp_path
    shutil.copytree(written.page.parent, out, dirs_exist_ok=True)
    first = written.page.read_text(encoding="utf-8")
    assert written.drawn
    made = sorted(written.drawn)
    _fewer_panels(monkeypatch)
    drawn: list[str] = []
    _spy_on_drawing(monkeypatch, drawn)
    second = write_thesis_page(results, out).read_text(encoding="utf-8")
    # only the requests that could not be drawn (a failed run, no run) are worked out again, for their reason
    assert set(drawn) < set(made)
    strip = re.compile(r"^Generated .*$", re.MULTILINE)
    assert strip.sub("", first) == strip.sub("", second)
