"""Every threshold and every reading of an ambiguous passage of thesis 3.1, typed.

Defaults are the thesis's values; where the thesis gives none, the default
is the resolution that worked in a prototype; ``docs/albot1-mapper.md``
lists each choice with the thesis text it resolves, and the "note N" in a
field's description is the number that page gives the resolution. The values a run uses come from
the presets file ``baselines/albot1.toml`` (``default`` = ``thesis``,
``exact``, ``literal``, ``plus``; read by
:class:`albot1.config.presets.TomlPresets`); the defaults here equal its
``[presets.default]`` so the model can also be built directly in code.
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field, model_validator

from albot1.config.method_model import MethodConfig
from albot1.methods.albot1.mapping.noise_split import MIN_WEIGHT
from albot1.methods.albot1.mapping.overlap import NO_LIMIT
from albot1.methods.albot1.mapping.plus_params import PlusParams
from albot1.methods.albot1.perception.view import ViewParams


class Albot1Config(MethodConfig):
    """Config of the Albot1 mapper (lengths in metres, angles in degrees)."""

    # 3.1.3 view construction
    max_range_m: float = Field(30.0, gt=0, description="3.1.3 step 1: readings beyond this are deleted")
    cluster_gap_m: float = Field(
        0.6, gt=0, description="3.1.3 step 2: Euclidean gap between consecutive points that starts a new cluster"
    )
    cluster_size_m: float = Field(
        0.2,
        ge=0,
        description="3.1.3 step 3: clusters whose first-to-last chord exceeds this get the split test (note 1)",
    )
    break_point_height_m: float = Field(
        0.1,
        gt=0,
        description="3.1.3 step 3: split at the point farthest from the chord when farther than this (note 2)",
    )
    surface_length_m: float = Field(0.1, ge=0, description="3.1.3 step 5: shorter surfaces are deleted")
    # 3.1.4 landmarks
    landmark_min_length_m: float = Field(0.4, ge=0, description="3.1.4: landmark surfaces are at least this long")
    corner_min_angle_deg: float = Field(
        30.0,
        gt=0,
        lt=180,
        description=(
            "3.1.4: smallest turn between two pieces of a cluster that is a corner (thesis: none given; note 5)"
        ),
    )
    occlusion_margin_m: float = Field(
        0.0, ge=0, description="3.1.4: the next return outward must be this much farther for an occluding end (note 4)"
    )
    continuation_tolerance_m: float = Field(
        0.1,
        ge=0,
        description=(
            "3.1.4: a cluster end whose next return outward lies within this of the surface's own line continued "
            "is a grazing-angle gap, not an occluding edge (0 = off; the thesis's 'obstructs' needs something "
            "else behind)"
        ),
    )
    end_spacing_max_m: float = Field(
        0.2,
        ge=0,
        description=(
            "3.1.4: an occluding or corner end whose neighbouring point on its own surface is farther than this is "
            "unstable: the beams are sparse there (a wall seen at a grazing angle), so the end is wherever the last "
            "beam fell and moves with the robot (0 = off; the thesis defines stability only loosely)"
        ),
    )
    end_spacing_grazing: float = Field(
        0.0,
        ge=0,
        description=(
            "3.1.4: with the beam-spacing test, also require the spacing to exceed this multiple of the spacing "
            "the same beams would have on a surface facing the robot (a grazing angle beyond arccos(1/value)), so "
            "far ends seen face-on keep their label (0 = the spacing alone decides)"
        ),
    )
    surface_fit: Literal["chord", "tls"] = Field(
        "chord",
        description=(
            "3.1.3 step 4: a surface is the chord from its first to its last point (the thesis), or the "
            "total-least-squares line of its points with ends projected onto it and corners at the intersection "
            "of neighbouring lines (Algorithm 4 allows any line extractor)"
        ),
    )
    # 3.1.5 recognition
    motion_model: Literal["thesis", "exact"] = Field(
        "thesis", description="eqs 3.1-3.2 distance+turn model, or the full SE(2) odometry increment (note 8)"
    )
    recognition_angle_deg: float = Field(
        5.0, gt=0, description="Algorithm 1 line 6: directions (P1->P2) closer than this"
    )
    recognition_distance_m: float = Field(
        0.4, gt=0, description="Algorithm 1 line 7: same-side stable endpoints closer than this (note 7)"
    )
    recognition_matching: Literal["greedy", "nested_loop"] = Field(
        "greedy", description="one-to-one by smallest gap, or Algorithm 1's nested loop verbatim (note 7)"
    )
    # Algorithm 4
    min_landmarks: int = Field(3, ge=1, description="Algorithm 4 line 12: update when fewer landmarks are recognised")
    pose_between_updates: Literal["localise", "odometry"] = Field(
        "localise",
        description="per-scan pose between updates: localise on the tracked landmarks (note 13), or compose odometry",
    )
    # 3.1.6 localisation
    outlier_min_candidates: int = Field(
        3, ge=2, description="apply the standard-deviation outlier rule with at least this many candidates (note 10)"
    )
    goodness_gap_floor_m: float = Field(
        0.01, gt=0, description="eq 3.5: floor of g_diff so a zero gap does not divide by zero (note 9)"
    )
    goodness_angle_floor_deg: float = Field(0.1, gt=0, description="eq 3.5: floor of a_diff (note 9)")
    goodness_distance_view: Literal["previous", "current"] = Field(
        "previous",
        description=(
            "eq 3.5 d_R: distance of the previous endpoint from the robot in the previous view (literal) "
            "or predicted into the current view"
        ),
    )
    # Albot1+ (docs/albot1-mapper.md, "Albot1+"): how a pose is computed; "landmark" is the thesis
    pose_estimate: Literal["landmark", "robust"] = Field(
        "landmark",
        description=(
            "3.1.6: the pose of the best-ranked landmark alone (Algorithm 2), or robust least squares over all "
            "recognised landmarks started from it (Albot1+)"
        ),
    )
    robust_line_sigma_m: float = Field(
        0.05, gt=0, description="Albot1+: sigma of a landmark endpoint's distance to its map copy's line"
    )
    robust_point_sigma_m: float = Field(
        0.1, gt=0, description="Albot1+: sigma of a stable endpoint's distance to its map copy"
    )
    robust_huber_sigmas: float = Field(
        2.0, gt=0, description="Albot1+: Huber threshold in sigmas (residuals beyond it count linearly)"
    )
    robust_iterations: int = Field(8, ge=1, description="Albot1+: Gauss-Newton iterations at most")
    scan_refinement: bool = Field(
        False,
        description="Albot1+: also fit the view's points to the surfaces of the last update view (point-to-line)",
    )
    scan_sigma_m: float = Field(0.05, gt=0, description="Albot1+: sigma of a view point's distance to its surface")
    scan_gate_m: float = Field(
        0.5, gt=0, description="Albot1+: a view point farther than this from every update-view surface is unused"
    )
    scan_beam_stride: int = Field(2, ge=1, description="Albot1+: use every n-th return of the scan")
    scan_overlap: Literal["gate", "surface"] = Field(
        "gate",
        description=(
            "Albot1+: where a view point may be matched to an update-view surface: anywhere within scan_gate_m"
            " (gate), or only where its projection falls on the surface, up to scan_overhang_m beyond its ends"
            " (surface: the overlap rule, albot1/methods/albot1/mapping/overlap.py)"
        ),
    )
    scan_overhang_m: float = Field(
        0.0, ge=0, description="Albot1+ overlap rule (scan_overlap = surface): how far beyond a surface's end"
    )
    odometry_prior: Literal["off", "fixed", "adaptive"] = Field(
        "off",
        description=(
            "Albot1+: the odometry since the last update as a prior whose variance grows with the motion since "
            "then, at the configured rate (fixed) or at a rate learnt from the views (adaptive)"
        ),
    )
    prior_xy_m_per_sqrt_m: float = Field(
        0.05,
        ge=0,
        description="Albot1+: odometry position sigma per sqrt(m) of motion (fixed prior; adaptive: start value)",
    )
    prior_deg_per_sqrt_m: float = Field(
        2.0,
        ge=0,
        description="Albot1+: odometry heading sigma per sqrt(m) of motion (fixed prior; adaptive: start value)",
    )
    prior_m_per_rad: float = Field(
        1.0, ge=0, description="Albot1+: a turn of one radian counts as this many metres of motion for the prior"
    )
    prior_learning_rate: float = Field(
        0.02,
        gt=0,
        le=1,
        description="Albot1+: weight of the newest view in the adaptive prior's estimate (exponential forgetting)",
    )
    degenerate_sd_m: float = Field(
        0.0,
        ge=0,
        description=(
            "Albot1+ (adaptive prior): a direction of the pose (a turn of 1 rad counting prior_m_per_rad m) that"
            " the view's fit knows worse than this standard deviation is degenerate and keeps the odometry's"
            " component (0 = off)"
        ),
    )
    gate_probability: float = Field(
        0.0,
        ge=0,
        lt=1,
        description=(
            "Albot1+ (adaptive prior): a view's pose whose disagreement with the odometry's prediction exceeds"
            " this chi-square quantile of their stated uncertainties is rejected for the odometry (0 = off)"
        ),
    )
    ambiguity_probability: float = Field(
        0.0,
        ge=0,
        lt=1,
        description=(
            "Albot1+ (adaptive prior): keep the odometry's prediction when the view's own robust cost there is"
            " within this chi-square quantile of its likelihood ratio to the fit (the view does not refute it;"
            " 0 = off)"
        ),
    )
    window_updates: int = Field(
        0,
        ge=0,
        description=(
            "Albot1+ (with the ambiguity test): also test the odometry since the oldest of this many update views"
            " against that view's surfaces, and keep it when not refuted (0 = off; docs/albot1-mapper.md)"
        ),
    )
    window_probability: float = Field(
        0.5,
        gt=0,
        lt=1,
        description=(
            "Albot1+ window test: the odometry over the window is kept when its likelihood ratio is within this"
            " chi-square quantile (stricter than the per-view test: a false acceptance freezes the odometry's"
            " error over the whole window, a false refusal only falls back to the per-view test)"
        ),
    )
    turn_bound_floor_deg: float = Field(
        0.0,
        ge=0,
        description=(
            "Albot1+ (adaptive prior) turn bound: a view no landmark places may depart from the odometry's"
            " predicted heading by"
            " at most this plus turn_bound_scale times the odometry's turn since the last update view unless it"
            " refutes the odometry beyond turn_bound_statistic: else it is fitted from the starts within that"
            " allowance, and a fit still beyond keeps the prediction (0 = off; docs/albot1-mapper.md)"
        ),
    )
    turn_bound_scale: float = Field(
        1.0, ge=0, description="Albot1+ turn bound: allowance per degree the odometry turned since the update"
    )
    turn_bound_statistic: float = Field(
        0.0,
        ge=0,
        description=(
            "Albot1+ turn bound: a view whose likelihood ratio of the odometry's prediction against its fit"
            " (the ambiguity test's statistic) exceeds this refutes the odometry strongly enough to turn freely"
        ),
    )
    consistent_information: float = Field(
        0.0,
        ge=0,
        description=(
            "Albot1+ (with the ambiguity test): scale a view's fit information so that its stated distance from"
            " the odometry's prediction is at most this times the view's likelihood ratio against it, before"
            " the fusion (0 = off; albot1/methods/albot1/mapping/consistency.py)"
        ),
    )
    view_noise_learning_rate: float = Field(
        0.0,
        ge=0,
        le=1,
        description=(
            "Albot1+ (adaptive prior with the ambiguity test): learn the fit's own scatter from the views that"
            " do not refute the odometry, at this rate, and take it out of the odometry learner's samples"
            " (0 = off; albot1/methods/albot1/mapping/view_noise.py)"
        ),
    )
    fit_noise_factor: float = Field(
        0.0,
        ge=0,
        description=(
            "Albot1+ (with the view noise): add this times the views' learnt scatter to the fit's stated"
            " covariance before the fusion with the odometry's prediction"
            " (0 = off; albot1/methods/albot1/mapping/fit_noise.py)"
        ),
    )
    fit_noise_statistic: float = Field(
        0.0,
        ge=0,
        description=(
            "Albot1+ fit noise: a view whose likelihood ratio against the prediction exceeds this gets the added"
            " scatter scaled by the square of this over its ratio (0 = every view gets all of it)"
        ),
    )
    fit_noise_source: Literal["kept", "cross"] = Field(
        "kept",
        description=(
            "Albot1+ fit noise: where the scatter it adds is learnt. kept: the view noise (the kept views'"
            " disagreement with the odometry's prediction); cross: a view's fit against the last update view"
            " against its fit against the update view before, which holds no odometry"
            " (albot1/methods/albot1/mapping/view_noise.py)"
        ),
    )
    mount_prior_m: float = Field(
        0.0,
        ge=0,
        description=(
            "Albot1+ (adaptive prior): learn where the odometry's frame sits on the scanner from the views that"
            " fix their pose, with this prior standard deviation (m) of the mount's position, and turn each"
            " odometry increment into the scanner's (0 = off; albot1/methods/albot1/mapping/mount.py)"
        ),
    )
    kept_views_teach: bool = Field(
        False,
        description=(
            "Albot1+ (adaptive prior with the ambiguity test): the views the test keeps as the odometry's"
            " prediction also teach the odometry learner, so its samples are not selected by their size"
            ' (docs/albot1-mapper.md, "Kept views teach, adopted in `plus`")'
        ),
    )
    refutation_probability: float = Field(
        0.0,
        ge=0,
        lt=1,
        description=(
            "Albot1+ (with the ambiguity test and the view noise): keep the odometry's prediction when the fit's"
            " departure from it is within this chi-square(3) quantile of the fit's stated covariance plus the views'"
            " learnt scatter (0 = off; albot1/methods/albot1/mapping/refutation.py)"
        ),
    )
    noise_split_samples: int = Field(
        0,
        ge=0,
        description=(
            "Albot1+ (adaptive prior): learn the odometry's spread and the views' own as the slope and intercept of"
            " the squared view-odometry disagreement against the motion since the update, over this many views"
            " of memory; the fusion adds the views' to the fit's covariance (0 = off;"
            " albot1/methods/albot1/mapping/noise_split.py)"
        ),
    )
    # 3.1.7 update
    update_polygon: Literal["robot_and_endpoints", "endpoints"] = Field(
        "robot_and_endpoints", description="Algorithm 3 line 7: polygon vertices (note 15)"
    )
    delete_margin_m: float = Field(
        0.4,
        ge=0,
        description="Algorithm 3 line 9: endpoints within this of the polygon boundary count as inside (note 16)",
    )
    delete_margin_from: Literal["surfaces", "boundary"] = Field(
        "surfaces",
        description=(
            "Algorithm 3 line 9: measure the 40 cm from the view's surfaces (perpendicular, within their extent) "
            "or from every polygon edge, including the field-of-view sides through unperceived space (see docs: "
            "the latter erases walls behind the robot when updates come less than 40 cm apart)"
        ),
    )
    correspond_angle_deg: float = Field(
        5.0, gt=0, description="Algorithm 3 line 12: a corresponding view surface is this parallel (note 17)"
    )
    correspond_distance_m: float = Field(
        0.4, gt=0, description="Algorithm 3 line 12: ... and this close (segment distance; note 17)"
    )
    partial_without_match: Literal["clip", "keep"] = Field(
        "clip",
        description=(
            "a partly covered map surface with no corresponding view surface: clip it at the grown polygon, "
            "or keep it whole"
        ),
    )
    # degenerate input and implementation
    odometry_jump_m: float = Field(5.0, gt=0, description="an odometry step longer than this is counted as a jump")
    stationary_m: float = Field(
        1e-6, ge=0, description="a step shorter than this and turning less than stationary_deg is stationary"
    )
    stationary_deg: float = Field(1e-6, ge=0, description="see stationary_m")
    accelerate: bool = Field(True, description="run the per-scan kernels with numba (results are identical)")

    def view_params(self) -> ViewParams:
        return ViewParams(
            max_range=self.max_range_m,
            cluster_gap=self.cluster_gap_m,
            cluster_size=self.cluster_size_m,
            break_point_height=self.break_point_height_m,
            surface_length=self.surface_length_m,
            corner_min_turn=math.radians(self.corner_min_angle_deg),
            occlusion_margin=self.occlusion_margin_m,
            continuation_tolerance=self.continuation_tolerance_m,
            end_spacing_max=self.end_spacing_max_m,
            end_spacing_grazing=self.end_spacing_grazing,
            fit_lines=self.surface_fit == "tls",
        )

    @model_validator(mode="after")
    def _settings_that_would_do_nothing(self) -> Albot1Config:
        """Refuse an Albot1+ setting that the others would leave without effect, rather than ignore it."""
        if self.refutation_probability > 0 and (self.view_noise_learning_rate == 0 or self.noise_split_samples > 0):
            raise ValueError(
                "refutation_probability needs the view noise (view_noise_learning_rate > 0) and no noise split"
                " (noise_split_samples = 0): without them it would do nothing"
            )
        if self.fit_noise_source != "kept" and (
            self.fit_noise_factor == 0 or self.view_noise_learning_rate == 0 or self.noise_split_samples > 0
        ):
            raise ValueError(
                f"fit_noise_source = {self.fit_noise_source!r} needs the fit noise (fit_noise_factor > 0), the view"
                " noise (view_noise_learning_rate > 0) and no noise split (noise_split_samples = 0): without them it"
                " would do nothing"
            )
        if 0 < self.noise_split_samples < MIN_WEIGHT:
            raise ValueError(
                f"noise_split_samples: expected 0 (off) or at least {MIN_WEIGHT:g} views (below that the split"
                f" never leaves its start values), got {self.noise_split_samples}"
            )
        return self

    def plus_params(self) -> PlusParams:
        return PlusParams(
            line_sigma=self.robust_line_sigma_m,
            point_sigma=self.robust_point_sigma_m,
            huber=self.robust_huber_sigmas,
            iterations=self.robust_iterations,
            scan_refinement=self.scan_refinement,
            scan_sigma=self.scan_sigma_m,
            scan_gate=self.scan_gate_m,
            scan_stride=self.scan_beam_stride,
            prior=self.odometry_prior,
            xy_per_sqrt_m=self.prior_xy_m_per_sqrt_m,
            rad_per_sqrt_m=math.radians(self.prior_deg_per_sqrt_m),
            m_per_rad=self.prior_m_per_rad,
            learning_rate=self.prior_learning_rate,
            degenerate_sd=self.degenerate_sd_m,
            gate_probability=self.gate_probability,
            ambiguity_probability=self.ambiguity_probability,
            window_updates=self.window_updates,
            window_probability=self.window_probability,
            motion_model=self.motion_model,
            overhang=self.scan_overhang_m if self.scan_overlap == "surface" else NO_LIMIT,
            turn_floor=math.radians(self.turn_bound_floor_deg),
            turn_scale=self.turn_bound_scale,
            turn_statistic=self.turn_bound_statistic,
            consistency=self.consistent_information,
            view_noise_rate=self.view_noise_learning_rate,
            cross_fit_noise=self.fit_noise_source == "cross",
            fit_noise=self.fit_noise_factor,
            fit_noise_statistic=self.fit_noise_statistic,
            mount_prior=self.mount_prior_m,
            kept_views_teach=self.kept_views_teach,
            refutation_probability=self.refutation_probability,
            noise_split=self.noise_split_samples,
        )
