"""``albot1 evaluate``'s summary line of the loop gap on routes that are no loop (an outsider's check, metric49).

The report leaves the loop gap out (n/a, with the reason) on a route that never returns to its start or never
leaves it; the summary printed ``route gap 3.552 m`` there as if it were one (synthetic-corridor, a 53 m straight
corridor) and ``route gap 0.129 m`` for ``intel-corrected[:3]`` (0.1 m of travel).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from albot1.cli.evaluate import headlines
from albot1.runs.evaluate import evaluate_pair


def _write_tum(path: Path, poses: np.ndarray) -> Path:
    lines = [
        f"{1000 + 0.1 * k:.9f} {x:.9f} {y:.9f} 0 0 0 {np.sin(th / 2):.12f} {np.cos(th / 2):.12f}"
        for k, (x, y, th) in enumerate(poses)
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    ("route", "reason"),
    [
        ("straight", "the route does not return to its start (it ends 19.9 m away; a loop closes within 1.0 m)"),
        ("still", "the route never leaves its start to return to it (it travels 0.0 m; a loop needs at least 10 m)"),
    ],
)
def test_the_evaluate_summary_says_a_route_gap_is_no_loop_gap(tmp_path: Path, route: str, reason: str) -> None:
    """A straight 19.9 m route and a robot that never moves: the route gap is printed with the report's n/a."""
    n = 200
    if route == "straight":
        ref = np.column_stack([0.1 * np.arange(n), np.zeros(n), np.zeros(n)])
    else:
        ref = np.tile([5.0, 5.0, 1.0], (n, 1))
    est = ref + np.column_stack([np.zeros(n), np.linspace(0, 0.05, n), np.zeros(n)])
    record, _ = evaluate_pair(_write_tum(tmp_path / "est.tum", est), _write_tum(tmp_path / "ref.tum", ref))
    [line] = [line for line in headlines(record) if line.split()[0] == "loop_gap"]
    assert line.endswith(f"; the report's loop gap column: n/a ({reason})"), line
    assert record.loop_gap is not None and record.loop_gap.route.gap_m == pytest.approx(0.05, abs=1e-6)


def test_a_returning_route_keeps_its_plain_loop_gap_line(tmp_path: Path) -> None:
    """A 20 m square that returns to its start: the line is the headline alone."""
    side = np.arange(50) * 0.1
    ref = np.concatenate(
        [
            np.column_stack([side, np.zeros(50), np.zeros(50)]),
            np.column_stack([np.full(50, 5.0), side, np.full(50, np.pi / 2)]),
            np.column_stack([5.0 - side, np.full(50, 5.0), np.full(50, np.pi)]),
            np.column_stack([np.zeros(51), 5.0 - np.arange(51) * 0.1, np.full(51, -np.pi / 2)]),
        ]
    )
    record, _ = evaluate_pair(_write_tum(tmp_path / "est.tum", ref), _write_tum(tmp_path / "ref.tum", ref))
    [line] = [line for line in headlines(record) if line.split()[0] == "loop_gap"]
    assert "column: n/a" not in line and "route gap 0.000 m" in line
