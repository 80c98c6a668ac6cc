"""Property tests of the degradation SPEC parser: any string parses or raises DegradationSpecError."""

from __future__ import annotations

import math

from hypothesis import given
from hypothesis import strategies as st

from albot1.data.degrade import EXPECTED_SPEC, DegradationSpecError, parse_spec

KINDS = st.sampled_from(
    ["none", "thesis", "gauss", "bias", "offset", "dropout", "GAUSS", "Bias", "Dropout", "noise", "", " thesis "]
)
NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**6), 10**6).map(str),
    st.text(alphabet="0123456789.-+eE_ naif", max_size=8),
)


def _check(spec: str) -> None:
    try:
        deg = parse_spec(spec)
    except DegradationSpecError as exc:
        assert repr(spec) in str(exc)
        assert EXPECTED_SPEC in str(exc) or (
            "changes nothing (" in str(exc)
            and str(exc).endswith("its runs would repeat the undegraded run under a degraded label; write none")
        )
        assert "\n" not in str(exc)
        return
    assert deg.kind in ("none", "thesis", "gauss", "bias", "offset", "dropout")
    assert math.isfinite(deg.a) and math.isfinite(deg.b) and math.isfinite(deg.c)
    if deg.kind == "gauss":
        assert deg.a >= 0 and deg.b >= 0
    if deg.kind == "dropout":
        assert 0 <= deg.a < 1
    # What parsed re-parses to the same degradation from its canonical text.
    assert parse_spec(deg.spec).kind == deg.kind
    assert deg.kind in ("none", "thesis") or deg.a or deg.b or deg.c  # a no-op is refused, never parsed


@given(st.text(max_size=40))
def test_random_strings_parse_or_raise_the_documented_error(spec: str) -> None:
    _check(spec)


@given(KINDS, st.lists(NUMBERS, max_size=4), st.sampled_from([":", "::", ": "]))
def test_mutated_specs_parse_or_raise_the_documented_error(kind: str, values: list[str], sep: str) -> None:
    _check(sep.join([kind, *values]) if values else kind)


@given(st.floats(0, 10, allow_nan=False), st.floats(0, 45, allow_nan=False))
def test_valid_gauss_specs_parse_to_their_values(sigma_xy: float, sigma_deg: float) -> None:
    if sigma_xy == sigma_deg == 0:  # changes nothing: refused (tests/unit/data/test_degrade_checks.py)
        return
    deg = parse_spec(f"gauss:{sigma_xy!r}:{sigma_deg!r}")
    assert deg.kind == "gauss"
    # to the 12 significant digits of the label, which is what `albot1 run` and suites run
    assert deg.a == float(f"{sigma_xy:.12g}")
    assert deg.b == math.radians(float(f"{sigma_deg:.12g}"))


@given(
    kind=st.sampled_from(["bias", "offset"]),
    mantissa=st.integers(1, 10**12 - 1),
    exponent=st.integers(0, 290),
    sign=st.sampled_from([1, -1]),
)
def test_a_turn_per_step_is_its_exact_remainder_of_a_whole_turn(
    kind: str, mantissa: int, exponent: int, sign: int
) -> None:
    """out49: `bias:0:1e20` turned each step by radians(1e20)'s float noise, not by 1e20 deg = 280 deg.

    A rotation of at most 12 significant digits (what the SPEC keeps) acts as its remainder of 360 deg,
    computed exactly here with integers; below a whole turn nothing changes.
    """
    written = sign * mantissa * 10**exponent
    text = f"{written:.12g}"
    rest = float(text)
    exact = math.copysign(abs(int(rest)) % 360, rest) if abs(rest) >= 360 else rest  # the float's own value mod 360
    values = f"0.1:{text}" if kind == "bias" else f"0.1:0:{text}"
    deg = parse_spec(f"{kind}:{values}")
    assert deg.b == math.radians(exact + 0.0)
    assert abs(math.degrees(deg.b)) < 360.0
    assert parse_spec(deg.spec) == deg  # the one spelling names the turn that runs


@given(kind=st.sampled_from(["none", "thesis", "gauss", "bias", "offset", "dropout"]), data=st.data())
def test_a_kind_with_one_letter_missing_is_suggested(kind: str, data: st.DataObject) -> None:
    """out49: `gaus:0.1:1` read "unknown kind 'gaus'" without the "did you mean" every other name gets."""
    at = data.draw(st.integers(0, len(kind) - 1))
    typo = kind[:at] + kind[at + 1 :]
    spec = f"{typo}:0.1:1"
    try:
        parse_spec(spec)
    except DegradationSpecError as exc:
        message = str(exc)
    else:
        raise AssertionError(f"{spec!r} parsed")
    assert message.startswith(f"degradation {spec!r} not understood (unknown kind {typo!r}) (did you mean ")
    assert repr(kind) in message.split("did you mean ", 1)[1].split("?)", 1)[0]
    assert message.endswith(EXPECTED_SPEC) and "\n" not in message
