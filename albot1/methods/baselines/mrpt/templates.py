"""Render an MRPT application's INI file from its template and a typed config.

Why templates and not MRPT's example files: the examples open windows, write
3D scenes every few steps and point at files elsewhere; the templates in
``templates/`` fix what must always hold (headless, no periodic logs, one
occupancy grid, ...) and leave a ``${field}`` placeholder for every value
that comes from the config model, so a config field and an INI key cannot
drift apart unnoticed: a placeholder without a value, or a config field
that no placeholder uses, is an error.
"""

from __future__ import annotations

import math
import string
from importlib import resources
from typing import Any

from pydantic import BaseModel

from albot1.methods.baselines.errors import BaselineError

#: Config fields the wrapper uses itself (never written into an INI file).
WRAPPER_FIELDS = frozenset(
    {
        "cpu_limit_s",
        "memory_limit_mb",
        "min_path_ratio",
        "max_path_ratio",
        "max_step_correction_m",
        "max_step_correction_deg",
        "map_occupied_probability",
        "motion_a1",
        "motion_a2",
        "motion_a3",
        "motion_a4",
        "motion_min_std_xy_m",
        "motion_min_std_theta_deg",
    }
)


def template_text(app: str) -> str:
    """The INI template of ``app`` (``icp-slam`` or ``rbpf-slam``), from the package's ``templates/``."""
    try:
        return resources.files(__package__).joinpath("templates", f"{app}.ini").read_text(encoding="ascii")
    except FileNotFoundError:
        raise BaselineError(f"no INI template for MRPT application {app!r}") from None


def ini_value(value: Any) -> str:
    """A config value as MRPT's INI parser reads it (bools as 1/0, floats round-tripping exactly)."""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        if not math.isfinite(value):
            raise BaselineError(f"cannot write the non-finite value {value!r} into an MRPT INI file")
        return repr(value)
    return str(value)


def render(app: str, config: BaseModel, **run_values: Any) -> str:
    """The INI text of ``app`` for ``config`` plus per-run values (paths, seed).

    Every placeholder must be filled and every config field outside
    :data:`WRAPPER_FIELDS` must be used by a placeholder.
    """
    template = string.Template(template_text(app))
    placeholders = {m.group("named") or m.group("braced") for m in template.pattern.finditer(template.template)}
    placeholders.discard(None)
    values = {name: ini_value(v) for name, v in config.model_dump().items() if name not in WRAPPER_FIELDS}
    values.update({name: ini_value(v) for name, v in run_values.items()})
    unused = sorted(set(values) - placeholders)
    missing = sorted(placeholders - set(values))
    if unused or missing:
        raise BaselineError(
            f"the {app} INI template and {type(config).__name__} disagree: "
            f"fields without a placeholder: {', '.join(unused) or 'none'}; "
            f"placeholders without a value: {', '.join(missing) or 'none'}"
        )
    return template.substitute(values)
