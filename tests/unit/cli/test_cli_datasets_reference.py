"""`albot1 datasets reference IN OUT.tum`: a source's reference poses as a TUM file, from the command line."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from albot1.cli import app as app_module
from albot1.cli.app import app
from albot1.data.open import open_sequence
from albot1.data.trajectory import read_trajectory

runner = CliRunner()
WORLD = "synthetic-office-loop[:25]"


def test_the_file_holds_every_scans_reference_pose(tmp_path: Path) -> None:
    out = tmp_path / "gt.tum"
    result = runner.invoke(app, ["datasets", "reference", WORLD, str(out)])
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == f"wrote 25 reference poses from synthetic:synthetic-office-loop to {out} (tum)"
    sequence = open_sequence(WORLD)
    back = read_trajectory(out)
    assert back.timestamps is not None and sequence.reference is not None
    np.testing.assert_allclose(back.timestamps, sequence.timestamps, atol=1e-9)
    np.testing.assert_allclose(back.poses[:, :2], sequence.reference[:, :2], atol=1e-9)
    heading_error = np.angle(np.exp(1j * (back.poses[:, 2] - sequence.reference[:, 2])))
    np.testing.assert_allclose(heading_error, 0.0, atol=1e-8)


def test_a_source_without_reference_is_one_error_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "run.albotlog"  # the robot's own log, its views without reference poses ("-")
    log.write_text(
        "ALBOT1-LOG 1\nUNITS length=m angle=rad time=s\nFRAME thesis\n"
        "SENSOR 3 10.0 -1.5707963267948966 1.5707963267948966\n"
        "VIEW 0 0.0 0.0 0.0 0.0 - -2.0 0.0 0.0 3.5 nan nan\n"
    )
    out = tmp_path / "gt.tum"
    monkeypatch.setattr(sys, "argv", ["albot1", "datasets", "reference", str(log), str(out)])
    with pytest.raises(SystemExit) as ended:
        app_module.main()
    err = capsys.readouterr().err
    assert ended.value.code == 1
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "gt.tum: scan 0 (t = 0.000000 s) of run has no reference pose" in err
    assert not out.exists()
