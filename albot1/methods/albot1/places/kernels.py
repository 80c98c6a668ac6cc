"""The places layer's kernels as one set, compiled or as written (``accelerate``; same results either way).

The loops themselves live by responsibility in :mod:`.exit_kernels`,
:mod:`.surface_kernels` and :mod:`.match_kernels`; how they are compiled is
:mod:`albot1.methods.albot1.compiled`.
"""

from __future__ import annotations

from albot1.methods.albot1.compiled import select
from albot1.methods.albot1.places import exit_kernels, match_kernels, surface_kernels


class PlacesKernels:
    """The places kernels a mapper calls: each compiled, or its Python source when ``compiled`` is False."""

    def __init__(self, compiled: bool = True) -> None:
        self.compiled = compiled
        self.detect_exits = select(exit_kernels.detect_exits, compiled)
        self.seen_through = select(exit_kernels.seen_through, compiled)
        self.near_exit = select(exit_kernels.near_exit, compiled)
        self.update_sides = select(exit_kernels.update_sides, compiled)
        self.merge_collinear = select(surface_kernels.merge_collinear, compiled)
        self.colocated = select(surface_kernels.colocated, compiled)
        self.same_any = select(surface_kernels.same_any, compiled)
        self.match_structure = select(match_kernels.match_structure, compiled)
