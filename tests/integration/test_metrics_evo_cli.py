"""Our ATE/RPE against evo's own command line on the TUM files a run folder holds."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from albot1.data.trajectory import read_tum, write_tum
from albot1.geometry import se2
from albot1.metrics.ate import ate
from albot1.metrics.rpe import rpe


def evo_tool(name: str) -> Path:
    path = Path(sys.executable).parent / name
    if not path.exists():
        pytest.skip(f"{name} is not installed next to {sys.executable}")
    return path


def run_evo(tool: str, *args: str, home: Path) -> dict[str, float]:
    """The statistics table evo prints (``max mean median min rmse sse std``)."""
    env = {**os.environ, "HOME": str(home), "MPLBACKEND": "Agg"}
    out = subprocess.run(
        [str(evo_tool(tool)), "tum", *args, "--no_warnings"],
        capture_output=True,
        text=True,
        env=env,
        check=True,
        timeout=120,
    ).stdout
    stats = dict(re.findall(r"^\s*(max|mean|median|min|rmse|sse|std)\s+([-+0-9.eE]+)\s*$", out, re.MULTILINE))
    assert stats, f"no statistics in evo's output:\n{out}"
    return {k: float(v) for k, v in stats.items()}


@pytest.fixture(scope="module")
def tum_pair(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    rng = np.random.default_rng(11)
    steps = np.column_stack([rng.uniform(0.1, 0.5, 400), rng.normal(0, 0.02, 400), rng.normal(0, 0.06, 400)])
    ref = se2.integrate_steps([3.0, -1.0, 0.5], steps)
    est = se2.integrate_steps([0.0, 0.0, 0.0], steps * [1.02, 1.0, 1.0] + [0, 0, np.radians(0.2)])
    stamps = 1000.0 + np.arange(len(ref)) * 0.25
    folder = tmp_path_factory.mktemp("tum")
    write_tum(folder / "reference.tum", stamps, ref)
    write_tum(folder / "trajectory.tum", stamps, est)
    return folder / "reference.tum", folder / "trajectory.tum"


@pytest.mark.parametrize("flag, alignment", [("--align", "rigid"), ("--align_origin", "first"), (None, "none")])
def test_ate_matches_evo_ape_cli(tum_pair: tuple[Path, Path], tmp_path: Path, flag: str | None, alignment: str) -> None:
    ref_file, est_file = tum_pair
    theirs = run_evo("evo_ape", str(ref_file), str(est_file), *([flag] if flag else []), home=tmp_path)
    _, ref = read_tum(ref_file)
    _, est = read_tum(est_file)
    ours = ate(est, ref, alignment)  # type: ignore[arg-type]
    for key in ("rmse", "mean", "median", "min", "max", "std"):
        # evo prints 6 decimals.
        assert ours[f"{key}_m"] == pytest.approx(theirs[key], abs=2e-6), key


@pytest.mark.parametrize("delta, unit", [("1", "f"), ("2.0", "m")])
def test_rpe_matches_evo_rpe_cli(tum_pair: tuple[Path, Path], tmp_path: Path, delta: str, unit: str) -> None:
    ref_file, est_file = tum_pair
    _, ref = read_tum(ref_file)
    _, est = read_tum(est_file)
    ours = rpe(est, ref, float(delta) if unit == "m" else int(delta), "m" if unit == "m" else "frames")
    args = (str(ref_file), str(est_file), "--delta", delta, "--delta_unit", unit, "--pairs_from_reference")
    trans = run_evo("evo_rpe", *args, home=tmp_path)
    rot = run_evo("evo_rpe", *args, "-r", "angle_deg", home=tmp_path)
    for key in ("rmse", "mean", "max", "std"):
        assert ours["translation_m"][key] == pytest.approx(trans[key], abs=2e-6), key
        assert ours["rotation_deg"][key] == pytest.approx(rot[key], abs=2e-6), key


def test_our_evo_result_files_sit_beside_evos_own_in_evo_res(tum_pair: tuple[Path, Path], tmp_path: Path) -> None:
    """`albot1 evaluate --evo` files and `evo_ape --save_results` files compared by evo_res: the same numbers."""
    from albot1.runs.evo_results import write_evo_results
    from albot1.runs.scored import Scored

    ref_file, est_file = tum_pair
    stamps, ref = read_tum(ref_file)
    _, est = read_tum(est_file)
    header = {"method": "ours", "key": "k"}
    scored = Scored(header, "pair", stamps, est, ref, None, "none", stamps, est)
    ours, _ = write_evo_results(scored, tmp_path, prefix="ours.")
    theirs = tmp_path / "theirs.zip"
    run_evo("evo_ape", str(ref_file), str(est_file), "--align", "--save_results", str(theirs), home=tmp_path)
    env = {**os.environ, "HOME": str(tmp_path), "MPLBACKEND": "Agg"}
    done = subprocess.run(
        [str(evo_tool("evo_res")), str(ours), str(theirs), "--use_filenames", "--no_warnings"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert str(ours) in done.stdout and str(theirs) in done.stdout  # both rows of evo_res's table
    from evo.tools.file_interface import load_res_file

    mine, evos = load_res_file(ours), load_res_file(theirs)
    assert mine.info["title"] == evos.info["title"]  # no title-mismatch warning in evo_res
    for key in ("rmse", "mean", "median", "std", "min", "max", "sse"):
        assert mine.stats[key] == pytest.approx(evos.stats[key], rel=1e-9), key
