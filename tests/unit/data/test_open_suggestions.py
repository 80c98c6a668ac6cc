"""Dataset-name typos and wrong option values: the closest name, not every name on one line."""

from __future__ import annotations

import pytest

from albot1.data import catalog
from albot1.data.errors import DatasetNotFoundError
from albot1.data.open import open_sequence


def test_a_dataset_typo_suggests_the_closest_and_points_to_the_listing() -> None:
    with pytest.raises(DatasetNotFoundError) as caught:
        open_sequence("synthetic-ofice-loop")
    message = str(caught.value)
    assert "(did you mean 'synthetic-office-loop'" in message
    assert "`albot1 datasets list` lists all" in message
    assert "acapulco-corrected" not in message  # not every name on one line


def test_a_catalog_typo_suggests_the_closest() -> None:
    with pytest.raises(DatasetNotFoundError, match=r"unknown dataset 'inel' \(did you mean 'intel'"):
        catalog.get("inel")


def test_a_wrong_odometry_value_on_a_world_names_the_value_and_the_valid_one() -> None:
    with pytest.raises(DatasetNotFoundError) as caught:
        open_sequence("synthetic-office-loop?odometry=referenc")
    message = str(caught.value)
    assert "odometry='referenc' (did you mean 'reference'?)" in message
    assert "takes odometry=reference only" in message and "unknown" not in message
