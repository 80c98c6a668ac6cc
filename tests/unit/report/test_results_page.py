"""The results page and the README block rendered from a hand-made record: exact text, round trip, stable bytes."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.bench.grid import GridPlan
from albot1.bench.store import ResultsStore
from albot1.report.errors import ReportError
from albot1.report.results_data import (
    AteCell,
    ResultsData,
    StandardRow,
    StoreStamp,
    VerdictRow,
    _standard_row,
    build_data,
    check_thesis_store,
)
from albot1.report.results_page import (
    BEGIN,
    END,
    PLACEHOLDER,
    ate_table,
    readme_block,
    render_page,
    render_readme_block,
    replace_block,
    standard_table,
    tally_text,
    verdict_counts,
    write_results,
)
from albot1.report.standard import STANDARD_LOGS, published_rows


def _row(log: str, kind: str, method: str, mean: float | None, **kw: object) -> StandardRow:
    base: dict[str, object] = {
        "status": "done",
        "translation_std_m": None,
        "rotation_mean_deg": None,
        "relations": None,
        "speed": None,
        "held_in": None,
        "source": "",
        "note": "",
    }
    base.update(kw)
    return StandardRow(log=log, kind=kind, method=method, translation_mean_m=mean, **base)  # type: ignore[arg-type]


def _data() -> ResultsData:
    return ResultsData(
        command="albot1 results-page results/default --thesis results/thesis",
        stores=[StoreStamp("results/default", "default", "0.1.0+abc", "deadbeef", 4, 3, 1)],
        libraries={"numpy": "2.0.0", "gtsam": None},
        machine="Test CPU, 2 logical CPUs, Python 3.11",
        standard=[
            _row("aces", "measured", "gtsam-graph", 0.0348, rotation_mean_deg=0.319, held_in=True, speed=76.2),
            _row("intel", "measured", "gtsam-graph", None, status="failed", note="diverged at scan 7"),
            _row("aces", "published", "GM", 0.044, rotation_mean_deg=0.4, source="Hess et al. 2016, Table II"),
        ],
        ate=[
            AteCell("intel-corrected?odometry=laser-pose", "gauss:0.1:1", "gtsam-graph", 0, 0.0782, ""),
            AteCell("intel-corrected?odometry=laser-pose", "gauss:0.1:1", "gtsam-graph", 1, 0.0692, ""),
            AteCell("intel-corrected?odometry=laser-pose", "gauss:0.1:1", "gtsam-graph", 2, None, "timed out"),
        ],
        verdict_columns={"thesis preset": "thesis preset", "Albot1+": "Albot1+"},
        verdicts=[
            VerdictRow("Experiment 1", "shape kept", "3.2.1", {"thesis preset": {"holds": 2}, "Albot1+": {"holds": 1}}),
            VerdictRow("Experiment 3", "setup", "4.6 m", {"": {"not comparable": 1}}),
            VerdictRow(
                "Experiment 6", "below odometry", "3.2.6", {"thesis preset": {"does not hold": 1}, "Albot1+": {}}
            ),
        ],
    )


def test_standard_table_keeps_published_apart_and_marks_tuned() -> None:
    assert standard_table(_data()) == [
        "| log | gtsam-graph | GM (published) |",
        "|---|---|---|",
        "| aces | 0.0348, 0.319° † | 0.0440, 0.400° |",
        "| intel | failed | – |",
        "| mit-csail | – | – |",
        "| fr079 | – | – |",
        "| fr-clinic | – | – |",
    ]


def test_a_column_from_the_thesis_store_is_named_with_its_store_on_the_page_and_in_the_readme() -> None:
    data = _data()
    plus = _row(
        "aces", "measured", "albot1:plus", 0.338, held_in=True, store="results/thesis", note="from results/thesis"
    )
    data.standard.insert(2, plus)
    assert standard_table(data)[:3] == [
        "| log | gtsam-graph | albot1:plus | GM (published) |",
        "|---|---|---|---|",
        "| aces | 0.0348, 0.319° † | 0.3380 † | 0.0440, 0.400° |",
    ]
    said = (
        "albot1:plus: from `results/thesis`, whose suite runs them on the default suite's datasets (the default "
        "suite does not); no speed is shown, as `make bench` runs that grid while the default report is drawn."
    )
    page, block = render_page(data), render_readme_block(data)
    assert said in page.splitlines() and said in block.splitlines()
    assert said not in render_page(_data())  # the default store's columns alone: no such line
    assert "| aces | albot1:plus † | 0.3380 | n/a | n/a | n/a |  |  | from results/thesis |" in page.splitlines()


def test_ate_table_lists_each_seed_in_order() -> None:
    assert ate_table(_data()) == [
        "| dataset | degradation (seeds) | gtsam-graph |",
        "|---|---|---|",
        "| `intel-corrected?odometry=laser-pose` | `gauss:0.1:1` (0, 1, 2) | 0.0782 / 0.0692 / n/a |",
    ]
    assert "- gtsam-graph on `intel-corrected?odometry=laser-pose` `gauss:0.1:1` seed 2: timed out" in render_page(
        _data()
    )


def test_verdict_tallies() -> None:
    assert tally_text({"holds": 1}) == "**holds**"
    assert tally_text({"holds": 2, "does not hold": 1}) == "holds 2, does not hold 1 (of 3 datasets)"
    assert tally_text({}) == "–"
    assert verdict_counts(_data()) == {
        "thesis preset": {"holds": 2, "does not hold": 1, "not comparable": 0},
        "Albot1+": {"holds": 1, "does not hold": 0, "not comparable": 0},
    }


def test_page_is_stamped_and_has_no_clock() -> None:
    page = render_page(_data())
    assert "suite `default`, code `0.1.0+abc`, commit `deadbeef`; 4 cells: 3 done, 1 failed" in page
    assert "Generated by `albot1 results-page results/default --thesis results/thesis`" in page
    assert "gtsam absent" in page
    assert "| Experiment 3 | setup | 4.6 m | **not comparable** | (setup check: same for every variant) |" in page
    assert "| aces | GM (**published**) | 0.0440 | 0.400 | Hess et al. 2016, Table II |" in page.splitlines()


def test_record_round_trip() -> None:
    data = _data()
    again = ResultsData.from_json(data.to_json(), "x.json")
    assert again == data
    assert render_page(again) == render_page(data)


@pytest.mark.parametrize("text", ["{}", "[1]", '{"format": 99}', "not json", '{"format": 1, "command": "x"}'])
def test_bad_record_is_one_report_error(text: str) -> None:
    with pytest.raises(ReportError, match=r"^r\.json: not a results record of format 1"):
        ResultsData.from_json(text, "r.json")


def test_readme_block_replaced_between_markers_only() -> None:
    readme = f"# X\n\nbefore\n\n{render_readme_block(None)}\n\nafter 0.0735\n"
    new = replace_block(readme, render_readme_block(_data()), "README.md")
    assert new.startswith("# X\n\nbefore\n\n" + BEGIN + "\n")
    assert new.endswith(END + "\n\nafter 0.0735\n")
    assert "| aces | 0.0348, 0.319° † | 0.0440, 0.400° |" in readme_block(new, "README.md")
    assert PLACEHOLDER in readme_block(readme, "README.md")
    with pytest.raises(ReportError, match="README.md: expected one"):
        replace_block("no markers", render_readme_block(None), "README.md")
    with pytest.raises(ReportError, match="README.md: expected one"):
        replace_block(readme + END, render_readme_block(None), "README.md")


def test_write_results_is_byte_stable(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text(f"top\n{render_readme_block(None)}\n", encoding="utf-8")
    page = tmp_path / "docs" / "results.md"
    written = write_results(_data(), page, readme)
    first = {p: p.read_bytes() for p in written}
    assert {p.name for p in written} == {
        "relation-metric.svg",
        "speed.svg",
        "thesis-verdicts.svg",
        "results.json",
        "results.md",
        "README.md",
    }
    write_results(_data(), page, readme)
    assert {p: p.read_bytes() for p in written} == first
    assert b"<dc:date>" not in first[page.parent / "results" / "speed.svg"]
    assert "](results/relation-metric.svg)" in page.read_text(encoding="utf-8")


def test_figures_without_numbers_are_removed(tmp_path: Path) -> None:
    page = tmp_path / "results.md"
    write_results(_data(), page, None)
    empty = _data()
    empty.standard, empty.verdicts = [], []
    write_results(empty, page, None)
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["results.json"]
    assert "## Figures" not in page.read_text(encoding="utf-8")


def test_readme_without_markers_is_refused_before_writing(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text("no block here\n", encoding="utf-8")
    with pytest.raises(ReportError, match="README.md: expected one"):
        write_results(_data(), tmp_path / "docs" / "results.md", readme)
    assert not (tmp_path / "docs").exists()
    assert readme.read_text(encoding="utf-8") == "no block here\n"


def test_an_empty_ate_table_leaves_one_blank_line_in_the_readme_block_and_the_page() -> None:
    data = _data()
    data.ate.clear()
    block = render_readme_block(data).splitlines()
    assert "" not in [a for a, b in zip(block, block[1:], strict=False) if a == b]  # no two blank lines in a row
    counts = next(i for i, line in enumerate(block) if line.startswith("Thesis verdicts"))
    assert block[counts - 2 :] == ["| fr-clinic | – | – |", "", block[counts], END]  # the standard table ends
    page = render_page(data)
    assert "\n\n\n" not in page
    assert "The default suite's store holds none of these cells.\n\n## The thesis's claims at a glance" in page
    full = render_readme_block(_data()).splitlines()  # with a table: table, one blank line, the counts
    assert full[-4:-2] == [
        "| `intel-corrected?odometry=laser-pose` | `gauss:0.1:1` (0, 1, 2) | 0.0782 / 0.0692 / n/a |",
        "",
    ]


def test_a_thesis_store_of_another_suite_is_refused_in_one_line(tmp_path: Path) -> None:
    """`--thesis results/default` used to draw the verdicts from the default suite's runs without a word."""
    for suite in ("default", "thesis"):
        ResultsStore(tmp_path / suite).write_plan(GridPlan(suite, None, "", [], [], [], {}, [0], ["none"], {}))
    with pytest.raises(ReportError) as caught:
        build_data(tmp_path / "default", tmp_path / "default", "albot1 results-page")
    assert str(caught.value) == (
        f"{(tmp_path / 'default').as_posix()}: --thesis expects the results of the 'thesis' suite (`albot1 bench "
        "thesis`), found those of suite 'default'; give its results folder, e.g. results/thesis"
    )
    check_thesis_store(tmp_path / "thesis")  # the thesis suite's store is taken


