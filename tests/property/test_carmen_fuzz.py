"""Random and mutated lines fed to the CARMEN parser raise only documented DataError subclasses."""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.carmen.loader import CarmenLoader

VALID = [
    "PARAM robot_frontlaser_offset 0.1 0 host 0",
    "ODOM 0.5 0.25 0.1 0 0 0 {t} host {t}",
    "FLASER 4 1.0 2.0 81.91 3.5 0.5 0.25 0.1 0.5 0.25 0.1 {t} host {t}",
    "TRUEPOS 1 2 0.3 1 2 0.3 {t} host {t}",
    "ROBOTLASER1 0 -1.57 3.14 0.785 80 0.01 0 5 1 2 3 4 5 0 0 0 0 0 0 0 0 0 0 0 0 {t} host {t}",
    "NEFF 12.3",
    "# comment",
]
TOKENS = st.sampled_from(
    [
        "FLASER",
        "ODOM",
        "ROBOTLASER1",
        "RAWLASER1",
        "TRUEPOS",
        "PARAM",
        "nan",
        "-1",
        "inf",
        "1e308",
        "0",
        "3",
        "180",
        "x",
        "#",
        "",
        "host",
        "1.5",
        "-0",
        "1_0",
        "١",
    ]
)


def base_lines(count: int) -> list[str]:
    return [VALID[i % len(VALID)].format(t=0.5 * i) for i in range(count)]


def mutate(line: str, ops: list[tuple[int, int, str]]) -> str:
    tokens = line.split(" ")
    for kind, where, token in ops:
        i = where % (len(tokens) + 1)
        if kind == 0 and tokens:
            tokens.pop(i % len(tokens))
        elif kind == 1:
            tokens.insert(i, token)
        elif tokens:
            tokens[i % len(tokens)] = token
    return " ".join(tokens)


def parse(text: bytes, **options: object) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.clf"
        path.write_bytes(text)
        try:
            seq = CarmenLoader().load(path, **options)
            for frame in seq.frames():
                assert frame.scan.ranges.shape == frame.scan.angles.shape
        except DataError:
            pass


@settings(max_examples=150, deadline=None)
@given(st.lists(st.binary(max_size=80), max_size=8))
def test_random_bytes(lines: list[bytes]) -> None:
    parse(b"\n".join(lines))


@settings(max_examples=250, deadline=None)
@given(
    st.integers(1, 14),
    st.integers(0, 13),
    st.lists(st.tuples(st.integers(0, 2), st.integers(0, 40), TOKENS), min_size=1, max_size=4),
    st.sampled_from(["laser-pose", "odom", "odom-segments"]),
    st.sampled_from(["auto", "none", "laser-pose"]),
)
def test_mutated_valid_lines(
    count: int, target: int, ops: list[tuple[int, int, str]], odometry: str, reference: str
) -> None:
    lines = base_lines(count)
    lines[target % count] = mutate(lines[target % count], ops)
    parse(("\n".join(lines) + "\n").encode(), odometry=odometry, reference=reference)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.text(alphabet=st.characters(codec="utf-8"), max_size=60), max_size=6))
def test_random_text_after_a_valid_prefix(lines: list[str]) -> None:
    parse(("\n".join(base_lines(5) + lines)).encode("utf-8"))
