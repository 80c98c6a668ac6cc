"""The kernels an Albot1 mapper calls, compiled or as written, in one object.

A mapper holds one :class:`MappingKernels` so that the same mapper code runs
the numba-compiled kernels or their Python source (``accelerate = false``,
and the parity tests), and so that a warm-up can list what it must compile
(:func:`albot1.methods.albot1.warm_up.warm_up`).
"""

from __future__ import annotations

from albot1.methods.albot1.compiled import select
from albot1.methods.albot1.mapping import ambiguity, localise_kernels, pose_kernels, screen_kernels, step_kernels
from albot1.methods.albot1.mapping.kernels import place_segments
from albot1.methods.albot1.mapping.update_kernels import update_surfaces


class MappingKernels:
    """The map-update and Albot1+ pose kernels a mapper calls: each compiled, or its Python source."""

    #: The kernels Albot1+ does not call on their own: :func:`~.step_kernels.perceive` calls them (compiled into it).
    FUSED: tuple[str, ...] = ("build_view", "landmark_rows", "scan_points")

    @staticmethod
    def not_called(pose_estimate: str) -> tuple[str, ...]:
        """The kernels a mapper with this ``pose_estimate`` never calls on their own (a warm-up leaves them out).

        Albot1+ (``robust``) calls the fused kernels of :mod:`.step_kernels` instead of :data:`FUSED`, which
        ``perceive`` compiles into itself; the other presets call neither Albot1+'s pose kernels nor
        ``perceive`` (which saves them no time: docs/albot1-mapper.md, "Fewer kernel calls"), so their first run
        does not pay for compiling them (:func:`albot1.methods.albot1.warm_up.warm_up`). Every preset calls
        ``robust_starts``: it is the thesis's localisation, compiled.
        """
        if pose_estimate == "robust":
            return MappingKernels.FUSED
        return (
            "refine_pose",
            "scan_points",
            "measurement_costs",
            "screen_directions",
            "perceive",
            "refine_and_score",
        )

    def __init__(self, compiled: bool = True) -> None:
        self.compiled = compiled
        self.update_surfaces = select(update_surfaces, compiled)
        self.place_segments = select(place_segments, compiled)
        self.refine_pose = select(pose_kernels.refine_pose, compiled)
        self.scan_points = select(pose_kernels.scan_points, compiled)
        self.measurement_costs = select(ambiguity.measurement_costs, compiled)
        self.screen_directions = select(screen_kernels.screen_directions, compiled)
        # Fused entry points (:mod:`.step_kernels`): one call per scan where the pieces above took two or three.
        self.perceive = select(step_kernels.perceive, compiled)
        self.refine_and_score = select(step_kernels.refine_and_score, compiled)
        # The thesis's localisation, with Albot1+'s start poses from it (:mod:`.localise_kernels`): one call a scan
        self.robust_starts = select(localise_kernels.robust_starts, compiled)
