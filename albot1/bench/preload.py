"""Imported once by the cell forkserver so that every forked cell starts warm.

Each import is attempted separately and a failure is ignored *here*: the
same import fails again inside the cell that needs it, where it is recorded
as that cell's failure with its traceback, instead of stopping every cell.
"""

from __future__ import annotations

import importlib

from albot1 import versions

# First, before the slow imports: every cell forked from this server shares this value, so the cells of
# one grid agree on the code version the runner planned with (see albot1.bench.cells).
versions.code_version()

import matplotlib  # noqa: E402

matplotlib.use("Agg")

_MODULES = (
    "numpy",
    "scipy.spatial",
    "shapely",
    "matplotlib.pyplot",
    "pydantic",
    "albot1.bench.cells",
    "albot1.bench.cell_main",
    "albot1.runs.execute",
    "albot1.runs.folder",
    "albot1.report.preview",
    "albot1.data.open",
    "albot1.data.catalog",
    "albot1.data.loaders.registry",
    "albot1.data.synthetic.worlds",
    "albot1.runs.evaluate",
    "albot1.metrics.ate",
    "albot1.metrics.rpe",
    "albot1.metrics.loop_gap",
    "albot1.metrics.orientation",
    "albot1.metrics.relations",
    "albot1.metrics.map_shape",
    "albot1.metrics.updates",
    "albot1.metrics.cost",
)


def _warm() -> None:
    for name in _MODULES:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 -- reported by the cell that needs the module
            continue
    from albot1.config.targets import resolve_target
    from albot1.data.loaders.registry import FORMATS
    from albot1.methods.registry import METHODS

    for loader_target, _ in FORMATS.values():
        try:
            resolve_target(loader_target)
        except Exception:  # noqa: BLE001 -- reported by the cell that reads this format
            continue

    for spec in METHODS.values():
        if not spec.available():
            continue
        try:
            spec.load_class()
        except Exception:  # noqa: BLE001 -- reported by the cell that runs this method
            continue
    _warm_matplotlib()


def _warm_matplotlib() -> None:
    """Render one tiny figure so the font cache and the Agg renderer are set up before forking."""
    import io

    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(1, 1))
    ax.plot([0, 1], [0, 1], label="x")
    ax.legend()
    fig.savefig(io.BytesIO(), format="png", bbox_inches="tight")
    plt.close(fig)


_warm()
