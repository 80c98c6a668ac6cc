"""Every method's numba kernels that a wheel carries: the list the build step compiles (``setup.py``, issue 24).

Why a module here: Albot1's kernel sets live in :mod:`albot1.methods.albot1`
and gtsam-graph's grid search and block sums in :mod:`albot1.methods.baselines.gtsam_graph`,
which imports Albot1's compile path (``compiled``, ``kernel_bundle``); the
list that names both can only sit above both, or the two packages would
import each other. The bundle itself is one mechanism for every method:
:mod:`albot1.methods.albot1.kernel_bundle_build` compiles and copies,
:mod:`albot1.methods.albot1.kernel_bundle` checks and loads (``docs/albot1-mapper.md``,
"Compile time, seventh round"). A kernel listed nowhere here is compiled by
the first run after a bare wheel install.

Importing gtsam-graph's grid search does not import GTSAM (the graph module
imports it only when a graph is built), so the build needs no GTSAM.
"""

from __future__ import annotations

from pathlib import Path

from albot1.methods.albot1 import kernel_bundle_build
from albot1.methods.baselines.gtsam_graph import block_sums, icp_loop, nearest

#: the kernels of methods other than Albot1 (whose kernel sets the build knows): (warm-up, sample calls) each
OTHERS: tuple[kernel_bundle_build.KernelSource, ...] = (
    (nearest.warm_up, nearest.sample_calls),
    (icp_loop.warm_up, icp_loop.sample_calls),
    (block_sums.warm_up, block_sums.sample_calls),
)


def calls() -> list[kernel_bundle_build.Call]:
    """Every bundled kernel's ``(name, kernel, sample arguments)``: Albot1's kernel sets', then :data:`OTHERS`'."""
    return [*kernel_bundle_build.albot1_calls(), *(call for _, sample_calls in OTHERS for call in sample_calls())]


def build(dest: Path) -> int:
    """The wheel's kernel bundle in ``dest`` (:func:`kernel_bundle_build.build` over every method): file count."""
    return kernel_bundle_build.build(dest, OTHERS)
