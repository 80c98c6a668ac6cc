"""index.html: one self-contained page whose every link and image resolves, rendered by a real browser.

The results folder is built by hand (the runner's store, run folders of
dead reckoning on a small loop, one failed cell) so the test needs no bench
run; the browser test runs Debian's ``chromium`` headless when it is
installed (``.ci/run`` installs it) and is skipped with the reason otherwise.
"""

from __future__ import annotations

import subprocess
from html.parser import HTMLParser
from pathlib import Path

import headless_chromium
import numpy as np
import pytest

from albot1.bench.grid import Cell, GridPlan
from albot1.bench.store import ResultsStore
from albot1.data.model import Frame, Scan, Sequence
from albot1.geometry import se2
from albot1.report.html import INDEX_HTML
from albot1.report.index import build_report
from albot1.runs.evaluate import evaluate_run
from albot1.runs.execute import run_method
from albot1.runs.folder import write_run

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 9)


def _loop() -> Sequence:
    truth = se2.integrate_steps(np.zeros(3), np.tile([[0.7, 0.0, np.radians(6.0)]], (59, 1)))
    frames = [Frame(i, Scan(np.full(len(ANGLES), 1.5), ANGLES, 10.0 + i, 5.0), truth[i], truth[i]) for i in range(60)]
    return Sequence.from_frames("loop", frames)


