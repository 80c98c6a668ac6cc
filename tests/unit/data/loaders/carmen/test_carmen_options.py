"""The CARMEN loader's options, parsed in one place: the catalog's fields apart, every CARMEN option checked."""

from __future__ import annotations

from pathlib import Path

import pytest

from albot1.data.errors import DataError
from albot1.data.loaders.carmen.options import CarmenOptions, describe_odometry, describe_reference, parse_options

LOG = Path("log.clf")


def test_catalog_fields_are_split_off_and_the_rest_validated() -> None:
    given = {"relations": "r.relations", "license": "CC0", "citation": "X", "odometry": "odom", "max_range": "30"}
    parsed = parse_options(LOG, given)
    assert parsed.relations == "r.relations" and parsed.license == "CC0" and parsed.citation == "X"
    assert parsed.carmen == CarmenOptions(odometry="odom", max_range=30.0)
    assert given["max_range"] == "30"  # the caller's options are not changed


def test_defaults_without_options() -> None:
    parsed = parse_options(LOG, {})
    assert parsed.relations is None and parsed.license == "" and parsed.citation == ""
    assert parsed.carmen == CarmenOptions()


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"odometry": "gps"}, r"log\.clf: odometry='gps'; expected one of laser-pose, odom, odom-segments"),
        ({"reference": "x"}, r"log\.clf: reference='x'; expected one of none, laser-pose, truepos, auto"),
        ({"laser": "SONAR"}, r"log\.clf: laser='SONAR'; expected one of "),
        ({"max_range": "-1"}, r"log\.clf: max_range=-1\.0; expected a positive number of metres"),
        ({"max_range": "far"}, r"log\.clf: max_range='far'; expected a number"),
        ({"time_tolerance": "nan"}, r"log\.clf: time_tolerance=nan; expected seconds >= 0 \(or inf\)"),
        ({"colour": "red"}, r"log\.clf: unknown CARMEN loader option\(s\) colour; expected some of "),
    ],
)
def test_each_bad_option_is_one_line_naming_the_file_value_and_expectation(options: dict, message: str) -> None:
    with pytest.raises(DataError, match=message):
        parse_options(LOG, options)


def test_the_metadata_says_which_fields_a_source_reads() -> None:
    assert describe_odometry("laser-pose", "FLASER") == "FLASER odom_x odom_y odom_theta fields"
    assert describe_odometry("laser-pose", "ROBOTLASER1") == "ROBOTLASER1 robot_x robot_y robot_theta fields"
    assert describe_reference("none", "FLASER") == ""
    assert describe_reference("laser-pose", "FLASER") == (
        "FLASER x y theta fields (the laser's pose) composed with the inverse laser mount: the robot's pose"
    )
