"""The thesis's own experiments' datasets, read from the thesis suite file (``benchmarks/thesis.toml``).

The suite file is the one place that says which data stands in for the
thesis's: each of its dataset entries for an experiment of the thesis
carries a tag (``tags = ["dense-views"]``), and the page's experiments find
their datasets by those tags, never by a copy of a label. The file is found
like every suite (:func:`albot1.bench.suite.find_suite`: a user's
``ALBOT1_CONFIG_DIR/benchmarks/`` first, then the project's), and the labels
are those the bench gives the runs (with a slice when the entry has one), so
the page reads exactly the cells the suite plans. Experiment 3's induced
error is the suite's one swept degradation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from albot1.bench.suite import Suite, find_suite, load_suite
from albot1.report.errors import ReportError

#: The suite whose report gets the thesis page, and that its experiments read their datasets from.
THESIS_SUITE = "thesis"


@dataclass(frozen=True)
class ThesisDatasets:
    """The dataset labels of the thesis's own experiments."""

    #: Experiments 1 and 3: the 96 m square start-stop route.
    square: str
    #: Experiment 3: the degradation that adds the thesis's induced odometry error.
    induced: str
    #: Experiment 4: the office loop as views 0.1 m / 1 deg apart.
    dense: str
    #: Experiment 5: the same route as views 1 m / 10 deg apart.
    sparse: str
    #: 4.2.1: the single loop through the six places, from each start point.
    places_starts: tuple[str, ...]
    #: 4.2.2: the double loop.
    double_loop: str
    #: 4.2.3: the single loop driven twice (exit predictions).
    two_laps: str

    @classmethod
    def from_suite(cls, suite: Suite) -> ThesisDatasets:
        """The labels of the suite's entries by tag; a ReportError names a tag with no entry or too many."""
        where = str(suite.path) if suite.path is not None else f"suite {suite.name!r}"

        def tagged(tag: str) -> tuple[str, ...]:
            labels = []
            for entry in suite.datasets:
                options = suite.options_for(entry.name) if tag in entry.tags else None
                if options is None:
                    continue
                if entry.is_pattern:
                    raise ReportError(
                        f"{where}: the entry tagged {tag!r} is a pattern ({entry.name!r}); expected a name"
                    )
                labels.append(options.label)
            if not labels:
                raise ReportError(f"{where}: no dataset entry tagged {tag!r}; the thesis page's experiments need one")
            return tuple(labels)

        def one(tag: str) -> str:
            labels = tagged(tag)
            if len(labels) > 1:
                raise ReportError(f"{where}: {len(labels)} dataset entries tagged {tag!r}; expected one")
            return labels[0]

        square = one("start-stop-square")
        opts = suite.options_for(square)
        swept = (opts.degradations if opts is not None else None) or suite.grid.degradations
        if len(swept) != 1:
            raise ReportError(
                f"{where}: `{square}` sweeps {len(swept)} degradations ({', '.join(swept) or 'none'}); expected "
                "one, Experiment 3's induced error"
            )
        return cls(
            square=square,
            induced=swept[0],
            dense=one("dense-views"),
            sparse=one("sparse-views"),
            places_starts=tagged("places-single-loop"),
            double_loop=one("places-double-loop"),
            two_laps=one("places-two-laps"),
        )


@cache
def thesis_datasets() -> ThesisDatasets:
    """The thesis suite's experiment datasets (read once per process)."""
    return ThesisDatasets.from_suite(load_suite(find_suite(THESIS_SUITE)))
