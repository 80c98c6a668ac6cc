"""Albot1+ on fr-clinic, the log whose learnt odometry spread held the views' own error: below its odometry.

Measured (``docs/albot1-mapper.md``, "View noise" and "Kept views teach, adopted"), relation metric, mean m:
0.952 with neither the view noise nor kept views teaching; `plus` 0.231 on the raw log and 0.385 / 0.217 with a
negligible perturbation (``gauss:0.002:0.02``, seeds 1 and 2), where without kept views teaching it was 0.526 and
0.779 / 0.693; the odometry's own 0.615 m. The bounds leave room for library versions; one burst coming or going
moves a run by tens of centimetres, so the test asks for the side of the odometry, not for the centimetre, and it
asks it of a perturbed repeat too, since one run below the odometry was luck before.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from albot1.data.open import open_sequence
from albot1.metrics.relations import relation_metric
from albot1.runs.execute import run_method

NEITHER = {"view_noise_learning_rate": 0.0, "kept_views_teach": False}


@pytest.mark.slow
@pytest.mark.whole_log
def test_plus_takes_fr_clinic_below_its_odometry_and_a_perturbed_repeat_too(
    data_file: Callable[[str], Path],
) -> None:
    data_file("radish/fr-clinic_robotlaser.clf.bz2")
    data_file("radish/fr-clinic.relations")
    sequence = open_sequence("fr-clinic")
    errors = {}
    for label, overrides, degradation, seed in (
        ("neither", NEITHER, "none", 0),
        ("plus", None, "none", 0),
        ("plus perturbed", None, "gauss:0.002:0.02", 1),
    ):
        result = run_method("albot1", sequence, preset="plus", overrides=overrides, degradation=degradation, seed=seed)
        errors[label] = relation_metric(result.timestamps, result.poses, result.relations, outside="exclude")[
            "translation_m"
        ]["mean"]
        odometry = relation_metric(result.timestamps, result.odometry, result.relations, outside="exclude")
        errors[label + " odometry"] = odometry["translation_m"]["mean"]
    assert errors["neither"] > 0.85, errors
    assert errors["plus"] < 0.5 * errors["plus odometry"], errors
    assert errors["plus perturbed"] < errors["plus perturbed odometry"] < 0.62, errors
