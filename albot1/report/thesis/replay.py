"""The perceptual map after every update of a stored Albot1 run, for Figure 3.17's trace and the animation.

A run folder stores the final map and the update trace (``extras.json``:
which scan triggered each update, from which view), not the map after each
update: that would multiply the folder's size by the number of updates.
Albot1 is deterministic, so the maps are recomputed instead: the run's
dataset reference, degradation, seed and resolved config (``result.json``)
are replayed with an observer on every update
(:attr:`~albot1.methods.albot1.mapping.mapper.Albot1Mapper.on_update`), and
the replay is accepted only if it reproduces the stored trajectory and
update trace. Otherwise (the code changed since the run, the dataset is
not available) a :class:`~albot1.report.errors.ReportError` says why and
the page shows that instead of a figure.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from albot1.data.open import open_as_run
from albot1.errors import Albot1Error
from albot1.geometry import se2
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.config import Albot1Config
from albot1.methods.albot1.mapping.mapper import Albot1Mapper, UpdateEvent
from albot1.methods.albot1.perception.frames import thesis_to_rep_pose, thesis_to_rep_segments
from albot1.report.errors import ReportError
from albot1.runs.folder import StoredRun, read_run
from albot1.settings import Settings

#: Largest position difference (m) between the replayed and the stored trajectory (TUM files hold 1e-9 m digits).
POSITION_TOLERANCE_M = 1e-6


@dataclass(frozen=True)
class MapState:
    """The map right after one update: the scan that triggered it, the view used, its surfaces (REP-103 frame)."""

    scan: int
    view: str
    view_scan: int
    pose: tuple[float, float, float]
    segments: FloatArray


@dataclass(frozen=True)
class Replay:
    """Every map state of a run, in update order, and the run it reproduces."""

    run: StoredRun
    states: list[MapState]


def replay_run(run_dir: Path, settings: Settings | None = None) -> Replay:
    """Recompute the maps after each update of the Albot1 run in ``run_dir``; ReportError when it cannot."""
    try:
        run = read_run(run_dir)
    except Albot1Error as exc:
        raise ReportError(f"{run_dir}: cannot read the run: {exc}") from None
    info = run.info
    if info.method != "albot1":
        raise ReportError(f"{run_dir}: a run of {info.method}, not of albot1: it has no perceptual-map updates")
    try:
        sequence = open_as_run(info.dataset, info.degradation, info.seed, settings=settings)
        mapper = Albot1Mapper(Albot1Config.model_validate(info.config), seed=info.seed)
    except Albot1Error as exc:
        raise ReportError(f"{run_dir}: cannot replay {info.dataset}: {exc}") from None
    except ValueError as exc:  # the stored config does not validate against today's config model
        raise ReportError(f"{run_dir}: the stored config no longer validates: {exc}") from None
    states: list[MapState] = []

    def observe(event: UpdateEvent) -> None:
        states.append(
            MapState(
                event.scan,
                event.view,
                event.view_scan,
                thesis_to_rep_pose(event.pose),
                thesis_to_rep_segments(mapper.map.segments()),
            )
        )

    mapper.on_update = observe
    try:
        for frame in sequence.frames():
            mapper.process(frame)
        output = mapper.finish()
    except Albot1Error as exc:
        raise ReportError(f"{run_dir}: the replay failed: {exc}") from None
    _check_same(run, np.asarray(output.poses, dtype=float), output.extras.get("update_trace"), states, run_dir)
    return Replay(run, states)


def _check_same(run: StoredRun, poses: FloatArray, trace: Any, states: list[MapState], run_dir: Path) -> None:
    if poses.shape != run.poses.shape:
        raise ReportError(f"{run_dir}: the replay made {len(poses)} poses, the run stored {len(run.poses)}")
    off = float(np.max(np.hypot(*(poses[:, :2] - run.poses[:, :2]).T))) if len(poses) else 0.0
    turn = float(np.max(np.abs(se2.wrap(poses[:, 2] - run.poses[:, 2])))) if len(poses) else 0.0
    if off > POSITION_TOLERANCE_M or turn > POSITION_TOLERANCE_M:
        raise ReportError(
            f"{run_dir}: the replay does not reproduce the stored trajectory (up to {off:.3g} m, {turn:.3g} rad "
            "apart): the code changed since the run; run the suite again"
        )
    if isinstance(trace, list) and [int(t["scan"]) for t in trace] != [s.scan for s in states]:
        raise ReportError(f"{run_dir}: the replay's updates differ from the stored update trace")
