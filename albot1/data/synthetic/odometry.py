"""Simulated wheel odometry: the true motion, step by step, with a seeded error model.

Odometry is modelled the way it goes wrong physically: each step between two
scans is measured with an error, and the measured steps are integrated from
the true first pose, so the error accumulates along the route.

Two kinds of error, both on the step's own motion (robot frame):

- *random*: zero-mean Gaussian noise whose **variance** is proportional to the
  motion (a random walk, like a gyro's angle random walk). Its standard
  deviation per step is ``sigma * sqrt(motion)``, so a 10 m leg accumulates
  the same error statistics whether it is logged in 0.1 m or 1 m steps.
  (With a standard deviation proportional to the motion instead, the
  accumulated error would shrink as the scan rate grows, and the continuous
  and start-stop versions of one world would not be comparable.)
- *systematic*: scale errors of distance and rotation (wheel radius,
  caster-wheel resistance: the thesis's robot "rotates less than it intends
  to", so its odometry over-reports turns) and a heading drift per metre
  (unequal wheel radii make a straight move curve). These are what make a
  real odometry map bend, as in the thesis's Figure 3.21a.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from albot1.data.synthetic.errors import SyntheticWorldError
from albot1.geometry import se2
from albot1.geometry.types import FloatArray


@dataclass(frozen=True)
class OdometryErrorModel:
    """Error of the simulated odometry; all zero means exact odometry.

    Random terms (standard deviation per square root of motion):
    ``sigma_distance`` (m per sqrt(m)) along the step, ``sigma_lateral``
    (m per sqrt(m)) across it, ``sigma_turn`` (rad per sqrt(rad) of turning),
    ``sigma_drift`` (rad per sqrt(m) of travel).
    Systematic terms: ``distance_scale`` and ``turn_scale`` multiply the true
    step (1.0 = exact), ``heading_bias`` (rad per m) is added to every step in
    proportion to its length.
    """

    sigma_distance: float = 0.0
    sigma_lateral: float = 0.0
    sigma_turn: float = 0.0
    sigma_drift: float = 0.0
    distance_scale: float = 1.0
    turn_scale: float = 1.0
    heading_bias: float = 0.0

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if not math.isfinite(value):
                raise SyntheticWorldError(f"odometry model: {name} must be finite, got {value}")
            if name.startswith("sigma_") and value < 0:
                raise SyntheticWorldError(f"odometry model: {name} must be >= 0, got {value}")

    @classmethod
    def exact(cls) -> OdometryErrorModel:
        return cls()

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def perturb_steps(steps: ArrayLike, model: OdometryErrorModel, rng: np.random.Generator) -> FloatArray:
    """Measured increments ``(N, 3)`` for true increments ``(N, 3)`` (dx, dy, dtheta in the robot frame).

    Four standard normals are drawn per step, always, so the random stream
    (and thus every other step's noise) does not depend on the model's values.
    """
    s = se2.as_poses(steps).reshape(-1, 3)
    noise = rng.standard_normal((len(s), 4))
    dist = np.hypot(s[:, 0], s[:, 1])
    turn = np.abs(s[:, 2])
    # Unit vectors along and across each step (forward for a turn on the spot).
    moving = dist > 0
    ux = np.where(moving, s[:, 0] / np.where(moving, dist, 1.0), 1.0)
    uy = np.where(moving, s[:, 1] / np.where(moving, dist, 1.0), 0.0)
    root_d = np.sqrt(dist)
    along = dist * model.distance_scale + model.sigma_distance * root_d * noise[:, 0]
    across = model.sigma_lateral * root_d * noise[:, 1]
    dtheta = (
        s[:, 2] * model.turn_scale
        + model.heading_bias * dist
        + model.sigma_turn * np.sqrt(turn) * noise[:, 2]
        + model.sigma_drift * root_d * noise[:, 3]
    )
    return np.column_stack([ux * along - uy * across, uy * along + ux * across, dtheta])


def simulate(true_poses: ArrayLike, model: OdometryErrorModel, *, seed: int | np.random.Generator) -> FloatArray:
    """Odometry poses ``(N, 3)`` for a true trajectory, starting at the true first pose."""
    truth = se2.as_poses(true_poses).reshape(-1, 3)
    if len(truth) == 0:
        return truth.copy()
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    measured = perturb_steps(se2.relative_steps(truth), model, rng)
    return se2.integrate_steps(truth[0], measured)
