"""Typed settings of the MRPT baselines (``mrpt-icp``, ``mrpt-rbpf``).

The models hold the types, bounds, units and meaning of every field; the
values live in ``baselines/mrpt-icp.toml`` and ``baselines/mrpt-rbpf.toml``
(see :mod:`albot1.config.presets`). Each field maps to one key of the INI file
MRPT's application reads (named in its description), except the run limits,
the output checks and the laser's mounting pose, which the wrapper uses.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, field_validator, model_validator

from albot1.config.method_model import MethodConfig

#: Upper bounds of the run limits: a day and 1 TB are beyond any machine this runs on, and
#: bounding them keeps a typo (``cpu_limit_s = 1e12``) from passing validation.
MAX_TIMEOUT_S = 86_400.0
MAX_MEMORY_MB = 1_048_576.0
#: The wall-clock backstop is this multiple of ``cpu_limit_s``. Why so generous: it is there only for a
#: program that hangs without burning CPU; a single-threaded program on two cores at load 16 gets about
#: an eighth of a core (mit-csail was measured at 5x its idle wall time at load 10-16), and a tighter
#: backstop would bring back the load-dependent failures the CPU limit removes.
WALL_BACKSTOP_FACTOR = 10.0
#: The field ``cpu_limit_s`` replaced (session 21); a config that still sets it is refused with one line.
_OLD_TIMEOUT = "timeout_s"


class MrptRunConfig(MethodConfig):
    """What every MRPT baseline shares: run limits and output checks."""

    cpu_limit_s: float = Field(
        gt=0,
        le=MAX_TIMEOUT_S,
        description=(
            "CPU-time limit (user + system seconds, polled) of the MRPT process and its children; beyond it the "
            f"process is killed. A wall-clock backstop of {WALL_BACKSTOP_FACTOR:g}x this stops a hang that burns "
            "no CPU. CPU, not wall: a wall limit failed runs on a loaded machine that pass on an idle one"
        ),
    )
    memory_limit_mb: float = Field(
        gt=0,
        le=MAX_MEMORY_MB,
        description="resident-memory limit of the MRPT process (polled); beyond it the process is killed",
    )
    min_path_ratio: float = Field(
        ge=0,
        description=(
            "the estimated path must be at least this fraction of the odometry's path length (when the odometry "
            "moved at least 1 m); a shorter path means MRPT did not track the robot"
        ),
    )
    max_path_ratio: float = Field(
        gt=0,
        description="the estimated path may be at most this multiple of the odometry's path length (jumps: divergence)",
    )
    max_step_correction_m: float = Field(
        gt=0,
        description=(
            "from one scan to the next the estimate may depart at most this far from the odometry's prediction; "
            "a larger jump is a divergence (a particle or an ICP match teleported) and fails the run"
        ),
    )
    max_step_correction_deg: float = Field(gt=0, description="the same bound on the heading (deg per scan)")

    @model_validator(mode="before")
    @classmethod
    def _renamed_timeout(cls, data: Any) -> Any:
        """Refuse the old ``timeout_s`` with what replaced it: taken as CPU seconds it would change meaning
        silently (it was wall-clock seconds), and "extra inputs are not permitted" would not say why."""
        if isinstance(data, dict) and _OLD_TIMEOUT in data:
            raise ValueError(
                f"{_OLD_TIMEOUT} (wall-clock seconds) was replaced by cpu_limit_s (CPU seconds of MRPT's process, "
                f"with a wall-clock backstop of {WALL_BACKSTOP_FACTOR:g}x); set cpu_limit_s instead"
            )
        return data

    @property
    def wall_limit_s(self) -> float:
        """The wall-clock backstop: :data:`WALL_BACKSTOP_FACTOR` times ``cpu_limit_s``."""
        return WALL_BACKSTOP_FACTOR * self.cpu_limit_s


class MrptIcpConfig(MrptRunConfig):
    """``icp-slam`` (``CMetricMapBuilderICP``): incremental ICP of each scan against a growing point map."""

    icp_algorithm: Literal["icpClassic", "icpLevenbergMarquardt"] = Field(
        description="[ICP] ICP_algorithm: the ICP variant"
    )
    icp_max_iterations: int = Field(ge=1, description="[ICP] maxIterations")
    icp_threshold_dist_m: float = Field(gt=0, description="[ICP] thresholdDist: initial pairing distance")
    icp_threshold_ang_deg: float = Field(
        ge=0, description="[ICP] thresholdAng_DEG: extra pairing distance per metre of range, as an angle"
    )
    icp_alfa: float = Field(gt=0, lt=1, description="[ICP] ALFA: thresholds shrink by this factor at each convergence")
    icp_smallest_threshold_dist_m: float = Field(
        gt=0, description="[ICP] smallestThresholdDist: final pairing distance"
    )
    icp_only_unique_robust: bool = Field(description="[ICP] onlyUniqueRobust: one-to-one correspondences only")
    icp_decimation: int = Field(ge=1, description="[ICP] corresponding_points_decimation: use every n-th scan point")
    localization_distance_m: float = Field(
        ge=0, description="[MappingApplication] localizationLinDistance: run ICP after this much odometry motion"
    )
    localization_angle_deg: float = Field(ge=0, description="[MappingApplication] localizationAngDistance")
    insertion_distance_m: float = Field(
        ge=0, description="[MappingApplication] insertionLinDistance: insert the scan into the map after this motion"
    )
    insertion_angle_deg: float = Field(ge=0, description="[MappingApplication] insertionAngDistance")
    min_icp_goodness: float = Field(
        ge=0, le=1, description="[MappingApplication] minICPgoodnessToAccept: worse matches keep the odometry"
    )
    map_point_spacing_m: float = Field(
        gt=0, description="[pointsMap insertOpts] minDistBetweenLaserPoints: thinning of the point map"
    )


class MrptRbpfConfig(MrptRunConfig):
    """``rbpf-slam`` (``CMetricMapBuilderRBPF``): a Rao-Blackwellized particle filter over occupancy grids."""

    pf_algorithm: Literal[0, 1, 2, 3] = Field(
        description=(
            "[MappingApplication] PF_algorithm: 0 = standard proposal (each particle drawn from the odometry's "
            "motion model, weighted by the scan likelihood), 1 = auxiliary PF with the standard proposal, "
            "2 = optimal proposal approximated by ICP against each particle's grid (GMapping, Grisetti et al. "
            "2007), 3 = optimal sampling (auxiliary PF, Blanco et al. 2010)"
        )
    )
    particles: int = Field(ge=1, le=10_000, description="[MappingApplication] sampleSize: fixed number of particles")
    resampling_method: Literal[0, 1, 2, 3] = Field(
        description="resamplingMethod: 0 multinomial, 1 residual, 2 stratified, 3 systematic"
    )
    resampling_ess: float = Field(
        gt=0, le=1, description="BETA: resample when the effective sample size falls below this fraction"
    )
    update_distance_m: float = Field(
        gt=0,
        description=(
            "localizeLinDistance = insertionLinDistance: the filter runs and the scan enters the maps after this "
            "much odometry motion (one threshold for both, as GMapping's linearUpdate)"
        ),
    )
    update_angle_deg: float = Field(gt=0, description="localizeAngDistance_deg = insertionAngDistance_deg")
    pow_factor: float = Field(gt=0, le=1, description="powFactor: exponent flattening the observation likelihood")
    optimal_max_search_samples: int = Field(
        ge=1, description="pfAuxFilterOptimal_MaximumSearchSamples: rejection-sampling budget (PF_algorithm 3)"
    )
    icp_global_align_min_quality: float = Field(
        ge=0, le=1, description="ICPGlobalAlign_MinQuality: worse ICP alignments fall back to odometry (PF_algorithm 2)"
    )
    icp_covariance_method: Literal["icpCovFiniteDifferences", "icpCovLinealMSE"] = Field(
        description=(
            "ICP_covariance_method: how the proposal's ICP estimates the Gaussian each particle is drawn from "
            "(PF_algorithm 2); finite differences give a long axis along corridors"
        )
    )
    icp_covariance_var_points_m2: float = Field(
        gt=0,
        description=(
            "covariance_varPoints: variance of one matched point (m^2), the scale of the icpCovLinealMSE covariance "
            "each particle is drawn from; unused by icpCovFiniteDifferences"
        ),
    )
    icp_max_iterations: int = Field(ge=1, description="maxIterations of the proposal's ICP (PF_algorithm 2)")
    icp_threshold_dist_m: float = Field(gt=0, description="thresholdDist of the proposal's ICP")
    icp_threshold_ang_deg: float = Field(ge=0, description="thresholdAng_DEG of the proposal's ICP")
    icp_alfa: float = Field(gt=0, lt=1, description="ALFA of the proposal's ICP")
    icp_smallest_threshold_dist_m: float = Field(gt=0, description="smallestThresholdDist of the proposal's ICP")
    grid_resolution_m: float = Field(gt=0, description="[occupancyGrid creationOpts] resolution: grid cell size")
    grid_max_insertion_range_m: float = Field(
        gt=0, description="[occupancyGrid insertOpts] maxDistanceInsertion: longer beams are not inserted"
    )
    grid_max_occupancy_update_certainty: float = Field(
        gt=0.5, lt=1, description="[occupancyGrid insertOpts] maxOccupancyUpdateCertainty: one scan's largest update"
    )
    grid_invalid_ranges_as_free: bool = Field(description="[occupancyGrid insertOpts] considerInvalidRangesAsFreeSpace")
    likelihood_decimation: int = Field(ge=1, description="[occupancyGrid likelihoodOpts] LF_decimation")
    likelihood_std_hit_m: float = Field(gt=0, description="[occupancyGrid likelihoodOpts] LF_stdHit")
    likelihood_max_corr_distance_m: float = Field(
        gt=0, description="[occupancyGrid likelihoodOpts] LF_maxCorrsDistance"
    )
    likelihood_z_hit: float = Field(gt=0, le=1, description="[occupancyGrid likelihoodOpts] LF_zHit")
    likelihood_z_random: float = Field(ge=0, lt=1, description="[occupancyGrid likelihoodOpts] LF_zRandom")
    likelihood_max_range_m: float = Field(gt=0, description="[occupancyGrid likelihoodOpts] LF_maxRange")
    likelihood_cache: bool = Field(
        description=(
            "[occupancyGrid likelihoodOpts] enableLikelihoodCache: keep each particle's likelihood field per cell "
            "(faster updates, several bytes per cell per particle)"
        )
    )
    motion_a1: float = Field(ge=0, description="Gaussian odometry model: std of x, y per metre driven (m/m)")
    motion_a2: float = Field(ge=0, description="Gaussian odometry model: std of x, y per radian turned (m/rad)")
    motion_a3: float = Field(ge=0, description="Gaussian odometry model: std of heading per metre driven (rad/m)")
    motion_a4: float = Field(ge=0, description="Gaussian odometry model: std of heading per radian turned (rad/rad)")
    motion_min_std_xy_m: float = Field(ge=0, description="Gaussian odometry model: least std of x, y per step")
    motion_min_std_theta_deg: float = Field(ge=0, description="Gaussian odometry model: least std of heading per step")
    map_occupied_probability: float = Field(
        gt=0.5, lt=1, description="grid cells at least this likely occupied become the stored map's points"
    )

    @field_validator("pf_algorithm", "resampling_method", mode="before")
    @classmethod
    def _choice_from_text(cls, value: Any) -> Any:
        """``--set pf_algorithm=0`` arrives as the text ``"0"``, which a ``Literal`` of integers refuses (pydantic
        converts text only for plain ``int`` fields); ASCII digits become the integer, anything else is left for
        the ``Literal`` to refuse with its usual message."""
        if isinstance(value, str) and value.isascii() and value.isdigit():
            return int(value)
        return value
