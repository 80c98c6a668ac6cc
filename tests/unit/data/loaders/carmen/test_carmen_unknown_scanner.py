"""FLASER lines carry no beam geometry: a beam count no 180-degree SICK LMS 2xx gives (a 360-degree scanner's
1440 readings) still gets CARMEN's -90..+90 deg default, but the load warns once instead of silently giving a
map squeezed into half the field of view; PARAM lines that state the geometry silence it."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pytest

from albot1.data.loaders.carmen.loader import CarmenLoader


def flaser(beams: int, stamp: float) -> str:
    return f"FLASER {beams} {' '.join(['2.000'] * beams)} 0 0 0 0 0 0 {stamp:.6f} host {stamp:.6f}"


def warnings_of(path: Path, caplog: pytest.LogCaptureFixture) -> tuple[list[str], np.ndarray]:
    with caplog.at_level(logging.WARNING):
        frames = list(CarmenLoader().load(path).frames())
    return [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING], frames[-1].scan.angles


def test_a_flaser_beam_count_no_sick_scanner_gives_is_warned_once(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "ring.log"
    path.write_text("\n".join([flaser(1440, 1.0), flaser(1440, 2.0)]) + "\n")
    said, angles = warnings_of(path, caplog)
    assert said == [
        f"{path}:1: FLASER lines of 1440 readings and no PARAM laser_front_laser_fov or laser_front_laser_resolution "
        "before them: their beams are taken to span -90..+90 deg (CARMEN's default, made for a 180-degree SICK LMS "
        "2xx, which gives 180, 181, 360, 361 readings); a scanner with another field of view needs those PARAM lines "
        "(or ROBOTLASER1 lines)"
    ]
    assert (angles[0], angles[-1]) == pytest.approx((-math.pi / 2, math.pi / 2))


@pytest.mark.parametrize("beams", [180, 181, 360, 361])
def test_sick_beam_counts_load_without_a_warning(tmp_path: Path, caplog: pytest.LogCaptureFixture, beams: int) -> None:
    path = tmp_path / "sick.log"
    path.write_text(flaser(beams, 1.0) + "\n")
    assert warnings_of(path, caplog)[0] == []


def test_param_geometry_silences_the_warning_and_a_full_turn_measures_each_direction_once(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "ring.log"
    path.write_text("\n".join(["PARAM laser_front_laser_fov 360 nohost 0 0", flaser(1440, 1.0)]) + "\n")
    said, angles = warnings_of(path, caplog)
    # CARMEN spreads a FLASER line's field of view over n - 1 steps: 360 deg makes beam 1440 repeat beam 1
    assert said == [
        f"{path}:2: FLASER: the last of 1440 beams points where the first does (the beams span exactly 360 deg); "
        "that repeated direction is dropped, leaving 1439 beams per scan"
    ]
    assert angles.shape == (1439,)
    assert angles[0] == pytest.approx(-math.pi)
    assert angles[1] - angles[0] == pytest.approx(2 * math.pi / 1439)


def test_the_warnings_survive_a_read_from_the_decoded_cache(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Decoded CARMEN frames are cached: the second load decodes nothing, so the warnings are said on opening."""
    from albot1.data import open_sequence

    monkeypatch.setenv("ALBOT1_DECODED_CACHE", str(tmp_path / "cache"))
    path = tmp_path / "ring.log"
    path.write_text("\n".join([flaser(1440, 1.0), flaser(1440, 2.0)]) + "\n")
    said = []
    for _ in range(2):
        caplog.clear()
        with caplog.at_level(logging.WARNING):
            frames = list(open_sequence(str(path)))
        assert len(frames) == 2
        said.append([r.getMessage()[: len(str(path)) + 24] for r in caplog.records if r.levelno >= logging.WARNING])
    assert list((tmp_path / "cache").iterdir())  # the second load read the cache
    assert said == [[f"{path}:1: FLASER lines of 1440"]] * 2
