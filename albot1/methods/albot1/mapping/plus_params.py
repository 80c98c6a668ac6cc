"""The settings of Albot1+'s localiser (:class:`PlusParams`), in SI units, apart from the localiser itself.

A module of its own so that the config (which builds them from its fields) and the localiser
(:mod:`.plus`, which reads them) share one definition without the config importing the localiser's
machinery, and so that :mod:`.plus` stays one idea per module: the pose of a view.
"""

from __future__ import annotations

from dataclasses import dataclass

from albot1.methods.albot1.mapping.overlap import NO_LIMIT


@dataclass(frozen=True, slots=True)
class PlusParams:
    """The Albot1+ fields of :class:`~albot1.methods.albot1.mapping.config.Albot1Config`, in SI units."""

    line_sigma: float
    point_sigma: float
    huber: float
    iterations: int
    scan_refinement: bool
    scan_sigma: float
    scan_gate: float
    scan_stride: int
    prior: str  # off | fixed | adaptive
    xy_per_sqrt_m: float  # m per sqrt(m of motion)
    rad_per_sqrt_m: float  # rad per sqrt(m of motion)
    m_per_rad: float  # a turn of 1 rad counts as this much motion
    learning_rate: float
    degenerate_sd: float = 0.0  # m (a turn of 1 rad counting m_per_rad m); 0 = off
    gate_probability: float = 0.0  # chi-square quantile of the disagreement with the odometry; 0 = off
    ambiguity_probability: float = 0.0  # chi-square quantile of the view's own likelihood ratio; 0 = off
    window_updates: int = 0  # the window test against the oldest of this many update views (:mod:`.window`); 0 = off
    window_probability: float = 0.5  # chi-square quantile below which the window's odometry is kept
    motion_model: str = "exact"  # how an odometry increment becomes a thesis-frame motion (the mapper's)
    overhang: float = NO_LIMIT  # m a view point may project beyond an update-view surface's end (:mod:`.overlap`)
    turn_floor: float = 0.0  # rad: the turn bound's allowance on a straight stretch (:mod:`.turn_bound`); 0 = off
    turn_scale: float = 1.0  # the turn bound's allowance per rad the odometry turned since the update
    turn_statistic: float = 0.0  # a view's likelihood ratio above which the turn bound does not apply
    consistency: float = 0.0  # the fit's information scaled to its likelihood ratio (:mod:`.consistency`); 0 = off
    view_noise_rate: float = 0.0  # the view's own scatter learnt and removed from the learner's samples; 0 = off
    cross_fit_noise: bool = False  # the fit noise's scatter from two fits of a view against two update views
    fit_noise: float = 0.0  # the view noise, times this, added to a fused fit's covariance (:mod:`.fit_noise`)
    fit_noise_statistic: float = 0.0  # ... falling with the square of the view's likelihood ratio beyond this
    mount_prior: float = 0.0  # m: prior sd of the odometry-to-scanner mount learnt online (:mod:`.mount`); 0 = off
    kept_views_teach: bool = False  # the views the ambiguity test keeps also teach the odometry learner
    refutation_probability: float = 0.0  # keep the prediction unless the fit departs beyond the view noise; 0 = off
    noise_split: int = 0  # views of memory of the line nu^2 = V + q s splitting the two noises (:mod:`.noise_split`)
