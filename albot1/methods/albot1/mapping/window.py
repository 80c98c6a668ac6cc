"""Albot1+'s window test: is the odometry since an older update view refuted by the scan against that view?

The per-view ambiguity test (:mod:`.ambiguity`) asks whether the view refutes
the odometry's prediction from the *last* update view. Two kinds of error get
past it, both measured on the held-in logs (``docs/albot1-mapper.md``, "The
window test"):

* a view that wrongly refutes good odometry (a false alarm, a mismatched
  surface) places an update off the odometry, and every later prediction is
  made from that wrong anchor: with *perfect* odometry, each false alarm
  freezes an error into the map that nothing undoes;
* the scan fit's own small bias (a heading bias of a few hundredths of a
  degree per view, from the change of viewpoint) accumulates over thousands
  of views where the fit, not the odometry, is kept.

Both are errors of the *chain* of update anchors, which the odometry over a
longer window does not share. So every view is also tested against the
oldest of the last ``window_updates`` update views: the odometry's motion
since that view, composed onto that view's pose, is the window's prediction;
the scan is fitted against that view's surfaces alone (scan terms only; the
landmarks are the last update's) and the same likelihood ratio as the
ambiguity test (:func:`~albot1.methods.albot1.mapping.ambiguity.likelihood_ratio`)
asks whether the window's prediction is refuted. Not refuted, with enough of
the scan matched to that view to tell (``WINDOW_MIN_MATCHED``), the window's
prediction is the pose: the odometry is trusted over the whole window, and
what the last anchors added is dropped. Refuted (or too little overlap), the
view goes to the per-view logic as before. Odometry that is bad over the
window (a heading bias of 0.5 deg a step, a raw log's drift) explains the scan
against an older view badly, so it is refuted there even where each view
alone cannot refute it.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from albot1.geometry.se2 import Pose, between_pose, compose_pose
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.mapping.ambiguity import Ambiguity, likelihood_ratio
from albot1.methods.albot1.mapping.overlap import NO_LIMIT
from albot1.methods.albot1.perception.recognition import motion_step

#: The share of the scan's points that must find a surface of the window's view (within the gate) at the fit for
#: the test to count: with less overlap the old view cannot refute anything, and silence is not agreement.
WINDOW_MIN_MATCHED = 0.2

#: How many of the latest window statistics (views with enough overlap) the running median takes: one view's
#: false alarm (a mismatched surface) does not end the trust in odometry that the views around it confirm.
WINDOW_HISTORY = 9

_NO_LANDMARKS = np.empty((0, 4))
_NO_POINT_OK = np.empty((0, 2), dtype=np.bool_)


@dataclass(frozen=True, slots=True)
class UpdateRecord:
    """One update view as the window test needs it: its pose, its odometry (REP-103) and its surfaces in the map."""

    pose: Pose
    odometry: Pose
    ref: FloatArray


@dataclass(frozen=True, slots=True)
class WindowOutcome:
    """The window test of one view."""

    prediction: Pose  # the odometry since the window's view, composed onto that view's pose
    test: Ambiguity  # the likelihood ratio of the prediction against the fit on that view's surfaces
    matched: float  # the share of the scan's points matched to that view's surfaces at the fit
    kept: bool  # the prediction is the pose


class OdometryWindow:
    """The last ``size`` update views and the window test against the oldest of them (module docstring)."""

    def __init__(self, size: int, motion_model: str) -> None:
        self.size = size
        self.motion_model = motion_model
        self._records: deque[UpdateRecord] = deque(maxlen=max(size, 1))
        self._history: deque[float] = deque(maxlen=WINDOW_HISTORY)

    def add(self, record: UpdateRecord) -> None:
        """A map update placed a view: it joins the window (the oldest leaves when the window is full)."""
        self._records.append(record)

    def test(
        self,
        odometry: Pose,
        measured: Pose,
        points: FloatArray,
        refine: Callable[..., tuple[float, float, float, FloatArray]],
        costs: Callable[..., tuple[FloatArray, object, float, int, int]],
        sigmas: tuple[float, float, float, float, float],
        iterations: int,
        limit: float,
        overhang: float = NO_LIMIT,
    ) -> WindowOutcome | None:
        """The window test of a view with odometry ``odometry`` (REP-103) and scan ``points``; None: no window.

        ``measured``: the view's pose fitted against the last update view, the fit's second start (the
        prediction is the first): from the prediction alone, an odometry off by degrees over the window would
        find its own nearest surfaces and a minimum next to it, and not be refuted.

        ``refine`` / ``costs``: the kernels :func:`~albot1.methods.albot1.mapping.pose_kernels.refine_pose`
        and :func:`~albot1.methods.albot1.mapping.ambiguity.measurement_costs` (compiled or not);
        ``sigmas``: line, point and scan sigma, Huber threshold (sigmas), scan gate; ``limit``: the
        chi-square quantile (:func:`~albot1.methods.albot1.mapping.ambiguity.threshold`); ``overhang``: the
        overlap rule (:mod:`~albot1.methods.albot1.mapping.overlap`).
        """
        if self.size < 2 or len(self._records) < 2 or points.shape[0] == 0:
            return None
        oldest = self._records[0]
        since = motion_step(between_pose(oldest.odometry, odometry), self.motion_model)  # type: ignore[arg-type]
        prediction = compose_pose(oldest.pose, since)
        starts = np.array([prediction, measured], dtype=float)
        line, point, scan, huber, gate = sigmas
        x, y, phi, _ = refine(
            starts,
            _NO_LANDMARKS,
            _NO_LANDMARKS,
            _NO_POINT_OK,
            points,
            oldest.ref,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            line,
            point,
            scan,
            huber,
            gate,
            iterations,
            overhang,
        )
        poses = np.array([(x, y, phi), prediction], dtype=float)
        c, per_surface, matched_cost, terms, independent = costs(
            poses,
            _NO_LANDMARKS,
            _NO_LANDMARKS,
            _NO_POINT_OK,
            points,
            oldest.ref,
            line,
            point,
            scan,
            huber,
            gate,
            overhang,
        )
        matched = float(np.sum(per_surface)) / points.shape[0]  # type: ignore[call-overload]
        test = likelihood_ratio(float(c[0]), float(c[1]), float(matched_cost), int(terms), int(independent), limit)
        if matched >= WINDOW_MIN_MATCHED:
            self._history.append(test.statistic)
        trusted = len(self._history) == WINDOW_HISTORY and float(np.median(self._history)) <= limit
        kept = (matched >= WINDOW_MIN_MATCHED and test.ambiguous) or trusted
        return WindowOutcome(prediction, test, matched, kept)
