"""Published figures of SLAM systems the project cannot run (``published.toml`` beside this module).

Why a data file: the thesis's Experiment 5 compares Albot1 with DP-SLAM,
which has no packaged implementation. Users expect the table to say what
is known about it, and what is known must be a cited, published number (or
the explicit finding that there is none), never a number produced here.
The report reads :func:`published_systems` and labels every figure
"published" with its source.
"""

from __future__ import annotations

import tomllib
from decimal import Decimal
from functools import lru_cache
from importlib.resources import files
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from albot1.config.validation import describe_errors
from albot1.errors import ConfigError

PUBLISHED_FILE = "published.toml"


class PublishedFigure(BaseModel):
    """One published figure on one log, with where it was printed."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    log: str = Field(min_length=1, description="catalog name of the log (e.g. intel)")
    #: relation error (Kuemmerle et al. 2009: mean +/- std over all relations), or the whole-log processing time
    #: on the authors' machine (``wall_clock_s``; ``note`` names the machine)
    metric: Literal["relation_translation_m", "relation_rotation_deg", "wall_clock_s"]
    mean: float = Field(ge=0, allow_inf_nan=False)
    std: float | None = Field(default=None, ge=0, allow_inf_nan=False)
    source: str = Field(min_length=1, description="table / page of the cited work")
    note: str = ""
    #: the decimals the source printed the figure with, where the numbers cannot say it (0.10 ± 0.20: a float
    #: keeps 0.1 and 0.2); None: worked out from the numbers (:attr:`decimals`)
    printed_decimals: int | None = Field(default=None, ge=0, le=12)

    @property
    def decimals(self) -> int:
        """The decimals the source printed: ``printed_decimals``, else the most ``mean`` and ``std`` are written with.

        Why: a published 0.044 is not 0.0440, and 0.4 deg is not 0.400 deg; padding a figure to a table's
        own decimals claims a precision its authors did not give. TOML keeps a number's digits but a
        float drops trailing zeros (0.220 reads 0.22), which the other number of the pair restores
        (0.220 +/- 0.296: three decimals), as it does for every figure of ``published.toml``.
        """
        if self.printed_decimals is not None:
            return self.printed_decimals
        return max(printed_decimals(v) for v in (self.mean, self.std) if v is not None)

    def text(self) -> str:
        """``mean ± std`` (``mean`` without a std) with the decimals the source printed (:attr:`decimals`)."""
        std = "" if self.std is None else f" ± {self.std:.{self.decimals}f}"
        return f"{self.mean:.{self.decimals}f}{std}"


def printed_decimals(value: float) -> int:
    """Decimals of ``value``'s shortest text (0.0375 -> 4, 0.4 -> 1, 41.0 -> 0, 1e-05 -> 5)."""
    exponent = Decimal(repr(value)).normalize().as_tuple().exponent
    if not isinstance(exponent, int):  # NaN or infinity: the figures refuse them (``allow_inf_nan=False``)
        raise ValueError(f"{value!r} is not a finite number")
    return max(0, -exponent)


class PublishedSystem(BaseModel):
    """A system known only from its publications."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(min_length=1)
    label: str = Field(min_length=1)
    citation: str = Field(min_length=1)
    implementation: str = Field(min_length=1, description="why it is not run here")
    searched: str = Field(min_length=1, description="what was looked for (an empty figure list is a finding)")
    figures: tuple[PublishedFigure, ...] = ()


class _File(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    systems: tuple[PublishedSystem, ...]


@lru_cache(maxsize=1)
def published_systems() -> tuple[PublishedSystem, ...]:
    """Every system of ``published.toml``, validated (ConfigError naming the file otherwise)."""
    resource = files(__package__).joinpath(PUBLISHED_FILE)
    try:
        data = tomllib.loads(resource.read_text(encoding="utf-8"))
        return _File.model_validate(data).systems
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{resource}: not valid TOML: {exc}") from None
    except ValidationError as exc:
        raise ConfigError(f"{resource}: {describe_errors(exc)}") from None
