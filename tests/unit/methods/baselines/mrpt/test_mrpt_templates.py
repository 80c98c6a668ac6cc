"""INI templates: every config field has a placeholder and every placeholder a value."""

from __future__ import annotations

import hashlib

import pytest
from pydantic import BaseModel

from albot1.errors import ConfigError
from albot1.methods.baselines.errors import BaselineError
from albot1.methods.baselines.mrpt.config import MrptIcpConfig, MrptRbpfConfig
from albot1.methods.baselines.mrpt.mapper import MrptIcpMapper, MrptRbpfMapper
from albot1.methods.baselines.mrpt.templates import ini_value, render
from albot1.methods.registry import resolve_config


def _ini(text: str) -> dict[str, str]:
    out = {}
    for line in text.splitlines():
        if "=" in line and not line.lstrip().startswith("#"):
            key, _, value = line.partition("=")
            out[key.strip()] = value.strip()
    return out


def test_icp_ini_carries_the_config_and_is_headless() -> None:
    config = MrptIcpConfig.model_validate(MrptIcpMapper.presets["default"])
    ini = _ini(render("icp-slam", config, rawlog_file="in.rawlog", output_dir="out"))
    assert ini["thresholdDist"] == "0.3" and ini["ICP_algorithm"] == "icpClassic"
    assert ini["insertionAngDistance"] == "45.0" and ini["onlyUniqueRobust"] == "1"
    assert ini["logOutput_dir"] == "out" and ini["rawlog_file"] == "in.rawlog"
    assert ini["SHOW_PROGRESS_3D_REAL_TIME"] == "0" and ini["SAVE_3D_SCENE"] == "0" and ini["LOG_FREQUENCY"] == "0"
    assert "cpu_limit_s" not in ini and "${" not in render("icp-slam", config, rawlog_file="a", output_dir="b")


def test_rbpf_ini_has_one_update_threshold_and_the_seed() -> None:
    config = MrptRbpfConfig.model_validate(MrptRbpfMapper.presets["optimal-sampling"])
    ini = _ini(render("rbpf-slam", config, rawlog_file="in.rawlog", output_dir="out", seed=5))
    assert ini["RANDOM_SEED"] == "5" and ini["PF_algorithm"] == "3" and ini["sampleSize"] == "25"
    assert ini["localizeLinDistance"] == ini["insertionLinDistance"] == "1.0"
    assert ini["localizeAngDistance_deg"] == ini["insertionAngDistance_deg"] == "40.0"
    assert ini["resolution"] == "0.07" and ini["SHOW_PROGRESS_IN_WINDOW"] == "0"


def test_rbpf_ini_carries_the_proposal_and_weight_settings() -> None:
    config = MrptRbpfConfig.model_validate(MrptRbpfMapper.presets["default"])
    changed = config.model_copy(update={"icp_covariance_var_points_m2": 0.01, "pow_factor": 1.0})
    ini = _ini(render("rbpf-slam", changed, rawlog_file="in.rawlog", output_dir="out", seed=0))
    assert ini["covariance_varPoints"] == "0.01" and ini["powFactor"] == "1.0"
    assert ini["ICP_covariance_method"] == "icpCovFiniteDifferences" and ini["PF_algorithm"] == "2"


class _Extra(BaseModel):
    surplus_m: float = 1.0


def test_a_field_without_placeholder_or_a_missing_value_is_an_error() -> None:
    with pytest.raises(
        BaselineError, match=r"fields without a placeholder: surplus_m; placeholders without a value: .*icp_alfa"
    ):
        render("icp-slam", _Extra(), rawlog_file="a", output_dir="b")
    config = MrptIcpConfig.model_validate(MrptIcpMapper.presets["default"])
    with pytest.raises(BaselineError, match="placeholders without a value: output_dir"):
        render("icp-slam", config, rawlog_file="a")
    with pytest.raises(BaselineError, match="no INI template"):
        render("graph-slam", config)


def test_values_are_written_as_mrpt_reads_them() -> None:
    assert (ini_value(True), ini_value(False), ini_value(0.1), ini_value(3), ini_value("x")) == (
        "1",
        "0",
        "0.1",
        "3",
        "x",
    )
    with pytest.raises(BaselineError, match="non-finite"):
        ini_value(float("nan"))


#: sha256 of the default preset's rendered INI (rawlog in.rawlog, output out, seed 0) as of main d1e7791.
#: Why pinned: fields added for issue 21 (PF_algorithm 0 and 1, ...) must leave the default filter's INI,
#: and so its runs, bit for bit the same; a deliberate change of the default updates this value.
DEFAULT_RBPF_INI_SHA256 = "2d1f4b65864e0233227171b5ba39f8675d658c38b6660b3828cb52b50f3774d1"


def test_default_rbpf_ini_is_unchanged() -> None:
    config = MrptRbpfConfig.model_validate(MrptRbpfMapper.presets["default"])
    text = render("rbpf-slam", config, rawlog_file="in.rawlog", output_dir="out", seed=0)
    ini = _ini(text)
    assert ini["PF_algorithm"] == "2" and ini["adaptiveSampleSize"] == "0" and ini["powFactor"] == "0.01"
    assert hashlib.sha256(text.encode("ascii")).hexdigest() == DEFAULT_RBPF_INI_SHA256


def test_rbpf_filter_choices_are_accepted_as_set_on_the_command_line() -> None:
    """``--set pf_algorithm=0`` comes as text; the standard proposal (0) and the auxiliary PF (1) are MRPT's too."""
    config = resolve_config("mrpt-rbpf", overrides={"pf_algorithm": "0", "resampling_method": "3"})
    assert isinstance(config, MrptRbpfConfig) and (config.pf_algorithm, config.resampling_method) == (0, 3)
    ini = _ini(render("rbpf-slam", config, rawlog_file="in.rawlog", output_dir="out", seed=0))
    assert ini["PF_algorithm"] == "0" and ini["resamplingMethod"] == "3"
    assert resolve_config("mrpt-rbpf", overrides={"pf_algorithm": "1"}).pf_algorithm == 1  # type: ignore[attr-defined]
    for bad in ("4", "x", "-1", "2.0"):
        with pytest.raises(ConfigError, match="pf_algorithm"):
            resolve_config("mrpt-rbpf", overrides={"pf_algorithm": bad})


def test_auxiliary_standard_preset_is_the_filter_measured_for_issue_21() -> None:
    """The preset must stay the configuration of its rows in docs/baselines.md (PF_algorithm 1, powFactor 1,
    GMapping's odometry noise in the rawlog's motion model), else those rows describe another filter."""
    config = MrptRbpfConfig.model_validate(MrptRbpfMapper.presets["auxiliary-standard"])
    ini = _ini(render("rbpf-slam", config, rawlog_file="in.rawlog", output_dir="out", seed=0))
    assert ini["PF_algorithm"] == "1" and ini["powFactor"] == "1.0" and ini["sampleSize"] == "30"
    motion = (config.motion_a1, config.motion_a2, config.motion_a3, config.motion_a4)
    assert motion == (0.1, 0.1, 0.2, 0.2)
