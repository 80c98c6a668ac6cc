"""evo result files (``.zip``) of an evaluation, so ``evo_res`` can compare them with other tools' results.

``evo_ape ... --save_results ape.zip`` and ``evo_rpe ... --save_results``
store an :class:`evo.core.result.Result`: ``info`` (title, names, label),
``stats`` (rmse, mean, median, std, min, max, sse), and ``np_arrays``
(``error_array`` plus time and distance axes). We write the same from our
own per-pose errors, so ``evo_res ours-ape.zip cartographer-ape.zip`` puts
this suite's runs in one table with results made by evo itself:

``ape.zip``
    the translation error of every pose after the rigid SE(2) alignment the
    ATE uses (its statistics are ``metrics.json`` ``ate``, digit for digit);
``rpe.zip``
    the translation error of consecutive 1-frame pairs (the first step of
    ``metrics.json`` ``rpe``, evo_rpe's default ``--delta 1 --delta_unit f``).

Only evaluations with reference poses have these errors; without them no
file is written and the caller is told why.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from albot1.atomic import atomic_write
from albot1.geometry import se2
from albot1.metrics.ate import position_errors
from albot1.metrics.rpe import pair_indices, relative_errors
from albot1.runs.errors import RunError
from albot1.runs.scored import Scored

APE_FILE = "ape.zip"
RPE_FILE = "rpe.zip"
#: evo's own titles for the same metrics (``evo_ape --align``; ``evo_rpe`` with its defaults), so ``evo_res``
#: compares our files with evo's without a title-mismatch warning. On planar poses (z = 0) evo's SE(3)
#: Umeyama alignment is our rigid SE(2) one (docs/metrics.md, the evo cross-checks).
APE_TITLE = "APE w.r.t. translation part (m)\n(with SE(3) Umeyama alignment)"
RPE_TITLE = "RPE w.r.t. translation part (m)\nfor delta = 1 (frames) using consecutive pairs\n(not aligned)"


def _stats(errors: NDArray[np.float64]) -> dict[str, float]:
    """evo's ``get_all_statistics``: population std, sum of squares."""
    return {
        "rmse": float(np.sqrt(np.mean(errors * errors))),
        "mean": float(np.mean(errors)),
        "median": float(np.median(errors)),
        "std": float(np.std(errors)),
        "min": float(np.min(errors)),
        "max": float(np.max(errors)),
        "sse": float(np.sum(errors * errors)),
    }


def write_evo_results(scored: Scored, folder: Path, prefix: str = "") -> list[Path]:
    """Write ``<prefix>ape.zip`` and ``<prefix>rpe.zip`` into ``folder``; RunError without reference poses."""
    from evo.core.result import Result
    from evo.tools.file_interface import save_res_file

    reference = scored.reference
    if reference is None:
        raise RunError("evo result files need reference poses (at least 2); the dataset has none")
    if len(reference) < 2:
        # said "the dataset has none" also when the reference had poses but only one was matched to the file
        raise RunError(f"evo result files need at least 2 poses scored against reference poses; {len(reference)} was")
    folder.mkdir(parents=True, exist_ok=True)
    label = str(scored.header["method"])
    ref_name = f"{scored.dataset} reference"
    travel = se2.cumulative_length(reference)
    seconds = scored.timestamps - scored.timestamps[0]

    ape = Result()
    ape_errors = position_errors(scored.poses, reference, "rigid")
    ape.add_info(
        {
            "title": APE_TITLE,
            "ref_name": ref_name,
            "est_name": label,
            "label": "APE (m)",
        }
    )
    ape.add_stats(_stats(ape_errors))
    ape.add_np_array("error_array", ape_errors)
    ape.add_np_array("timestamps", scored.timestamps)
    ape.add_np_array("seconds_from_start", seconds)
    ape.add_np_array("distances_from_start", travel)

    pairs = pair_indices(reference, 1, "frames")
    rpe_errors = np.hypot(*relative_errors(scored.poses, reference, pairs)[:, :2].T)
    rpe = Result()
    rpe.add_info(
        {
            "title": RPE_TITLE,
            "ref_name": ref_name,
            "est_name": label,
            "label": "RPE (m)",
        }
    )
    rpe.add_stats(_stats(rpe_errors))
    rpe.add_np_array("error_array", rpe_errors)
    rpe.add_np_array("timestamps", scored.timestamps[pairs[:, 1]])
    rpe.add_np_array("seconds_from_start", seconds[pairs[:, 1]])
    rpe.add_np_array("distances_from_start", travel[pairs[:, 1]])

    written = []
    for name, result in ((APE_FILE, ape), (RPE_FILE, rpe)):
        path = folder / f"{prefix}{name}"
        atomic_write(path, partial(save_res_file, result_obj=result))
        written.append(path)
    return written
