"""The small synthetic loop the report tests run methods on: 60 frames on a circle, a reference or not.

One definition for every report test that builds a store from real runs,
so that they exercise the same geometry (a 0.7 m / 6 deg step, 9 beams of
1.5 m) and a change to it is made once.
"""

from __future__ import annotations

import numpy as np

from albot1.data.model import Frame, Scan, Sequence
from albot1.geometry import se2

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 9)


def loop(name: str, with_reference: bool) -> Sequence:
    """``name``: 60 frames whose odometry is the true loop; reference poses only when ``with_reference``."""
    truth = se2.integrate_steps(np.zeros(3), np.tile([[0.7, 0.0, np.radians(6.0)]], (59, 1)))
    frames = [
        Frame(i, Scan(np.full(len(ANGLES), 1.5), ANGLES, 10.0 + i, 5.0), truth[i], truth[i] if with_reference else None)
        for i in range(60)
    ]
    return Sequence.from_frames(name, frames)
