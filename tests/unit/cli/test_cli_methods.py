"""`albot1 methods [--presets] [METHOD] [--json]`."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from albot1.cli.app import app
from albot1.methods.registry import method_registry

runner = CliRunner()


def test_plain_listing_is_one_line_per_method() -> None:
    result = runner.invoke(app, ["methods"])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    # one row per method; an unavailable one (MRPT's apps not installed here) has its reason on an indented line
    rows = [line for line in lines if not line.startswith(" ")]
    assert [row.split()[0] for row in rows] == method_registry().names()
    assert rows[1].split(None, 2) == ["albot1", "available", "the Albot1 perceptual mapper (thesis chapter 3)"]
    # every row's columns start at the same place, the longest name and the longest status included
    assert {row.index(row.split()[1]) for row in rows} == {len("albot1-places") + 2}
    status_width = max(len(row.split()[1]) for row in rows)
    assert {row.index(row.split(None, 2)[2]) for row in rows} == {len("albot1-places") + 2 + status_width + 2}
    for before, line in zip(lines, lines[1:], strict=False):
        if line.startswith(" "):
            assert line.strip().startswith("-> ") and before.split()[1] == "unavailable"


def test_presets_table_of_one_method() -> None:
    result = runner.invoke(app, ["methods", "--presets", "albot1"])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0] == "albot1: the Albot1 perceptual mapper (thesis chapter 3)"
    assert "environment prefix ALBOT1_ALBOT1_" in lines[1]
    assert lines[2].startswith("  presets file ") and lines[2].endswith("baselines/albot1.toml")
    header = next(line for line in lines if line.lstrip().startswith("field"))
    assert header.split() == ["field", "unit", "type", "default", "meaning"]
    row = next(line for line in lines if line.strip().startswith("corner_min_angle_deg"))
    assert row.split()[:4] == ["corner_min_angle_deg", "deg", "float", "30.0"]
    row = next(line for line in lines if line.strip().startswith("motion_model"))
    assert row.split()[:4] == ["motion_model", "-", "thesis|exact", "thesis"]
    row = next(line for line in lines if line.strip().startswith("accelerate"))
    assert row.split()[:4] == ["accelerate", "-", "bool", "true"]
    tail = lines[lines.index("  presets (fields that differ from default):") + 1 :]
    assert tail == [
        "    default  the default column above",
        "    thesis   (same as default)",
        "    exact    motion_model = exact",
        "    literal  continuation_tolerance_m = 0.0 m, end_spacing_max_m = 0.0 m, delete_margin_from = boundary",
        "    plus     end_spacing_max_m = 0.0 m, surface_fit = tls, motion_model = exact, pose_estimate = robust, "
        "scan_refinement = true, scan_overlap = surface, scan_overhang_m = 0.05 m, odometry_prior = adaptive, "
        "degenerate_sd_m = 0.05 m, ambiguity_probability = 0.99, turn_bound_floor_deg = 3.0 deg, "
        "turn_bound_statistic = 40.0, view_noise_learning_rate = 0.05, kept_views_teach = true",
    ]


def test_presets_json_of_every_method() -> None:
    result = runner.invoke(app, ["methods", "--presets", "--json"])
    assert result.exit_code == 0, result.output
    records = {record["name"]: record for record in json.loads(result.output)["methods"]}
    assert list(records) == method_registry().names()
    albot1 = records["albot1"]
    assert albot1["config_model"] == "albot1.methods.albot1.mapping.config.Albot1Config"
    assert albot1["presets"] == {
        "default": {},
        "thesis": {},
        "exact": {"motion_model": "exact"},
        "literal": {"continuation_tolerance_m": 0.0, "end_spacing_max_m": 0.0, "delete_margin_from": "boundary"},
        "plus": {
            "end_spacing_max_m": 0.0,
            "surface_fit": "tls",
            "motion_model": "exact",
            "pose_estimate": "robust",
            "scan_refinement": True,
            "scan_overlap": "surface",
            "scan_overhang_m": 0.05,
            "odometry_prior": "adaptive",
            "degenerate_sd_m": 0.05,
            "ambiguity_probability": 0.99,
            "turn_bound_floor_deg": 3.0,
            "turn_bound_statistic": 40.0,
            "view_noise_learning_rate": 0.05,
            "kept_views_teach": True,
        },
    }
    field = next(f for f in albot1["fields"] if f["name"] == "delete_margin_m")
    assert field["unit"] == "m" and field["default"] == 0.4 and field["type"] == "float"
    assert field["description"].startswith("Algorithm 3 line 9")
    odometry = records["odometry"]
    assert odometry["presets_file"].endswith("baselines/odometry.toml")
    assert odometry["presets"]["sparse-map"] == {"map_every": 10}
    assert [f["name"] for f in odometry["fields"]] == ["map_voxel_m", "map_every"]


def test_json_without_presets_has_no_fields() -> None:
    result = runner.invoke(app, ["methods", "--json"])
    assert result.exit_code == 0, result.output
    record = json.loads(result.output)["methods"][0]
    assert record == {
        "name": "odometry",
        "available": True,
        "requires": [],
        "description": method_registry().get("odometry").description,
        "env_prefix": "ALBOT1_ODOMETRY_",
    }


def test_unknown_method_is_a_config_error() -> None:
    result = runner.invoke(app, ["methods", "nope"])
    assert result.exit_code != 0
    assert "unknown method 'nope'" in str(result.exception)