def _cell(key: str, label: str, degradation: str, seed: int, dataset: str = "loop") -> Cell:
    return Cell("tiny", dataset, dataset, "odometry", label, "default", degradation, seed, key, "v", 60.0, 100.0)


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A results folder of 5 completed cells on two datasets and 1 failed one, and its report (plots included).

    Built serially (``jobs=1``): the worker-process test draws the same store's figures in worker processes and
    compares them with these, so the module draws the serial figures once for both claims.
    """
    root = tmp_path_factory.mktemp("results") / "tiny"
    store = ResultsStore(root)
    store.runs.mkdir(parents=True)
    cells = []
    for label, degradation, seed, dataset in (
        ("odometry", "none", 0, "loop"),
        ("odometry", "gauss:0.05:1", 0, "loop"),
        ("odometry", "gauss:0.05:1", 1, "loop"),
        ("biased", "bias:0.01:0.5", 0, "loop"),
        ("odometry", "gauss:0.05:1", 1, "loop-b"),
    ):
        run_dir = write_run(run_method("odometry", _loop(), degradation=degradation, seed=seed), store.runs)
        evaluate_run(run_dir)
        cells.append(_cell(run_dir.name, label, degradation, seed, dataset))
    failed = _cell("f" * 16, "broken", "none", 0)
    store.prepare(failed)
    store.record_failure(failed, "RuntimeError: injected", "exception", traceback_text="Traceback ...")
    cells.append(failed)
    plan = GridPlan("tiny", None, "A tiny grid.", cells, [], [], {}, [0, 1], ["none", "gauss:0.05:1"], {})
    store.write_plan(plan)
    return build_report(root, root.parent / "report").parent


class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.links: list[str] = []
        self.ids: set[str] = set()
        self.tables = 0
        self.images = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = dict(attrs)
        self.tables += tag == "table"
        self.images += tag == "img"
        if values.get("id"):
            self.ids.add(str(values["id"]))
        for name in ("href", "src"):
            if values.get(name):
                self.links.append(str(values[name]))


@pytest.mark.slow
def test_every_link_and_image_of_index_html_resolves_inside_the_report(report: Path) -> None:
    page = report / INDEX_HTML
    parser = _Links()
    parser.feed(page.read_text(encoding="utf-8"))
    assert parser.tables >= 3 and parser.images >= 6  # accuracy, cost, failures; the loop's plots
    assert any(link.endswith(".svg") for link in parser.links) and any(link.endswith(".tex") for link in parser.links)
    for link in parser.links:
        if link.startswith("#"):
            assert link[1:] in parser.ids, link
            continue
        assert "://" not in link and not link.startswith("/"), f"not a relative link: {link}"
        assert (report / link).is_file(), f"{link} does not resolve from {report}"
    assert "cell.log" in " ".join(parser.links)  # the failed cell's log, in the results folder
    text = page.read_text(encoding="utf-8")
    assert "<script>" in text and "sortable" in text and "failed (exception: RuntimeError: injected)" in text


@pytest.mark.slow
def test_the_readme_links_the_page_and_every_table_format(report: Path) -> None:
    readme = (report / "README.md").read_text(encoding="utf-8")
    assert "(index.html)" in readme and "[LaTeX](metrics.tex)" in readme and ".svg)" in readme


@pytest.mark.slow
def test_the_page_says_how_a_number_over_seeds_reads_with_the_formatters_own_example(report: Path) -> None:
    """The legend above the tables names the median and shows a cell as the tables write it."""
    page = (report / "index.html").read_text(encoding="utf-8")
    legend = "Each number: mean ± sample std over the completed seeds, their median, then (min–max), e.g. "
    assert legend + "<code>4.33 ± 4.93, median 2.00 (1.00–10.00)</code> for seeds of 1, 2 and 10. " in page


@pytest.mark.slow
@pytest.mark.skipif(headless_chromium.browser() is None, reason=headless_chromium.NO_BROWSER)
def test_a_headless_browser_renders_the_page_with_its_tables(report: Path, tmp_path: Path) -> None:
    browser = headless_chromium.browser()
    assert browser is not None
    flags = [*headless_chromium.flags(tmp_path / "profile", offline=False, window=None), "--disable-quic"]
    url = (report / INDEX_HTML).resolve().as_uri()
    shot = tmp_path / "page.png"
    done = subprocess.run(
        [browser, *flags, f"--screenshot={shot}", "--window-size=1280,2000", url],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert shot.is_file(), done.stderr[-2000:]
    from matplotlib.image import imread  # here, not at collection: matplotlib costs every test run's collection

    pixels = imread(shot)[..., :3]
    assert float(pixels.std()) > 0.05  # something was drawn: not a blank page
    assert float((pixels < 0.5).mean()) > 0.002  # dark text and lines on the white page
    dom = subprocess.run([browser, *flags, "--dump-dom", url], capture_output=True, text=True, timeout=120)
    assert dom.stdout.count("<table") >= 3 and "Benchmark report" in dom.stdout
    assert dom.stdout.count("<img") >= 6 and "gauss:0.05:1" in dom.stdout


def test_a_results_folder_whose_grid_planned_no_cell_still_gets_a_report(tmp_path: Path) -> None:
    store = ResultsStore(tmp_path / "empty")
    store.runs.mkdir(parents=True)
    store.write_plan(GridPlan("empty", None, "", [], [], [], {}, [], [], {}))
    readme = build_report(store.root, tmp_path / "report")
    assert "Cells: 0 planned" in readme.read_text()
    assert "No planned cells." in (tmp_path / "report" / "metrics.md").read_text()
    assert (tmp_path / "report" / INDEX_HTML).is_file()


@pytest.mark.slow
def test_plots_drawn_by_worker_processes_are_the_same_files(report: Path, tmp_path: Path) -> None:
    """The module's report (drawn in this process) built again by 2 worker processes: the same files and links."""
    parallel = build_report(report.parent / "tiny", tmp_path / "parallel", jobs=2).parent
    serial = sorted(p.name for p in (report / "plots").glob("*.png"))
    drawn = sorted(p.name for p in (parallel / "plots").glob("*.png"))
    assert serial == drawn
    assert any(n.startswith("loop-b-") for n in serial) and any(
        n.startswith("loop-") and "-b-" not in n for n in serial
    )
    from matplotlib.image import imread

    for name in serial:
        a = imread(report / "plots" / name)
        b = imread(parallel / "plots" / name)
        assert np.array_equal(a, b), name
    links = [line for line in (report / "README.md").read_text().splitlines() if "plots/" in line]
    assert links and all(line in (parallel / "README.md").read_text() for line in links)
