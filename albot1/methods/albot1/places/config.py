"""The config of ``albot1-places``: every chapter-3 field plus the thresholds of chapter 4.

The chapter-3 fields are inherited from
:class:`~albot1.methods.albot1.mapping.config.Albot1Config` unchanged (the
places layer wraps that mapper); the chapter-4 ones are :class:`PlacesFields`,
whose values live in ``baselines/albot1-places.toml`` (which
``extends = "albot1"``: :mod:`albot1.config.presets` puts each on the
chapter-3 preset of the same name). Where the thesis gives a value (the 40 cm surface
length, 40 cm gap and 5 degrees of Algorithm 6, "more than 4" matches, exits
of about 1 m) it is the default; every other value is our reading, listed
with its reason in ``docs/places.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from pydantic import Field, model_validator

from albot1.config.method_model import MethodConfig
from albot1.methods.albot1.mapping.config import Albot1Config


@dataclass(frozen=True, slots=True)
class ExitParams:
    """Exit detection and tracking (metres, radians); see the fields of :class:`Albot1PlacesConfig`."""

    min_width: float = 0.6
    max_width: float = 1.2
    min_depth: float = 0.5
    max_distance: float = 6.0
    both_occluding: bool = True
    track_distance: float = 0.5
    track_angle: float = math.radians(20.0)
    min_sightings: int = 3
    crossing_band: float = 0.2
    crossing_margin: float = 0.2
    twin_distance: float = 1.0
    recent_scans: int = 100


@dataclass(frozen=True, slots=True)
class MatchParams:
    """Structural matching (Algorithm 6; metres, radians)."""

    min_surface: float = 0.4
    angle: float = math.radians(5.0)
    gap: float = 0.4
    min_matches: int = 5
    max_surfaces: int = 30
    anchors: int = 1
    trigger_fraction: float = 0.2
    trigger_min: int = 4
    retry_growth: int = 3
    retry_scans: int = 20
    max_conflicts: int = 0
    max_turn: float = math.radians(45.0)
    max_shift: float = 3.0


class PlacesFields(MethodConfig):
    """The chapter-4 fields alone (lengths in metres, angles in degrees), set by ``baselines/albot1-places.toml``."""

    # exits (4.1.1: "a gap whose typical size is about 1 meter")
    exit_min_width_m: float = Field(0.6, gt=0, description="4.1.1: narrowest gap between two endpoints that is an exit")
    exit_max_width_m: float = Field(1.2, gt=0, description="4.1.1: widest gap that is an exit (doorways ~1 m)")
    exit_min_depth_m: float = Field(
        0.5,
        ge=0,
        description="what is seen through the gap lies at least this far beyond it (a recess is not an exit)",
    )
    exit_max_distance_m: float = Field(6.0, gt=0, description="exits farther than this from the robot are ignored")
    exit_endpoints: Literal["occluding", "one_occluding"] = Field(
        "occluding",
        description=(
            "both gap ends occluding (our reading: 4.1.1 names only 'a gap whose typical size is about 1 meter', "
            "not its ends), or one occluding and the other a corner"
        ),
    )
    exit_track_distance_m: float = Field(
        0.5, gt=0, description="a detection whose midpoint is this close to a tracked exit's is that exit"
    )
    exit_track_angle_deg: float = Field(20.0, gt=0, description="... and whose direction differs by less than this")
    exit_min_sightings: int = Field(3, ge=1, description="an exit can be crossed once seen in this many views")
    exit_recent_scans: int = Field(
        100,
        ge=1,
        description=(
            "exits seen within this many scans decide what is seen through an exit and whether the robot stands in "
            "one (older placements have drifted with the map)"
        ),
    )
    crossing_band_m: float = Field(
        0.2, ge=0, description="the robot is on one side of an exit only when farther than this from its line"
    )
    crossing_margin_m: float = Field(
        0.2, ge=0, description="a crossing path may pass this far beyond the exit's ends (jamb noise)"
    )
    # recognition (4.1.2, Algorithm 6)
    place_surface_min_m: float = Field(
        0.4, ge=0, description="4.1.2: only surfaces longer than this describe a place's structure"
    )
    match_angle_deg: float = Field(5.0, gt=0, description="4.1.2: matched surfaces differ in direction by less")
    match_gap_m: float = Field(0.4, gt=0, description="4.1.2: matched surfaces are not separated by a larger gap")
    match_min_matches: int = Field(5, ge=1, description="Algorithm 6 line 11: 'Matched_Surfaces > 4'")
    match_max_surfaces: int = Field(
        30, ge=2, description="the longest this many surfaces of each place enter the match (bounds its cost)"
    )
    match_anchors: Literal["midpoint", "midpoint_and_ends"] = Field(
        "midpoint",
        description=(
            "Algorithm 6 line 6 'centering on S_j': a hypothesis puts S_k's midpoint on S_j's, or also tries "
            "their left and right ends"
        ),
    )
    match_max_conflicts: int = Field(
        0,
        ge=0,
        description=(
            "a hypothesis is refused when it puts more than this many unmatched remembered surfaces where the "
            "current view sees empty space (our addition; a large value turns it off)"
        ),
    )
    match_max_turn_deg: float = Field(
        45.0,
        gt=0,
        le=180,
        description=(
            "hypotheses turn a remembered place by at most this from where the perceptual map put it (the map "
            "drifts slowly; 180 = any turn, the thesis's search)"
        ),
    )
    match_max_shift_m: float = Field(
        3.0,
        gt=0,
        description=(
            "a confirming hypothesis moves the remembered place's centre at most this far from where the "
            "perceptual map put it (its surfaces co-located with the view there; large = the thesis's search)"
        ),
    )
    revisit_evidence: Literal["memory", "perceptual_map"] = Field(
        "memory",
        description=(
            "4.1.2 co-locating surfaces: the view against each remembered place's surfaces where the map held "
            "them when learned, or (literal) the map surfaces an update deletes or edits, by the places they "
            "were marked with"
        ),
    )
    revisit_trigger_fraction: float = Field(
        0.2,
        ge=0,
        description=(
            "4.1.2 n: more than max(revisit_trigger_min, this x the remembered place's surfaces) co-locating "
            "surfaces trigger a match"
        ),
    )
    revisit_trigger_min: int = Field(4, ge=0, description="4.1.2 n for the smallest places")
    match_retry_scans: int = Field(
        20, ge=0, description="... and no sooner than this many scans after it (bounds the cost on sparse logs)"
    )
    recognition_exit_clearance_m: float = Field(
        0.5,
        ge=0,
        description=(
            "no recognition while the robot is this close to a tracked exit: in a doorway the view is mostly "
            "the place beyond"
        ),
    )
    match_retry_growth: int = Field(
        3, ge=1, description="a failed match is retried once the current place has this many more surfaces"
    )
    exit_link_distance_m: float = Field(
        1.0,
        gt=0,
        description=(
            "a crossed exit is a remembered or predicted exit when their midpoints are this close "
            "(Algorithm 7 line 13 'co-locates')"
        ),
    )

    @model_validator(mode="after")
    def _widths_ordered(self) -> PlacesFields:
        if self.exit_min_width_m >= self.exit_max_width_m:
            raise ValueError(
                f"exit_min_width_m ({self.exit_min_width_m}) must be smaller than exit_max_width_m "
                f"({self.exit_max_width_m})"
            )
        return self

    def exit_params(self) -> ExitParams:
        return ExitParams(
            min_width=self.exit_min_width_m,
            max_width=self.exit_max_width_m,
            min_depth=self.exit_min_depth_m,
            max_distance=self.exit_max_distance_m,
            both_occluding=self.exit_endpoints == "occluding",
            track_distance=self.exit_track_distance_m,
            track_angle=math.radians(self.exit_track_angle_deg),
            min_sightings=self.exit_min_sightings,
            crossing_band=self.crossing_band_m,
            crossing_margin=self.crossing_margin_m,
            twin_distance=self.exit_link_distance_m,
            recent_scans=self.exit_recent_scans,
        )

    def match_params(self) -> MatchParams:
        return MatchParams(
            min_surface=self.place_surface_min_m,
            angle=math.radians(self.match_angle_deg),
            gap=self.match_gap_m,
            min_matches=self.match_min_matches,
            max_surfaces=self.match_max_surfaces,
            anchors=1 if self.match_anchors == "midpoint" else 3,
            trigger_fraction=self.revisit_trigger_fraction,
            trigger_min=self.revisit_trigger_min,
            retry_growth=self.match_retry_growth,
            retry_scans=self.match_retry_scans,
            max_conflicts=self.match_max_conflicts,
            max_turn=math.radians(self.match_max_turn_deg),
            max_shift=self.match_max_shift_m,
        )


class Albot1PlacesConfig(Albot1Config, PlacesFields):
    """Config of ``albot1-places``: every chapter-3 field (:class:`Albot1Config`) and the chapter-4 ones."""