def test_published_figures_show_as_printed_with_their_spread_and_each_log_with_its_own_source() -> None:
    """The published rows of the data file on the page and in the README block: 0.044 ± 0.044 m and 0.4 ± 0.4 deg
    as Hess et al. print them (not 0.0440, 0.400°), the spread beside every mean, and the Freiburg hospital's note
    on the fr-clinic figure only (a list per system read as if it held for every log)."""
    data = _data()
    data.standard = [_standard_row(row) for row in published_rows()]
    table = standard_table(data)
    gm = list(STANDARD_LOGS).index("aces"), _methods_in(table[0]).index("GM (Kuemmerle et al. 2009) (published)")
    assert table[2 + gm[0]].split(" | ")[1 + gm[1]] == "0.044, 0.4°"
    sm = _methods_in(table[0]).index("SM (Kuemmerle et al. 2009) (published)")
    assert table[2 + list(STANDARD_LOGS).index("intel")].split(" | ")[1 + sm] == "0.220"
    lines = render_page(data).splitlines()
    assert (
        "| aces | GM (Kuemmerle et al. 2009) (**published**) | 0.044 ± 0.044 | 0.4 ± 0.4 | "
        "Hess et al. 2016, Table II (quoting Kuemmerle et al. 2009) |"
    ) in lines
    assert (
        "| fr-clinic | GM (Kuemmerle et al. 2009) (**published**) | 0.143 ± 0.180 | 0.9 ± 2.2 | "
        "Hess et al. 2016, Table II (quoting Kuemmerle et al. 2009); Freiburg hospital, local relations set |"
    ) in lines
    assert "| intel | SM (Kuemmerle et al. 2009) (**published**) | 0.220 ± 0.296 | n/a | " in "\n".join(lines)
    assert not any(line.startswith("| aces |") and "Freiburg hospital" in line for line in lines)


def _methods_in(head: str) -> list[str]:
    return head.strip("| ").split(" | ")[1:]


def test_every_measured_row_shows_medians_beside_the_means() -> None:
    """The standard asks for means as well as medians: one wrong loop closure moves a mean, not the median."""
    data = _data()
    data.standard[0] = _row(
        "aces",
        "measured",
        "gtsam-graph",
        0.0348,
        translation_std_m=0.031,
        translation_median_m=0.0281,
        rotation_mean_deg=0.319,
        rotation_std_deg=0.402,
        rotation_median_deg=0.2106,
        relations=1279,
        held_in=True,
        speed=76.2,
    )
    assert (
        "| aces | gtsam-graph † | 0.0348 ± 0.0310 | 0.0281 | 0.319 ± 0.402 | 0.211 | 1279 | 76x |  |"
        in render_page(data).splitlines()
    )
