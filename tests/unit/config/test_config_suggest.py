"""One "did you mean" for every typed name (albot1.config.suggest)."""

from __future__ import annotations

from albot1.config.suggest import LIST_AT_MOST, closest, did_you_mean, unknown_name_message

METHODS = ["odometry", "albot1", "albot1-places", "kiss-icp", "gtsam-graph"]


def test_case_and_underscores_are_folded() -> None:
    assert closest("kiss_icp", METHODS)[0] == "kiss-icp"
    assert closest("Thesis", ["default", "thesis", "exact"])[0] == "thesis"
    assert closest("pluss", ["default", "thesis", "plus"]) == ["plus"]


def test_nothing_close_suggests_nothing() -> None:
    assert closest("zzzz", METHODS) == []
    assert did_you_mean("zzzz", METHODS) == ""
    assert did_you_mean("odometri", METHODS) == " (did you mean 'odometry'?)"


def test_a_long_list_is_not_printed_but_pointed_to() -> None:
    known = [f"name-{i:02d}" for i in range(LIST_AT_MOST + 17)]
    message = unknown_name_message("dataset", "name-0x", known, listing="albot1 datasets list")
    assert message.startswith("unknown dataset 'name-0x' (did you mean ")
    assert message.endswith(f"`albot1 datasets list` lists all {len(known)}")
    assert message.count("name-") <= 4  # the typo and at most three suggestions, not the whole list
    short = unknown_name_message("method", "kiss_icp", METHODS, listing="albot1 methods")
    assert short == f"unknown method 'kiss_icp' (did you mean 'kiss-icp'?); expected one of: {', '.join(METHODS)}"
