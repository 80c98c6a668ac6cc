"""The typed configuration of the GTSAM graph baseline.

The model holds types, bounds and meaning; the values (with the reasons
for them) live in ``baselines/gtsam-graph.toml`` and are loaded by
:mod:`albot1.config.presets`. Angles are degrees in the config (what a
person reads and edits) and radians everywhere inside.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from albot1.config.method_model import MethodConfig
from albot1.methods.baselines.gtsam_graph.registration import IcpParams


class GtsamGraphConfig(MethodConfig):
    """Every knob of the graph SLAM baseline, with units in the field names."""

    # Nodes (Grisetti et al. 2010: a node when the robot moved enough to see something new).
    node_translation_m: float = Field(gt=0, description="odometry translation since the last node that creates a node")
    node_rotation_deg: float = Field(
        gt=0, description="odometry rotation (deg) since the last node that creates a node"
    )

    # Scan preprocessing.
    min_range_m: float = Field(ge=0, description="beams shorter than this are dropped (robot body, dust)")
    max_range_m: float = Field(gt=0, description="beams longer than this are dropped (sparse, noisy far points)")
    scan_voxel_m: float = Field(ge=0, description="source scans keep one point per cell of this size (0 = all)")

    # Registration (point-to-line ICP, albot1.methods.baselines.gtsam_graph.registration).
    icp_max_iterations: int = Field(ge=1, description="Gauss-Newton iterations per registration")
    icp_max_correspondence_m: float = Field(gt=0, description="initial correspondence gate (annealed down)")
    icp_min_correspondence_m: float = Field(
        gt=0, description="final correspondence gate; inliers are counted within it"
    )
    point_sigma_m: float = Field(gt=0, description="std dev of one point-to-line residual (sets the match information)")
    normal_neighbours: int = Field(ge=3, description="neighbours used to fit each target point's line")
    normal_radius_m: float = Field(gt=0, description="neighbours farther than this are not used for the line fit")
    max_planarity: float = Field(
        gt=0, le=1, description="target points whose neighbourhood eigenvalue ratio exceeds this get no line"
    )

    # Sequential edges.
    track_scans: bool = Field(
        description="register every scan against the local map to carry the next node's guess (else: odometry)"
    )
    track_velocity_guess: bool = Field(
        description="also try the last tracked motion as the guess when it disagrees with the odometry increment"
    )
    track_velocity_only_after_stall: bool = Field(
        description="try the velocity guess only when this scan's or the previous scan's odometry increment is "
        "exactly zero (a repeated odometry reading: a stall or its catch-up step)"
    )
    track_velocity_time_scaled: bool = Field(
        description="the velocity guess follows the last tracked motion's twist for this scan's elapsed time, not for "
        "one scan: scaled by dt_now / dt_last where both stamp differences are positive (velocity_time.py)"
    )
    track_velocity_max_time_ratio: float = Field(
        ge=1, description="... that ratio clamped to [1 / this, this] (a clock that jumps cannot fling the guess)"
    )
    track_velocity_max_shift: bool = Field(
        description="a velocity match may replace a passing odometry match only within the tracker's translation "
        "gate of the odometry guess (velocity_slide.py)"
    )
    track_velocity_distinct_ratio: float = Field(
        ge=0,
        le=1,
        description="... only if the odometry match scores at most this fraction of the velocity match's "
        "likelihood-field score on the local map (0 = off; velocity_slide.py)",
    )
    track_prior_sigma_xy_m: float = Field(
        gt=0, description="prior std dev of the odometry guess over one scan period (x, y), used inside tracking ICP"
    )
    track_prior_sigma_theta_deg: float = Field(gt=0, description="... (theta)")
    track_max_correspondence_m: float = Field(gt=0, description="initial correspondence gate of tracking matches")
    track_max_correction_m: float = Field(gt=0, description="a tracking match may move its guess this far at most")
    track_max_correction_deg: float = Field(gt=0, description="... and rotate it this much at most")
    track_wide_correction_deg: float = Field(
        gt=0, description="a tracking match that fits clearly may rotate its guess up to this much (deg)"
    )
    track_wide_min_fitness: float = Field(ge=0, le=1, description="... where 'clearly' is this inlier fraction")
    track_outlier_factor: float = Field(
        ge=0,
        description="a tracking correction beyond this many times the recent ones' median must fit clearly "
        "(track_wide_min_fitness), else the odometry guess stands (0 = off)",
    )
    track_outlier_window: int = Field(ge=1, description="... the median over this many recent tracked scans")
    local_map_nodes: int = Field(
        ge=1, description="the last k node scans form the local map the new node is matched against"
    )
    odometry_sigma_xy_m: float = Field(
        gt=0, description="prior std dev of the odometry guess per node step (x, y), used inside ICP"
    )
    odometry_sigma_theta_deg: float = Field(
        gt=0, description="prior std dev of the odometry guess per node step (theta)"
    )
    odometry_trust: bool = Field(
        description="fuse each node's odometry step into its matched sequential edge, weighted by the odometry's "
        "variance learnt from its disagreement with recent matches (unbiased components only; odometry_trust.py)"
    )
    odometry_trust_factors: bool = Field(
        description="... as its own between factor per node step instead of a fused edge, every matched step judged "
        "once the variance can be learnt, the first ones too (odometry_trust.OdometryFactors)"
    )
    odometry_trust_translation: bool = Field(description="... in translation too (else: the heading alone)")
    odometry_trust_translation_follows_heading: bool = Field(
        description="... the translation trusted wherever the heading is, at its earned variance, and each step gated "
        "on its heading alone (odometry_trust.OdometryTrust._estimate; needs odometry_trust_translation)"
    )
    odometry_trust_window: int = Field(ge=2, description="... learnt from this many recent matched node steps")
    odometry_trust_bias_z: float = Field(
        gt=0, description="... a component whose median disagreement is this many standard errors from 0 is not fused"
    )
    odometry_trust_gate_chi2: float = Field(
        gt=0, description="... nor a step whose odometry and match disagree beyond this Mahalanobis distance squared"
    )
    odometry_trust_bias_horizon: int = Field(
        ge=0, description="... its median disagreement counts as a bias accumulated over this many steps (0: off)"
    )
    odometry_trust_min_variance_ratio: float = Field(
        ge=0, description="... a trusted component's variance never below this times its match's (1: never more weight)"
    )
    odometry_trust_floor_turn_deg: float = Field(
        ge=0,
        description="... that floor only on steps whose odometry turns at least this much (0: every step; not "
        "consulted for a kind learnt apart, odometry_trust_turn_deg, once it holds odometry_trust_kind_min_steps)",
    )
    odometry_trust_turn_scale: bool = Field(
        description="... a heading scale error learnt from every matched step (odometry_scale.TurnScale) adds to a "
        "step's heading variance in proportion to its turn, counted like the bias over odometry_trust_bias_horizon"
    )
    odometry_trust_turn_deg: float = Field(
        gt=0,
        allow_inf_nan=True,  # inf (the preset's value) means "one population"; gt=0 still refuses NaN
        description="... steps whose odometry turns more than this learnt and judged apart from the others "
        "(odometry_trust.OdometryTrust.kind; inf: one population)",
    )
    odometry_trust_kind_min_steps: int = Field(
        ge=2, description="... a kind's own history vetoes (and lifts the floor) once it holds this many steps"
    )
    odometry_trust_earned_level: float = Field(
        ge=0,
        lt=1,
        description="... a step whose odometry and match disagree beyond this chi-square level keeps the side with the "
        "smaller earned variance along the disagreement (earned_choice.py; 0: off)",
    )
    span_nodes: int = Field(
        ge=0,
        description="each new node is also matched against the scans ending this many nodes back, as a between edge "
        "spanning the run of steps (span_edges.py; 0: off; 1 is the sequential edge itself and is refused)",
    )
    span_map_nodes: int = Field(
        ge=1, description="... against this many node scans ending there (1: that node's alone)"
    )
    span_sigma_scale: float = Field(gt=0, description="... the match's stated standard deviations times this")
    span_max_correction_m: float = Field(
        gt=0, description="... a span match may move the guess the sequential edges give this far at most (m)"
    )
    span_max_correction_deg: float = Field(gt=0, description="... and rotate it this much at most (deg)")
    span_translation: bool = Field(
        description="... the span edge constrains the translation too (else the heading alone, translation sigma "
        "fallback_sigma_xy_m x 100)"
    )
    span_kernel: Literal["cauchy", "huber", "none"] = Field(description="... robust kernel on those edges")
    odometry_trust_run_nodes: int = Field(
        ge=0,
        description="... and the odometry's heading over non-overlapping runs of this many matched node steps as its "
        "own factor, learnt and judged against the chain of their matches like a step (odometry_runs.py; 0: off)",
    )
    odometry_trust_run_variance_ratio: float = Field(
        ge=0, description="... a run factor's variance never below this times its chain of matches' stated variance"
    )
    odometry_trust_run_max_turn_deg: float = Field(
        gt=0,
        allow_inf_nan=True,  # inf (the preset's value) means "no run is left out"; gt=0 still refuses NaN
        description="... runs holding a node step whose odometry turns more than this are left out (inf: none)",
    )
    seq_min_fitness: float = Field(ge=0, le=1, description="a sequential match needs this inlier fraction")
    seq_max_rmse_m: float = Field(
        gt=0, description="a sequential match needs this inlier RMS point-to-line distance or less"
    )
    seq_max_correction_m: float = Field(
        gt=0, description="a sequential match may move the odometry guess this far at most"
    )
    seq_max_correction_deg: float = Field(gt=0, description="... and rotate it this much at most")
    seq_retries: int = Field(
        ge=0, description="failed sequential matches are retried from the guess rotated by +-1..n steps"
    )
    seq_retry_rotation_deg: float = Field(gt=0, description="rotation step of those retries (deg)")
    match_sigma_floor_xy_m: float = Field(
        gt=0, description="added to every match's std dev (x, y): matches are never perfect"
    )
    match_sigma_floor_theta_deg: float = Field(gt=0, description="added to every match's std dev (theta)")
    match_covariance_shaped: bool = Field(
        description="a sequential match's translation covariance shaped by ICP's information: the floor on its "
        "best-constrained axis, larger along weaker ones by the eigenvalue ratio (match_covariance.py)"
    )
    fallback_sigma_xy_m: float = Field(
        gt=0, description="std dev (x, y) of an odometry edge used when the match is poor"
    )
    fallback_sigma_theta_deg: float = Field(gt=0, description="std dev (theta) of an odometry fallback edge")
    max_consecutive_fallbacks: int = Field(
        ge=1, description="this many poor matches in a row abort the run (registration diverged)"
    )

    # Loop closures.
    loop_search_radius_m: float = Field(
        gt=0, description="earlier nodes within this distance of the current estimate are candidates"
    )
    loop_radius_growth: float = Field(
        ge=0, description="the search radius grows by this fraction of the path since the last closure"
    )
    loop_max_search_radius_m: float = Field(gt=0, description="upper bound of the grown search radius")
    loop_min_node_gap: int = Field(
        ge=1, description="nodes this recent are never loop candidates (they are sequential)"
    )
    loop_max_candidates: int = Field(
        ge=1, description="at most this many candidates (nearest first, distinct places) per node"
    )
    loop_every_nodes: int = Field(ge=1, description="search for loop closures at every n-th node")
    loop_submap_nodes: int = Field(
        ge=0, description="a candidate's submap is its scan plus this many node scans either side"
    )
    loop_max_correspondence_m: float = Field(gt=0, description="initial correspondence gate of loop matches")
    loop_coarse_max_half_width_m: float = Field(
        ge=0, description="failed loop matches are retried from a correlative search this wide at most (0 = off)"
    )
    loop_coarse_min_half_width_m: float = Field(
        gt=0, description="the search half-width is loop_radius_growth x path since the last closure, at least this"
    )
    loop_coarse_step_m: float = Field(gt=0, description="translation step of the correlative search grid")
    loop_coarse_half_angle_deg: float = Field(
        ge=0, description="the correlative search tries rotations within +-this of the guess"
    )
    loop_coarse_step_deg: float = Field(gt=0, description="rotation step of the correlative search")
    loop_max_ambiguity: float = Field(
        gt=0,
        le=1,
        description="a correlative match is refused when a pose >1 m away scores this fraction of the best or more",
    )
    loop_min_fitness: float = Field(ge=0, le=1, description="a loop match needs this inlier fraction")
    loop_max_rmse_m: float = Field(gt=0, description="a loop match needs this inlier RMS distance or less")
    loop_max_correction_m: float = Field(
        gt=0, description="a loop match may disagree with the current estimate this much at most (m)"
    )
    loop_max_correction_deg: float = Field(gt=0, description="... and this much at most (deg)")
    loop_min_sigma_ratio: float = Field(
        gt=0,
        le=1,
        description=(
            "reject matches whose weakest direction is this much less constrained than the strongest (corridors)"
        ),
    )
    loop_confirmations: int = Field(
        ge=1, description="consecutive nodes whose loop matches must agree before they are added"
    )
    loop_agreement_m: float = Field(
        gt=0, description="two loop matches agree when their corrections differ by less than this (m)"
    )
    loop_agreement_deg: float = Field(gt=0, description="... and this (deg)")
    loop_distinct_half_width_m: float = Field(
        ge=0,
        description=(
            "a loop match is refused when a correlative search this wide around its pose finds a better pose more "
            "than 1 m away (0 = off; loop_distinct.py)"
        ),
    )
    loop_distinct_max_ambiguity: float = Field(
        gt=0,
        le=1,
        description="... or when a pose more than 1 m away scores more than this fraction of the best (1: only that)",
    )
    loop_kernel: Literal["cauchy", "huber", "none"] = Field(description="robust kernel on loop-closure edges")
    loop_kernel_scale: float = Field(
        gt=0, description="kernel parameter on the whitened error (in standard deviations)"
    )

    # Place recognition (large-drift loops; docs/baselines.md, "Place recognition").
    place_recognition: bool = Field(
        description="search the whole map region the drift allows with a branch-and-bound correlative match"
    )
    place_every_nodes: int = Field(ge=1, description="run the place-recognition search at every n-th node")
    place_min_path_m: float = Field(
        ge=0, description="earlier nodes closer than this along the graph (m) are left to the ordinary loop search"
    )
    place_drift_rate: float = Field(
        gt=0, description="an earlier node is searched if within this fraction of its graph distance (path length)"
    )
    place_max_radius_m: float = Field(gt=0, description="upper bound of that radius and of the search half-width (m)")
    place_half_angle_deg: float = Field(ge=0, description="rotations within +-this of the estimate are searched")
    place_step_deg: float = Field(gt=0, description="rotation step of the search (deg)")
    place_cell_m: float = Field(gt=0, description="cell of the search's likelihood field and translation step (m)")
    place_sigma_m: float = Field(gt=0, description="std dev of the likelihood field (m)")
    place_source_nodes: int = Field(
        ge=1, description="the searched scan is the local map of the last n node scans (more structure than one)"
    )
    place_max_points: int = Field(ge=10, description="the searched local map is thinned evenly to this many points")
    place_min_score: float = Field(
        ge=0, le=1, description="the best pose must score this fraction of the searched points"
    )
    place_max_ambiguity: float = Field(
        gt=0, le=1, description="refused when a pose >2 m away scores this fraction of the best or more"
    )
    place_max_blocks: int = Field(
        ge=1, description="the search gives up (no match) when more blocks than this survive a level of its tree"
    )

    # Optimisation.
    isam_relinearize_threshold: float = Field(
        gt=0, description="ISAM2 relinearises variables that moved more than this"
    )
    isam_extra_updates_on_loop: int = Field(ge=0, description="extra ISAM2 iterations after a loop closure is added")
    final_lm: bool = Field(description="run Levenberg-Marquardt over the whole graph in finish()")
    lm_max_iterations: int = Field(ge=1, description="iteration cap of the final Levenberg-Marquardt")

    # Per-scan poses (albot1.methods.baselines.gtsam_graph.refine).
    refine_scans: bool = Field(
        description="register every scan that is not a node against the optimised map around it in finish()"
    )
    refine_nodes_either_side: int = Field(
        ge=0, description="the refinement's local map: the scan's node and this many node scans either side"
    )
    refine_max_correspondence_m: float = Field(gt=0, description="initial correspondence gate of the refinement")
    refine_min_fitness: float = Field(ge=0, le=1, description="a refined pose needs this inlier fraction")
    refine_max_rmse_m: float = Field(gt=0, description="... and this inlier RMS point-to-line distance or less")
    refine_max_correction_m: float = Field(gt=0, description="... and may move its seed this far at most (m)")
    refine_max_correction_deg: float = Field(gt=0, description="... and rotate it this much at most (deg)")

    # Map.
    map_voxel_m: float = Field(gt=0, description="grid cell for thinning the projected map points")
    map_every: int = Field(ge=1, description="project every n-th scan into the map")

    @model_validator(mode="after")
    def _settings_that_would_do_nothing(self) -> GtsamGraphConfig:
        """Refuse the earned choice without the odometry factors it judges, rather than ignore it."""
        if self.odometry_trust_earned_level > 0 and not self.odometry_trust_factors:
            raise ValueError(
                "odometry_trust_earned_level needs odometry_trust_factors = true: without it it does nothing"
            )
        if self.odometry_trust_run_nodes and not (self.odometry_trust and self.odometry_trust_factors):
            raise ValueError(
                "odometry_trust_run_nodes needs odometry_trust = true and odometry_trust_factors = true: without them "
                "it does nothing"
            )
        if self.odometry_trust_translation_follows_heading and not self.odometry_trust_translation:
            raise ValueError(
                "odometry_trust_translation_follows_heading needs odometry_trust_translation = true: without it it "
                "does nothing"
            )
        if self.track_velocity_time_scaled and not (self.track_scans and self.track_velocity_guess):
            raise ValueError(
                "track_velocity_time_scaled needs track_scans = true and track_velocity_guess = true: without them "
                "there is no velocity guess to scale"
            )
        if self.odometry_trust_run_nodes == 1:
            raise ValueError("odometry_trust_run_nodes = 1 would repeat the per-step factors: use 0 (off) or 2 or more")
        if self.span_nodes == 1:
            raise ValueError("span_nodes = 1 would repeat the sequential edge: use 0 (off) or 2 or more")
        return self

    def track_icp(self) -> IcpParams:
        """Registration parameters of per-scan tracking (a guess one scan period of odometry away)."""
        return IcpParams(
            max_iterations=self.icp_max_iterations,
            max_correspondence_m=self.track_max_correspondence_m,
            min_correspondence_m=self.icp_min_correspondence_m,
            point_sigma_m=self.point_sigma_m,
            cauchy_scale_m=2.0 * self.point_sigma_m,
            prior_sigma_xy_m=self.track_prior_sigma_xy_m,
            prior_sigma_theta_rad=math.radians(self.track_prior_sigma_theta_deg),
        )

    def refine_icp(self) -> IcpParams:
        """Registration parameters of the per-scan refinement (the seed is close: a narrower starting gate)."""
        return IcpParams(
            max_iterations=self.icp_max_iterations,
            max_correspondence_m=self.refine_max_correspondence_m,
            min_correspondence_m=self.icp_min_correspondence_m,
            point_sigma_m=self.point_sigma_m,
            cauchy_scale_m=2.0 * self.point_sigma_m,
            prior_sigma_xy_m=self.refine_max_correction_m,
            prior_sigma_theta_rad=math.radians(self.refine_max_correction_deg),
        )

    def match_floor(self) -> NDArray[np.float64]:
        """The covariance added to every match edge's (sequential, loop, place): matches are never perfect."""
        return np.diag([self.match_sigma_floor_xy_m**2] * 2 + [math.radians(self.match_sigma_floor_theta_deg) ** 2])

    def icp(self, loop: bool = False) -> IcpParams:
        """Registration parameters for sequential (``loop=False``) or loop matches."""
        return IcpParams(
            max_iterations=self.icp_max_iterations,
            max_correspondence_m=self.loop_max_correspondence_m if loop else self.icp_max_correspondence_m,
            min_correspondence_m=self.icp_min_correspondence_m,
            point_sigma_m=self.point_sigma_m,
            cauchy_scale_m=2.0 * self.point_sigma_m,
            prior_sigma_xy_m=self.loop_max_correction_m if loop else self.odometry_sigma_xy_m,
            prior_sigma_theta_rad=math.radians(self.loop_max_correction_deg if loop else self.odometry_sigma_theta_deg),
        )
