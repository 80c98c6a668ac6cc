"""A metric module is checked by mypy: a block that compute and headline disagree on, or a missing part, fails."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]

MODULE = """
    from albot1.metrics.unit import Metric, MetricInputs
    from albot1.records import Record


    class GoodBlock(Record):
        x_m: float


    class OtherBlock(Record):
        y_m: float


    def compute(inputs: MetricInputs) -> {returns}:
        return {returns}({field}=1.0)


    def headline(block: GoodBlock) -> str:
        return f"{{block.x_m}} m"


    METRIC: Metric[GoodBlock] = Metric(
        name="typed", position=1, models=(GoodBlock,), needs=(), {parts}
    )
"""


def _mypy(tmp_path: Path, **fill: str) -> tuple[int, str]:
    api = pytest.importorskip("mypy.api")
    source = tmp_path / "typed.py"
    source.write_text(textwrap.dedent(MODULE.format(**fill)))
    out, err, code = api.run(["--config-file", str(ROOT / "pyproject.toml"), "--strict", str(source)])
    return code, out + err


@pytest.mark.slow
def test_a_well_formed_metric_module_passes_mypy_strict(tmp_path: Path) -> None:
    code, out = _mypy(tmp_path, returns="GoodBlock", field="x_m", parts="compute=compute, headline=headline")
    assert code == 0, out


@pytest.mark.slow
def test_compute_returning_another_block_than_headline_takes_fails_mypy(tmp_path: Path) -> None:
    code, out = _mypy(tmp_path, returns="OtherBlock", field="y_m", parts="compute=compute, headline=headline")
    assert code == 1
    assert 'Argument "compute" to "Metric" has incompatible type "Callable[[MetricInputs], OtherBlock]"' in out


@pytest.mark.slow
def test_a_metric_without_compute_and_headline_fails_mypy(tmp_path: Path) -> None:
    code, out = _mypy(tmp_path, returns="GoodBlock", field="x_m", parts="")
    assert code == 1
    assert 'Missing positional arguments "compute", "headline" in call to "Metric"' in out
