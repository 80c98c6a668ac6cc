"""``ate_windows``: ATE of consecutive windows of reference travel (:func:`albot1.metrics.ate.windowed_ate`)."""

from __future__ import annotations

from albot1.metrics.ate import windowed_ate
from albot1.metrics.blocks import block_of, fmt
from albot1.metrics.unit import REFERENCE, ColumnSpec, Metric, MetricInputs
from albot1.records import Count, NonNegative, Record


class WindowStats(Record):
    """:class:`albot1.metrics.blocks.Stats` of the windows' RMSE with the unit in the key (``_m``)."""

    mean_m: NonNegative
    std_m: NonNegative
    median_m: NonNegative
    min_m: NonNegative
    max_m: NonNegative
    rmse_m: NonNegative
    n: Count
    std_ddof: Count


class AteWindow(Record):
    """One window of ``ate_windows``: its scans (inclusive) and its ATE."""

    first_scan: Count
    last_scan: Count
    rmse_m: NonNegative
    max_m: NonNegative


class AteWindowsBlock(Record):
    """``ate_windows``: ATE of consecutive windows of ``window_m`` reference travel, each aligned on its own.

    ``windows``: the windows scored; ``windows_without_scan``: those no scan falls in, left out (absent from
    files written before they were).
    """

    alignment: str
    window_m: NonNegative
    windows: Count
    windows_without_scan: Count | None = None
    uncovered_m: float  # may be -1e-9 m: the window count tolerates rounding (albot1.metrics.ate.windowed_ate)
    units: dict[str, str]
    mean_rmse_m: NonNegative
    window_rmse: WindowStats
    per_window: list[AteWindow]


def compute(inputs: MetricInputs) -> AteWindowsBlock:
    assert inputs.reference is not None  # REFERENCE is a need
    return block_of(AteWindowsBlock, windowed_ate(inputs.poses, inputs.reference))


def headline(block: AteWindowsBlock) -> str:
    return (
        f"mean rmse {fmt(block.mean_rmse_m)} m over {block.windows} windows of {block.window_m:g} m "
        f"(max {fmt(block.window_rmse.max_m)} m)"
    )


METRIC = Metric(
    name="ate_windows",
    position=20,
    models=(AteWindowsBlock,),
    needs=(REFERENCE,),
    compute=compute,
    headline=headline,
    columns=(ColumnSpec("ate_windows_m", "mean_rmse_m", "ATE per 50 m window, mean (m)"),),
)
